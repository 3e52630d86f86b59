// Turns a hit into a colour. Every effect is behind its own flag and its code sits in its own file under
// lib/effects/, which the Python side includes only when the scene's Style declares the effect
// (splinevis/effects.py). Nothing here refers to an effect's function unless its flag is defined.

#ifdef SV_MODEL_ROTATED
// A model drawn rotated (a volume on a rotated lattice): the ray cast works in the model frame, while the
// normal colours, the environment (z up) and the reflection lines are world-frame pictures.
uniform vec3 sv_world_from_model[3];  // rows of the rotation
vec3 sv_to_world(vec3 v) {
    return vec3(dot(sv_world_from_model[0], v), dot(sv_world_from_model[1], v), dot(sv_world_from_model[2], v));
}
#else
#define sv_to_world(v) (v)
#endif

vec4 sv_shade(SvHit h, vec3 rd) {
#ifdef SV_DEBUG_NO_SHADING
    // debug builds that time the ray cast alone (splinevis.terrain.program, option debug): a constant colour
    return vec4(sv_color, 1.0);
#endif
    vec3 n = normalize(h.normal);
    if (dot(n, rd) > 0.0) n = -n;  // two-sided: the normal faces the viewer
#if defined(SV_OUT_NORMALS)
    return vec4(sv_normal_color(sv_to_world(n)), 1.0);
#elif defined(SV_OUT_CURVATURE)
    return vec4(sv_curvature_color(h.curvature), 1.0);
#elif defined(SV_OUT_DRAFT)
    return vec4(sv_draft_color(sv_to_world(h.normal)), 1.0);
#elif defined(SV_OUT_DEPTH)
    return vec4(h.depth, 0.0, 0.0, 1.0);
#else
    vec3 base = sv_color;
#ifdef SV_COLORMAP
    base = sv_colormap(h.scalar);
#endif
#ifdef SV_TEXTURE
    base = sv_texture_color(h.uv, base);
#endif
    vec3 col = base;
#ifdef SV_NUM_LIGHTS
    col = sv_lights(n, -rd, base);
#endif
#ifdef SV_ENVIRONMENT
    col = mix(col, sv_environment(sv_to_world(reflect(rd, n))), 0.4);
#endif
#ifdef SV_REFLECTION_LINES
    col *= sv_reflection_lines(sv_to_world(reflect(rd, n)));
#endif
#ifdef SV_HIGHLIGHT_LINES
    col *= sv_highlight_lines(h.pos, n);
#endif
#ifdef SV_ISOPHOTES
    col *= sv_isophotes(n);
#endif
#ifdef SV_TRANSPARENCY
    return vec4(col, sv_opacity);
#else
    return vec4(col, 1.0);
#endif
#endif
}

// Turns a hit into a colour. Every effect is behind its own flag and its code sits in its own file under
// lib/effects/, which the Python side includes only when the scene's Style declares the effect
// (splinevis/effects.py). Nothing here refers to an effect's function unless its flag is defined.

vec4 sv_shade(SvHit h, vec3 rd) {
    vec3 n = normalize(h.normal);
    if (dot(n, rd) > 0.0) n = -n;  // two-sided: the normal faces the viewer
#if defined(SV_OUT_NORMALS)
    return vec4(sv_normal_color(n), 1.0);
#elif defined(SV_OUT_CURVATURE)
    return vec4(sv_curvature_color(h.curvature), 1.0);
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
    col = mix(col, sv_environment(reflect(rd, n)), 0.4);
#endif
#ifdef SV_REFLECTION_LINES
    col *= sv_reflection_lines(reflect(rd, n));
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

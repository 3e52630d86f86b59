// Reflection of a latitude-longitude environment image (z up): direction -> (longitude, latitude).
// The sampler (sv_environment_tex) is declared by VTK, which binds the texture set on the actor property.

vec3 sv_environment(vec3 r) {
    r = normalize(r);
    float u = atan(r.y, r.x) / 6.283185307179586 + 0.5;
    float v = acos(clamp(r.z, -1.0, 1.0)) / 3.141592653589793;
    return texture(sv_environment_tex, vec2(u, 1.0 - v)).rgb;
}

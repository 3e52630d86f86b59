// Base colour from an image draped over the parameter domain (hit.uv in [0,1]^2).
// The sampler (sv_texture_tex) is declared by VTK, which binds the texture set on the actor property.

vec3 sv_texture_color(vec2 uv) {
    return texture(sv_texture_tex, clamp(uv, 0.0, 1.0)).rgb;
}

// Base colour from the surface scalar through a colormap stored as a 256x1 RGBA texture.
// The sampler (sv_colormap_tex) is declared by VTK, which binds the texture set on the actor property.
uniform vec2 sv_scalar_range;

vec3 sv_colormap(float s) {
    float x = clamp((s - sv_scalar_range.x) / (sv_scalar_range.y - sv_scalar_range.x), 0.0, 1.0);
    return texture(sv_colormap_tex, vec2((x * 255.0 + 0.5) / 256.0, 0.5)).rgb;
}

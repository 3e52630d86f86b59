// Base colour from an image draped over the surface. hit.uv is the position in the model's parameter
// domain ([0,1]^2 over a terrain's grid extent); sv_texture_map = (scale_u, scale_v, shift_u, shift_v)
// geo-references the image: image uv = hit.uv * scale + shift (identity when the image covers exactly
// the grid; Style.texture_extent sets it for an image with its own extent). Outside the image the
// surface keeps its base colour.
// The sampler (sv_texture_tex) is declared by VTK, which binds the texture set on the actor property.
uniform vec4 sv_texture_map;

vec3 sv_texture_color(vec2 uv, vec3 base) {
    vec2 st = uv * sv_texture_map.xy + sv_texture_map.zw;
    if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0)))) return base;
    return texture(sv_texture_tex, st).rgb;
}

// One direction of the separable binomial smoothing [1, 2, 1] / 4, all four channels, with the border
// replicated (neighbours outside the texture are clamped to the edge texel).
//   sv_axis = ivec2(1, 0): along x (within a row); ivec2(0, 1): along y (within a column).
uniform sampler2D sv_src;
uniform ivec2 sv_axis;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 last = textureSize(sv_src, 0) - 1;
    vec4 a = texelFetch(sv_src, clamp(p - sv_axis, ivec2(0), last), 0);
    vec4 b = texelFetch(sv_src, p, 0);
    vec4 c = texelFetch(sv_src, clamp(p + sv_axis, ivec2(0), last), 0);
    // Scaling by 0.25 and 0.5 is exact (powers of two), so the two additions are the only roundings:
    // the error bound of smoothing on the CPU side counts two per output and direction.
    sv_frag_out0 = (0.25 * a + 0.25 * c) + 0.5 * b;
}

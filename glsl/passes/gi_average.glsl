// The averaging step A of bicubic subdivision [Losasso2003, sec. 5, Table 1]: the mask
// [1 2 1]^T [1 2 1] / 16 with the outermost sample cropped on every side, a Q x Q image becomes
// (Q-2) x (Q-2): output texel p is the mask centred on source texel p + 1.
// Separable with integer weights, each direction summed as (a + b) + (b + c), then one exact scaling by
// 1/16: 4 roundings on every path (9 terms: at most 8 in any order a compiler may choose). A half turn of
// the padding rules swaps the pairs, so the padding stays exact (Mesa keeps this form as written; it
// redistributes scalings inside the sums). CPU twin: splinevis.geometry_image.subdivision.average.
uniform sampler2D sv_src;

vec4 sv_row_sum(ivec2 c) {
    vec4 a = texelFetch(sv_src, c - ivec2(1, 0), 0);
    vec4 b = texelFetch(sv_src, c, 0);
    vec4 d = texelFetch(sv_src, c + ivec2(1, 0), 0);
    return (a + b) + (b + d);
}

void main() {
    ivec2 c = ivec2(gl_FragCoord.xy) + 1;
    vec4 lo = sv_row_sum(c - ivec2(0, 1));
    vec4 mid = sv_row_sum(c);
    vec4 hi = sv_row_sum(c + ivec2(0, 1));
    sv_frag_out0 = 0.0625 * ((lo + mid) + (mid + hi));
}

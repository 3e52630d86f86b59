// The splitting step L of bicubic subdivision of a padded geometry image [Losasso2003, sec. 5, Table 1]:
// a (m+1) x (m+1) image becomes (2m+1) x (2m+1), the source bilinearly interpolated at half-integers by the
// paper's floor formula. Texel (x, y) is column x, row y (see splinevis/gl/passes.py).
// With (I, J) the integer and (a, b) in {0, 1/2} the fractional parts of p / 2, the formula's weights are
// 0, 1/4, 1/2 or 1, so it is (1/4) ((A + B) + (C + D)) with A = g[I, J], B = g[I + o], C = g[I + o.x, J],
// D = g[I, J + o.y] and o = 2 (a, b) in {0, 1}^2 (a weight 1/2 is one texel fetched twice, a weight 1 four
// times). Rounding: the scaling is exact and at most 2 additions round (pairs of equal terms add exactly).
// The pairs are swapped by a half turn of the padding rules and the compiler keeps (A + B) + (C + D) as
// written, so the padding stays the X-cut padding bit for bit. CPU twin:
// splinevis.geometry_image.subdivision.split.
uniform sampler2D sv_src;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 I = p / 2;           // integer part of p / 2 (p >= 0)
    ivec2 o = p - 2 * I;       // twice the fractional part
    vec4 A = texelFetch(sv_src, I, 0);
    vec4 B = texelFetch(sv_src, I + o, 0);
    vec4 C = texelFetch(sv_src, ivec2(I.x + o.x, I.y), 0);
    vec4 D = texelFetch(sv_src, ivec2(I.x, I.y + o.y), 0);
    sv_frag_out0 = 0.25 * ((A + B) + (C + D));
}

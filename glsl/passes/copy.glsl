// Copy of the input texture, texel for texel: the identity pass (a chain's first or last step when a
// texture has to be duplicated, and the check that a pass round trip is exact).
uniform sampler2D sv_src;

void main() {
    sv_frag_out0 = texelFetch(sv_src, ivec2(gl_FragCoord.xy), 0);
}

// Colour-coded unit normals: rgb = (n + 1) / 2, the encoding of the paper's normal comparison figures.
vec3 sv_normal_color(vec3 n) {
    return 0.5 * (n + vec3(1.0));
}

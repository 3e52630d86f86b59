// The de Casteljau steps of lib/simplex/bb_triangle.glsl written out with constant indices (same ordering, same
// arithmetic), for loops that evaluate a patch many times: llvmpipe keeps the values in registers.
// Value f and barycentric first derivatives a of a quartic at l: D_u f = 4 dot(u, a).
void sv_tri_quartic_fa(in float b[15], vec3 l, out float f, out vec3 a) {
    float w0 = l.x * b[0] + l.y * b[1] + l.z * b[2];
    float w1 = l.x * b[1] + l.y * b[3] + l.z * b[4];
    float w2 = l.x * b[2] + l.y * b[4] + l.z * b[5];
    float w3 = l.x * b[3] + l.y * b[6] + l.z * b[7];
    float w4 = l.x * b[4] + l.y * b[7] + l.z * b[8];
    float w5 = l.x * b[5] + l.y * b[8] + l.z * b[9];
    float w6 = l.x * b[6] + l.y * b[10] + l.z * b[11];
    float w7 = l.x * b[7] + l.y * b[11] + l.z * b[12];
    float w8 = l.x * b[8] + l.y * b[12] + l.z * b[13];
    float w9 = l.x * b[9] + l.y * b[13] + l.z * b[14];
    float v0 = l.x * w0 + l.y * w1 + l.z * w2;
    float v1 = l.x * w1 + l.y * w3 + l.z * w4;
    float v2 = l.x * w2 + l.y * w4 + l.z * w5;
    float v3 = l.x * w3 + l.y * w6 + l.z * w7;
    float v4 = l.x * w4 + l.y * w7 + l.z * w8;
    float v5 = l.x * w5 + l.y * w8 + l.z * w9;
    float u0 = l.x * v0 + l.y * v1 + l.z * v2;
    float u1 = l.x * v1 + l.y * v3 + l.z * v4;
    float u2 = l.x * v2 + l.y * v4 + l.z * v5;
    a = vec3(u0, u1, u2);
    f = dot(l, a);
}

// Bound of |D_w D_w f| on the whole triangle, for a barycentric direction w (components summing to zero):
// the BB coefficients of D_w D_w f are 12 times the second differences of b along w [Farin2002, ch. 17.5];
// by the convex hull property their largest magnitude bounds the quadratic everywhere on the triangle.
float sv_tri_quartic_d2_bound(in float b[15], vec3 w) {
    float w0 = w.x * b[0] + w.y * b[1] + w.z * b[2];
    float w1 = w.x * b[1] + w.y * b[3] + w.z * b[4];
    float w2 = w.x * b[2] + w.y * b[4] + w.z * b[5];
    float w3 = w.x * b[3] + w.y * b[6] + w.z * b[7];
    float w4 = w.x * b[4] + w.y * b[7] + w.z * b[8];
    float w5 = w.x * b[5] + w.y * b[8] + w.z * b[9];
    float w6 = w.x * b[6] + w.y * b[10] + w.z * b[11];
    float w7 = w.x * b[7] + w.y * b[11] + w.z * b[12];
    float w8 = w.x * b[8] + w.y * b[12] + w.z * b[13];
    float w9 = w.x * b[9] + w.y * b[13] + w.z * b[14];
    float v0 = w.x * w0 + w.y * w1 + w.z * w2;
    float v1 = w.x * w1 + w.y * w3 + w.z * w4;
    float v2 = w.x * w2 + w.y * w4 + w.z * w5;
    float v3 = w.x * w3 + w.y * w6 + w.z * w7;
    float v4 = w.x * w4 + w.y * w7 + w.z * w8;
    float v5 = w.x * w5 + w.y * w8 + w.z * w9;
    return 12.0 * max(max(max(abs(v0), abs(v1)), max(abs(v2), abs(v3))), max(abs(v4), abs(v5)));
}

// Value f, barycentric first derivatives a and the quadratic de Casteljau coefficients d (ordered (2,0,0),
// (1,1,0), (1,0,1), (0,2,0), (0,1,1), (0,0,2)) of a quartic at l: sv_tri_quartic_jet of
// lib/simplex/bb_triangle.glsl with constant indices (same steps, same arithmetic).
void sv_tri_quartic_jet_unrolled(in float b[15], vec3 l, out float f, out vec3 a, out float d[6]) {
    float w0 = l.x * b[0] + l.y * b[1] + l.z * b[2];
    float w1 = l.x * b[1] + l.y * b[3] + l.z * b[4];
    float w2 = l.x * b[2] + l.y * b[4] + l.z * b[5];
    float w3 = l.x * b[3] + l.y * b[6] + l.z * b[7];
    float w4 = l.x * b[4] + l.y * b[7] + l.z * b[8];
    float w5 = l.x * b[5] + l.y * b[8] + l.z * b[9];
    float w6 = l.x * b[6] + l.y * b[10] + l.z * b[11];
    float w7 = l.x * b[7] + l.y * b[11] + l.z * b[12];
    float w8 = l.x * b[8] + l.y * b[12] + l.z * b[13];
    float w9 = l.x * b[9] + l.y * b[13] + l.z * b[14];
    d[0] = l.x * w0 + l.y * w1 + l.z * w2;
    d[1] = l.x * w1 + l.y * w3 + l.z * w4;
    d[2] = l.x * w2 + l.y * w4 + l.z * w5;
    d[3] = l.x * w3 + l.y * w6 + l.z * w7;
    d[4] = l.x * w4 + l.y * w7 + l.z * w8;
    d[5] = l.x * w5 + l.y * w8 + l.z * w9;
    float u0 = l.x * d[0] + l.y * d[1] + l.z * d[2];
    float u1 = l.x * d[1] + l.y * d[3] + l.z * d[4];
    float u2 = l.x * d[2] + l.y * d[4] + l.z * d[5];
    a = vec3(u0, u1, u2);
    f = dot(l, a);
}

// Per-fragment trimming: is the parameter point p inside the patch's trim loops? Even-odd count of the
// v-monotone rational Bezier pieces (degree <= 3) crossed by the ray from p towards +u; the crossing's u
// comes from bisection on the monotone v(t) = p.y, so the boundary is the exact curve at any zoom.
// Float64 twin and the derivation of the pieces: splinevis/nurbs/trim.py. Table layout: 8 texels per piece
// (splinevis.nurbs.trim.PIECE_FLOATS): 4 homogeneous control points (u w, v w, w, -), the hull's
// (umin, umax, vmin, vmax), (degree, -, -, -), one texel of padding.
// The sampler sv_trim_table is declared by VTK for the actor's texture (a harness declares it itself).

#ifndef SV_MAX_TRIM_PIECES
#define SV_MAX_TRIM_PIECES 4096
#endif
const int SV_TRIM_BISECTIONS = 26;  // t to 2^-26: below float32 resolution of t in [0, 1]

vec3 sv_trim_point(vec3 c[4], int degree, float t) {
    // de Casteljau on homogeneous points; unused control points are never read
    vec3 q0 = c[0], q1 = c[1], q2 = c[2], q3 = c[3];
    if (degree >= 3) { q0 = mix(q0, q1, t); q1 = mix(q1, q2, t); q2 = mix(q2, q3, t); }
    if (degree >= 2) { q0 = mix(q0, q1, t); q1 = mix(q1, q2, t); }
    q0 = mix(q0, q1, t);
    return q0;
}

bool sv_trim_inside(int start, int count, vec2 p) {
    if (count <= 0) return true;
    int crossings = 0;
    for (int k = 0; k < SV_MAX_TRIM_PIECES; ++k) {
        if (k >= count) break;
        ivec2 a = sv_table_address((start + k) * 8);
        vec3 c[4];
        for (int q = 0; q < 4; ++q) c[q] = texelFetch(sv_trim_table, a + ivec2(q, 0), 0).xyz;
        vec4 box = texelFetch(sv_trim_table, a + ivec2(4, 0), 0);
        int degree = int(texelFetch(sv_trim_table, a + ivec2(5, 0), 0).x + 0.5);
        float v0 = c[0].y / c[0].z;
        vec3 e = degree == 1 ? c[1] : (degree == 2 ? c[2] : c[3]);
        float v1 = e.y / e.z;
        if (!(p.y >= min(v0, v1) && p.y < max(v0, v1))) continue;  // half-open: shared ends count once
        if (box.x > p.x) { crossings += 1; continue; }             // the whole piece right of p
        if (box.y <= p.x) continue;                                  // the whole piece left of p
        bool up = v1 > v0;
        float lo = 0.0, hi = 1.0;
        for (int it = 0; it < SV_TRIM_BISECTIONS; ++it) {
            float m = 0.5 * (lo + hi);
            vec3 h = sv_trim_point(c, degree, m);
            if ((h.y / h.z < p.y) == up) lo = m; else hi = m;
        }
        vec3 h = sv_trim_point(c, degree, 0.5 * (lo + hi));
        if (h.x / h.z > p.x) crossings += 1;
    }
    return (crossings & 1) == 1;
}

// A ray against one quartic BB triangle patch of a graph surface z = f(x, y) ([Reis2008, sec. V]): the
// step shared by the analytic patch and every terrain triangle.
//
// 1. Clip t in [ta, tb] to the triangle (barycentric coordinates >= -margin; the ray's barycentric
//    coordinates are affine: lam_o + t lam_d) and to the slab between the smallest and largest
//    coefficient (convex hull property), widened by ~16 ulps of the heights involved so that a flat
//    patch does not collapse it to a point and leave hit or miss to rounding.
// 2. Restrict f to the segment by blossoming ([Reis2008, eqs. (6)-(7)]) and subtract the ray's height, a linear
//    function written as a quartic: c_k -= z0 + (k/4)(z1 - z0).
// 3. A segment that starts on the surface within the rounding error of c (below) is a hit at its start:
//    the true crossing lies within that error of the shared edge, and the neighbour that owns it may have
//    computed the wrong sign too (pinholes along cell edges and diagonals of steep terrain seen from afar).
// 4. No sign change among the c_k: no root (convex hull), skip the root finder; else the first root.
// The float64 twin is splinevis.bb.ray.graph_patch_first_hit.
#include "lib/core/raycast.glsl"
#include "lib/simplex/blossom.glsl"
#include "lib/core/roots.glsl"


float sv_graph_patch_hit(float b[15], vec3 lam_o, vec3 lam_d, float oz, float dz, float ta, float tb, float margin,
                         int iterations) {
    float t0 = ta;
    float t1 = tb;
    for (int k = 0; k < 3; ++k) {
        if (abs(lam_d[k]) < 1e-30) {
            if (lam_o[k] < -margin) return SV_NO_HIT;
        } else {
            float tc = (-margin - lam_o[k]) / lam_d[k];
            if (lam_d[k] > 0.0) t0 = max(t0, tc); else t1 = min(t1, tc);
        }
    }
    float zlo = b[0];
    float zhi = b[0];
    for (int q = 1; q < 15; ++q) { zlo = min(zlo, b[q]); zhi = max(zhi, b[q]); }
    float zpad = 1.0e-6 * (max(abs(zlo), abs(zhi)) + abs(oz)) + 1.0e-30;
    zlo -= zpad;
    zhi += zpad;
    if (abs(dz) < 1e-30) {
        if (oz < zlo || oz > zhi) return SV_NO_HIT;
    } else {
        float za = (zlo - oz) / dz;
        float zb = (zhi - oz) / dz;
        t0 = max(t0, min(za, zb));
        t1 = min(t1, max(za, zb));
    }
    if (!(t0 <= t1)) return SV_NO_HIT;
    float c[5];
    sv_restrict_quartic_tri(b, lam_o + t0 * lam_d, lam_o + t1 * lam_d, c);
    float z0 = oz + t0 * dz;
    float z1 = oz + t1 * dz;
    for (int k = 0; k < 5; ++k) c[k] -= mix(z0, z1, float(k) / 4.0);
    // Rounding error of the c_k (float32, u = 2^-24; splinevis.bb.ray.start_tolerance is the derivation):
    // blossoming of coefficients up to max|b| and the ray's height: 32 u (max|b| + |z|); the ray's
    // barycentric coordinates, lam_o + t lam_d with lam ~ L, carry 4 u L, moving f by its barycentric slope
    // (<= 4 (zhi - zlo) for a quartic): 16 u L (zhi - zlo).
    float L = 0.0;
    for (int k = 0; k < 3; ++k) L = max(L, abs(lam_o[k]) + max(abs(t0), abs(t1)) * abs(lam_d[k]));
    float eps_c = 5.9604644775390625e-08 * (32.0 * (max(abs(zlo), abs(zhi)) + max(abs(z0), abs(z1))) + 16.0 * L * (zhi - zlo));
    if (abs(c[0]) <= eps_c) return t0;
    float cmin = min(min(min(c[0], c[1]), min(c[2], c[3])), c[4]);
    float cmax = max(max(max(c[0], c[1]), max(c[2], c[3])), c[4]);
    if (cmin > 0.0 || cmax < 0.0) return SV_NO_HIT;
#ifdef SV_DEBUG_NO_ROOTS
    return t0;  // debug build without the root finder (terrain option debug="restrict"): the segment's start
#endif
#ifdef SV_DEBUG_COUNTERS
    sv_count_root_calls += 1;
#endif
    float s = sv_first_root(c, 4, iterations);
    return s < 0.0 ? SV_NO_HIT : mix(t0, t1, s);
}

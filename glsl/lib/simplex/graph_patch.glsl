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


// Steps 1-4 without the root finder: SV_PATCH_MISS (no root on the segment), SV_PATCH_START (a hit at t0) or
// SV_PATCH_ROOT (the first root of c, the restricted polynomial on [t0, t1], is the hit, if it has one). A
// caller that runs the root finder itself (the terrain's walk, one copy for both triangles of a cell) gets the
// same hits as sv_graph_patch_hit.
const int SV_PATCH_MISS = 0;
const int SV_PATCH_START = 1;
const int SV_PATCH_ROOT = 2;

int sv_graph_patch_prepare(float b[15], vec3 lam_o, vec3 lam_d, float oz, float dz, float ta, float tb, float margin,
                           out float t0, out float t1, out float c[5]) {
    t0 = ta;
    t1 = tb;
    for (int k = 0; k < 5; ++k) c[k] = 0.0;
    for (int k = 0; k < 3; ++k) {
        if (abs(lam_d[k]) < 1e-30) {
            if (lam_o[k] < -margin) return SV_PATCH_MISS;
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
        if (oz < zlo || oz > zhi) return SV_PATCH_MISS;
    } else {
        float za = (zlo - oz) / dz;
        float zb = (zhi - oz) / dz;
        t0 = max(t0, min(za, zb));
        t1 = min(t1, max(za, zb));
    }
    if (!(t0 <= t1)) return SV_PATCH_MISS;
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
    if (abs(c[0]) <= eps_c) return SV_PATCH_START;
    float cmin = min(min(min(c[0], c[1]), min(c[2], c[3])), c[4]);
    float cmax = max(max(max(c[0], c[1]), max(c[2], c[3])), c[4]);
    if (cmin > 0.0 || cmax < 0.0) return SV_PATCH_MISS;
#ifdef SV_DEBUG_NO_ROOTS
    return SV_PATCH_START;  // debug build without the root finder (terrain option debug="restrict"): the segment's start
#endif
    return SV_PATCH_ROOT;
}

// The hit of a prepared segment (sv_graph_patch_prepare's result k, t0, t1, c): t0, the first root, or SV_NO_HIT.
float sv_graph_patch_finish(int k, float t0, float t1, float c[5], int iterations) {
    if (k == SV_PATCH_MISS) return SV_NO_HIT;
    if (k == SV_PATCH_START) return t0;
#ifdef SV_DEBUG_COUNTERS
    sv_count_root_calls += 1;
#endif
    float s = sv_first_root(c, 4, iterations);
    return s < 0.0 ? SV_NO_HIT : mix(t0, t1, s);
}

float sv_graph_patch_hit(float b[15], vec3 lam_o, vec3 lam_d, float oz, float dz, float ta, float tb, float margin,
                         int iterations) {
    float t0;
    float t1;
    float c[5];
    int k = sv_graph_patch_prepare(b, lam_o, lam_d, oz, dz, ta, tb, margin, t0, t1, c);
    return sv_graph_patch_finish(k, t0, t1, c, iterations);
}

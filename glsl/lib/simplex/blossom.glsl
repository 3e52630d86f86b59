// Restriction of a quartic Bernstein-Bezier triangle patch to a segment, by blossoming.
#include "lib/simplex/blossom_steps.glsl"
//
// The 15 coefficients b[q] are ordered as splinevis.bb.simplex.multi_indices(4, 2) (lexicographic
// descending: (4,0,0), (3,1,0), (3,0,1), (2,2,0), (2,1,1), (2,0,2), (1,3,0), ...).  Along the segment
// from barycentric point l0 to l1 the patch is the univariate quartic with BB coefficients
//     c_k = blossom(l0^{4-k}, l1^k),   k = 0..4              [Reis2008, eq. (5); Farin2002, ch. 17.4]
// The blossom is evaluated by de Casteljau steps using l0 for the first 4 - k levels and l1 for the
// remaining k.  The float64 twin is splinevis.bb.simplex.restrict_to_segment (same step order, same
// summation order l.x*a + l.y*b + l.z*c).  Rounding: each level rounds each term at most 3 times
// (one product, at most two sums), so |fl(c_k) - c_k| <= gamma_{12} blossom(|b|; |l0|^{4-k}, |l1|^k).

// Positions of alpha + e_0, alpha + e_1, alpha + e_2 (degree m) for the degree m - 1 multi-index at
// position q; thanks to the nested ordering the table for degree m is the first m (m + 1) / 2 rows of
// the degree 4 table (generated from splinevis.bb.simplex._step_table(4, 2)).
const int SV_TRI_STEP[30] = int[30](0, 1, 2, 1, 3, 4, 2, 4, 5, 3, 6, 7, 4, 7, 8,
                                    5, 8, 9, 6, 10, 11, 7, 11, 12, 8, 12, 13, 9, 13, 14);

// One de Casteljau step degree m -> m - 1 (m in 1..4) at the barycentric point l.
void sv_blossom_tri_step(float src[15], int m, vec3 l, out float dst[15]) {
    int count = (m * (m + 1)) / 2;
    for (int q = 0; q < 15; ++q) dst[q] = 0.0;
    for (int q = 0; q < 10; ++q) {
        if (q < count) {
            int base = 3 * q;
            dst[q] = l.x * src[SV_TRI_STEP[base]] + l.y * src[SV_TRI_STEP[base + 1]]
                   + l.z * src[SV_TRI_STEP[base + 2]];
        }
    }
}

// c[k] = blossom(l0^{4-k}, l1^k) of the quartic triangle patch b (k = 0..4): 4 - k steps with l0, then
// k steps with l1, exactly the order of the float64 twin, unrolled into fixed-degree steps
// (lib/simplex/blossom_steps.glsl) so that no local array is indexed dynamically: 55 three-term combinations.
void sv_restrict_quartic_tri(float b[15], vec3 l0, vec3 l1, out float c[5]) {
    float a1[10];
    float a2[6];
    float a3[3];
    float t10[10];
    float t6[6];
    float t3[3];
    sv_tri_step4(b, l0, a1);                // one step with l0
    sv_tri_step3(a1, l0, a2);               // two
    sv_tri_step2(a2, l0, a3);               // three
    c[0] = sv_tri_step1(a3, l0);            // l0^4
    c[1] = sv_tri_step1(a3, l1);            // l0^3 l1
    sv_tri_step2(a2, l1, t3);
    c[2] = sv_tri_step1(t3, l1);            // l0^2 l1^2
    sv_tri_step3(a1, l1, t6);
    sv_tri_step2(t6, l1, t3);
    c[3] = sv_tri_step1(t3, l1);            // l0 l1^3
    sv_tri_step4(b, l1, t10);
    sv_tri_step3(t10, l1, t6);
    sv_tri_step2(t6, l1, t3);
    c[4] = sv_tri_step1(t3, l1);            // l1^4
}

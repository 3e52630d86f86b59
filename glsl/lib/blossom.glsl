// Restriction of a quartic Bernstein-Bezier triangle patch to a segment, by blossoming.
//
// The 15 coefficients b[q] are ordered as splinevis.bb.simplex.multi_indices(4, 2) (lexicographic
// descending: (4,0,0), (3,1,0), (3,0,1), (2,2,0), (2,1,1), (2,0,2), (1,3,0), ...).  Along the segment
// from barycentric point l0 to l1 the patch is the univariate quartic with BB coefficients
//     c_k = blossom(l0^{4-k}, l1^k),   k = 0..4              (paper 000, eq. (5); Farin ch. 17.4)
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

// c[k] = blossom(l0^{4-k}, l1^k) of the quartic triangle patch b (k = 0..4).
void sv_restrict_quartic_tri(float b[15], vec3 l0, vec3 l1, out float c[5]) {
    float w[15];          // b after j steps with l0 (degree 4 - j)
    float v[15];
    float tmp[15];
    w = b;
    for (int j = 0; j <= 4; ++j) {
        // here w holds b after j steps with l0; finish with 4 - j steps with l1 -> c[4 - j]
        v = w;
        for (int s = 0; s < 4; ++s) {
            if (s < 4 - j) {
                sv_blossom_tri_step(v, 4 - j - s, l1, tmp);
                v = tmp;
            }
        }
        c[4 - j] = v[0];
        if (j < 4) {
            sv_blossom_tri_step(w, 4 - j, l0, tmp);
            w = tmp;
        }
    }
}

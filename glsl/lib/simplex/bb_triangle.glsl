// Quartic Bernstein-Bezier triangle patches: value, gradient and Hessian by de Casteljau.
//
// 15 coefficients b[ijk], i+j+k = 4, ordered as splinevis.bb.simplex.multi_indices(4, 2): i descending,
// then j descending ((4,0,0), (3,1,0), (3,0,1), (2,2,0), ...).  A point is given by barycentric
// coordinates l (l.x + l.y + l.z = 1).  After r de Casteljau steps at l the degree-(4-r) coefficients
// give the derivatives [Farin2002, ch. 17.5; LaiSchumaker2007, Thm. 2.15]
//     D_u f = 4 * sum_i u_i a[e_i]                     (r = 3, a linear in the step's point)
//     D_u D_v f = 12 * sum_{i,j} u_i v_j d[e_i + e_j]   (r = 2)
// for directions u, v with components summing to zero.

// Position of (i, j, k) with i + j + k = n in the ordering above.
int sv_tri_index(int i, int j, int n) {
    int off = 0;
    for (int a = n; a > i; --a) off += n - a + 1;
    return off + (n - i - j);
}

// One de Casteljau step on a triangle patch of degree n (n <= 4): degree n -> n - 1.
// dst[(i,j,k)] = l.x src[(i+1,j,k)] + l.y src[(i,j+1,k)] + l.z src[(i,j,k+1)].
void sv_tri_decasteljau_step(in float src[15], int n, vec3 l, out float dst[15]) {
    for (int q = 0; q < 15; ++q) dst[q] = 0.0;
    int m = n - 1;
    for (int i = 0; i <= m; ++i) {
        for (int j = 0; j <= m - i; ++j) {
            dst[sv_tri_index(i, j, m)] = l.x * src[sv_tri_index(i + 1, j, n)]
                                       + l.y * src[sv_tri_index(i, j + 1, n)]
                                       + l.z * src[sv_tri_index(i, j, n)];
        }
    }
}

// Value f, barycentric first derivatives a (f's directional derivative along u is 4 * dot(u, a)) and
// the quadratic de Casteljau coefficients d (for second derivatives) of a quartic patch at l.
// d is ordered (2,0,0), (1,1,0), (1,0,1), (0,2,0), (0,1,1), (0,0,2).
void sv_tri_quartic_jet(in float b[15], vec3 l, out float f, out vec3 a, out float d[6]) {
    float w3[15];
    float w2[15];
    float w1[15];
    sv_tri_decasteljau_step(b, 4, l, w3);
    sv_tri_decasteljau_step(w3, 3, l, w2);
    for (int q = 0; q < 6; ++q) d[q] = w2[q];
    sv_tri_decasteljau_step(w2, 2, l, w1);
    a = vec3(w1[0], w1[1], w1[2]);
    f = dot(l, a);
}

// Second directional derivative D_u D_v f of a quartic from its quadratic coefficients d.
float sv_tri_quartic_d2(in float d[6], vec3 u, vec3 v) {
    return 12.0 * (u.x * v.x * d[0] + (u.x * v.y + u.y * v.x) * d[1] + (u.x * v.z + u.z * v.x) * d[2]
                   + u.y * v.y * d[3] + (u.y * v.z + u.z * v.y) * d[4] + u.z * v.z * d[5]);
}

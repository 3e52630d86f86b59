// Tensor-product Bezier patches of degree (m, n) <= (3, 3) on [0, 1]^2: value and first partial derivatives
// by de Casteljau in u for every row, then in v [Farin2002, ch. 16]. The building block of the
// tensor-product families (NURBS segments after knot insertion [Kumar1997], geometry-image B-spline patches
// [Losasso2003]). Coefficients c[4 i + j] multiply B^m_i(u) B^n_j(v); only i <= m, j <= n are read.
// The float64 twin is splinevis.bb.tensor.bezier_patch_eval, which performs the same operations in the same
// order.
//
// Rounding (float32, u = 2^-24): the rows are m levels of s a + t b (3 roundings each), then n levels in v on
// values that carry the rows' error: |fl(f) - f| <= gamma_{3(m + n)} sum_ij |c_ij| B_i(u) B_j(v); the
// derivatives one more level and a product each (splinevis.bb.tensor.BEZIER_PATCH_BOUND).
#include "lib/core/bernstein.glsl"

// Value f, df/du and df/dv at (u, v).
void sv_bezier_patch_eval(float c[16], int m, int n, vec2 uv, out float f, out float fu, out float fv) {
    float row[5];
    float row_du[5];
    float col[5];
    for (int j = 0; j < 4; ++j) {
        float a[5] = float[5](c[j], c[4 + j], c[8 + j], c[12 + j], 0.0);
        float value;
        float slope;
        sv_bernstein_eval_deriv(a, m, uv.x, value, slope);
        row[j] = value;
        row_du[j] = slope;
    }
    row[4] = 0.0;
    row_du[4] = 0.0;
    sv_bernstein_eval_deriv(row, n, uv.y, f, fv);
    float unused;
    sv_bernstein_eval_deriv(row_du, n, uv.y, fu, unused);
}

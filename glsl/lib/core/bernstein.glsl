// Univariate Bernstein-Bezier (BB) polynomials of degree n <= 4 on [0, 1], evaluated by de Casteljau.
//
// Coefficients live in a fixed-size array float c[5]; only c[0..n] are read.  Coefficient k multiplies
//     B^n_k(t) = C(n, k) (1 - t)^(n - k) t^k
// (the ordering of splinevis.bb.simplex.multi_indices(n, 1)).  [Farin2002, ch. 3] (de Casteljau) and
// [Farin2002, ch. 5] (derivatives).  The float64 twin is splinevis.bb.roots._eval_deriv,
// which performs the same operations in the same order.
//
// Rounding (float32, unit roundoff u = 2^-24): every level computes s*a + t*b with s = fl(1 - t), i.e.
// at most 3 roundings per level, so |fl(f) - f| <= gamma_{3n} * sum_k |c_k| B^n_k(t)
// [MainarPena1999], gamma_m = m u / (1 - m u) [Higham2002, sec. 3.4].  A fused multiply-add only removes
// roundings.

// de Casteljau down to the last two intermediate values (n - 1 levels, n >= 1):
//     b0 = sum_k c_k B^{n-1}_k(t),   b1 = sum_k c_{k+1} B^{n-1}_k(t).
void sv_bernstein_last2(float c[5], int n, float t, out float b0, out float b1) {
    float s = 1.0 - t;
    float b[5] = c;
    for (int level = 1; level <= 3; ++level) {
        if (level < n) {
            for (int k = 0; k < 4; ++k) {
                if (k <= n - level) b[k] = s * b[k] + t * b[k + 1];
            }
        }
    }
    b0 = b[0];
    b1 = b[1];
}

// Value f(t) and derivative f'(t) = n (b1 - b0) ([Farin2002, eq. 5.23]: the last de Casteljau level gives
// the tangent).  n = 0: f = c[0], f' = 0.
void sv_bernstein_eval_deriv(float c[5], int n, float t, out float f, out float fp) {
    if (n <= 0) {
        f = c[0];
        fp = 0.0;
        return;
    }
    float b0;
    float b1;
    sv_bernstein_last2(c, n, t, b0, b1);
    f = (1.0 - t) * b0 + t * b1;
    fp = float(n) * (b1 - b0);
}

// f(t) = sum_k c_k B^n_k(t) by de Casteljau (n levels of (1 - t) a + t b).
float sv_bernstein_eval(float c[5], int n, float t) {
    float f;
    float fp;
    sv_bernstein_eval_deriv(c, n, t, f, fp);
    return f;
}

// f'(t) = n sum_k (c_{k+1} - c_k) B^{n-1}_k(t), computed as n (b1 - b0) after n - 1 de Casteljau levels.
float sv_bernstein_deriv(float c[5], int n, float t) {
    float f;
    float fp;
    sv_bernstein_eval_deriv(c, n, t, f, fp);
    return fp;
}

// Four evaluations at once (the paper's vector arithmetic): value and derivative at each component of x.
// Component-wise identical to sv_bernstein_eval_deriv.
void sv_bernstein_eval_deriv4(float c[5], int n, vec4 x, out vec4 f, out vec4 fp) {
    if (n <= 0) {
        f = vec4(c[0]);
        fp = vec4(0.0);
        return;
    }
    vec4 s = vec4(1.0) - x;
    vec4 b[5];
    for (int k = 0; k < 5; ++k) b[k] = vec4(c[k]);
    for (int level = 1; level <= 3; ++level) {
        if (level < n) {
            for (int k = 0; k < 4; ++k) {
                if (k <= n - level) b[k] = s * b[k] + x * b[k + 1];
            }
        }
    }
    f = s * b[0] + x * b[1];
    fp = float(n) * (b[1] - b[0]);
}

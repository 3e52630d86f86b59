// First root in [0, 1] of a univariate BB polynomial of degree n <= 4, two methods:
//
// * sv_first_root_newton4 -- the Newton iteration of the quartic ray-patch intersection of
//   [Reis2008, sec. V] (its pseudo-code "x0 = (0, w0, w1, 1); for (i = 0; i < 6; i++)
//   x_{i+1} = x_i - F(x_i)/F'(x_i)"): Newton from the secure starting points, residual acceptance.
//   Measured to return a LATER root than the first one in ~17% of well-conditioned quartic cases with
//   6 steps (Newton from 0 converges to the first root only linearly while far from it), to miss double
//   roots, and to overshoot out of [0, 1] when the root sits near s = 1 (ray-caster holes at patch borders).
// * sv_first_root_bracketed -- bracketed Newton on convex pieces (the default, see below).
//
// sv_first_root(c, n, iterations) is the bracketed method unless SV_ROOTS_PAPER is defined.
// The float64 twins are splinevis.bb.roots.newton_secure and splinevis.bb.roots.first_root_bracketed;
// they mirror this file line by line.
#include "lib/core/bernstein.glsl"
#ifdef SV_DEBUG_COUNTERS
#include "lib/core/counters.glsl"
#endif

// Acceptance constant K_n (in units of eps32 = 2^-23) of the residual test |f(x)| <= K_n eps32 S(x),
// S(x) = sum_k |c_k| B^n_k(x).  Derivation (u = 2^-24 = eps32 / 2):
//   * the computed f(x) is within gamma_{3n} S(x) of the exact f at the float32 x (see bernstein.glsl);
//   * at the float32 number x nearest a simple root x*, |f(x)| ~ |f'(x*)| |x - x*|; for roots that are
//     not argument-ill-conditioned (|f'(x*)| ulp(x*)/2 <= gamma_{3n} S(x*)) this adds another gamma_{3n} S;
//   * S itself is computed with relative error <= gamma_{3n}, and K eps32 S costs two more roundings.
// Hence K_n = 2 gamma_{3n} / eps32 * (1 + small) = 3n / ((1 - 3nu)(1 - gamma_{3n})) (1 + u)^2
//           <= 3n (1 + 2^-16) for n <= 4.
#define SV_ROOT_EPS32 1.1920928955078125e-07
float sv_root_tol_k(int n) {
    return 3.0 * float(n) * (1.0 + 1.52587890625e-05);
}

// Roots in (0, 1) of the second derivative (inflection points), w0 <= w1; -1.0 marks "none".
// f'' = n (n - 1) sum_k a_k B^{n-2}_k with a_k = c_{k+2} - 2 c_{k+1} + c_k.
//   n = 4: a quadratic a0 (1-t)^2 + 2 a1 (1-t) t + a2 t^2 = A t^2 + B t + C, solved with the
//          cancellation-free formula q = -(B + sign(B) sqrt(B^2 - 4AC)) / 2, roots q/A and C/q;
//   n = 3: a line a0 (1-t) + a1 t, root a0 / (a0 - a1).
void sv_inflection_points(float c[5], int n, out float w0, out float w1) {
    w0 = -1.0;
    w1 = -1.0;
    if (n == 4) {
        float a0 = c[2] - 2.0 * c[1] + c[0];
        float a1 = c[3] - 2.0 * c[2] + c[1];
        float a2 = c[4] - 2.0 * c[3] + c[2];
        float A = a0 - 2.0 * a1 + a2;
        float B = 2.0 * (a1 - a0);
        float C = a0;
        if (A == 0.0) {
            if (B != 0.0) w0 = -C / B;
        } else {
            float disc = B * B - 4.0 * A * C;
            if (disc >= 0.0) {
                float sgn = (B >= 0.0) ? 1.0 : -1.0;
                float q = -0.5 * (B + sgn * sqrt(disc));
                float r0 = q / A;
                float r1 = (q != 0.0) ? C / q : r0;
                w0 = min(r0, r1);
                w1 = max(r0, r1);
            }
        }
    } else if (n == 3) {
        float a0 = c[2] - 2.0 * c[1] + c[0];
        float a1 = c[3] - 2.0 * c[2] + c[1];
        if (a0 != a1) w0 = a0 / (a0 - a1);
    }
}

// Newton from the four starts x with `iterations` (1..8) steps and the residual acceptance of
// sv_first_root_newton4: the smallest accepted x in [0, 1], -1.0 if none (shared by the 4-start variant of
// [Reis2008, sec. V] and the 3-start variant of [Kalbe2008, sec. 5.3]).
float sv_newton_from_starts(float c[5], int n, vec4 x, int iterations) {
    vec4 f;
    vec4 fp;
    for (int it = 0; it < 8; ++it) {
        if (it < iterations) {
#ifdef SV_DEBUG_COUNTERS
            sv_count_root_steps += 1;
#endif
            sv_bernstein_eval_deriv4(c, n, x, f, fp);
            bvec4 nz = notEqual(fp, vec4(0.0));
            vec4 xn = x - f / mix(vec4(1.0), fp, nz);
            // keep x where f' = 0 or the step is not finite (|xn| < 1e30 is false for inf and NaN)
            bvec4 ok = bvec4(nz.x && abs(xn.x) < 1e30, nz.y && abs(xn.y) < 1e30,
                             nz.z && abs(xn.z) < 1e30, nz.w && abs(xn.w) < 1e30);
            x = mix(x, xn, ok);
        }
    }
    float ca[5];
    for (int k = 0; k < 5; ++k) ca[k] = abs(c[k]);
    vec4 S;
    vec4 dummy;
    sv_bernstein_eval_deriv4(c, n, x, f, fp);
    sv_bernstein_eval_deriv4(ca, n, x, S, dummy);
    vec4 tol = sv_root_tol_k(n) * SV_ROOT_EPS32 * S;
    float best = 2.0;
    for (int i = 0; i < 4; ++i) {
        if (x[i] >= 0.0 && x[i] <= 1.0 && abs(f[i]) <= tol[i]) best = min(best, x[i]);
    }
    return (best <= 1.0) ? best : -1.0;
}

// The method of [Reis2008, sec. V].  Smallest root in [0, 1] of f(t) = sum_{k<=n} c_k B^n_k(t), n in 0..4, after
// `iterations` (1..8) Newton steps from x = (0, w0, w1, 1).  Returns -1.0 when no candidate passes the residual test
// |f(x)| <= K_n eps32 sum_k |c_k| B^n_k(x) (the Python twin returns NaN there).  A start whose
// derivative is 0, or whose step is not finite, keeps its x.  Nothing is clamped: iterates leaving
// [0, 1] are simply not accepted.  The zero polynomial returns 0.
float sv_first_root_newton4(float c[5], int n, int iterations) {
    float w0;
    float w1;
    sv_inflection_points(c, n, w0, w1);
    if (!(w0 > 0.0 && w0 < 1.0)) w0 = 1.0 / 3.0;
    if (!(w1 > 0.0 && w1 < 1.0)) w1 = 2.0 / 3.0;
    return sv_newton_from_starts(c, n, vec4(0.0, w0, w1, 1.0), iterations);
}

// ------------------------------------------------------------------------------------------------------
// Bracketed Newton on convex pieces (the default method).
//
// The secure points p0 = 0 <= w0 <= w1 <= p3 = 1 (inflection points; a missing one is replaced by the
// neighbouring end, so a piece may be empty) split [0, 1] into three pieces on which f'' has constant
// sign: f is convex or concave on each piece.  The pieces are processed left to right; the first piece
// yielding a root gives the answer.  On a piece [a, b]:
//   * |f(a)| <= tol(a) (tol = K_n eps32 sum_k |c_k| B_k, the residual test of the paper's method):
//     a is a root at float32 precision (this includes f(a) = 0 and the zero polynomial) -> return a.
//   * sign change f(a) f(b) < 0: a convex (or concave) function with a sign change has EXACTLY one root
//     in the piece.  If f(b) = 0 there is an earlier root in (a, b) iff f(a) f'(b) > 0 (f crosses zero
//     before coming back to 0 at b); otherwise b is the first root and the next piece returns it.
//     The root is found by sv_bracket_newton (below), which keeps a bracket with the sign change.
//   * no sign change: a root needs an interior extremum on the far side of zero.  Let f(a) > 0 (the
//     other case is symmetric): a concave piece attains its minimum at an end, so f > 0; a convex piece
//     has an interior minimum iff f'(a) < 0 < f'(b).  Together (f'' has the sign of f'(b) - f'(a)):
//         f(a) f'(a) < 0  and  f'(a) f'(b) < 0.
//     The extremum m (the single root of the monotone f' on the piece) is found by sv_bracket_newton
//     applied to f'.  If |f(m)| <= tol(m) it is a touching (double) root / tangential ray -> return m;
//     if f(m) has the opposite sign of f(a), the first root is the unique one in [a, m] -> bracketed
//     Newton there.  Otherwise the piece has no root.
//   * after the last piece: |f(1)| <= tol(1) -> return 1.
// Fixed budget: every bracketed run takes exactly `iterations` steps (no data-dependent loop bounds);
// per piece at most two runs plus one scalar evaluation, i.e. at most 3 (2 N + 1) + 3 vec4 evaluations.
#define SV_ROOT_MAX_ITERATIONS 16

// Safeguarded Newton for the single root of g = sum_k g_k B^m_k in [lo, hi] (m >= 0), given the values
// glo = g(lo) != 0, ghi = g(hi) with a sign change (ghi may be 0) and derivatives dlo, dhi there.
// sigma: a number with the sign of g'' on the bracket (0 = unknown).  Each of the `iterations` steps
// evaluates g, g' at four points in one vec4 de Casteljau (the paper's vector arithmetic):
//   lane 0: the Newton step x - g/g' from the FOURIER end x of the bracket, the end where g has the sign
//           of g'' (g(x) g''(x) >= 0), so that Newton converges monotonically into the bracket; if it is
//           not strictly inside (lo, hi) -- or not finite, or sigma = 0 and the end with the smaller |g|
//           was taken -- the regula falsi point lo + (hi - lo) g(lo) / (g(lo) - g(hi)) is used;
//   lanes 1..3: the quarter points lo + (hi - lo) (1/4, 1/2, 3/4).
// The bracket shrinks to the sub-interval with the sign change (a point with g = 0 counts as the hi
// side).  Accuracy after N steps: the bracket is at most 4^-N (hi - lo) wide in any case (e.g. 1.5e-5 of
// the piece for N = 8, 2.4e-4 for N = 6), and the Fourier end moves at least as fast as Newton's
// monotone, eventually quadratic, iteration; in float32 it stops at the rounding level, where the sign
// of the computed g is unreliable (|g| <= gamma_{3m} sum |g_k| B_k).  The result is one more Newton
// step from the Fourier end (values already known), replaced by the regula falsi point if it leaves
// [lo, hi]: always inside the final bracket.
float sv_bracket_newton(float g[5], int m, float lo, float hi, float glo, float ghi, float dlo, float dhi,
                        float sigma, int iterations) {
    // A uniform loop bound (iterations is the same for every fragment): ~10% faster on llvmpipe than a
    // constant bound with a masked body. Callers keep iterations in 1..SV_ROOT_MAX_ITERATIONS.
    for (int it = 0; it < iterations; ++it) {
        {
#ifdef SV_DEBUG_COUNTERS
            sv_count_root_steps += 1;
#endif
            bool from_lo = (sigma != 0.0) ? ((glo < 0.0) == (sigma < 0.0)) : (abs(glo) <= abs(ghi));
            float x = from_lo ? lo : hi;
            float gx = from_lo ? glo : ghi;
            float dx = from_lo ? dlo : dhi;
            float xn = x - gx / dx;
            if (!(xn > lo && xn < hi)) xn = lo + (hi - lo) * (glo / (glo - ghi));
            float w = hi - lo;
            vec4 p = vec4(xn, lo + 0.25 * w, lo + 0.5 * w, lo + 0.75 * w);
            vec4 gp;
            vec4 dp;
            sv_bernstein_eval_deriv4(g, m, p, gp, dp);
            for (int i = 0; i < 4; ++i) {
                if (p[i] > lo && p[i] < hi) {
                    if (gp[i] != 0.0 && ((gp[i] < 0.0) == (glo < 0.0))) {
                        lo = p[i];
                        glo = gp[i];
                        dlo = dp[i];
                    } else {
                        hi = p[i];
                        ghi = gp[i];
                        dhi = dp[i];
                    }
                }
            }
        }
    }
    bool from_lo = (sigma != 0.0) ? ((glo < 0.0) == (sigma < 0.0)) : (abs(glo) <= abs(ghi));
    float x = from_lo ? lo : hi;
    float gx = from_lo ? glo : ghi;
    float dx = from_lo ? dlo : dhi;
    float xr = x - gx / dx;
    if (!(xr >= lo && xr <= hi)) xr = lo + (hi - lo) * (glo / (glo - ghi));
    return xr;
}

// Bracketed Newton on convex pieces: smallest root in [0, 1] of f(t) = sum_{k<=n} c_k B^n_k(t),
// n in 0..4, with `iterations` (1..16) steps per bracketed run; -1.0 when there is none (the Python twin
// returns NaN).  n = 0: 0 if c0 = 0; the zero polynomial returns 0; non-finite coefficients return -1.
float sv_first_root_bracketed(float c[5], int n, int iterations) {
    for (int k = 0; k < 5; ++k) {
        if (k <= n && !(abs(c[k]) <= 3.4028234663852886e38)) return -1.0;
    }
    if (n <= 0) return (c[0] == 0.0) ? 0.0 : -1.0;
    float w0;
    float w1;
    sv_inflection_points(c, n, w0, w1);
    if (!(w0 > 0.0 && w0 < 1.0)) w0 = 0.0;
    if (!(w1 > 0.0 && w1 < 1.0)) w1 = 1.0;
    vec4 p = vec4(0.0, w0, w1, 1.0);
    float ca[5];
    for (int k = 0; k < 5; ++k) ca[k] = abs(c[k]);
    // derivative coefficients: f' = sum_k d_k B^{n-1}_k, d_k = n (c_{k+1} - c_k)
    float d[5];
    for (int k = 0; k < 4; ++k) d[k] = (k < n) ? float(n) * (c[k + 1] - c[k]) : 0.0;
    d[4] = 0.0;
    vec4 f;
    vec4 fp;
    vec4 S;
    vec4 g;
    vec4 gp;
    sv_bernstein_eval_deriv4(c, n, p, f, fp);
    sv_bernstein_eval_deriv4(ca, n, p, S, fp);
    sv_bernstein_eval_deriv4(d, n - 1, p, g, gp);  // g = f', gp = f'' at the secure points
    vec4 tol = sv_root_tol_k(n) * SV_ROOT_EPS32 * S;
    // The pieces are scanned left to right; the first that brackets a root is refined by ONE call of
    // sv_bracket_newton after the scan (a single inlined copy: on SIMD rasterizers every copy costs all
    // lanes). Same decisions and arithmetic as before, so the float32 twin is unchanged.
    bool have = false;
    float A = 0.0;
    float B = 0.0;
    float FA = 0.0;
    float FB = 0.0;
    float DA = 0.0;
    float DB = 0.0;
    float SIG = 0.0;
    for (int i = 0; i < 3; ++i) {
        if (have) break;
        float a = p[i];
        float b = p[i + 1];
        float fa = f[i];
        float fb = f[i + 1];
        if (abs(fa) <= tol[i]) return a;
        float sigma = g[i + 1] - g[i];  // has the sign of f'' on the piece
        bool change = (fb == 0.0) ? (g[i + 1] != 0.0 && ((fa < 0.0) == (g[i + 1] < 0.0)))
                                  : ((fa < 0.0) != (fb < 0.0));
        if (change) {
            have = true;
            A = a; B = b; FA = fa; FB = fb; DA = g[i]; DB = g[i + 1]; SIG = sigma;
        } else {
            bool dip = g[i] != 0.0 && g[i + 1] != 0.0 && ((fa < 0.0) != (g[i] < 0.0))
                       && ((g[i] < 0.0) != (g[i + 1] < 0.0));
            if (dip) {
                float m = sv_bracket_newton(d, n - 1, a, b, g[i], g[i + 1], gp[i], gp[i + 1], 0.0, iterations);
                float fm;
                float fpm;
                float Sm;
                float dummy;
                sv_bernstein_eval_deriv(c, n, m, fm, fpm);
                sv_bernstein_eval_deriv(ca, n, m, Sm, dummy);
                if (abs(fm) <= sv_root_tol_k(n) * SV_ROOT_EPS32 * Sm) return m;
                if ((fm < 0.0) != (fa < 0.0)) {
                    have = true;
                    A = a; B = m; FA = fa; FB = fm; DA = g[i]; DB = fpm; SIG = sigma;
                }
            }
        }
    }
    if (have) return sv_bracket_newton(c, n, A, B, FA, FB, DA, DB, SIG, iterations);
    return (abs(f[3]) <= tol[3]) ? 1.0 : -1.0;
}

// The method the ray-cast programs use: bracketed Newton on convex pieces, or the 4-start Newton
// iteration of [Reis2008, sec. V] when SV_ROOTS_PAPER is defined (for comparison).
float sv_first_root(float c[5], int n, int iterations) {
#ifdef SV_ROOTS_PAPER
    return sv_first_root_newton4(c, n, iterations);
#else
    return sv_first_root_bracketed(c, n, iterations);
#endif
}

// ------------------------------------------------------------------------------------------------------
// Closed form for quadratics ([Kalbe2008, sec. 5.3]: "well known formulae [HE95] ... in an analytical and
// stable way").  f(t) = c0 (1-t)^2 + 2 c1 (1-t) t + c2 t^2 = A t^2 + B t + C with A = c0 - 2 c1 + c2,
// B = 2 (c1 - c0), C = c0.  Roots by q = -(B + sign(B) sqrt(B^2 - 4 A C)) / 2, t = q / A and C / q (no
// cancellation between B and the square root).  A negative discriminant within rounding of a touching
// parabola (|f(t*)| <= tol at the vertex t* = -B / (2A), tol the residual test above) returns t*: a ray
// tangent to the isosurface is a (double) root, not a miss.  Smallest root in [0, 1], -1.0 if none.
// The float64 twin is splinevis.bb.roots.first_root_quadratic.
float sv_first_root_quadratic(float c[5]) {
    float A = c[0] - 2.0 * c[1] + c[2];
    float B = 2.0 * (c[1] - c[0]);
    float C = c[0];
    if (C == 0.0) return 0.0;
    float best = 2.0;
    float disc = B * B - 4.0 * A * C;
    if (A == 0.0) {
        float r = (B != 0.0) ? -C / B : -1.0;
        if (r >= 0.0 && r <= 1.0) best = r;
    } else if (disc >= 0.0) {
        float q = -0.5 * (B + (B >= 0.0 ? 1.0 : -1.0) * sqrt(disc));
        float r1 = q / A;
        float r2 = (q != 0.0) ? C / q : r1;
        if (r1 >= 0.0 && r1 <= 1.0) best = min(best, r1);
        if (r2 >= 0.0 && r2 <= 1.0) best = min(best, r2);
    } else {
        float ts = -B / (2.0 * A);
        if (ts >= 0.0 && ts <= 1.0) {
            float s = 1.0 - ts;
            float f = c[0] * s * s + 2.0 * c[1] * s * ts + c[2] * ts * ts;
            float S = abs(c[0]) * s * s + 2.0 * abs(c[1]) * s * ts + abs(c[2]) * ts * ts;
            if (abs(f) <= sv_root_tol_k(2) * SV_ROOT_EPS32 * S) best = ts;
        }
    }
    return (best <= 1.0) ? best : -1.0;
}

// ------------------------------------------------------------------------------------------------------
// Stable closed form for cubics ([Kalbe2008, sec. 5.3]: "well known formulae [HE95] ... in an
// analytical and stable way").  The float64/float32 twin is splinevis.bb.roots.first_root_cubic.
//
// Homogeneous form.  With x = t, w = 1 - t the cubic BB polynomial is
//     f = c3 x^3 + 3 c2 x^2 w + 3 c1 x w^2 + c0 w^3 =: A x^3 + 3 B x^2 w + 3 C x w^2 + D w^3,
// i.e. the BB coefficients ARE the coefficients of the binary cubic (no conversion to the power basis,
// whose leading coefficient c3 - 3 c2 + 3 c1 - c0 cancels).  A root (x : w) gives t = x / (x + w); t is in
// [0, 1] iff x and w have the same sign, and then x + w does not cancel.  A root at t = 1 is w = 0, one at
// t = infinity (power-form leading coefficient 0) is x = -w: neither is a special case here, so a
// "degenerate leading coefficient" needs no fallback to sv_first_root_quadratic (the quadratic's roots
// come out of the same formulas; measured in tests/test_roots_cubic.py).
// Hessian d1 = AC - B^2, d2 = AD - BC, d3 = BD - C^2; discriminant disc = 4 d1 d3 - d2^2 (> 0: three real
// roots, < 0: one).  Two depressed forms ([Blinn2007] and parts 1-4 of the same column):
//   A-form: x = (y - B) / A with y^3 + 3 d1 y + (A d2 - 2 B d1) = 0   accurate for |x / w| large (t ~ 1),
//   D-form: w = (z - C) / D with z^3 + 3 d3 z + (D d2 - 2 C d3) = 0   accurate for |x / w| small (t ~ 0);
// their depressed discriminants are 4 (-d1)^3 - Q_A^2 = A^2 disc and 4 (-d3)^3 - Q_D^2 = D^2 disc, so
// square roots of the (cancellation-prone) depressed discriminants are taken as |A| sqrt(|disc|).
// * disc >= 0, trigonometric method: y_k = 2 sqrt(-d1) cos(phi + 2 pi k / 3), phi = atan(|A| sqrt(disc),
//   -Q_A) / 3.  The A-form contributes the root with the largest |y - B| (no cancellation in y - B: the
//   largest |x / w|), the D-form the one with the largest |z - C| (the smallest |x / w|); the third root is
//   the cofactor of their quadratic factor E x^2 + F x w + G w^2: (x : w) = (C F - B G : C E - B F).  A
//   fourth lane holds the A-form's middle root directly (redundant; whichever passes the test).
// * disc < 0, Cardano without cancellation (sv_cardano_real): the real root in BOTH forms, and the real
//   part -y/2 of the complex pair in both forms (a pair within rounding of the real axis is a touching /
//   double root, i.e. a tangential ray: accepted by the residual test, not missed).
// Scaling: the coefficients are multiplied by 2^-e, e = floor(log2 max |c_k|) (exact), so that the
// products up to degree 4 (disc) neither overflow (|c| ~ 1e30) nor underflow for coefficients spanning
// ~1e8 in magnitude.
// Selection: the four candidates t (non-finite ones dropped, the others clamped to [0, 1]) are polished
// by SV_CUBIC_POLISH Newton steps on the BB form (de Casteljau, vec4); every iterate is tested with the
// residual test |f(x)| <= K_3 eps32 sum |c_k| B_k(x) + eps32 |x f'(x)| (the newton4 test widened by the
// argument rounding: at a root x* with |f'(x*)| ulp(x*) / 2 > gamma_9 S no float32 x passes the plain test,
// measured on 2% of well-conditioned random cubics), a lane keeps its passing iterate of smallest |f|
// (the steps may drift along a flat, double root), and the smallest accepted t wins.  The closed form alone leaves the candidates at
// cond * eps32 (the transcendental functions add a few ulps).  Measured (float32 twin vs roots_reference,
// error in units of the derived tolerance splinevis.volume.root_methods.first_root_tolerance): one Newton
// step halves the median and 90th-percentile error (ray cubics: 0.022 -> 0.015, 0.075 -> 0.043; random
// hard cubics: 0.013 -> 0.008, 0.195 -> 0.089); a second step does not help further (the smallest accepted
// iterate may then be a half-converged one of another lane), so SV_CUBIC_POLISH = 1.  No root is missed
// without polishing either: the polish is for accuracy only.
// c0 = 0 (includes the zero polynomial) returns 0; non-finite coefficients return -1.0; -1.0 if no root.
#ifndef SV_CUBIC_POLISH
#define SV_CUBIC_POLISH 1
#endif

// Real root of y^3 + 3 P y + Q = 0 given R = sqrt(Q^2 + 4 P^3) >= 0 (one real root): u^3 = s is the root of
// s^2 + Q s - P^3 = 0 of larger magnitude (no cancellation), v = -P / u, y = u + v; for P > 0 (u, v of
// opposite signs) y = -Q / (u^2 + v^2 + P) instead, which has no cancellation either (y (y^2 + 3P) = -Q).
float sv_cardano_real(float P, float Q, float R) {
    float s = -0.5 * (Q + ((Q >= 0.0) ? R : -R));
    float u = sign(s) * pow(abs(s), 1.0 / 3.0);
    float v = (u != 0.0) ? -P / u : 0.0;
    return (P > 0.0) ? -Q / (u * u + v * v + P) : u + v;
}

float sv_first_root_cubic(float c[5]) {
    for (int k = 0; k < 4; ++k) {
        if (!(abs(c[k]) <= 3.4028234663852886e38)) return -1.0;
    }
    if (c[0] == 0.0) return 0.0;
    float m = max(max(abs(c[0]), abs(c[1])), max(abs(c[2]), abs(c[3])));
    float sc = exp2(-clamp(floor(log2(m)), -126.0, 126.0));
    float cs[5];
    for (int k = 0; k < 4; ++k) cs[k] = c[k] * sc;
    cs[4] = 0.0;
    float A = cs[3];
    float B = cs[2];
    float C = cs[1];
    float D = cs[0];
    float d1 = A * C - B * B;
    float d2 = A * D - B * C;
    float d3 = B * D - C * C;
    float disc = 4.0 * d1 * d3 - d2 * d2;
    float QA = -2.0 * B * d1 + A * d2;
    float QD = -2.0 * C * d3 + D * d2;
    vec4 X;
    vec4 W;
    if (disc >= 0.0) {
        float sq = sqrt(disc);
        float phA = atan(abs(A) * sq, -QA) / 3.0;
        float rA = sqrt(max(-d1, 0.0));
        float cA = cos(phA);
        float sA = sin(phA);
        float y1 = 2.0 * rA * cA;
        float y3 = -rA * (cA + 1.7320508 * sA);
        float y2 = rA * (1.7320508 * sA - cA);
        float yL = (y1 + y3 > 2.0 * B) ? y1 : y3;
        float phD = atan(abs(D) * sq, -QD) / 3.0;
        float rD = sqrt(max(-d3, 0.0));
        float cD = cos(phD);
        float sD = sin(phD);
        float z1 = 2.0 * rD * cD;
        float z3 = -rD * (cD + 1.7320508 * sD);
        float zS = (z1 + z3 > 2.0 * C) ? z1 : z3;
        float xL = yL - B;
        float wL = A;
        float xS = D;
        float wS = zS - C;
        float E = wL * wS;
        float F = -(wL * xS + xL * wS);
        float G = xL * xS;
        X = vec4(xL, xS, C * F - B * G, y2 - B);
        W = vec4(wL, wS, C * E - B * F, A);
    } else {
        float sq = sqrt(-disc);
        float yA = sv_cardano_real(d1, QA, abs(A) * sq);
        float zD = sv_cardano_real(d3, QD, abs(D) * sq);
        X = vec4(yA - B, D, -0.5 * yA - B, D);
        W = vec4(A, zD - C, A, -0.5 * zD - C);
    }
    vec4 den = X + W;
    vec4 x;
    bvec4 valid;
    for (int i = 0; i < 4; ++i) {
        float t = X[i] / ((den[i] != 0.0) ? den[i] : 1.0);
        valid[i] = den[i] != 0.0 && abs(t) < 1e30;
        x[i] = valid[i] ? clamp(t, 0.0, 1.0) : -1.0;
    }
    float ca[5];
    for (int k = 0; k < 5; ++k) ca[k] = abs(cs[k]);
    vec4 acc = vec4(2.0);
    vec4 accf = vec4(3.4028234663852886e38);
    for (int it = 0; it <= SV_CUBIC_POLISH; ++it) {
        vec4 f;
        vec4 fp;
        vec4 S;
        vec4 dummy;
        sv_bernstein_eval_deriv4(cs, 3, x, f, fp);
        sv_bernstein_eval_deriv4(ca, 3, x, S, dummy);
        vec4 tol = sv_root_tol_k(3) * SV_ROOT_EPS32 * S + SV_ROOT_EPS32 * abs(x * fp);
        for (int i = 0; i < 4; ++i) {
            if (valid[i] && abs(f[i]) <= tol[i] && abs(f[i]) < accf[i]) {
                acc[i] = x[i];
                accf[i] = abs(f[i]);
            }
            if (it < SV_CUBIC_POLISH) {
                float xn = x[i] - f[i] / ((fp[i] != 0.0) ? fp[i] : 1.0);
                if (valid[i] && fp[i] != 0.0 && abs(xn) < 1e30) x[i] = clamp(xn, 0.0, 1.0);
            }
        }
    }
    float best = min(min(acc.x, acc.y), min(acc.z, acc.w));
    return (best <= 1.0) ? best : -1.0;
}

// ------------------------------------------------------------------------------------------------------
// The method of [Kalbe2008, sec. 5.3]: Newton's method from the three starting values 0, the inflection point
// w of the cubic (the root of f'', w = 1/2 if there is none in (0, 1)) and 1, with a fixed number of
// iterations (the paper: I = 5).  Same residual acceptance, no clamping and the same guards as
// sv_first_root_newton4 (the paper gives no acceptance rule; a returned iterate must pass
// |f(x)| <= K_3 eps32 sum |c_k| B_k(x)).  The fourth vec4 lane repeats the start w (no effect on the
// result).  The twin is splinevis.bb.roots.newton_three_starts.  iterations in 1..8; -1.0 if no root.
float sv_first_root_newton3(float c[5], int iterations) {
    float w0;
    float w1;
    sv_inflection_points(c, 3, w0, w1);
    if (!(w0 > 0.0 && w0 < 1.0)) w0 = 0.5;
    // the fourth lane repeats the middle start (vec4 arithmetic; it changes nothing)
    return sv_newton_from_starts(c, 3, vec4(0.0, w0, 1.0, w0), iterations);
}

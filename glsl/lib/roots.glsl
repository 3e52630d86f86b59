// First root in [0, 1] of a univariate BB polynomial of degree n <= 4 by Newton iteration from secure
// starting points (Kalbe, Zeilfelder et al., "High-quality rendering of varying isosurfaces with cubic
// trivariate C1-continuous splines" / the quartic ray-patch intersection of paper 000, sec. VI, the
// pseudo-code "x0 = (0, w0, w1, 1); for (i = 0; i < 6; i++) x_{i+1} = x_i - F(x_i)/F'(x_i)").
// Newton converges to the roots of every convex or concave piece when started at its end points, and
// the pieces of f on [0, 1] are delimited by 0, the (at most two) inflection points w0 <= w1, and 1.
//
// The float64 twin is splinevis.bb.roots.newton_secure; it mirrors this file line by line.
#include "lib/bernstein.glsl"

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

// Smallest root in [0, 1] of f(t) = sum_{k<=n} c_k B^n_k(t), n in 0..4, after `iterations` (1..8)
// Newton steps from x = (0, w0, w1, 1).  Returns -1.0 when no candidate passes the residual test
// |f(x)| <= K_n eps32 sum_k |c_k| B^n_k(x) (the Python twin returns NaN there).  A start whose
// derivative is 0, or whose step is not finite, keeps its x.  Nothing is clamped: iterates leaving
// [0, 1] are simply not accepted.  The zero polynomial returns 0.
float sv_first_root(float c[5], int n, int iterations) {
    float w0;
    float w1;
    sv_inflection_points(c, n, w0, w1);
    if (!(w0 > 0.0 && w0 < 1.0)) w0 = 1.0 / 3.0;
    if (!(w1 > 0.0 && w1 < 1.0)) w1 = 2.0 / 3.0;
    vec4 x = vec4(0.0, w0, w1, 1.0);
    vec4 f;
    vec4 fp;
    for (int it = 0; it < 8; ++it) {
        if (it < iterations) {
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

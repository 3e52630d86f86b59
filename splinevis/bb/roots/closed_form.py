"""Closed-form first roots of quadratic and cubic BB polynomials, stable in float32 (line-by-line twins
of the GLSL ``sv_first_root_quadratic`` and ``sv_first_root_cubic``)."""

from __future__ import annotations

import numpy as np

from .bernstein import _eval_deriv
from .tolerance import EPS32, _check_dtype, _check_univariate, root_tolerance_k

__all__ = ["first_root_quadratic", "first_root_cubic", "CUBIC_POLISH"]


def first_root_quadratic(c, *, dtype=np.float64):
    """First root in [0, 1] of a quadratic BB polynomial by the stable closed form (NaN if none).

    Mirrors ``sv_first_root_quadratic`` in ``glsl/lib/core/roots.glsl`` operation by operation:
    ``f = A t^2 + B t + C`` with ``A = c0 - 2 c1 + c2``, ``B = 2 (c1 - c0)``, ``C = c0``;
    ``q = -(B + sign(B) sqrt(B^2 - 4AC)) / 2``, roots ``q / A`` and ``C / q``; ``c0 = 0`` gives 0; ``A = 0``
    the linear root ``-C / B``; a negative discriminant returns the vertex ``-B / (2A)`` if it passes the
    residual test ``|f| <= K_2 EPS32 sum |c_k| B_k`` (a tangent ray), else nothing.

    Parameters
    ----------
    c : (..., 3) array_like
        BB coefficients.
    dtype : numpy float type
        np.float32 reproduces the GPU's arithmetic; np.float64 is the reference precision.

    Examples
    --------
    >>> first_root_quadratic([[3 / 16, -5 / 16, 3 / 16], [1.0, 2.0, 1.0]])  # (t - 1/4)(t - 3/4); no root
    array([0.25,  nan])
    """
    c = _check_univariate(c, high=2)
    if c.shape[-1] != 3:
        raise ValueError(f"first_root_quadratic needs 3 coefficients (degree 2), got {c.shape[-1]}.")
    dt = _check_dtype(dtype)
    c = c.astype(dt)
    two, half = dt(2.0), dt(0.5)
    with np.errstate(all="ignore"):
        A = c[..., 0] - two * c[..., 1] + c[..., 2]
        B = two * (c[..., 1] - c[..., 0])
        C = c[..., 0]
        disc = B * B - dt(4.0) * A * C
        sq = np.sqrt(np.maximum(disc, dt(0)))
        q = -half * (B + np.where(B >= 0, dt(1), dt(-1)) * sq)
        r1 = q / A
        r2 = np.where(q != 0, C / q, r1)
        lin = -C / B
        ts = -B / (two * A)
        s = dt(1) - ts
        f = c[..., 0] * s * s + two * c[..., 1] * s * ts + c[..., 2] * ts * ts
        S = np.abs(c[..., 0]) * s * s + two * np.abs(c[..., 1]) * s * ts + np.abs(c[..., 2]) * ts * ts
        touch = np.abs(f) <= dt(root_tolerance_k(2) * EPS32) * S

        def ok(r):
            return (r >= 0) & (r <= 1)

        best = np.full(A.shape, np.inf, dtype=dt)
        quad = (A != 0) & (disc >= 0)
        best = np.where(quad & ok(r1), np.minimum(best, r1), best)
        best = np.where(quad & ok(r2), np.minimum(best, r2), best)
        best = np.where((A == 0) & (B != 0) & ok(lin), lin, best)
        best = np.where((A != 0) & (disc < 0) & ok(ts) & touch, ts, best)
        best = np.where(C == 0, dt(0), best)
    return np.where(best <= 1, best, np.nan).astype(np.float64)


#: Newton steps polishing the closed-form candidates (``SV_CUBIC_POLISH`` in ``glsl/lib/core/roots.glsl``).
CUBIC_POLISH = 1
_SQRT3 = 1.7320508075688772


def _cardano_real(P, Q, R, dt):
    """mirrors glsl/lib/core/roots.glsl sv_cardano_real: real root of y^3 + 3 P y + Q, R = sqrt(Q^2 + 4 P^3)."""
    s = dt(-0.5) * (Q + np.where(Q >= 0.0, R, -R))                 # s = -0.5 * (Q + (Q >= 0 ? R : -R))
    u = (np.sign(s) * np.power(np.abs(s), dt(1.0 / 3.0))).astype(dt)  # sign(s) * pow(abs(s), 1.0 / 3.0)
    v = np.where(u != 0.0, -P / np.where(u != 0.0, u, dt(1.0)), dt(0.0))
    return np.where(P > 0.0, -Q / (u * u + v * v + P), u + v).astype(dt)


def first_root_cubic(c, *, dtype=np.float64, polish: int = CUBIC_POLISH):
    """First root in [0, 1] of cubic BB polynomials by a stable closed form (NaN if none).

    Mirrors ``sv_first_root_cubic`` in ``glsl/lib/core/roots.glsl`` operation by operation (the GLSL's
    ``atan``, ``cos``, ``sin``, ``pow``, ``log2`` and ``exp2`` are not correctly rounded, so the float32
    twin agrees with the GPU only after the Newton polish, within the root's rounding level).

    Method
    ------
    With ``x = t``, ``w = 1 - t`` the cubic is the binary form ``A x^3 + 3B x^2 w + 3C x w^2 + D w^3`` with
    ``(A, B, C, D) = (c3, c2, c1, c0)``; roots ``(x : w)`` give ``t = x / (x + w)``, in [0, 1] iff ``x, w``
    have the same sign. After exact power-of-two scaling (``max |c_k|`` in [1, 2)), the Hessian
    ``d1 = AC - B^2, d2 = AD - BC, d3 = BD - C^2`` and ``disc = 4 d1 d3 - d2^2`` decide between

    * ``disc >= 0``: the trigonometric solution of the two depressed forms ``y^3 + 3 d1 y + Q_A``
      (``x = y - B, w = A``; ``Q_A = A d2 - 2 B d1``) and ``z^3 + 3 d3 z + Q_D`` (``x = D, w = z - C``;
      ``Q_D = D d2 - 2 C d3``), taking from each the extreme root without cancellation (the largest and the
      smallest ``|x / w|``), the third root from the quadratic cofactor, plus the A-form's middle root;
    * ``disc < 0``: cancellation-free Cardano in both forms (the real root), and the real part of the
      complex pair in both forms (a tangency candidate).

    ``sqrt`` of the depressed discriminants is taken as ``|A| sqrt(|disc|)`` resp. ``|D| sqrt(|disc|)``
    (exact identities). The four candidates (non-finite dropped, the rest clamped to [0, 1]) get ``polish``
    Newton steps on the BB form; every iterate is tested with ``|f(x)| <= K_3 EPS32 sum |c_k| B_k(x)``
    (:func:`root_tolerance_k`) widened by the argument rounding ``EPS32 |x f'(x)|`` (needed where
    ``|f'| ulp / 2`` exceeds the evaluation error: no float32 number passes the plain test there); each
    lane keeps its passing iterate of smallest ``|f|``, the smallest accepted ``t`` wins.

    Parameters
    ----------
    c : (..., 4) array_like
        BB coefficients of degree 3 (non-finite values allowed: no root).
    dtype : {numpy.float64, numpy.float32}
        float32 emulates the GPU (without FMA).
    polish : int
        Newton steps after the closed form (0..4); the GLSL uses ``SV_CUBIC_POLISH`` (default 1).

    Returns
    -------
    ndarray, shape ``c.shape[:-1]``
        First root, NaN if none. ``c0 == 0`` (including the zero polynomial) gives 0.

    Examples
    --------
    ``(t - 1/4)(t - 3/4)`` elevated to a cubic, in float64 and as the GPU computes it:

    >>> c = np.array([3 / 16, -7 / 48, -7 / 48, 3 / 16])
    >>> r32 = first_root_cubic(c.astype(np.float32), dtype=np.float32)
    >>> round(float(first_root_cubic(c)), 12), float(r32), r32.dtype
    (0.25, 0.25, dtype('float32'))
    """
    c = _check_univariate(c, high=3, finite=False)
    if c.shape[-1] != 4:
        raise ValueError(f"first_root_cubic needs 4 coefficients (degree 3), got {c.shape[-1]}.")
    if isinstance(polish, bool) or not isinstance(polish, (int, np.integer)) or not 0 <= polish <= 4:
        raise ValueError(f"polish must be an integer in 0..4; got {polish!r}.")
    dt = _check_dtype(dtype)
    lead = c.shape[:-1]
    cc = c.astype(dt).reshape(-1, 4)
    two, half = dt(2.0), dt(0.5)
    with np.errstate(all="ignore"):
        finite = np.all(np.abs(cc) <= np.finfo(np.float32).max, axis=-1)
        m = np.max(np.abs(cc), axis=-1)
        e = np.clip(np.floor(np.log2(np.where(m > 0, m, dt(1.0)))), -126.0, 126.0).astype(dt)
        cs = cc * np.exp2(-e).astype(dt)[:, None]                  # exact power-of-two scaling
        A, B, C, D = cs[:, 3], cs[:, 2], cs[:, 1], cs[:, 0]
        d1 = A * C - B * B
        d2 = A * D - B * C
        d3 = B * D - C * C
        disc = dt(4.0) * d1 * d3 - d2 * d2
        QA = dt(-2.0) * B * d1 + A * d2
        QD = dt(-2.0) * C * d3 + D * d2
        three_real = disc >= 0.0
        # disc >= 0: trigonometric method
        sq = np.sqrt(np.abs(disc))
        s3 = dt(_SQRT3)
        phA = np.arctan2(np.abs(A) * sq, -QA) / dt(3.0)
        rA = np.sqrt(np.maximum(-d1, dt(0.0)))
        cA, sA = np.cos(phA), np.sin(phA)
        y1 = two * rA * cA
        y3 = -rA * (cA + s3 * sA)
        y2 = rA * (s3 * sA - cA)
        yL = np.where(y1 + y3 > two * B, y1, y3)
        phD = np.arctan2(np.abs(D) * sq, -QD) / dt(3.0)
        rD = np.sqrt(np.maximum(-d3, dt(0.0)))
        cD, sD = np.cos(phD), np.sin(phD)
        z1 = two * rD * cD
        z3 = -rD * (cD + s3 * sD)
        zS = np.where(z1 + z3 > two * C, z1, z3)
        xL, wL, xS, wS = yL - B, A, D, zS - C
        E = wL * wS
        F = -(wL * xS + xL * wS)
        G = xL * xS
        X3 = np.stack([xL, xS, C * F - B * G, y2 - B], axis=-1)
        W3 = np.stack([wL, wS, C * E - B * F, A], axis=-1)
        # disc < 0: Cardano in both forms plus the real parts of the complex pair
        yA = _cardano_real(d1, QA, np.abs(A) * sq, dt)
        zD = _cardano_real(d3, QD, np.abs(D) * sq, dt)
        X1 = np.stack([yA - B, D, -half * yA - B, D], axis=-1)
        W1 = np.stack([A, zD - C, A, -half * zD - C], axis=-1)
        X = np.where(three_real[:, None], X3, X1).astype(dt)
        W = np.where(three_real[:, None], W3, W1).astype(dt)
        den = X + W
        t = X / np.where(den != 0.0, den, dt(1.0))
        valid = (den != 0.0) & (np.abs(t) < 1e30)
        x = np.where(valid, np.clip(t, dt(0.0), dt(1.0)), dt(-1.0)).astype(dt)
        c4 = cs[:, None, :]
        ca4 = np.abs(c4)
        kt = dt(root_tolerance_k(3)) * dt(EPS32)
        acc = np.full(x.shape, 2.0, dtype=dt)
        accf = np.full(x.shape, np.finfo(np.float32).max, dtype=dt)
        for it in range(polish + 1):
            f, fp = _eval_deriv(c4, x, dt)
            S, _ = _eval_deriv(ca4, x, dt)
            tol = kt * S + dt(EPS32) * np.abs(x * fp)                # ... * S + SV_ROOT_EPS32 * abs(x * fp)
            take = valid & (np.abs(f) <= tol) & (np.abs(f) < accf)   # a lane keeps its passing iterate of
            acc = np.where(take, x, acc)                               # smallest |f|
            accf = np.where(take, np.abs(f), accf)
            if it < polish:
                xn = x - f / np.where(fp != 0.0, fp, dt(1.0))
                ok = valid & (fp != 0.0) & (np.abs(xn) < 1e30)
                x = np.where(ok, np.clip(xn, dt(0.0), dt(1.0)), x).astype(dt)
        best = np.min(acc, axis=-1)
        res = np.where(best <= 1.0, best, np.nan)
        res = np.where(cc[:, 0] == 0.0, 0.0, res)                  # if (c[0] == 0.0) return 0.0;
        res = np.where(finite, res, np.nan)
    return res.astype(dt).reshape(lead)

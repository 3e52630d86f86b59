"""Bracketed Newton on the convex pieces between the inflection points: the default GPU root finder
(a line-by-line twin of the GLSL ``sv_first_root_bracketed``)."""

from __future__ import annotations

import numpy as np

from .bernstein import _eval_deriv, _inflection_points
from .tolerance import EPS32, _check_dtype, _check_univariate, root_tolerance_k

__all__ = ["MAX_BRACKET_ITERATIONS", "first_root_bracketed"]

#: Largest ``iterations`` of :func:`first_root_bracketed` (the constant loop bound of the GLSL).
MAX_BRACKET_ITERATIONS = 16


def _fourier_step(lo, hi, glo, ghi, dlo, dhi, sigma):
    """mirrors glsl/lib/core/roots.glsl sv_bracket_newton: Newton step from the Fourier end of [lo, hi]."""
    # bool from_lo = (sigma != 0.0) ? ((glo < 0.0) == (sigma < 0.0)) : (abs(glo) <= abs(ghi));
    from_lo = np.where(sigma != 0.0, (glo < 0.0) == (sigma < 0.0), np.abs(glo) <= np.abs(ghi))
    x = np.where(from_lo, lo, hi)
    gx = np.where(from_lo, glo, ghi)
    dx = np.where(from_lo, dlo, dhi)
    return x - gx / dx                                             # float xn = x - gx / dx;


def _bracket_newton(g, lo, hi, glo, ghi, dlo, dhi, sigma, iterations, dtype):
    """mirrors glsl/lib/core/roots.glsl sv_bracket_newton (rows independent). g: (M, m+1); the rest (M,)."""
    quarter, half, three = dtype(0.25), dtype(0.5), dtype(0.75)
    g3 = g[:, None, :]
    for _ in range(iterations):                                    # for (it < 16) if (it < iterations)
        xn = _fourier_step(lo, hi, glo, ghi, dlo, dhi, sigma)
        rf = lo + (hi - lo) * (glo / (glo - ghi))                  # regula falsi point
        xn = np.where((xn > lo) & (xn < hi), xn, rf)               # if (!(xn > lo && xn < hi)) xn = ...
        w = hi - lo
        p = np.stack([xn, lo + quarter * w, lo + half * w, lo + three * w], axis=-1)
        gp, dp = _eval_deriv(g3, p, dtype)                         # sv_bernstein_eval_deriv4(g, m, p, gp, dp);
        dp = np.broadcast_to(dp, gp.shape)
        for i in range(4):                                         # lanes in order 0..3
            pi, gi, di = p[:, i], gp[:, i], dp[:, i]
            inside = (pi > lo) & (pi < hi)
            lo_side = (gi != 0.0) & ((gi < 0.0) == (glo < 0.0))
            to_lo = inside & lo_side
            to_hi = inside & ~lo_side
            lo, glo, dlo = np.where(to_lo, pi, lo), np.where(to_lo, gi, glo), np.where(to_lo, di, dlo)
            hi, ghi, dhi = np.where(to_hi, pi, hi), np.where(to_hi, gi, ghi), np.where(to_hi, di, dhi)
    xr = _fourier_step(lo, hi, glo, ghi, dlo, dhi, sigma)
    rf = lo + (hi - lo) * (glo / (glo - ghi))
    return np.where((xr >= lo) & (xr <= hi), xr, rf).astype(dtype)  # if (!(xr >= lo && xr <= hi)) xr = rf;


def first_root_bracketed(c, iterations: int = 8, *, dtype=np.float64):
    """First root in [0, 1] by bracketed Newton on convex pieces (the default GPU method).

    Mirrors ``sv_first_root_bracketed`` in ``glsl/lib/core/roots.glsl`` line by line (``sv_first_root``
    dispatches to it unless ``SV_ROOTS_PAPER`` is defined).

    Method
    ------
    The secure points ``0 <= w0 <= w1 <= 1`` (the inflection points of :func:`inflection_points`, a
    missing one replaced by the neighbouring end so that a piece can be empty) split [0, 1] into three
    pieces on which ``f''`` has constant sign, i.e. ``f`` is convex or concave. Pieces are processed left
    to right and the first one yielding a root gives the answer. On a piece ``[a, b]``:

    * ``|f(a)| <= K_n eps32 sum_k |c_k| B_k(a)`` (the residual tolerance of :func:`root_tolerance_k`):
      ``a`` is a root at float32 precision (includes ``f(a) = 0`` and the zero polynomial).
    * Sign change ``f(a) f(b) < 0``: a convex or concave function with a sign change has exactly one
      root in the piece. (If ``f(b) = 0`` there is an earlier root in ``(a, b)`` iff ``f(a) f'(b) > 0``;
      otherwise ``b`` itself is the first root and the next piece returns it.) It is found by the
      safeguarded Newton iteration below.
    * No sign change, say ``f(a) > 0``: a concave piece stays above ``min(f(a), f(b)) > 0``; a convex
      piece dips below zero only around an interior minimum, which exists iff ``f'(a) < 0 < f'(b)``.
      Since ``f''`` has the sign of ``f'(b) - f'(a)``, both signs together read
      ``f(a) f'(a) < 0 and f'(a) f'(b) < 0``. The extremum ``m`` (single root of the monotone ``f'``) is
      found by the same safeguarded iteration applied to ``f'``. If ``|f(m)| <= tol(m)`` it is a touching
      (double) root / tangential ray and ``m`` is returned; if ``f(m)`` has the sign opposite to
      ``f(a)`` the first root is the unique root in ``[a, m]``; otherwise the piece has no root.
    * After the last piece, ``|f(1)| <= tol(1)`` returns 1.

    Safeguarded Newton on a bracket ``[lo, hi]`` with a sign change: each of the ``iterations`` steps
    evaluates ``g, g'`` at four points in one vec4 de Casteljau (the paper's vector arithmetic, so one
    step costs what one step of the 4-start method costs): the Newton step ``x - g/g'`` from the Fourier
    end ``x`` (where ``g(x) g''(x) >= 0``: Newton then converges monotonically), replaced by the regula
    falsi point if not strictly inside ``(lo, hi)`` or not finite, and the three quarter points. The
    bracket shrinks to the sub-interval with the sign change. Worst-case accuracy: the bracket is at
    most ``4^-N`` of the piece after ``N`` steps (1.5e-5 for N = 8, 2.4e-4 for N = 6) even when no
    Newton step helps; near a simple root the Fourier end converges quadratically (Newton). In float32
    it stops at the rounding level, ``|x - x*| ~ gamma_{3n} S / |f'|``. The result is one more Newton
    step from the Fourier end (already evaluated), clamped into the final bracket.

    The budget is fixed (no data-dependent loop bounds): per piece at most two bracketed runs of
    ``iterations`` steps plus one scalar evaluation.

    Parameters
    ----------
    c : (..., n + 1) array_like
        Coefficients, degree n in 0..4.
    iterations : int
        Steps per bracketed run, 1..16 (default 8; the ray caster passes ``newton_iterations``, 6 by
        default). More steps never hurt: the bracket only shrinks.
    dtype : {numpy.float64, numpy.float32}
        Arithmetic precision; float32 emulates the GPU operation by operation (without FMA).

    Returns
    -------
    ndarray, shape ``c.shape[:-1]``
        The first root, NaN if none (the GLSL returns -1.0). Degree 0: 0 if ``c0 == 0``. The zero
        polynomial gives 0; non-finite coefficients give NaN. Coefficients so large that ``n (c_{k+1} - c_k)``
        or the de Casteljau sums overflow (|c| ~ 1e38 in float32) are outside the contract: the GPU's
        inf/NaN propagation may then differ from this twin.

    Examples
    --------
    ``(t - 1/4)(t - 3/4)`` and the touching ``(t - 1/2)^2`` (a tangential ray), elevated to quartics:

    >>> round(float(first_root_bracketed([3 / 16, -1 / 16, -7 / 48, -1 / 16, 3 / 16])), 12)
    0.25
    >>> c = np.array([0.25, 0.0, -1 / 12, 0.0, 0.25])
    >>> r32 = first_root_bracketed(c.astype(np.float32), dtype=np.float32)
    >>> float(first_root_bracketed(c)), float(r32), r32.dtype
    (0.5, 0.5, dtype('float32'))
    """
    c = _check_univariate(c, finite=False)
    if (isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer))
            or not 1 <= iterations <= MAX_BRACKET_ITERATIONS):
        raise ValueError(f"iterations must be an integer in 1..{MAX_BRACKET_ITERATIONS}; got {iterations!r}.")
    dtype = _check_dtype(dtype)
    n = c.shape[-1] - 1
    lead = c.shape[:-1]
    cc = c.astype(dtype).reshape(-1, n + 1)
    zero, one = dtype(0.0), dtype(1.0)
    res = np.full(cc.shape[0], np.nan, dtype=dtype)
    with np.errstate(all="ignore"):
        finite = np.all(np.isfinite(cc), axis=-1)                  # abs(c[k]) <= FLT_MAX, else -1
        if n == 0:
            res = np.where(finite & (cc[:, 0] == 0.0), zero, res)  # (c[0] == 0.0) ? 0.0 : -1.0
            return res.reshape(lead)
        done = ~finite
        w0, w1 = _inflection_points(cc, dtype)
        w0 = np.where((w0 > 0.0) & (w0 < 1.0), w0, zero)           # if (!(w0 > 0.0 && w0 < 1.0)) w0 = 0.0;
        w1 = np.where((w1 > 0.0) & (w1 < 1.0), w1, one)            # if (!(w1 > 0.0 && w1 < 1.0)) w1 = 1.0;
        p = np.stack([np.zeros_like(w0), w0, w1, np.ones_like(w0)], axis=-1).astype(dtype)
        ca = np.abs(cc)
        d = np.stack([dtype(n) * (cc[:, k + 1] - cc[:, k]) for k in range(n)], axis=-1)  # d_k = n (c_{k+1} - c_k)
        f, _ = _eval_deriv(cc[:, None, :], p, dtype)
        S, _ = _eval_deriv(ca[:, None, :], p, dtype)
        g, gp = _eval_deriv(d[:, None, :], p, dtype)               # g = f', gp = f'' at the secure points
        gp = np.broadcast_to(gp, g.shape)
        kt = dtype(root_tolerance_k(n)) * dtype(EPS32)
        tol = kt * S
        for i in range(3):
            a, b, fa, fb = p[:, i], p[:, i + 1], f[:, i], f[:, i + 1]
            ga, gb = g[:, i], g[:, i + 1]
            acc = ~done & (np.abs(fa) <= tol[:, i])                # if (abs(fa) <= tol[i]) return a;
            res = np.where(acc, a, res)
            done |= acc
            sigma = gb - ga                                        # sign of f'' on the piece
            change = np.where(fb == 0.0, (gb != 0.0) & ((fa < 0.0) == (gb < 0.0)), (fa < 0.0) != (fb < 0.0))
            idx = np.nonzero(~done & change)[0]
            if idx.size:
                res[idx] = _bracket_newton(cc[idx], a[idx], b[idx], fa[idx], fb[idx], ga[idx], gb[idx],
                                           sigma[idx], iterations, dtype)
                done[idx] = True
            dip = ((ga != 0.0) & (gb != 0.0) & ((fa < 0.0) != (ga < 0.0)) & ((ga < 0.0) != (gb < 0.0)))
            idx = np.nonzero(~done & dip)[0]
            if idx.size:
                m = _bracket_newton(d[idx], a[idx], b[idx], ga[idx], gb[idx], gp[idx, i], gp[idx, i + 1],
                                    np.zeros(idx.size, dtype), iterations, dtype)
                fm, fpm = _eval_deriv(cc[idx], m, dtype)
                Sm, _ = _eval_deriv(ca[idx], m, dtype)
                touch = np.abs(fm) <= kt * Sm                      # if (abs(fm) <= tol(m)) return m;
                cross = ~touch & ((fm < 0.0) != (fa[idx] < 0.0))
                r = np.where(touch, m, np.nan).astype(dtype)
                j = np.nonzero(cross)[0]
                if j.size:
                    k = idx[j]
                    r[j] = _bracket_newton(cc[k], a[k], m[j], fa[k], fm[j], ga[k], fpm[j], sigma[k], iterations, dtype)
                sel = touch | cross
                res[idx[sel]] = r[sel]
                done[idx[sel]] = True
        last = ~done & (np.abs(f[:, 3]) <= tol[:, 3])              # return (abs(f[3]) <= tol[3]) ? 1.0 : -1.0;
        res = np.where(last, one, res)
    return res.reshape(lead)

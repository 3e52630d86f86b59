"""Roots on [0, 1] of univariate Bernstein-Bezier polynomials of degree <= 4.

Three methods:

* :func:`first_root_bracketed` -- the default GPU method (``sv_first_root_bracketed``, used by
  ``sv_first_root`` in ``glsl/lib/roots.glsl``), a line-by-line twin: bracketed Newton on the convex
  pieces between the inflection points, with a fixed iteration budget.
* :func:`newton_secure` -- paper 000's GPU method (``sv_first_root_newton4``; ``sv_first_root`` with
  ``SV_ROOTS_PAPER_NEWTON`` defined), a line-by-line twin: Newton iteration from the "secure" starting
  points ``(0, w0, w1, 1)`` (end points and inflection points), accepting the smallest iterate in [0, 1]
  that passes a residual test whose constant is derived from the float32 rounding bound of de
  Casteljau's algorithm (paper 000, sec. VI). It often returns a later root than the first one.
* :func:`roots_reference` -- a robust float64 reference that reports every root in [0, 1] (companion
  matrix eigenvalues, a sign-change scan with bisection, Newton polishing, merging of duplicates).

Coefficients are arrays ``(..., n + 1)``; ``n = c.shape[-1] - 1`` is the degree (0..4) and coefficient
``k`` multiplies ``B^n_k(t) = C(n, k) (1 - t)^(n - k) t^k`` (see :mod:`splinevis.bb.simplex`).
"""

from __future__ import annotations

from math import comb

import numpy as np

from .._validation import as_float64_array, check_degree

__all__ = [
    "first_root_quadratic",
    "MAX_ROOT_DEGREE",
    "EPS32",
    "root_tolerance_k",
    "eval_deriv",
    "inflection_points",
    "newton_secure",
    "first_root_bracketed",
    "MAX_BRACKET_ITERATIONS",
    "roots_reference",
    "first_root_reference",
]

#: Largest degree the root finders accept (the GPU code uses ``float c[5]``).
MAX_ROOT_DEGREE = 4
#: float32 machine epsilon 2^-23 (= 2u, u the unit roundoff).
EPS32 = 2.0**-23
_U32 = 2.0**-24


def root_tolerance_k(n: int) -> float:
    """Constant ``K_n`` of the residual test ``|f(x)| <= K_n * EPS32 * sum_k |c_k| B_k(x)``.

    Notes
    -----
    With u = 2^-24: the float32 de Casteljau value is within ``gamma_{3n} S`` of the exact value at the
    float32 argument (``S = sum |c_k| B_k``; each level rounds ``1 - t``, two products and one sum), and
    rounding a simple root ``x*`` to float32 adds ``|f'(x*)| ulp/2``, which is bounded by another
    ``gamma_{3n} S`` unless the root is argument-ill-conditioned (those cases are classified in the
    self-test). S itself is computed with relative error ``gamma_{3n}`` and ``K eps S`` costs two more
    roundings, so ``K_n = 2 gamma_{3n} / eps32 / (1 - gamma_{3n}) (1 + u)^2 <= 3n (1 + 2^-16)`` for
    n <= 4. Same expression as ``sv_root_tol_k`` in ``glsl/lib/roots.glsl``.
    """
    return 3.0 * float(n) * (1.0 + 2.0**-16)


def _check_univariate(c, name="coefficients", high=MAX_ROOT_DEGREE, finite=True):
    c = as_float64_array(c, name, finite=finite)
    if c.ndim < 1 or c.shape[-1] < 1:
        raise ValueError(f"{name} must have shape (..., n + 1) with degree n in 0..{high}; got shape {c.shape}.")
    check_degree(c.shape[-1] - 1, f"degree n (= {name}.shape[-1] - 1)", low=0, high=high)
    return c


# ----------------------------------------------------------------------------------------------------
# twin of glsl/lib/bernstein.glsl
# ----------------------------------------------------------------------------------------------------

def _eval_deriv(c, x, dtype):
    """mirrors glsl/lib/bernstein.glsl sv_bernstein_eval_deriv(4): value and derivative at x.
    c: (..., n+1), x: broadcasting against c[..., 0] (possibly with an extra trailing axis handled by caller)."""
    n = c.shape[-1] - 1
    one = dtype(1.0)
    if n == 0:
        f = np.broadcast_to(c[..., 0], np.broadcast_shapes(c[..., 0].shape, np.shape(x))).astype(dtype)
        return f, np.zeros_like(f)
    s = one - x                                        # float s = 1.0 - t;
    b = [c[..., k] for k in range(n + 1)]              # float b[5] = c;
    for level in range(1, n):                          # for level < n
        for k in range(0, n - level + 1):              #   for k <= n - level
            b[k] = s * b[k] + x * b[k + 1]             #     b[k] = s * b[k] + t * b[k + 1];
    f = s * b[0] + x * b[1]                            # f = (1.0 - t) * b0 + t * b1;
    fp = dtype(n) * (b[1] - b[0])                      # fp = float(n) * (b1 - b0);
    return f, fp


def eval_deriv(c, t, *, dtype=np.float64):
    """Value and derivative of univariate BB polynomials exactly as the GPU computes them.

    Parameters
    ----------
    c : (..., n + 1) array_like
        Coefficients, degree n in 0..4.
    t : array_like
        Parameters, broadcasting against ``c.shape[:-1]``.
    dtype : {numpy.float64, numpy.float32}
        Arithmetic precision. float32 reproduces ``sv_bernstein_eval_deriv`` of
        ``glsl/lib/bernstein.glsl`` operation by operation (up to fused multiply-adds on the GPU).

    Returns
    -------
    f, fp : ndarray
        ``f(t)`` after n de Casteljau levels and ``f'(t) = n (b1 - b0)``.
    """
    c = _check_univariate(c)
    t = as_float64_array(t, "t")
    dtype = _check_dtype(dtype)
    with np.errstate(all="ignore"):
        return _eval_deriv(c.astype(dtype), t.astype(dtype), dtype)


def _check_dtype(dtype):
    if dtype in (np.float64, np.float32):
        return dtype
    dt = np.dtype(dtype)
    if dt == np.float64:
        return np.float64
    if dt == np.float32:
        return np.float32
    raise TypeError(f"dtype must be numpy.float64 or numpy.float32, got {dtype!r}.")


def _inflection_points(c, dtype):
    """mirrors glsl/lib/roots.glsl sv_inflection_points."""
    n = c.shape[-1] - 1
    shape = c.shape[:-1]
    w0 = np.full(shape, -1.0, dtype=dtype)
    w1 = np.full(shape, -1.0, dtype=dtype)
    two = dtype(2.0)
    if n == 4:
        a0 = c[..., 2] - two * c[..., 1] + c[..., 0]
        a1 = c[..., 3] - two * c[..., 2] + c[..., 1]
        a2 = c[..., 4] - two * c[..., 3] + c[..., 2]
        A = a0 - two * a1 + a2
        B = two * (a1 - a0)
        C = a0
        lin = A == 0.0
        # if (A == 0.0) { if (B != 0.0) w0 = -C / B; }
        w0 = np.where(lin & (B != 0.0), -C / np.where(B != 0.0, B, 1.0), w0)
        disc = B * B - dtype(4.0) * A * C
        quad = ~lin & (disc >= 0.0)
        sgn = np.where(B >= 0.0, dtype(1.0), dtype(-1.0))
        q = dtype(-0.5) * (B + sgn * np.sqrt(np.where(quad, disc, 0.0)))
        r0 = q / np.where(lin, 1.0, A)
        r1 = np.where(q != 0.0, C / np.where(q != 0.0, q, 1.0), r0)
        w0 = np.where(quad, np.minimum(r0, r1), w0)
        w1 = np.where(quad, np.maximum(r0, r1), w1)
    elif n == 3:
        a0 = c[..., 2] - two * c[..., 1] + c[..., 0]
        a1 = c[..., 3] - two * c[..., 2] + c[..., 1]
        ok = a0 != a1
        w0 = np.where(ok, a0 / np.where(ok, a0 - a1, 1.0), w0)
    return w0.astype(dtype), w1.astype(dtype)


def inflection_points(c, *, dtype=np.float64):
    """Roots ``w0 <= w1`` of the second derivative (closed form), ``-1`` where there is none.

    Degree 4: the quadratic ``f''`` is solved with the cancellation-free formula; degree 3: the linear
    ``f''``; lower degrees have none. Values are not restricted to (0, 1) here.

    Returns
    -------
    w0, w1 : ndarray, shape ``c.shape[:-1]``
    """
    c = _check_univariate(c)
    dtype = _check_dtype(dtype)
    with np.errstate(all="ignore"):
        return _inflection_points(c.astype(dtype), dtype)


def _newton_from_starts(cc, n, x, iterations, dtype):
    """Twin of ``sv_newton_from_starts``: ``iterations`` Newton steps from the starts x (..., 4), then the
    smallest x in [0, 1] passing ``|f(x)| <= K_n eps32 sum_k |c_k| B_k(x)``; (root or NaN, x, accepted)."""
    c4 = cc[..., None, :]  # broadcast the coefficients over the four starts
    for _ in range(iterations):
        f, fp = _eval_deriv(c4, x, dtype)
        nz = fp != 0.0                                       # bvec4 nz = notEqual(fp, vec4(0.0));
        xn = x - f / np.where(nz, fp, dtype(1.0))            # vec4 xn = x - f / mix(vec4(1.0), fp, nz);
        ok = nz & (np.abs(xn) < 1e30)                        # keep x where f' = 0 or step not finite
        x = np.where(ok, xn, x).astype(dtype)                # x = mix(x, xn, ok);
    f, _ = _eval_deriv(c4, x, dtype)
    S, _ = _eval_deriv(np.abs(c4), x, dtype)                 # S = sum |c_k| B_k(x)
    tol = dtype(root_tolerance_k(n)) * dtype(EPS32) * S      # vec4 tol = sv_root_tol_k(n) * SV_ROOT_EPS32 * S;
    accept = (x >= 0.0) & (x <= 1.0) & (np.abs(f) <= tol)
    best = np.min(np.where(accept, x, np.inf), axis=-1)
    return np.where(np.isfinite(best), best, np.nan), x, accept


def newton_secure(c, iterations: int = 6, *, dtype=np.float64, return_candidates: bool = False):
    """First root in [0, 1] by Newton iteration from secure starting points (the GPU method).

    Paper 000's method. Mirrors ``sv_first_root_newton4`` in ``glsl/lib/roots.glsl`` line by line
    (``sv_first_root`` with ``SV_ROOTS_PAPER_NEWTON`` defined):

    1. inflection points ``w0 <= w1`` (roots of ``f''``); ``w0 := 1/3`` unless in (0, 1), ``w1 := 2/3``
       unless in (0, 1) (paper 000, sec. VI pseudo-code);
    2. ``iterations`` Newton steps ``x <- x - f(x)/f'(x)`` from each of ``x = (0, w0, w1, 1)``; a start
       with ``f'(x) = 0`` or a non-finite step keeps its ``x``; nothing is clamped;
    3. the result is the smallest of the four ``x`` in [0, 1] with
       ``|f(x)| <= K_n eps32 sum_k |c_k| B_k(x)`` (:func:`root_tolerance_k`), NaN if none.

    Parameters
    ----------
    c : (..., n + 1) array_like
        Coefficients, degree n in 0..4.
    iterations : int
        Newton steps, 1..8 (the paper uses 6: "full floating point accuracy").
    dtype : {numpy.float64, numpy.float32}
        Arithmetic precision; float64 is the reference twin, float32 emulates the GPU (without FMA).
        The constants 1/3 and 2/3 are the float32 values in both cases, as on the GPU.
    return_candidates : bool
        Also return the four final iterates ``(..., 4)`` and the acceptance mask ``(..., 4)``.

    Returns
    -------
    ndarray, shape ``c.shape[:-1]``
        The first accepted root, NaN if none (the GLSL returns -1.0). The zero polynomial gives 0.
    """
    c = _check_univariate(c)
    if isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer)) or not 1 <= iterations <= 8:
        raise ValueError(f"iterations must be an integer in 1..8; got {iterations!r}.")
    dtype = _check_dtype(dtype)
    n = c.shape[-1] - 1
    with np.errstate(all="ignore"):
        cc = c.astype(dtype)
        w0, w1 = _inflection_points(cc, dtype)
        # if (!(w0 > 0.0 && w0 < 1.0)) w0 = 1.0 / 3.0;  (float32 constants, as the GPU folds them)
        w0 = np.where((w0 > 0.0) & (w0 < 1.0), w0, dtype(np.float32(1.0 / 3.0)))
        w1 = np.where((w1 > 0.0) & (w1 < 1.0), w1, dtype(np.float32(2.0 / 3.0)))
        # vec4 x = vec4(0.0, w0, w1, 1.0);
        x = np.stack([np.zeros_like(w0), w0, w1, np.ones_like(w0)], axis=-1).astype(dtype)
        root, x, accept = _newton_from_starts(cc, n, x, iterations, dtype)
    if return_candidates:
        return root, x, accept
    return root


# ----------------------------------------------------------------------------------------------------
# bracketed Newton on convex pieces (the default GPU method)
# ----------------------------------------------------------------------------------------------------

#: Largest ``iterations`` of :func:`first_root_bracketed` (the constant loop bound of the GLSL).
MAX_BRACKET_ITERATIONS = 16


def _fourier_step(lo, hi, glo, ghi, dlo, dhi, sigma):
    """mirrors glsl/lib/roots.glsl sv_bracket_newton: Newton step from the Fourier end of [lo, hi]."""
    # bool from_lo = (sigma != 0.0) ? ((glo < 0.0) == (sigma < 0.0)) : (abs(glo) <= abs(ghi));
    from_lo = np.where(sigma != 0.0, (glo < 0.0) == (sigma < 0.0), np.abs(glo) <= np.abs(ghi))
    x = np.where(from_lo, lo, hi)
    gx = np.where(from_lo, glo, ghi)
    dx = np.where(from_lo, dlo, dhi)
    return x - gx / dx                                             # float xn = x - gx / dx;


def _bracket_newton(g, lo, hi, glo, ghi, dlo, dhi, sigma, iterations, dtype):
    """mirrors glsl/lib/roots.glsl sv_bracket_newton (rows independent). g: (M, m+1); the rest (M,)."""
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

    Mirrors ``sv_first_root_bracketed`` in ``glsl/lib/roots.glsl`` line by line (``sv_first_root``
    dispatches to it unless ``SV_ROOTS_PAPER_NEWTON`` is defined).

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


# ----------------------------------------------------------------------------------------------------
# robust float64 reference
# ----------------------------------------------------------------------------------------------------

_MERGE = 1e-7        # candidates closer than this are one root (below float32 resolution on [0, 1])
_SCAN = 64           # grid intervals of the sign-change scan
_EIG_IMAG = 1e-5     # |Im z| up to this keeps an eigenvalue as a candidate (double roots split ~1e-8)


def _f64(c, x):
    """float64 de Casteljau value (c: (M, n+1), x: (M, K))."""
    f, _ = _eval_deriv(c[:, None, :], x, np.float64)
    return f


def _to_power(c):
    """BB -> power form: f(t) = sum_j p_j t^j, p_j = C(n,j) sum_{k<=j} (-1)^(j-k) C(j,k) c_k."""
    n = c.shape[-1] - 1
    mat = np.zeros((n + 1, n + 1))
    for j in range(n + 1):
        for k in range(j + 1):
            mat[j, k] = comb(n, j) * comb(j, k) * (-1) ** (j - k)
    return c @ mat.T


def _isolated_roots(flat: np.ndarray) -> np.ndarray:
    """Roots in [0, 1] by recursive isolation: the roots of f' split [0, 1] into pieces where f is
    monotone, so each piece holds at most one root, found by 60 float64 bisections where f changes
    sign; a critical point where |f| is at rounding level is a multiple root. Exact by construction up to
    float64 rounding, whatever the root spacing (a candidate source for :func:`roots_reference`).
    flat: (m, n + 1). Returns (m, n) sorted, NaN padded (n >= 1)."""
    m, n1 = flat.shape
    n = n1 - 1
    out = np.full((m, max(n, 1)), np.nan)
    if n == 0:
        return out
    if n == 1:
        with np.errstate(all="ignore"):
            t = flat[:, 0] / (flat[:, 0] - flat[:, 1])
        out[:, 0] = np.where((t >= 0.0) & (t <= 1.0), t, np.nan)
        return out
    crit = _isolated_roots(n * (flat[:, 1:] - flat[:, :-1]))  # (m, n - 1)
    brk = np.sort(np.concatenate([np.zeros((m, 1)), crit, np.ones((m, 1))], axis=1), axis=1)  # NaN last
    a, b = brk[:, :-1], brk[:, 1:]
    valid = np.isfinite(a) & np.isfinite(b) & (b > a)
    a0, b0 = np.where(valid, a, 0.0), np.where(valid, b, 0.0)
    c3 = flat[:, None, :]
    fa, _ = _eval_deriv(c3, a0, np.float64)
    fb, _ = _eval_deriv(c3, b0, np.float64)
    S, _ = _eval_deriv(np.abs(c3), a0, np.float64)
    tol = 8 * n * np.finfo(np.float64).eps * S
    found = np.full(a.shape, np.nan)
    found = np.where(valid & (np.abs(fa) <= tol), a0, found)  # root (possibly multiple) at the piece start
    change = valid & np.isnan(found) & (np.signbit(fa) != np.signbit(fb)) & (fb != 0.0)
    lo, hi, flo = a0.copy(), b0.copy(), fa.copy()
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        fm, _ = _eval_deriv(c3, mid, np.float64)
        same = np.signbit(fm) == np.signbit(flo)
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    found = np.where(change, 0.5 * (lo + hi), found)
    f1, _ = _eval_deriv(c3, np.ones((m, 1)), np.float64)
    S1, _ = _eval_deriv(np.abs(c3), np.ones((m, 1)), np.float64)
    end = np.where(np.abs(f1[:, 0]) <= 8 * n * np.finfo(np.float64).eps * S1[:, 0], 1.0, np.nan)
    x = np.sort(np.concatenate([found, end[:, None]], axis=1), axis=1)
    x[:, 1:] = np.where(x[:, 1:] - x[:, :-1] <= 1e-14, np.nan, x[:, 1:])
    return np.sort(x, axis=1)[:, : max(n, 1)]


def roots_reference(c) -> np.ndarray:
    """Every root in [0, 1] of univariate BB polynomials, in float64.

    Parameters
    ----------
    c : (..., n + 1) array_like
        Coefficients, degree n in 0..4.

    Returns
    -------
    (..., max(n, 1)) ndarray
        The distinct roots in [0, 1], ascending, padded with NaN. A double (or triple) root is reported
        once. The zero polynomial is reported as the single root 0 (like :func:`newton_secure`).

    Notes
    -----
    Candidates come from (a) the eigenvalues of the companion matrix of the power form whose imaginary
    part is below 1e-5 (a double root splits into a pair ~1e-8 off the real axis) and (b) a scan of
    signs on a 64-interval grid refined by 52 bisection steps (catches roots the eigenvalues misplace),
    plus exact zeros at the grid points, and (c) recursive isolation: the roots of f' (found the same way)
    cut [0, 1] into monotone pieces, each bisected where f changes sign, critical points with |f| at
    rounding level being multiple roots. Eigenvalue candidates are polished by 20 float64 Newton steps
    (a step is taken only if it lowers ``|f|``) and kept if ``|f(x)| <= 16 n eps64 sum |c_k| B_k(x)``;
    candidates closer than 1e-7 are merged.
    """
    c = _check_univariate(c)
    lead = c.shape[:-1]
    n = c.shape[-1] - 1
    flat = c.reshape(-1, n + 1)
    m = flat.shape[0]
    width = max(n, 1)
    out = np.full((m, width), np.nan)
    if m == 0:
        return out.reshape(lead + (width,))
    zero = np.all(flat == 0.0, axis=-1)
    out[zero, 0] = 0.0
    if n == 0:
        return out.reshape(lead + (width,))
    with np.errstate(all="ignore"):
        cands = [np.full((m, 0), np.nan)]
        # (a) companion matrix eigenvalues, grouped by exact degree of the power form
        p = _to_power(flat)
        nzmask = p != 0.0
        deg = np.where(nzmask.any(-1), n - np.argmax(nzmask[:, ::-1], axis=-1), 0)
        eig_c = np.full((m, n), np.nan)
        for g in range(1, n + 1):
            rows = np.nonzero((deg == g) & ~zero)[0]
            if rows.size == 0:
                continue
            mono = p[rows, :g] / p[rows, g, None]
            comp = np.zeros((rows.size, g, g))
            comp[:, 0, :] = -mono[:, ::-1]
            if g > 1:
                comp[:, np.arange(1, g), np.arange(0, g - 1)] = 1.0
            z = np.linalg.eigvals(comp)
            real = np.where(np.abs(z.imag) <= _EIG_IMAG * (1.0 + np.abs(z)), z.real, np.nan)
            real = np.where((real > -1e-3) & (real < 1.0 + 1e-3), real, np.nan)
            eig_c[rows, :g] = real
        cands.append(eig_c)
        # (b) sign-change scan with bisection, plus exact zeros on the grid
        grid = np.linspace(0.0, 1.0, _SCAN + 1)
        fg = _f64(flat, np.broadcast_to(grid, (m, _SCAN + 1)))
        cands.append(np.where(fg == 0.0, grid, np.nan))
        change = np.signbit(fg[:, :-1]) != np.signbit(fg[:, 1:])
        change &= (fg[:, :-1] != 0.0) & (fg[:, 1:] != 0.0)
        r_idx, i_idx = np.nonzero(change)
        bis = np.full((m, _SCAN), np.nan)
        if r_idx.size:
            lo = grid[i_idx].copy()
            hi = grid[i_idx + 1].copy()
            flo = fg[r_idx, i_idx]
            cc = flat[r_idx]
            for _ in range(52):
                mid = 0.5 * (lo + hi)
                fm = _f64(cc, mid[:, None])[:, 0]
                same = np.signbit(fm) == np.signbit(flo)
                lo = np.where(same, mid, lo)
                hi = np.where(same, hi, mid)
            bis[r_idx, i_idx] = 0.5 * (lo + hi)
        cands.append(bis)
        # polish the eigenvalue candidates with guarded float64 Newton steps (a step must lower |f|)
        xe = np.clip(eig_c, 0.0, 1.0)
        c3 = flat[:, None, :]
        for _ in range(20):
            f, fp = _eval_deriv(c3, xe, np.float64)
            xn = np.clip(xe - f / np.where(fp != 0.0, fp, np.inf), 0.0, 1.0)
            fn, _ = _eval_deriv(c3, xn, np.float64)
            xe = np.where(np.abs(fn) < np.abs(f), xn, xe)
        f, _ = _eval_deriv(c3, xe, np.float64)
        S, _ = _eval_deriv(np.abs(c3), xe, np.float64)
        xe = np.where(np.abs(f) <= 16 * n * np.finfo(np.float64).eps * S, xe, np.nan)
        # (c) recursive isolation on monotone pieces (catches close pairs and multiple roots)
        iso = _isolated_roots(flat)
        # grid zeros are exact roots, bisection brackets are roots by the sign change
        x = np.concatenate([xe, cands[2], bis, iso], axis=1)
        x = np.where(~zero[:, None], x, np.nan)
        x = np.sort(x, axis=1)
        dup = np.zeros_like(x, dtype=bool)
        dup[:, 1:] = (x[:, 1:] - x[:, :-1]) <= _MERGE
        # chains of near-equal candidates collapse onto their first member
        x = np.where(dup, np.nan, x)
        x = np.sort(x, axis=1)[:, :width]
        out[~zero] = x[~zero]
    return out.reshape(lead + (width,))


def first_root_reference(c) -> np.ndarray:
    """Smallest root in [0, 1] by :func:`roots_reference`, NaN if none; shape ``c.shape[:-1]``."""
    return roots_reference(c)[..., 0]


def first_root_quadratic(c, *, dtype=np.float64):
    """First root in [0, 1] of a quadratic BB polynomial by the stable closed form (NaN if none).

    Mirrors ``sv_first_root_quadratic`` in ``glsl/lib/roots.glsl`` operation by operation:
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


# ----------------------------------------------------------------------------------------------------
# stable closed form for cubics, and paper 003's Newton from three starts (issue 4)
# ----------------------------------------------------------------------------------------------------

__all__ += ["first_root_cubic", "newton_three_starts", "CUBIC_POLISH"]

#: Newton steps polishing the closed-form candidates (``SV_CUBIC_POLISH`` in ``glsl/lib/roots.glsl``).
CUBIC_POLISH = 1
_SQRT3 = 1.7320508075688772


def _cardano_real(P, Q, R, dt):
    """mirrors glsl/lib/roots.glsl sv_cardano_real: real root of y^3 + 3 P y + Q, R = sqrt(Q^2 + 4 P^3)."""
    s = dt(-0.5) * (Q + np.where(Q >= 0.0, R, -R))                 # s = -0.5 * (Q + (Q >= 0 ? R : -R))
    u = (np.sign(s) * np.power(np.abs(s), dt(1.0 / 3.0))).astype(dt)  # sign(s) * pow(abs(s), 1.0 / 3.0)
    v = np.where(u != 0.0, -P / np.where(u != 0.0, u, dt(1.0)), dt(0.0))
    return np.where(P > 0.0, -Q / (u * u + v * v + P), u + v).astype(dt)


def first_root_cubic(c, *, dtype=np.float64, polish: int = CUBIC_POLISH):
    """First root in [0, 1] of cubic BB polynomials by a stable closed form (NaN if none).

    Mirrors ``sv_first_root_cubic`` in ``glsl/lib/roots.glsl`` operation by operation (the GLSL's
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


def newton_three_starts(c, iterations: int = 5, *, dtype=np.float64):
    """First root in [0, 1] of cubic BB polynomials by paper 003's Newton from three starts (NaN if none).

    Mirrors ``sv_first_root_newton3`` in ``glsl/lib/roots.glsl`` line by line: ``iterations`` Newton steps
    from ``0``, the inflection point ``w`` (root of ``f''``; ``1/2`` unless in (0, 1)) and ``1`` (paper 003,
    sec. 5.3, ``I = 5``), then the smallest iterate in [0, 1] passing the residual test
    ``|f(x)| <= K_3 EPS32 sum |c_k| B_k(x)`` of :func:`newton_secure`. A start with ``f' = 0`` or a
    non-finite step keeps its ``x``; nothing is clamped. The zero polynomial gives 0.

    Parameters
    ----------
    c : (..., 4) array_like
        BB coefficients of degree 3.
    iterations : int
        1..8.
    dtype : {numpy.float64, numpy.float32}
    """
    c = _check_univariate(c, high=3)
    if c.shape[-1] != 4:
        raise ValueError(f"newton_three_starts needs 4 coefficients (degree 3), got {c.shape[-1]}.")
    if isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer)) or not 1 <= iterations <= 8:
        raise ValueError(f"iterations must be an integer in 1..8; got {iterations!r}.")
    dt = _check_dtype(dtype)
    with np.errstate(all="ignore"):
        cc = c.astype(dt)
        w0, _ = _inflection_points(cc, dt)
        w0 = np.where((w0 > 0.0) & (w0 < 1.0), w0, dt(0.5))          # if (!(w0 > 0 && w0 < 1)) w0 = 0.5;
        x = np.stack([np.zeros_like(w0), w0, np.ones_like(w0), w0], axis=-1).astype(dt)
        root, _, _ = _newton_from_starts(cc, 3, x, iterations, dt)
    return root

"""Roots on [0, 1] of univariate Bernstein-Bezier polynomials of degree <= 4.

Two methods:

* :func:`newton_secure` -- the GPU method, a line-by-line float64 twin of ``glsl/lib/roots.glsl``:
  Newton iteration from the "secure" starting points ``(0, w0, w1, 1)`` (end points and inflection
  points), accepting the smallest iterate in [0, 1] that passes a residual test whose constant is
  derived from the float32 rounding bound of de Casteljau's algorithm (paper 000, sec. VI).
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
    "MAX_ROOT_DEGREE",
    "EPS32",
    "root_tolerance_k",
    "eval_deriv",
    "inflection_points",
    "newton_secure",
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


def _check_univariate(c, name="coefficients", high=MAX_ROOT_DEGREE):
    c = as_float64_array(c, name)
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


def newton_secure(c, iterations: int = 6, *, dtype=np.float64, return_candidates: bool = False):
    """First root in [0, 1] by Newton iteration from secure starting points (the GPU method).

    Mirrors ``sv_first_root`` in ``glsl/lib/roots.glsl`` line by line:

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
        root = np.where(np.isfinite(best), best, np.nan)
    if return_candidates:
        return root, x, accept
    return root


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
    plus exact zeros at the grid points. Eigenvalue candidates are polished by 20 float64 Newton steps
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
        # grid zeros are exact roots, bisection brackets are roots by the sign change
        x = np.concatenate([xe, cands[2], bis], axis=1)
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

"""Robust float64 reference: every root in [0, 1] of a univariate BB polynomial (companion-matrix
eigenvalues, a sign-change scan with bisection, recursive isolation on monotone pieces, Newton polishing
and merging of duplicates). The judge the GPU twins are compared against.
"""

from __future__ import annotations

from math import comb

import numpy as np

from .bernstein import _eval_deriv
from .tolerance import _check_univariate

__all__ = ["roots_reference", "first_root_reference"]

_MERGE = 1e-7        # candidates closer than this are one root (below float32 resolution on [0, 1])
_SCAN = 64           # grid intervals of the sign-change scan
_EIG_IMAG = 1e-5     # |Im z| up to this keeps an eigenvalue as a candidate (double roots split ~1e-8)


def _f64(c, x):
    """float64 de Casteljau value (c: (M, n+1), x: (M, K)). The loops pass c in Fortran order: de Casteljau
    reads coefficient k of every row at once, faster from contiguous columns (the values are the same)."""
    f, _ = _eval_deriv(c[:, None, :], x, np.float64)
    return f


def _bisect(c, lo, hi, flo, steps: int):
    """Midpoints of the brackets ``[lo, hi]`` (one per row of ``c``, ``flo`` the value at ``lo``, the sign
    changing inside) after ``steps`` float64 bisections."""
    cc = np.asfortranarray(c)  # see _f64
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        fm = _f64(cc, mid[:, None])[:, 0]
        same = np.signbit(fm) == np.signbit(flo)
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return 0.5 * (lo + hi)


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
    c3 = np.asfortranarray(flat)[:, None, :]  # see _f64
    fa, _ = _eval_deriv(c3, a0, np.float64)
    fb, _ = _eval_deriv(c3, b0, np.float64)
    S, _ = _eval_deriv(np.abs(c3), a0, np.float64)
    tol = 8 * n * np.finfo(np.float64).eps * S
    found = np.full(a.shape, np.nan)
    found = np.where(valid & (np.abs(fa) <= tol), a0, found)  # root (possibly multiple) at the piece start
    change = valid & np.isnan(found) & (np.signbit(fa) != np.signbit(fb)) & (fb != 0.0)
    # bisect only the brackets that are kept; often there is none (a third of the calls of a terrain walk)
    r_idx, k_idx = np.nonzero(change)
    if r_idx.size:
        found[r_idx, k_idx] = _bisect(flat[r_idx], a0[r_idx, k_idx], b0[r_idx, k_idx], fa[r_idx, k_idx], 60)
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

    Examples
    --------
    >>> roots_reference([3 / 16, -1 / 16, -7 / 48, -1 / 16, 3 / 16])  # (t - 1/4)(t - 3/4)
    array([0.25, 0.75,  nan,  nan])
    >>> roots_reference([[0.25, -0.25, 0.25], [1.0, 2.0, 1.0]])  # a double root 1/2; none
    array([[0.5, nan],
           [nan, nan]])
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
            bis[r_idx, i_idx] = _bisect(flat[r_idx], grid[i_idx], grid[i_idx + 1], fg[r_idx, i_idx], 52)
        cands.append(bis)
        # polish the eigenvalue candidates with guarded float64 Newton steps (a step must lower |f|)
        xe = np.clip(eig_c, 0.0, 1.0)
        c3 = np.asfortranarray(flat)[:, None, :]
        # f and f' at a moved candidate are those already computed at xn: one evaluation a step
        f, fp = _eval_deriv(c3, xe, np.float64)
        for _ in range(20):
            xn = np.clip(xe - f / np.where(fp != 0.0, fp, np.inf), 0.0, 1.0)
            fn, fpn = _eval_deriv(c3, xn, np.float64)
            step = np.abs(fn) < np.abs(f)
            if not step.any():  # no candidate moves: every later step would repeat this one
                break
            xe = np.where(step, xn, xe)
            f = np.where(step, fn, f)
            fp = np.where(step, fpn, fp)
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
    """Smallest root in [0, 1] by :func:`roots_reference`, NaN if none; shape ``c.shape[:-1]``.

    Examples
    --------
    >>> first_root_reference([[3 / 16, -5 / 16, 3 / 16], [1.0, 2.0, 1.0]])
    array([0.25,  nan])
    """
    return roots_reference(c)[..., 0]

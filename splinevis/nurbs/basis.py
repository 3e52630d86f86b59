"""B-spline basis functions on a knot vector, vectorized over parameters (float64).

Names follow [PieglTiller1997, ch. 2]: ``find_span`` (A2.1), ``basis_funs`` (A2.2), ``ders_basis_funs``
(A2.3). Each takes an array of parameters and returns one row per parameter; the loops run over the degree
(at most MAX_DEGREE = 25), never over the parameters. This is the float64 twin of ``glsl/lib/nurbs/basis.glsl``.

Conventions
-----------
* A knot vector ``U = (u_0, ..., u_m)`` of degree ``p`` carries ``n + 1 = m - p`` basis functions; the
  parameter domain is ``[u_p, u_{n+1}]`` (clamped or not).
* ``find_span`` returns the ``i`` with ``u_i <= u < u_{i+1}`` and ``p <= i <= n``; at the domain's right end
  ``u = u_{n+1}`` it returns ``n`` (the last non-empty span), so the end point is evaluated from the left.
* Parameters outside the domain are clamped to it by the callers that allow it; here they raise.
"""

from __future__ import annotations

import numpy as np

__all__ = ["check_knots", "find_span", "basis_funs", "ders_basis_funs", "MAX_DEGREE", "at_fraction", "into_domain"]

#: Highest degree handled (per direction): OpenCASCADE's limit (``Geom_BSplineSurface::MaxDegree()``), as STEP
#: files from automotive CAD carry degrees 8-9 and more; the GPU program sizes its arrays by the model's degree.
MAX_DEGREE = 25


def check_knots(knots, degree: int, count: int, name: str = "knots") -> np.ndarray:
    """Validate a knot vector for ``count`` control points of degree ``degree``; return it as float64.

    Checks: degree 1..MAX_DEGREE, ``len(knots) == count + degree + 1``, finite, non-decreasing, no knot of
    multiplicity above ``degree + 1`` (``degree`` inside the domain: a C(-1) break is two patches), and a
    domain of positive length.

    Examples
    --------
    >>> check_knots([0, 0, 0, 0.5, 1, 1, 1], 2, 4)
    array([0. , 0. , 0. , 0.5, 1. , 1. , 1. ])
    >>> check_knots([0, 0, 1, 0.5, 1, 1], 2, 3)
    Traceback (most recent call last):
    ValueError: knots must be non-decreasing; knots[3] = 0.5 < knots[2] = 1.0.
    >>> check_knots([0, 0, 1, 1], 2, 3)
    Traceback (most recent call last):
    ValueError: knots of degree 2 for 3 control points must have 6 entries (n + p + 2), got 4.
    """
    if not (isinstance(degree, (int, np.integer)) and 1 <= degree <= MAX_DEGREE):
        raise ValueError(f"degree must be an integer in 1..{MAX_DEGREE}, got {degree!r} ({name}).")
    U = np.asarray(knots, dtype=np.float64)
    if U.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence, got shape {U.shape}.")
    if count < degree + 1:
        raise ValueError(f"degree {degree} needs at least {degree + 1} control points per direction, got {count} ({name}).")
    if U.size != count + degree + 1:
        raise ValueError(f"{name} of degree {degree} for {count} control points must have {count + degree + 1} "
                         f"entries (n + p + 2), got {U.size}.")
    if not np.isfinite(U).all():
        k = int(np.argmin(np.isfinite(U)))
        raise ValueError(f"{name} must be finite; {name}[{k}] = {float(U[k])!r}.")
    dec = np.nonzero(np.diff(U) < 0)[0]
    if dec.size:
        k = int(dec[0]) + 1
        raise ValueError(f"{name} must be non-decreasing; {name}[{k}] = {float(U[k])!r} < {name}[{k - 1}] = {float(U[k - 1])!r}.")
    lo, hi = U[degree], U[count]
    if not hi > lo:
        raise ValueError(f"{name}: the domain [u_p, u_(n+1)] = [{float(lo)!r}, {float(hi)!r}] is empty.")
    values, counts = np.unique(U, return_counts=True)
    inner = (values > lo) & (values < hi)
    over = np.nonzero((counts > degree + 1) | (inner & (counts > degree)))[0]
    if over.size:
        k = int(over[0])
        limit = degree if inner[k] else degree + 1
        raise ValueError(f"{name}: knot {float(values[k])!r} has multiplicity {counts[k]}, more than {limit} for degree "
                         f"{degree} ({'inside the domain: the surface would break apart' if inner[k] else 'at an end'}).")
    return U


def at_fraction(lo, hi, t) -> np.ndarray:
    """Parameters at fractions ``t`` of the domain ``[lo, hi]``, never outside it.

    ``lo + t (hi - lo)`` rounds: with ``lo = -54.0036550378855``, ``hi = -1.2874806216379383e-32`` and ``t = 1`` it
    gives ``0.0 > hi``, and ``find_span`` refuses it. Here ``t = 0`` gives ``lo`` and ``t = 1`` gives ``hi``
    exactly, and every value is clamped into ``[lo, hi]`` (a rounding step at most; the fractions themselves
    must lie in [0, 1]). Broadcasts ``lo``, ``hi`` and ``t``.

    Examples
    --------
    >>> at_fraction(-54.0036550378855, -1.2874806216379383e-32, [0.0, 1.0]).tolist()
    [-54.0036550378855, -1.2874806216379383e-32]
    >>> float(-54.0036550378855 + 1.0 * (-1.2874806216379383e-32 + 54.0036550378855))  # the plain formula
    0.0
    >>> at_fraction(0.0, 1.0, 1.5)
    Traceback (most recent call last):
    ValueError: fractions of the knot domain must lie in [0, 1], got 1.5.
    """
    lo, hi, t = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64), np.asarray(t, dtype=np.float64)
    if t.size and not (t.min() >= 0.0 and t.max() <= 1.0):  # also refuses NaN
        bad = t[~((t >= 0.0) & (t <= 1.0))].ravel()[0]
        raise ValueError(f"fractions of the knot domain must lie in [0, 1], got {float(bad)!r}.")
    u = np.where(t == 0.0, lo, np.where(t == 1.0, hi, lo + t * (hi - lo)))
    return np.minimum(np.maximum(u, lo), hi)


def into_domain(u, lo, hi) -> np.ndarray:
    """Clamp parameters computed near the domain (Newton steps, pulled-back trims, a fraction of a span) into
    ``[lo, hi]``; NaN is refused, not clamped.

    >>> into_domain([1.0000000000000002, -3e-17, 0.5], 0.0, 1.0).tolist()
    [1.0, 0.0, 0.5]
    """
    u = np.asarray(u, dtype=np.float64)
    if np.isnan(u).any():
        raise ValueError("a parameter is NaN (a failed projection or a degenerate surface); nothing to clamp.")
    return np.minimum(np.maximum(u, lo), hi)


def find_span(p: int, U: np.ndarray, u) -> np.ndarray:
    """Knot span index ``i`` with ``U[i] <= u < U[i+1]`` for each parameter [PieglTiller1997, A2.1].

    Examples
    --------
    >>> U = np.array([0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5.0])  # the book's Ex2.3 knot vector, p = 2
    >>> find_span(2, U, [0.0, 2.5, 4.0, 4.5, 5.0])
    array([2, 4, 7, 7, 7])
    """
    U = np.asarray(U, dtype=np.float64)
    u = np.asarray(u, dtype=np.float64)
    n = U.size - p - 2
    lo, hi = U[p], U[n + 1]
    if u.size and (np.isnan(u).any() or u.min() < lo or u.max() > hi):
        bad = u[(u < lo) | (u > hi) | np.isnan(u)].ravel()[0]
        raise ValueError(f"parameter {float(bad)!r} is outside the knot domain [{float(lo)!r}, {float(hi)!r}]; "
                         "clamp or rescale the parameters into the domain.")
    span = np.searchsorted(U, u, side="right") - 1
    return np.clip(span, p, n)


def basis_funs(span, u, p: int, U: np.ndarray) -> np.ndarray:
    """The ``p + 1`` non-zero basis functions ``N[i-p..i, p](u)`` per parameter [PieglTiller1997, A2.2].

    Returns ``(len(u), p + 1)``; each row sums to 1 (partition of unity).

    Examples
    --------
    >>> U = np.array([0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5.0])
    >>> basis_funs(find_span(2, U, [2.5]), [2.5], 2, U)  # the book's Ex2.3: 1/8, 6/8, 1/8
    array([[0.125, 0.75 , 0.125]])
    """
    return ders_basis_funs(span, u, p, 0, U)[:, 0, :]


def ders_basis_funs(span, u, p: int, n: int, U: np.ndarray) -> np.ndarray:
    """Basis functions and their derivatives up to order ``n`` [PieglTiller1997, A2.3].

    Returns ``ders`` of shape ``(len(u), n + 1, p + 1)``: ``ders[:, k, j]`` is the k-th derivative of
    ``N[span-p+j, p]``. Derivatives above ``p`` are zero.

    Examples
    --------
    >>> U = np.array([0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5.0])
    >>> d = ders_basis_funs(find_span(2, U, [2.5]), [2.5], 2, 2, U)[0]
    >>> d[1], d[2]  # N' = (-1/2, 0, 1/2), N'' = (1, -2, 1) at u = 5/2 (the book's Ex2.4)
    (array([-0.5,  0. ,  0.5]), array([ 1., -2.,  1.]))
    """
    u = np.atleast_1d(np.asarray(u, dtype=np.float64))
    span = np.atleast_1d(np.asarray(span, dtype=np.int64))
    U = np.asarray(U, dtype=np.float64)
    m = u.size
    ndu = np.zeros((p + 1, p + 1, m))
    ndu[0, 0] = 1.0
    left = np.zeros((p + 1, m))
    right = np.zeros((p + 1, m))
    for j in range(1, p + 1):
        left[j] = u - U[span + 1 - j]
        right[j] = U[span + j] - u
        saved = np.zeros(m)
        for r in range(j):
            ndu[j, r] = right[r + 1] + left[j - r]  # lower triangle: knot differences
            with np.errstate(divide="ignore", invalid="ignore"):
                temp = np.where(ndu[j, r] != 0.0, ndu[r, j - 1] / ndu[j, r], 0.0)
            ndu[r, j] = saved + right[r + 1] * temp  # upper triangle: basis functions
            saved = left[j - r] * temp
        ndu[j, j] = saved
    ders = np.zeros((m, n + 1, p + 1))
    ders[:, 0, :] = ndu[:, p, :].T
    for r in range(p + 1):
        a = np.zeros((2, p + 1, m))
        a[0, 0] = 1.0
        s1, s2 = 0, 1
        for k in range(1, min(n, p) + 1):
            d = np.zeros(m)
            rk, pk = r - k, p - k
            if r >= k:
                a[s2, 0] = _safe_div(a[s1, 0], ndu[pk + 1, rk])
                d = a[s2, 0] * ndu[rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[s2, j] = _safe_div(a[s1, j] - a[s1, j - 1], ndu[pk + 1, rk + j])
                d = d + a[s2, j] * ndu[rk + j, pk]
            if r <= pk:
                a[s2, k] = _safe_div(-a[s1, k - 1], ndu[pk + 1, r])
                d = d + a[s2, k] * ndu[r, pk]
            ders[:, k, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, min(n, p) + 1):
        ders[:, k, :] *= factor
        factor *= p - k
    return ders


def _safe_div(a, b):
    """a / b where b != 0, else 0 (zero-length knot spans: repeated knots)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(b != 0.0, a / np.where(b != 0.0, b, 1.0), 0.0)

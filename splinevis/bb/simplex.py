"""Bernstein-Bezier (BB) form on simplices of dimension 1, 2 and 3, any degree 0..20, in float64.

A polynomial of degree ``n`` on a ``d``-simplex with vertices ``V_0, ..., V_d`` is written in
barycentric coordinates ``lam = (lam_0, ..., lam_d)`` (``sum lam_i = 1``) as

.. math:: p(\\lambda) = \\sum_{|\\alpha| = n} c_\\alpha B^n_\\alpha(\\lambda), \\qquad
          B^n_\\alpha(\\lambda) = \\frac{n!}{\\alpha_0! \\cdots \\alpha_d!}
          \\lambda_0^{\\alpha_0} \\cdots \\lambda_d^{\\alpha_d}

([Farin2002, ch. 5] for d = 1 and [Farin2002, ch. 17] for triangles; [LaiSchumaker2007, ch. 2] for
triangles and [LaiSchumaker2007, ch. 15] for tetrahedra).

Coefficient layout
------------------
Coefficients are arrays of shape ``(..., N)`` with ``N = C(n + d, d)``; the leading axes index patches
and every function is vectorized over them. Coefficient ``q`` belongs to the multi-index
``multi_indices(n, d)[q]``; the order is lexicographic *descending*: first index descending, then the
second, ... For d = 1 this is ``(n, 0), (n-1, 1), ..., (0, n)``, so univariate coefficient ``k`` multiplies
``B^n_k(t) = C(n, k) (1 - t)^(n-k) t^k`` with ``lam = (1 - t, t)``. For d = 2 and n = 4 the order is
``(4,0,0), (3,1,0), (3,0,1), (2,2,0), (2,1,1), (2,0,2), (1,3,0), ...`` -- the order the GLSL code in
``glsl/lib/simplex/blossom.glsl`` and ``glsl/lib/simplex/bb_triangle.glsl`` uses.

All arithmetic is float64; inputs of other dtypes are converted. Every public function validates its
inputs (finite values, shapes, degree range, barycentric points summing to one) and raises ValueError or
TypeError naming the offending argument before doing any work.
"""

from __future__ import annotations

import functools
from math import comb, factorial

import numpy as np

from .._validation import as_float64_array, check_degree

__all__ = [
    "MAX_DEGREE",
    "num_coefficients",
    "multi_indices",
    "index_of",
    "degree_of",
    "bernstein_basis",
    "de_casteljau",
    "blossom",
    "derivative",
    "gradient",
    "elevate",
    "subdivide",
    "reparametrize",
    "restrict_to_segment",
]

#: Largest supported polynomial degree.
MAX_DEGREE = 20

# Barycentric points must sum to one up to this many float64 ulps of sum(|lam_i|) (inputs that were
# rounded to float32 and promoted are accepted: their sums are off by a few float32 ulps, < 2^-20).
_BARY_TOL = 2.0**-20


# ----------------------------------------------------------------------------------------------------
# index tables
# ----------------------------------------------------------------------------------------------------

def num_coefficients(n: int, d: int) -> int:
    """Number ``C(n + d, d)`` of BB coefficients of degree ``n`` on a ``d``-simplex.

    Examples
    --------
    >>> num_coefficients(4, 2), num_coefficients(3, 3)  # a quartic triangle, a cubic tetrahedron
    (15, 20)
    """
    n = check_degree(n, "degree n", low=0, high=MAX_DEGREE)
    d = check_degree(d, "simplex dimension d", low=1, high=3)
    return comb(n + d, d)


@functools.lru_cache(maxsize=None)
def _multi_indices(n: int, d: int) -> np.ndarray:
    def rec(total: int, parts: int):
        if parts == 1:
            yield (total,)
            return
        for first in range(total, -1, -1):
            for rest in rec(total - first, parts - 1):
                yield (first,) + rest

    arr = np.array(list(rec(n, d + 1)), dtype=np.int64).reshape(-1, d + 1)
    arr.setflags(write=False)
    return arr


def multi_indices(n: int, d: int) -> np.ndarray:
    """Multi-indices ``alpha`` (``|alpha| = n``) of the BB coefficients, in the library's fixed order.

    Parameters
    ----------
    n : int
        Degree, 0..20.
    d : int
        Simplex dimension: 1 (interval), 2 (triangle) or 3 (tetrahedron).

    Returns
    -------
    (N, d + 1) int64 ndarray
        ``N = C(n + d, d)`` rows in lexicographic descending order (first index descending, then the
        second, ...). For d = 1: ``(n, 0), (n-1, 1), ..., (0, n)``, i.e. coefficient ``k`` belongs to
        ``B^n_k(t) = C(n, k) (1-t)^(n-k) t^k``.

    Examples
    --------
    >>> multi_indices(2, 2).tolist()
    [[2, 0, 0], [1, 1, 0], [1, 0, 1], [0, 2, 0], [0, 1, 1], [0, 0, 2]]
    """
    n = check_degree(n, "degree n", low=0, high=MAX_DEGREE)
    d = check_degree(d, "simplex dimension d", low=1, high=3)
    return _multi_indices(n, d).copy()


@functools.lru_cache(maxsize=None)
def _index_of(n: int, d: int) -> dict:
    return {tuple(int(v) for v in a): q for q, a in enumerate(_multi_indices(n, d))}


def index_of(n: int, d: int) -> dict:
    """Dictionary mapping a multi-index tuple ``alpha`` to its position in :func:`multi_indices`.

    Examples
    --------
    >>> index_of(4, 2)[(3, 0, 1)]
    2
    """
    n = check_degree(n, "degree n", low=0, high=MAX_DEGREE)
    d = check_degree(d, "simplex dimension d", low=1, high=3)
    return dict(_index_of(n, d))


@functools.lru_cache(maxsize=None)
def _step_table(m: int, d: int) -> np.ndarray:
    """For degree m -> m-1: table (N_{m-1}, d+1) of positions of alpha + e_i in the degree-m list."""
    hi = _index_of(m, d)
    eye = np.eye(d + 1, dtype=np.int64)
    tab = np.array([[hi[tuple(int(v) for v in a + eye[i])] for i in range(d + 1)] for a in _multi_indices(m - 1, d)],
                   dtype=np.int64).reshape(-1, d + 1)
    tab.setflags(write=False)
    return tab


@functools.lru_cache(maxsize=None)
def _degree_by_count(d: int) -> dict:
    return {comb(n + d, d): n for n in range(MAX_DEGREE + 1)}


def degree_of(num: int, d: int) -> int:
    """Degree ``n`` with ``C(n + d, d) == num``; ValueError if there is none in 0..20.

    Examples
    --------
    >>> degree_of(15, 2), degree_of(10, 3)
    (4, 2)
    """
    d = check_degree(d, "simplex dimension d", low=1, high=3)
    table = _degree_by_count(d)
    if num not in table:
        valid = ", ".join(str(k) for k in list(table)[:8])
        raise ValueError(
            f"coefficients must have C(n+{d},{d}) entries on their last axis for a degree n in 0..{MAX_DEGREE} "
            f"on a {d}-simplex (1 entry for n=0, then {valid}, ...); got {num}."
        )
    return table[num]


# ----------------------------------------------------------------------------------------------------
# validation helpers
# ----------------------------------------------------------------------------------------------------

def _check_coefficients(c, d) -> tuple[np.ndarray, int, int]:
    d = check_degree(d, "simplex dimension d", low=1, high=3)
    c = as_float64_array(c, "coefficients")
    if c.ndim < 1:
        raise ValueError(f"coefficients must have shape (..., N) with N = C(n+{d},{d}); got a scalar.")
    n = degree_of(c.shape[-1], d)
    return c, n, d


def _check_point(lam, d: int, name: str, *, affine: bool = True) -> np.ndarray:
    lam = as_float64_array(lam, name)
    if lam.ndim < 1 or lam.shape[-1] != d + 1:
        raise ValueError(
            f"{name} must be barycentric coordinates of shape (..., {d + 1}) for a {d}-simplex; got shape {lam.shape}."
        )
    s = lam.sum(axis=-1)
    target = 1.0 if affine else 0.0
    bad = np.abs(s - target) > _BARY_TOL * np.maximum(1.0, np.abs(lam).sum(axis=-1))
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(np.atleast_1d(bad))[0]) if bad.ndim else ()
        what = "barycentric points must sum to 1" if affine else "direction vectors must have components summing to 0"
        raise ValueError(f"{name}: {what}; the entry at index {idx} sums to {float(np.atleast_1d(s)[idx] if idx else s)!r}.")
    return lam


# ----------------------------------------------------------------------------------------------------
# workers (no validation)
# ----------------------------------------------------------------------------------------------------

def _step(c: np.ndarray, m: int, d: int, lam: np.ndarray) -> np.ndarray:
    """One de Casteljau step, degree m -> m-1: out[a] = sum_i lam_i c[a + e_i] (sum in order i = 0..d)."""
    tab = _step_table(m, d)
    out = lam[..., 0, None] * c[..., tab[:, 0]]
    for i in range(1, d + 1):
        out = out + lam[..., i, None] * c[..., tab[:, i]]
    return out


def _decasteljau(c, n, d, lam):
    for m in range(n, 0, -1):
        c = _step(c, m, d, lam)
    return c[..., 0]


def _reparametrize(c, n, d, verts):
    """Coefficients w.r.t. the simplex with barycentric vertices verts[0..e] (e = len(verts) - 1):
    out[beta] = blossom(verts[0]^beta_0, ..., verts[e]^beta_e), beta in multi_indices(n, e) order."""
    e = len(verts) - 1
    results = {}

    def rec(arr, m, j, prefix):
        # arr: degree-m coefficients (original simplex) after applying the points fixed in prefix
        if j == e:
            a = arr
            for mm in range(m, 0, -1):
                a = _step(a, mm, d, verts[j])
            results[prefix + (m,)] = a[..., 0]
            return
        a = arr
        for b in range(0, m + 1):
            rec(a, m - b, j + 1, prefix + (b,))
            if b < m:
                a = _step(a, m - b, d, verts[j])

    rec(c, n, 0, ())
    order = _multi_indices(n, e)
    return np.stack([results[tuple(int(v) for v in beta)] for beta in order], axis=-1)


# ----------------------------------------------------------------------------------------------------
# public API
# ----------------------------------------------------------------------------------------------------

def bernstein_basis(n: int, d: int, lam) -> np.ndarray:
    """Bernstein polynomials ``B^n_alpha(lam)`` of degree ``n`` on a ``d``-simplex.

    Parameters
    ----------
    n : int
        Degree, 0..20.
    d : int
        Simplex dimension, 1..3.
    lam : (..., d + 1) array_like
        Barycentric points (components sum to 1).

    Returns
    -------
    (..., N) ndarray
        Values in :func:`multi_indices` order. They sum to one (partition of unity) and are
        nonnegative inside the simplex [Farin2002, ch. 17.2].

    Examples
    --------
    >>> bernstein_basis(2, 1, [0.5, 0.5])  # (1 - t)^2, 2 (1 - t) t, t^2 at t = 1/2
    array([0.25, 0.5 , 0.25])
    """
    n = check_degree(n, "degree n", low=0, high=MAX_DEGREE)
    d = check_degree(d, "simplex dimension d", low=1, high=3)
    lam = _check_point(lam, d, "lam")
    alpha = _multi_indices(n, d)
    coef = np.array([factorial(n) / np.prod([factorial(int(v)) for v in a]) for a in alpha])
    powers = np.prod(lam[..., None, :] ** alpha, axis=-1)
    return coef * powers


def de_casteljau(c, lam, *, d: int) -> np.ndarray:
    """Evaluate BB polynomials at barycentric points by de Casteljau's algorithm.

    Parameters
    ----------
    c : (..., N) array_like
        Coefficients in :func:`multi_indices` order, ``N = C(n + d, d)``.
    lam : (..., d + 1) array_like
        Barycentric points; leading axes broadcast against those of ``c``.
    d : int
        Simplex dimension, 1..3.

    Returns
    -------
    ndarray
        ``p(lam)``, shape = broadcast of ``c.shape[:-1]`` and ``lam.shape[:-1]``.

    Notes
    -----
    ``n`` steps of ``c[a] <- sum_i lam_i c[a + e_i]`` [Farin2002, ch. 17.3; ch. 3 for d = 1]. Inside the
    simplex every step is a convex combination, which makes the algorithm stable: in floating point
    with unit roundoff u, ``|computed - exact| <= gamma_{3n} sum |c_a| B_a(lam)`` for d = 1 (each level
    rounds ``1 - t``, two products and a sum; [MainarPena1999]), ``gamma_m = m u / (1 - m u)``
    [Higham2002, sec. 3.4].

    Examples
    --------
    >>> de_casteljau([0.0, 0.0, 1.0], [[0.5, 0.5], [0.0, 1.0]], d=1)  # p(t) = t^2 at t = 1/2 and 1
    array([0.25, 1.  ])
    >>> de_casteljau([0.0, 1.0, 0.0], [0.2, 0.3, 0.5], d=2)  # a linear patch: the coordinate lam_1
    array(0.3)
    """
    c, n, d = _check_coefficients(c, d)
    lam = _check_point(lam, d, "lam")
    return _decasteljau(c, n, d, lam)


def blossom(c, lams, *, d: int) -> np.ndarray:
    """The blossom (polar form) ``b[lam_1, ..., lam_n]`` of BB polynomials.

    The blossom is the unique symmetric, multi-affine function of ``n`` points whose diagonal is the
    polynomial: ``b[lam, ..., lam] = p(lam)`` [Farin2002, ch. 4 and 17.4; Ramshaw1987]. It is computed by
    de Casteljau steps using a different point at each level.

    Parameters
    ----------
    c : (..., N) array_like
        Coefficients of degree ``n``.
    lams : sequence of n (..., d + 1) array_like, or (n, ..., d + 1) array_like
        The ``n`` arguments, each a barycentric point broadcasting against the patches.
    d : int
        Simplex dimension.

    Returns
    -------
    ndarray
        The blossom values, shape = broadcast of the leading axes.

    Examples
    --------
    The blossom of ``p(t) = t^2`` is ``b[s, t] = s t``; its diagonal is ``p``:

    >>> float(blossom([0.0, 0.0, 1.0], [[0.7, 0.3], [0.5, 0.5]], d=1))  # s = 0.3, t = 0.5
    0.15
    >>> float(blossom([0.0, 0.0, 1.0], [[0.5, 0.5], [0.5, 0.5]], d=1))
    0.25
    """
    c, n, d = _check_coefficients(c, d)
    if isinstance(lams, np.ndarray) and lams.ndim >= 1:
        seq = [lams[i] for i in range(lams.shape[0])] if lams.ndim >= 2 else [lams]
    else:
        try:
            seq = list(lams)
        except TypeError:
            raise TypeError(f"lams must be a sequence of {n} barycentric points; got {type(lams).__name__}.") from None
    if len(seq) != n:
        raise ValueError(f"lams must hold exactly n = {n} barycentric points (the degree); got {len(seq)}.")
    pts = [_check_point(p, d, f"lams[{i}]") for i, p in enumerate(seq)]
    a = c
    for i, m in enumerate(range(n, 0, -1)):
        a = _step(a, m, d, pts[i])
    return a[..., 0]


def derivative(c, direction, *, d: int) -> np.ndarray:
    """BB coefficients (degree ``n - 1``) of the directional derivative ``D_u p``.

    Parameters
    ----------
    c : (..., N) array_like
        Coefficients of degree ``n``.
    direction : (..., d + 1) array_like
        Direction ``u`` in barycentric form: components sum to 0 (the difference of two barycentric
        points). For d = 1, ``u = (-1, 1)`` gives ``dp/dt``.
    d : int
        Simplex dimension.

    Returns
    -------
    (..., C(n - 1 + d, d)) ndarray
        ``n * sum_i u_i c[a + e_i]`` [Farin2002, ch. 17.5; LaiSchumaker2007, Thm. 2.15]. For ``n = 0`` the
        derivative is the zero polynomial, returned as one zero coefficient (degree 0).

    Examples
    --------
    >>> derivative([0.0, 0.0, 1.0], [-1, 1], d=1)  # d/dt t^2 = 2 t: linear coefficients 0, 2
    array([0., 2.])
    """
    c, n, d = _check_coefficients(c, d)
    u = _check_point(direction, d, "direction", affine=False)
    if n == 0:
        return np.zeros(np.broadcast_shapes(c.shape[:-1], u.shape[:-1]) + (1,))
    return n * _step(c, n, d, u)


def gradient(c, *, d: int) -> np.ndarray:
    """Barycentric partial derivatives ``dp/dlam_i`` (p read as a homogeneous polynomial in lam).

    Returns
    -------
    (..., d + 1, C(n - 1 + d, d)) ndarray
        Row ``i`` holds the degree ``n - 1`` coefficients ``n c[a + e_i]``; the directional derivative
        along ``u`` is ``sum_i u_i`` row ``i`` (see :func:`derivative`). For ``n = 0`` rows are one zero.

    Examples
    --------
    >>> g = gradient([0.0, 0.0, 1.0], d=1)  # p = lam_1^2
    >>> g
    array([[0., 0.],
           [0., 2.]])
    >>> g[1] - g[0]  # u = (-1, 1): the derivative
    array([0., 2.])
    """
    c, n, d = _check_coefficients(c, d)
    if n == 0:
        return np.zeros(c.shape[:-1] + (d + 1, 1))
    tab = _step_table(n, d)
    return n * np.stack([c[..., tab[:, i]] for i in range(d + 1)], axis=-2)


def elevate(c, *, d: int) -> np.ndarray:
    """Degree elevation ``n -> n + 1`` (same polynomial).

    ``c'[b] = sum_{i: b_i > 0} (b_i / (n + 1)) c[b - e_i]`` [Farin2002, ch. 6 for d = 1, ch. 17.6;
    LaiSchumaker2007, Thm. 2.39].

    Returns
    -------
    (..., C(n + 1 + d, d)) ndarray

    Examples
    --------
    >>> elevate([0.0, 0.0, 1.0], d=1)  # t^2 as a cubic
    array([0.        , 0.        , 0.33333333, 1.        ])
    """
    c, n, d = _check_coefficients(c, d)
    if n + 1 > MAX_DEGREE:
        raise ValueError(f"cannot elevate degree {n} coefficients: the result would exceed MAX_DEGREE = {MAX_DEGREE}.")
    lo = _index_of(n, d)
    hi = _multi_indices(n + 1, d)
    out = np.zeros(c.shape[:-1] + (len(hi),))
    eye = np.eye(d + 1, dtype=np.int64)
    for q, b in enumerate(hi):
        for i in range(d + 1):
            if b[i] > 0:
                out[..., q] += (b[i] / (n + 1)) * c[..., lo[tuple(int(v) for v in b - eye[i])]]
    return out


def reparametrize(c, vertices, *, d: int) -> np.ndarray:
    """Coefficients of the same polynomial over another simplex (same dimension d).

    Parameters
    ----------
    c : (..., N) array_like
        Coefficients over the reference simplex.
    vertices : sequence of d + 1 (..., d + 1) array_like
        Barycentric coordinates (w.r.t. the reference simplex) of the new simplex's vertices.

    Returns
    -------
    (..., N) ndarray
        ``c'[b] = blossom(W_0^{b_0}, ..., W_d^{b_d})`` [Farin2002, ch. 17.4] ("blossoms and subdivision").

    Examples
    --------
    ``p(t) = t^2`` over the interval [1/2, 1]:

    >>> reparametrize([0.0, 0.0, 1.0], [[0.5, 0.5], [0.0, 1.0]], d=1)
    array([0.25, 0.5 , 1.  ])
    """
    c, n, d = _check_coefficients(c, d)
    verts = list(vertices)
    if len(verts) != d + 1:
        raise ValueError(f"vertices must list d + 1 = {d + 1} barycentric points; got {len(verts)}.")
    verts = [_check_point(v, d, f"vertices[{i}]") for i, v in enumerate(verts)]
    return _reparametrize(c, n, d, verts)


def subdivide(c, at, *, d: int):
    """Subdivide BB polynomials at a point.

    Parameters
    ----------
    c : (..., N) array_like
        Coefficients of degree n.
    at : float or array_like
        For d = 1 the parameter ``t`` (scalar or array broadcasting against the patches). For d = 2, 3 a
        barycentric point (..., d + 1), usually interior.
    d : int
        Simplex dimension.

    Returns
    -------
    tuple of ndarray
        d = 1: ``(left, right)``, the coefficients over ``[0, t]`` and ``[t, 1]`` (the two outer edges
        of de Casteljau's triangle, [Farin2002, ch. 3.5]). d = 2, 3: ``d + 1`` arrays; entry ``i`` holds the
        coefficients over the sub-simplex whose vertex ``i`` is replaced by ``at`` (its vertices stay in
        the original order), computed by blossoming.

    Examples
    --------
    >>> left, right = subdivide([0.0, 0.0, 1.0], 0.5, d=1)  # t^2 over [0, 1/2] and [1/2, 1]
    >>> left, right
    (array([0.  , 0.  , 0.25]), array([0.25, 0.5 , 1.  ]))
    """
    c, n, d = _check_coefficients(c, d)
    eye = np.eye(d + 1)
    if d == 1:
        t = as_float64_array(at, "at (the parameter t)")
        p = np.stack([1.0 - t, t], axis=-1)
        left = _reparametrize(c, n, 1, [eye[0], p])
        right = _reparametrize(c, n, 1, [p, eye[1]])
        return left, right
    p = _check_point(at, d, "at")
    out = []
    for i in range(d + 1):
        verts = [p if j == i else eye[j] for j in range(d + 1)]
        out.append(_reparametrize(c, n, d, verts))
    return tuple(out)


def restrict_to_segment(c, lam0, lam1, *, d: int) -> np.ndarray:
    """Univariate BB coefficients of ``p`` along the segment from ``lam0`` to ``lam1``.

    ``q(s) = p((1 - s) lam0 + s lam1)`` for ``s`` in [0, 1] has coefficients
    ``c_k = blossom(lam0^{n-k}, lam1^k)`` [Farin2002, ch. 17.4]; the ray-segment restriction of
    [Reis2008, eq. (5)] for triangles and [Kalbe2008, Fig. 10] for tetrahedra. This is what the ray casters
    compute per fragment.

    Parameters
    ----------
    c : (..., N) array_like
        Coefficients of degree n on a d-simplex.
    lam0, lam1 : (..., d + 1) array_like
        Barycentric end points (may lie outside the simplex).
    d : int
        Simplex dimension.

    Returns
    -------
    (..., n + 1) ndarray
        Univariate coefficients, coefficient k for ``B^n_k(s) = C(n,k) (1-s)^(n-k) s^k``.

    Examples
    --------
    ``p = lam_1^2`` on a triangle, from vertex 0 to the midpoint of the opposite edge, is ``(s / 2)^2``:

    >>> restrict_to_segment([0.0, 0.0, 0.0, 1.0, 0.0, 0.0], [1, 0, 0], [0, 0.5, 0.5], d=2)
    array([0.  , 0.  , 0.25])
    """
    c, n, d = _check_coefficients(c, d)
    l0 = _check_point(lam0, d, "lam0")
    l1 = _check_point(lam1, d, "lam1")
    return _reparametrize(c, n, d, [l0, l1])

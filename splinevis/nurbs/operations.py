"""Geometry-preserving operations on NURBS surfaces: knot insertion and refinement, degree elevation and
the decomposition into rational Bezier patches.

All of them act on the homogeneous control points ``(w P, w)`` of a rational surface (on ``P`` itself for a
polynomial one), one parameter direction at a time, vectorized over the rows of the other direction:

* ``insert_knot`` is the surface knot insertion [PieglTiller1997, A5.3], i.e. the curve insertion
  [PieglTiller1997, A5.1] applied to every row of the net with the same coefficients;
* ``refine_knots`` inserts a sorted list of knots (the effect of [PieglTiller1997, A5.5], knot by knot);
* ``elevate_degree`` raises the degree by the blossom identity behind [PieglTiller1997, A5.9, A5.10]: the
  elevated control point ``Q_i`` is the symmetrized degree-p blossom at the knots ``u_(i+1)..u_(i+p+1)`` of
  the elevated knot vector (every distinct knot gains one multiplicity, so continuity is kept);
* ``bezier_patches`` raises every knot in the domain to multiplicity ``p`` (the decomposition of
  [PieglTiller1997, A5.7], here by knot insertion as in [Kumar1997]) and cuts out the single-span
  patches.

The surface represented is unchanged (to rounding) on its domain; only the representation changes.
An unclamped knot vector is clamped at the domain ends first where the operation needs it (elevation,
Bezier extraction): the surface outside the domain is not part of the model.
"""

from __future__ import annotations

import numpy as np

from .basis import find_span
from .surface import NurbsSurface

__all__ = ["bezier_segments", "insert_knot", "refine_knots", "elevate_degree", "bezier_patches"]


def _axis(direction) -> int:
    """0 for ``'u'``/0, 1 for ``'v'``/1."""
    if direction in (0, "u"):
        return 0
    if direction in (1, "v"):
        return 1
    raise ValueError(f"direction must be 'u' (0) or 'v' (1), got {direction!r}.")


def _net(surface: NurbsSurface, axis: int):
    """The control net (homogeneous when rational) with ``axis`` first, flattened to ``(n, rest)``."""
    Q = surface.control_points if surface.weights is None else surface.homogeneous()
    Q = np.moveaxis(Q, axis, 0)
    return Q.reshape(Q.shape[0], -1), Q.shape[1:]


def _rebuild(surface: NurbsSurface, axis: int, flat, tail, degree: int, knots, name=None) -> NurbsSurface:
    """A surface from the new curve data of ``_net`` in direction ``axis``."""
    Q = np.moveaxis(flat.reshape((flat.shape[0],) + tuple(tail)), 0, axis)
    degrees, kv = list(surface.degree), list(surface.knots)
    degrees[axis], kv[axis] = degree, np.asarray(knots, dtype=np.float64)
    name = surface.name if name is None else name
    if surface.weights is None:
        return NurbsSurface(tuple(degrees), tuple(kv), Q, None, name)
    w = Q[..., 3]
    return NurbsSurface(tuple(degrees), tuple(kv), Q[..., :3] / w[..., None], w, name)


def _curve_insert(p: int, U: np.ndarray, Pw: np.ndarray, u: float, r: int, where: str):
    """Insert ``u`` ``r`` times into a curve of degree ``p``: [PieglTiller1997, A5.1], rows of ``Pw`` are
    control points (any number of columns). Returns ``(UQ, Qw)``."""
    n = Pw.shape[0] - 1
    lo, hi = U[p], U[n + 1]
    if not lo <= u <= hi:
        raise ValueError(f"knot {u!r} is outside the {where} domain [{float(lo)!r}, {float(hi)!r}]; insert knots "
                         "inside the domain.")
    s = int(np.count_nonzero(U == u))
    if s + r > p:
        raise ValueError(f"knot {u!r} has multiplicity {s} in {where} (degree {p}); inserting it {r} more time(s) "
                         f"would exceed the degree (the surface would break apart): insert it at most {max(p - s, 0)} "
                         "more time(s).")
    if r <= 0:
        return U.copy(), Pw.copy()
    k = int(np.searchsorted(U, u, side="right")) - 1  # last index with U[k] <= u (< U[k + 1] since s <= p)
    UQ = np.concatenate([U[:k + 1], np.full(r, u), U[k + 1:]])
    Qw = np.empty((n + 1 + r,) + Pw.shape[1:])
    Qw[:k - p + 1] = Pw[:k - p + 1]
    Qw[k - s + r:] = Pw[k - s:]
    Rw = Pw[k - p:k - s + 1].copy()
    L = k - p
    for j in range(1, r + 1):
        L = k - p + j
        for i in range(p - j - s + 1):
            alpha = (u - U[L + i]) / (U[i + k + 1] - U[L + i])
            Rw[i] = alpha * Rw[i + 1] + (1.0 - alpha) * Rw[i]
        Qw[L] = Rw[0]
        Qw[k + r - j - s] = Rw[p - j - s]
    for i in range(L + 1, k - s):
        Qw[i] = Rw[i - L]
    return UQ, Qw


def _curve_refine(p, U, Pw, knots, where):
    """Insert every knot of ``knots`` (a multiset) with [PieglTiller1997, A5.1]."""
    values, counts = np.unique(np.asarray(knots, dtype=np.float64), return_counts=True)
    for x, c in zip(values, counts):
        U, Pw = _curve_insert(p, U, Pw, float(x), int(c), where)
    return U, Pw


def _curve_clamp(p, U, Pw, where):
    """Clamp both ends of the domain (multiplicity ``p + 1``), dropping the control points that only act
    outside it."""
    n = Pw.shape[0] - 1
    lo, hi = float(U[p]), float(U[n + 1])
    need = [x for x in (lo, hi) for _ in range(max(p - int(np.count_nonzero(U == x)), 0))]
    U, Pw = _curve_refine(p, U, Pw, need, where)
    first = int(np.searchsorted(U, lo, side="left"))  # lo now sits at U[first .. first + p - 1] (or more)
    last = int(np.searchsorted(U, hi, side="right"))  # hi at U[.. last - 1]
    a = max(first - 1, 0)  # keep one knot before the run of lo: N_a is the first function alive on the domain
    b = min(last + 1, U.size)
    U, Pw = U[a:b].copy(), Pw[a:b - p - 1]
    U[0], U[-1] = lo, hi
    return U, Pw


def _curve_elevate(p, U, Pw, where):
    """Raise a clamped curve from degree ``p`` to ``p + 1``: ``Q_i = 1/(p+1) sum_j b(t_(i+1) .. t_(i+p+1)
    without t_(i+j))`` with ``b`` the blossom of the degree-p piece on a span in the support of ``Q_i``."""
    vals, mult = np.unique(U, return_counts=True)
    T = np.repeat(vals, mult + 1)  # elevated knot vector: every multiplicity + 1
    nq = T.size - (p + 1) - 1  # number of elevated control points
    lo, hi = U[p], U[Pw.shape[0]]
    idx = np.arange(nq)
    # a non-empty span l of T with i <= l <= i + p + 1 inside the domain, as a span of U
    spans = np.empty(nq, dtype=np.int64)
    for i in range(nq):
        for l in range(i, i + p + 2):
            if T[l] < T[l + 1] and T[l] >= lo and T[l + 1] <= hi:
                spans[i] = find_span(p, U, [0.5 * (T[l] + T[l + 1])])[0]
                break
        else:  # cannot happen for a clamped knot vector with a non-empty domain
            raise ValueError(f"{where}: no knot span supports elevated control point {i}.")
    args = T[idx[:, None] + 1 + np.arange(p + 1)]  # (nq, p + 1)
    Q = np.zeros((nq,) + Pw.shape[1:])
    for j in range(p + 1):
        t = np.delete(args, j, axis=1)  # (nq, p): the blossom's arguments
        d = np.stack([Pw[spans - p + m] for m in range(p + 1)], axis=1)  # (nq, p + 1, C)
        for r in range(1, p + 1):  # de Boor's algorithm with the r-th argument at level r
            for m in range(p, r - 1, -1):
                left = U[spans - p + m]
                alpha = (t[:, r - 1] - left) / (U[spans + m + 1 - r] - left)
                d[:, m] = (1.0 - alpha)[:, None] * d[:, m - 1] + alpha[:, None] * d[:, m]
        Q += d[:, p]
    return T, Q / (p + 1)


# -------------------------------------------------------------------------------------------------
def insert_knot(surface: NurbsSurface, direction, knot: float, times: int = 1) -> NurbsSurface:
    """Insert ``knot`` ``times`` times in direction ``'u'`` or ``'v'`` [PieglTiller1997, A5.3].

    The knot must lie in the domain and its multiplicity may reach the degree, not more (a ValueError
    says how many insertions are left). The surface is unchanged; the net gains ``times`` rows.

    >>> from splinevis.nurbs.exact import torus
    >>> t = torus()
    >>> t2 = insert_knot(t, "u", 0.1, 2)
    >>> t2.shape, float(np.abs(t2.evaluate([0.13], [0.7]) - t.evaluate([0.13], [0.7])).max()) < 1e-14
    ((11, 9), True)
    >>> insert_knot(t, "v", 0.25)
    Traceback (most recent call last):
    ValueError: knot 0.25 has multiplicity 2 in knots[1] (v) (degree 2); inserting it 1 more time(s) would exceed the degree (the surface would break apart): insert it at most 0 more time(s).
    """
    a = _axis(direction)
    p, U = surface.degree[a], surface.knots[a]
    flat, tail = _net(surface, a)
    where = "knots[0] (u)" if a == 0 else "knots[1] (v)"
    UQ, Q = _curve_insert(p, U, flat, float(knot), int(times), where)
    return _rebuild(surface, a, Q, tail, p, UQ)


def refine_knots(surface: NurbsSurface, direction, knots) -> NurbsSurface:
    """Insert all ``knots`` (a sequence, repeats allowed) in one direction (the result of
    [PieglTiller1997, A5.5]).

    >>> from splinevis.nurbs.exact import sphere
    >>> s = sphere()
    >>> r = refine_knots(s, "v", [0.1, 0.1, 0.3, 0.7])
    >>> r.shape, r.knots[1].tolist()
    ((9, 9), [0.0, 0.0, 0.0, 0.1, 0.1, 0.3, 0.5, 0.5, 0.7, 1.0, 1.0, 1.0])
    """
    a = _axis(direction)
    p, U = surface.degree[a], surface.knots[a]
    flat, tail = _net(surface, a)
    where = "knots[0] (u)" if a == 0 else "knots[1] (v)"
    UQ, Q = _curve_refine(p, U, flat, knots, where)
    return _rebuild(surface, a, Q, tail, p, UQ)


def elevate_degree(surface: NurbsSurface, direction, times: int = 1) -> NurbsSurface:
    """Raise the degree in one direction by ``times`` (up to ``basis.MAX_DEGREE``), keeping the surface and its continuity
    (every distinct knot gains one multiplicity per step) [PieglTiller1997, A5.9, A5.10].

    An unclamped knot vector is clamped at the domain ends first.

    >>> from splinevis.nurbs.exact import cylinder
    >>> c = cylinder()
    >>> e = elevate_degree(c, "v", 2)
    >>> e.degree, e.knots[1].tolist(), float(np.abs(e.evaluate([0.3], [0.6]) - c.evaluate([0.3], [0.6])).max()) < 1e-14
    ((2, 3), [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0], True)
    """
    from .basis import MAX_DEGREE

    a = _axis(direction)
    p, U = surface.degree[a], surface.knots[a]
    times = int(times)
    if times < 0 or p + times > MAX_DEGREE:
        raise ValueError(f"cannot elevate degree {p} by {times}: the degree must stay in 1..{MAX_DEGREE}.")
    if times == 0:
        return surface
    flat, tail = _net(surface, a)
    where = "knots[0] (u)" if a == 0 else "knots[1] (v)"
    U, Q = _curve_clamp(p, U, flat, where)
    for step in range(times):
        U, Q = _curve_elevate(p + step, U, Q, where)
    return _rebuild(surface, a, Q, tail, p + times, U)


def _curve_decompose(p, U, Pw, where):
    """Clamp the curve and raise every interior knot to multiplicity p [PieglTiller1997, A5.6]: ``(U, Qw, spans)``
    with ``spans`` the ``(first control point, (t0, t1))`` of each Bezier segment ``Qw[first:first + p + 1]``."""
    U, Q = _curve_clamp(p, U, Pw, where)
    vals, mult = np.unique(U[p + 1:-(p + 1)], return_counts=True)
    U, Q = _curve_refine(p, U, Q, np.repeat(vals, np.maximum(p - mult, 0)), where)
    starts = [k for k in range(p, U.size - p - 1) if U[k] < U[k + 1]]
    return U, Q, [(k - p, (float(U[k]), float(U[k + 1]))) for k in starts]


def bezier_segments(degree: int, knots, Pw, where: str = "curve knots") -> list:
    """The Bezier segments of a (rational) B-spline curve, clamped or not: a list of ``(p + 1, k)`` arrays of
    its control points (rows, e.g. homogeneous ``(w x, w y, w)``), one per non-empty knot span of the domain.

    >>> segs = bezier_segments(2, [0, 0, 0, 0.5, 1, 1, 1], np.array([[0.0], [1.0], [3.0], [4.0]]))
    >>> [s.ravel().tolist() for s in segs]
    [[0.0, 1.0, 2.0], [2.0, 3.0, 4.0]]
    """
    p = int(degree)
    _, Q, spans = _curve_decompose(p, np.asarray(knots, dtype=np.float64), np.asarray(Pw, dtype=np.float64), where)
    return [Q[first:first + p + 1] for first, _ in spans]


def bezier_patches(surface: NurbsSurface) -> list:
    """The (rational) Bezier patches of the surface, one per non-empty knot rectangle, in order u-major:
    a list of ``(patch, ((u0, u1), (v0, v1)))``; each patch is a clamped single-span :class:`NurbsSurface`
    on its own rectangle (same parameters as the whole surface) [PieglTiller1997, A5.7], [Kumar1997].

    >>> from splinevis.nurbs.exact import torus
    >>> patches = bezier_patches(torus())
    >>> len(patches), patches[5][0].shape, patches[5][1]
    (16, (3, 3), ((0.25, 0.5), (0.25, 0.5)))
    """
    s = surface
    pieces = []
    for a in (0, 1):
        p, U = s.degree[a], s.knots[a]
        flat, tail = _net(s, a)
        where = "knots[0] (u)" if a == 0 else "knots[1] (v)"
        U, Q, spans = _curve_decompose(p, U, flat, where)
        s = _rebuild(s, a, Q, tail, p, U)
        pieces.append(spans)
    (p, q), W = s.degree, s.weights
    out = []
    for i0, (u0, u1) in pieces[0]:
        for j0, (v0, v1) in pieces[1]:
            P = s.control_points[i0:i0 + p + 1, j0:j0 + q + 1]
            w = None if W is None else W[i0:i0 + p + 1, j0:j0 + q + 1]
            knots = ([u0] * (p + 1) + [u1] * (p + 1), [v0] * (q + 1) + [v1] * (q + 1))
            name = f"{surface.name}[{u0:g}..{u1:g}, {v0:g}..{v1:g}]"
            out.append((NurbsSurface((p, q), knots, P, w, name), ((u0, u1), (v0, v1))))
    return out

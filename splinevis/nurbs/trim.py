"""Trim loops as v-monotone rational Bezier pieces, and the even-odd inside test on them (float64 twin of
``glsl/lib/nurbs/trim.glsl``).

Each :class:`~splinevis.nurbs.model.TrimCurve` (degree 1..3) is cut into its Bezier segments by knot
insertion [PieglTiller1997, A5.1] and each segment at the parameters where ``v(t)`` turns (roots of the
numerator of ``v'(t) = (Y' W - Y W') / W^2``), so every piece is monotone in v. A point ``(u0, v0)`` is
inside when a ray from it towards +u crosses an odd number of pieces (even-odd rule: outer loops, holes and
islands need no labels). A piece is crossed when ``v0`` lies in its half-open v-range (a shared end point
counts once) and the piece's ``u`` at ``v = v0`` exceeds ``u0``; that ``u`` comes from the one root of the
monotone ``v(t) = v0`` (bisection, exact to the last bit of t in float64 here and float32 on the GPU), and
is skipped when the piece's control hull already lies wholly left or right of ``u0`` (the convex-hull
property of a rational Bezier curve with positive weights). So the trim boundary is the exact curve at any
zoom: no polygon, no staircase.
"""

from __future__ import annotations

import weakref
from functools import cache
from math import comb

import numpy as np

from .operations import bezier_segments

__all__ = ["TrimPieces", "trim_pieces", "inside", "inside_many", "MAX_TRIM_DEGREE", "PIECE_FLOATS"]

#: Highest trim-curve degree the per-fragment test handles.
MAX_TRIM_DEGREE = 3
#: Floats per piece in the GPU table (8 texels: a record never straddles a table row): 4 homogeneous control
#: points (u w, v w, w, pad), the hull's bbox, the degree, padding.
PIECE_FLOATS = 32


class TrimPieces:
    """All pieces of a model: ``ctrl`` (n, 4, 3) homogeneous control points (unused rows zero), ``degree``
    (n,), ``bbox`` (n, 4) = (umin, umax, vmin, vmax) of the hull, and ``start``/``count`` per patch.

    >>> from splinevis.nurbs.model import TrimCurve
    >>> square = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in
    ...           [((0.2, 0.2), (0.8, 0.2)), ((0.8, 0.2), (0.8, 0.8)), ((0.8, 0.8), (0.2, 0.8)), ((0.2, 0.8), (0.2, 0.2))]]
    >>> p = trim_pieces([[square], None])
    >>> p.count.tolist(), p.start.tolist()  # 4 lines for patch 0 (2 of them horizontal), none for patch 1
    ([4, 0], [0, 4])
    """

    def __init__(self, ctrl, degree, bbox, start, count):
        self.ctrl, self.degree, self.bbox = ctrl, degree, bbox
        self.start, self.count = start, count

    def table(self) -> np.ndarray:
        """``(n, PIECE_FLOATS)`` float64 rows: 4 control points x (uw, vw, w, 0), bbox, degree, zeros.

        >>> TrimPieces(np.zeros((1, 4, 3)), np.array([1]), np.zeros((1, 4)), np.zeros(1), np.ones(1)).table().shape
        (1, 32)
        """
        n = len(self.degree)
        t = np.zeros((n, PIECE_FLOATS))
        t[:, :16] = np.concatenate([self.ctrl, np.zeros((n, 4, 1))], axis=2).reshape(n, 16)
        t[:, 16:20] = self.bbox
        t[:, 20] = self.degree
        return t


def _bezier_segments(curve):
    """Homogeneous Bezier segments (k, p+1, 3) of a TrimCurve (:func:`splinevis.nurbs.operations.bezier_segments`)."""
    w = np.ones(len(curve.control_points)) if curve.weights is None else curve.weights
    Pw = np.column_stack([curve.control_points * w[:, None], w])
    p, U = curve.degree, curve.knots
    if len(Pw) == p + 1 and U[0] == U[p] and U[p + 1] == U[-1]:  # one clamped span: its net is the segment
        return Pw[None]
    return np.asarray(bezier_segments(p, U, Pw, "trim curve knots"))


def _split(seg, t):
    """De Casteljau split of a homogeneous Bezier segment at t: (left, right)."""
    pts = [seg]
    while len(pts[-1]) > 1:
        prev = pts[-1]
        pts.append((1 - t) * prev[:-1] + t * prev[1:])
    return np.array([q[0] for q in pts]), np.array([q[-1] for q in pts[::-1]])


def _v_turns(seg) -> list:
    """Parameters in (0, 1) where v(t) = Y/W turns: real roots of Y' W - Y W' (power basis; one segment of
    :func:`_v_turns_all`). A line (degree 1) has the constant numerator ``y1 w0 - y0 w1`` and never turns.

    >>> _v_turns(np.array([[0.0, 0.0, 1.0], [0.5, 1.0, 1.0], [1.0, 0.0, 1.0]]))  # a parabola's apex
    [0.5]
    """
    return _v_turns_all(np.asarray(seg, dtype=np.float64)[None])[0]


def _v_turns_all(segs) -> list:
    """:func:`_v_turns` of every segment of ``segs`` (k, p + 1, 3) at once: per segment the sorted parameters in
    (0, 1) where v(t) turns. The numerators ``Y' W - Y W'`` in power form for all segments together, their
    trailing exact zeros dropped per segment, then the roots of those of each degree together (a line's root
    directly, the rest from batched companion matrices, as ``polyroots`` builds them one by one).

    >>> _v_turns_all(np.array([[[0.0, 0.0, 1.0], [0.5, 1.0, 1.0], [1.0, 0.0, 1.0]]] * 2))
    [[0.5], [0.5]]
    """
    segs = np.asarray(segs, dtype=np.float64)
    k, p = len(segs), segs.shape[1] - 1
    out = [[] for _ in range(k)]
    if p <= 1 or k == 0:
        return out
    M = _power_matrix(p)
    Y, W = segs[:, :, 1] @ M.T, segs[:, :, 2] @ M.T
    j = np.arange(1, p + 1)
    dY, dW = Y[:, 1:] * j, W[:, 1:] * j
    num = np.zeros((k, 2 * p))
    for a in range(p):  # num = dY * W - Y * dW as polynomial products
        num[:, a: a + p + 1] += dY[:, a: a + 1] * W - Y * dW[:, a: a + 1]
    # the t^(2p-1) terms, p Y_p W_p - p Y_p W_p, cancel in exact arithmetic; in floating point they leave a
    # rounding residue that would make a spurious huge root and perturb the others: dropped
    num = num[:, : 2 * p - 1]
    nz = num != 0
    deg = np.where(nz.any(axis=1), 2 * p - 2 - np.argmax(nz[:, ::-1], axis=1), 0)
    for d in np.unique(deg[deg >= 1]):
        rows = np.flatnonzero(deg == d)
        c = num[rows, : d + 1]
        if d == 1:
            roots = (-c[:, 0] / c[:, 1])[:, None].astype(complex)
        else:
            comp = np.zeros((len(rows), d, d))
            comp[:, np.arange(1, d), np.arange(d - 1)] = 1.0
            comp[:, :, -1] = -c[:, :-1] / c[:, -1:]
            roots = np.linalg.eigvals(comp[:, ::-1, ::-1])
        keep = (np.abs(roots.imag) < 1e-12) & (roots.real > 1e-12) & (roots.real < 1 - 1e-12)
        for r, row, ok in zip(roots.real, rows, keep):
            out[row] = sorted(float(x) for x in r[ok])
    return out


@cache
def _power_matrix(p: int) -> np.ndarray:
    """Power coefficients a_k of t^k from Bernstein coefficients of degree p (row k)."""
    M = np.array([[comb(p, i) * comb(p - i, k - i) * (-1) ** (k - i) if k >= i else 0 for i in range(p + 1)]
                  for k in range(p + 1)], dtype=np.float64)
    M.setflags(write=False)
    return M


def trim_pieces(trims) -> TrimPieces:
    """Pieces of every patch's loops (``trims``: per patch None or a list of loops of TrimCurve).

    >>> from splinevis.nurbs.exact import CIRCLE_KNOTS, circle_net
    >>> from splinevis.nurbs.model import TrimCurve
    >>> xy, w = circle_net()
    >>> p = trim_pieces([[[TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.3 * xy, w)]]])
    >>> p.count.tolist(), p.degree.tolist()  # 4 quarter arcs, monotone in v already (v turns at their joints)
    ([4], [2, 2, 2, 2])
    """
    ctrl, degree, bbox, start, count = [], [], [], [], []
    total = 0
    for loops in trims:
        start.append(total)
        n0 = total
        for loop in loops or ():
            for curve in loop:
                c, d, b = _curve_pieces(curve)
                ctrl.append(c)
                degree.append(d)
                bbox.append(b)
                total += len(d)
        count.append(total - n0)
    if not ctrl:
        return TrimPieces(np.zeros((0, 4, 3)), np.zeros(0, dtype=np.int64), np.zeros((0, 4)), np.asarray(start),
                          np.asarray(count))
    return TrimPieces(np.concatenate(ctrl), np.concatenate(degree).astype(np.int64), np.concatenate(bbox),
                      np.asarray(start), np.asarray(count))


def _curve_pieces(curve) -> tuple:
    """One curve's pieces as lists (ctrl, degree, bbox), kept while the curve lives (curves are immutable; the
    orientation pass and the program build of a read model cut the same curves)."""
    hit = _PIECES.get(curve)
    if hit is not None:
        return hit
    if curve.degree > MAX_TRIM_DEGREE:
        raise ValueError(f"trim curve of degree {curve.degree}: the per-fragment trim test handles degree "
                         f"<= {MAX_TRIM_DEGREE}; reduce it (e.g. approximate the loop) before drawing.")
    segs = _bezier_segments(curve)
    pieces = []
    for seg, cuts in zip(segs, _v_turns_all(segs)):
        rest, done = seg, 0.0
        for t in cuts:
            left, rest = _split(rest, (t - done) / (1 - done))
            done = t
            pieces.append(left)
        pieces.append(rest)
    seg = np.asarray(pieces).reshape(len(pieces), curve.degree + 1, 3)
    ctrl = np.zeros((len(seg), 4, 3))
    ctrl[:, : curve.degree + 1] = seg
    pts = seg[:, :, :2] / seg[:, :, 2:3]
    bbox = np.column_stack([pts[..., 0].min(axis=1), pts[..., 0].max(axis=1), pts[..., 1].min(axis=1),
                            pts[..., 1].max(axis=1)])
    out = (ctrl, np.full(len(seg), curve.degree), bbox)
    _PIECES[curve] = out
    return out


_PIECES = weakref.WeakKeyDictionary()  # TrimCurve (hashed by identity) -> its pieces


def _eval(ctrl, deg, t):
    """Rational Bezier points (m, 2) of pieces (m, 4, 3) with degrees (m,) at t (m,) (de Casteljau)."""
    out = np.empty((len(t), 3))
    for p in np.unique(deg):
        sel = deg == p
        q = ctrl[sel, : p + 1].copy()
        tt = t[sel][:, None]
        for r in range(p):
            q = (1 - tt[:, None]) * q[:, :-1] + tt[:, None] * q[:, 1:]
        out[sel] = q[:, 0]
    return out[:, :2] / out[:, 2:3]


def _evaluator(ctrl, deg):
    """``f(t, axis)``: coordinate ``axis`` of :func:`_eval` ``(ctrl, deg, t)`` (the same arithmetic, the same
    bits), with the pieces grouped by degree once."""
    groups = []
    for p in np.unique(deg):
        sel = np.flatnonzero(deg == p)
        groups.append((int(p), sel, ctrl[sel, : p + 1]))

    def f(t, axis):
        out = np.empty((len(t), 3))
        for p, sel, c in groups:
            q = c
            tt = t[sel][:, None]
            for r in range(p):
                q = (1 - tt[:, None]) * q[:, :-1] + tt[:, None] * q[:, 1:]
            out[sel] = q[:, 0]
        return out[:, axis] / out[:, 2]

    return f


def inside(pieces: TrimPieces, patch: int, u, v, iterations: int = 60) -> np.ndarray:
    """Even-odd inside test of parameters ``(u, v)`` of patch ``patch`` (True everywhere for an untrimmed patch).

    >>> from splinevis.nurbs.model import TrimCurve
    >>> from splinevis.nurbs.exact import circle_net, CIRCLE_KNOTS
    >>> xy, w = circle_net()
    >>> hole = [TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.3 * xy, w)]
    >>> border = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in
    ...           [((0, 0), (1, 0)), ((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))]]
    >>> p = trim_pieces([[border, hole]])
    >>> inside(p, 0, [0.5, 0.5 + 0.2999, 0.5 + 0.3001, 0.05], [0.5, 0.5, 0.5, 0.05]).tolist()
    [False, False, True, True]
    """
    u = np.atleast_1d(np.asarray(u, dtype=np.float64))
    s, c = int(pieces.start[patch]), int(pieces.count[patch])
    own = TrimPieces(pieces.ctrl[s: s + c], pieces.degree[s: s + c], pieces.bbox[s: s + c], np.zeros(1, dtype=np.int64),
                     np.array([c]))  # the patch's pieces alone
    return inside_many(own, np.zeros(u.shape, dtype=np.int64), u, v, iterations).reshape(u.shape)


def inside_many(pieces: TrimPieces, patch, u, v, iterations: int = 60, pairs: int = 1 << 20) -> np.ndarray:
    """:func:`inside` of each parameter ``(u[i], v[i])`` in its own patch ``patch[i]`` (the same test, point by
    point, for points of many patches at once; at most ``pairs`` point-piece pairs at a time).

    >>> from splinevis.nurbs.model import TrimCurve
    >>> square = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in
    ...           [((0.2, 0.2), (0.8, 0.2)), ((0.8, 0.2), (0.8, 0.8)), ((0.8, 0.8), (0.2, 0.8)), ((0.2, 0.8), (0.2, 0.2))]]
    >>> inside_many(trim_pieces([[square], None]), [0, 0, 1], [0.5, 0.1, 0.1], [0.5, 0.5, 0.5]).tolist()
    [True, False, True]
    """
    u = np.atleast_1d(np.asarray(u, dtype=np.float64)).ravel()
    v = np.atleast_1d(np.asarray(v, dtype=np.float64)).ravel()
    patch = np.atleast_1d(np.asarray(patch, dtype=np.int64)).ravel()
    ctrl, deg, box = pieces.ctrl, pieces.degree, pieces.bbox
    n = len(deg)
    first = ctrl[np.arange(n), 0, 1] / ctrl[np.arange(n), 0, 2]
    last = ctrl[np.arange(n), deg, 1] / ctrl[np.arange(n), deg, 2]
    lo, hi = np.minimum(first, last), np.maximum(first, last)
    count = np.asarray(pieces.count, dtype=np.int64)[patch]
    start = np.asarray(pieces.start, dtype=np.int64)[patch]
    crossings = np.zeros(u.size, dtype=np.int64)
    ends = np.cumsum(count)
    a = 0
    while a < u.size:  # chunks of at most ``pairs`` pairs (at least one point)
        b = max(int(np.searchsorted(ends, (ends[a - 1] if a else 0) + pairs, side="right")), a + 1)
        c = count[a:b]
        pi = np.repeat(np.arange(a, b), c)
        pk = np.repeat(start[a:b] - (np.cumsum(c) - c), c) + np.arange(pi.size)
        U, V = u[pi], v[pi]
        spans = (V >= lo[pk]) & (V < hi[pk])  # half-open: a vertex shared by two pieces is counted once
        sure = spans & (box[pk, 0] > U)  # the whole hull right of u0
        unsure = spans & ~sure & (box[pk, 1] > U)
        crossings[a:b] += np.bincount(pi[sure] - a, minlength=b - a)
        pi, pk = pi[unsure], pk[unsure]
        if pi.size:
            up = last[pk] > first[pk]
            lo_t, hi_t = np.zeros(pi.size), np.ones(pi.size)
            evaluate = _evaluator(ctrl[pk], deg[pk])  # the pieces sorted by degree once, not at every step
            for _ in range(iterations):  # bisection on the monotone v(t) = v0
                m = 0.5 * (lo_t + hi_t)
                vm = evaluate(m, 1)
                below = (vm < v[pi]) == up
                lo_t, hi_t = np.where(below, m, lo_t), np.where(below, hi_t, m)
            um = evaluate(0.5 * (lo_t + hi_t), 0)
            crossings[a:b] += np.bincount(pi[um > u[pi]] - a, minlength=b - a)
        a = b
    return (crossings % 2 == 1) | (count == 0)  # an untrimmed patch keeps everything

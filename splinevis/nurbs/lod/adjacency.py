"""Which Bezier patch sides are the same boundary curve: the edges of a model's patch mesh.

Crack-free tessellation and the growth of super-surfaces both need, for every patch side, the sides that
share its curve [Kumar1997, sec. 3 and 4.2]. A patch has four sides, numbered

* ``0``: ``v = 0``, running along ``u`` from ``u = 0`` to ``u = 1`` (control points ``C[:, 0]``);
* ``1``: ``u = 1``, running along ``v`` (``C[-1, :]``);
* ``2``: ``v = 1``, running along ``u`` (``C[:, -1]``);
* ``3``: ``u = 0``, running along ``v`` (``C[0, :]``);

each oriented by its increasing parameter (not around the patch), and flat side ``4 i + k`` is side ``k``
of patch ``i``. Two sides are one edge when their boundary curves have the same degree and the same
control points, forward or reversed: Cartesian points equal within ``tol`` in every coordinate and weights
(each side's scaled to a largest weight of 1, which leaves a rational curve unchanged) equal within
``tol / size``. A side whose control points all lie within ``tol`` of its first one is collapsed (a pole
of a sphere or the teapot's knob): it has no edge.

Matching never compares all pairs. The side end points are clustered on a grid of cell ``4 tol`` (a point
and its partners within ``tol`` lie in the point's cell or the neighbours toward the nearer cell faces:
eight cells), the sides are keyed by the unordered pair of their end clusters and their degree, sorted,
and only sides with one key are compared control point by control point: ``O(S log S)`` for ``S`` sides.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np

from .bezier import BezierGroup, BezierSet

__all__ = ["SIDE_NAMES", "side_curves", "cluster_points", "Edges", "find_edges"]

#: Which boundary each side number is.
SIDE_NAMES = ("v=0", "u=1", "v=1", "u=0")


def side_curves(group: BezierGroup, side: int) -> np.ndarray:
    """Homogeneous control points of side ``side`` of every patch of ``group``, in the side's parameter
    direction: ``(N, p + 1, 4)`` for sides 0 and 2, ``(N, q + 1, 4)`` for sides 1 and 3.

    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.exact import saddle
    >>> side_curves(bezier_set(saddle()).groups[0], 1)[0, :, :3].tolist()  # u = 1: x = 1, y from -1 to 1
    [[1.0, -1.0, 0.0], [1.0, 0.0, 2.0], [1.0, 1.0, 0.0]]
    """
    C = group.control
    return (C[:, :, 0], C[:, -1, :], C[:, :, -1], C[:, 0, :])[int(side)]


@dataclass(frozen=True, eq=False)
class Edges:
    """The unique edges of a :class:`BezierSet` (build it with :func:`find_edges`).

    Attributes
    ----------
    side_edge : (P, 4) int array
        The edge of each patch side; -1 for a collapsed side.
    side_reversed : (P, 4) bool array
        The side runs against its edge's direction (an edge runs as its first side does).
    collapsed : (P, 4) bool array
        The side's control points coincide within ``tol`` (a pole).
    edge_side : (E,) int array
        The first flat side ``4 i + k`` of each edge (edges are numbered in the order of these).
    edge_degree : (E,) int array
        The degree of each edge's curve.
    offsets, members : (E + 1,) and (S,) int arrays
        The flat sides of edge ``e`` are ``members[offsets[e]:offsets[e + 1]]``, the first being ``edge_side[e]``.
    tol : float
        The tolerance used.

    Examples
    --------
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.exact import sphere
    >>> e = find_edges(bezier_set(sphere()))
    >>> e.counts()
    {'edges': 12, 'open': 0, 'shared': 12, 'nonmanifold': 0, 'collapsed': 8}
    >>> e.sides(0).tolist()  # patch 0's side v = 0 is the south pole, so edge 0 is its u = 1 side
    [[0, 1, 0], [2, 3, 0]]
    """

    side_edge: np.ndarray
    side_reversed: np.ndarray
    collapsed: np.ndarray
    edge_side: np.ndarray
    edge_degree: np.ndarray
    offsets: np.ndarray
    members: np.ndarray
    tol: float

    def __len__(self) -> int:
        return int(self.edge_side.size)

    @property
    def count(self) -> np.ndarray:
        """``(E,)`` the number of patch sides on each edge: 1 open, 2 shared, more non-manifold.

        >>> from splinevis.nurbs.lod.bezier import bezier_set
        >>> from splinevis.nurbs.exact import saddle
        >>> find_edges(bezier_set(saddle())).count.tolist()
        [1, 1, 1, 1]
        """
        return np.diff(self.offsets)

    def counts(self) -> dict:
        """How many edges there are, how many are open (1 side: a boundary of the model), shared (2),
        non-manifold (3 or more), and how many sides are collapsed.

        >>> from splinevis.nurbs.lod.bezier import bezier_set
        >>> from splinevis.nurbs.exact import torus
        >>> find_edges(bezier_set(torus())).counts()
        {'edges': 32, 'open': 0, 'shared': 32, 'nonmanifold': 0, 'collapsed': 0}
        """
        c = self.count
        return {"edges": len(self), "open": int((c == 1).sum()), "shared": int((c == 2).sum()),
                "nonmanifold": int((c > 2).sum()), "collapsed": int(self.collapsed.sum())}

    def sides(self, edge: int) -> np.ndarray:
        """``(k, 3)`` rows ``(patch, side, reversed)`` of the sides on ``edge``, its first side first.

        >>> from splinevis.nurbs.lod.bezier import bezier_set
        >>> from splinevis.nurbs.exact import torus
        >>> find_edges(bezier_set(torus())).sides(2).tolist()  # patch 0's v = 1 is patch 1's v = 0
        [[0, 2, 0], [1, 0, 0]]
        """
        f = self.members[self.offsets[edge]:self.offsets[edge + 1]]
        return np.column_stack([f // 4, f % 4, self.side_reversed.ravel()[f]])

    def open_sides(self) -> np.ndarray:
        """``(k, 2)`` rows ``(patch, side)`` of the sides on open edges (the model's boundary), by patch.

        >>> from splinevis.nurbs.lod.bezier import bezier_set
        >>> from splinevis.nurbs.exact import cylinder
        >>> find_edges(bezier_set(cylinder())).open_sides()[:3].tolist()  # the rims v = 0 and v = 1
        [[0, 0], [0, 2], [1, 0]]
        """
        f = self.edge_side[self.count == 1]
        f = np.sort(f)
        return np.column_stack([f // 4, f % 4])

    def nonmanifold(self) -> np.ndarray:
        """Ids of the edges with 3 or more sides (faces meeting like pages of a book: worth a report).

        >>> from splinevis.nurbs.lod.bezier import bezier_set
        >>> from splinevis.nurbs.exact import torus
        >>> find_edges(bezier_set(torus())).nonmanifold().tolist()
        []
        """
        return np.flatnonzero(self.count > 2)

    @property
    def mate(self) -> np.ndarray:
        """``(P, 4)`` the other flat side of each side's edge when the edge has exactly two sides, else -1
        (open, collapsed, non-manifold). The two run the same way when their ``side_reversed`` agree.

        >>> from splinevis.nurbs.lod.bezier import bezier_set
        >>> from splinevis.nurbs.exact import torus
        >>> divmod(int(find_edges(bezier_set(torus())).mate[0, 3]), 4)  # patch 0's u = 0 closes on patch 12's u = 1
        (12, 1)
        """
        out = np.full(self.side_edge.size, -1, dtype=np.int64)
        two = np.flatnonzero(self.count == 2)
        a, b = self.members[self.offsets[two]], self.members[self.offsets[two] + 1]
        out[a], out[b] = b, a
        return out.reshape(self.side_edge.shape)


# -------------------------------------------------------------------------------------------------
def _hash(c: np.ndarray) -> np.ndarray:
    """One int64 per integer cell (collisions only add candidates; every pair is checked by distance)."""
    with np.errstate(over="ignore"):
        return (c[:, 0] * np.int64(73856093)) ^ (c[:, 1] * np.int64(19349663)) ^ (c[:, 2] * np.int64(83492791))


def _ranges(lo, hi):
    """``(owner, index)`` of every index in the ranges ``[lo[k], hi[k])``."""
    cnt = hi - lo
    owner = np.repeat(np.arange(lo.size), cnt)
    within = np.arange(owner.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    return owner, np.repeat(lo, cnt) + within


def cluster_points(X: np.ndarray, tol: float) -> np.ndarray:
    """Labels ``0..k-1`` of the points ``X (n, 3)`` with points within ``tol`` (max norm) in one cluster
    (transitively), by hashing a grid of cell ``4 tol``: no all-pairs comparison.

    >>> cluster_points(np.array([[0.0, 0, 0], [1, 0, 0], [1e-10, 0, 0], [1, 2e-10, 0]]), 1e-9).tolist()
    [0, 1, 0, 1]
    """
    X = np.asarray(X, dtype=np.float64).reshape(-1, 3) + 0.0  # -0.0 + 0.0 = +0.0: one bit pattern for zero
    uniq, inv = np.unique(X, axis=0, return_inverse=True)
    inv = inv.ravel()
    n = uniq.shape[0]
    if tol <= 0 or n < 2:
        return inv
    h = 4.0 * tol
    f = uniq / h
    if np.abs(f).max() >= 2.0**52:
        raise ValueError(f"tol = {tol!r} is below the rounding of coordinates up to {float(np.abs(uniq).max())!r}; "
                         "pass a larger tolerance (or 0 for exact comparison).")
    c = np.floor(f).astype(np.int64)
    step = np.where(f - c < 0.5, -1, 1)  # toward the nearer cell face
    key = _hash(c)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    I, J = [], []
    for d in product((0, 1), repeat=3):
        k = _hash(c + step * np.array(d))
        owner, pos = _ranges(np.searchsorted(skey, k, "left"), np.searchsorted(skey, k, "right"))
        other = order[pos]
        keep = (owner != other) & (np.abs(uniq[owner] - uniq[other]).max(axis=1) <= tol)
        I.append(owner[keep])
        J.append(other[keep])
    I, J = np.concatenate(I), np.concatenate(J)
    lab = np.arange(n)
    while I.size:  # connected components: propagate the smallest label, then jump pointers
        m = np.minimum(lab[I], lab[J])
        new = lab.copy()
        np.minimum.at(new, I, m)
        np.minimum.at(new, J, m)
        new = new[new]
        if np.array_equal(new, lab):
            break
        lab = new
    return np.unique(lab, return_inverse=True)[1].ravel()[inv]


def _match(Xa, Wa, Xb, Wb, tol, wtol):
    """Forward and reversed agreement of side curves ``a`` with ``b`` (rows)."""
    fwd = (np.abs(Xa - Xb).max(axis=(1, 2)) <= tol) & (np.abs(Wa - Wb).max(axis=1) <= wtol)
    rev = (np.abs(Xa[:, ::-1] - Xb).max(axis=(1, 2)) <= tol) & (np.abs(Wa[:, ::-1] - Wb).max(axis=1) <= wtol)
    return fwd, rev


def find_edges(bezier: BezierSet, tol: float | None = None) -> Edges:
    """The unique edges of the patches' sides (conventions in the module docstring) [Kumar1997, sec. 3].

    ``tol`` defaults to ``1e-9 * bezier.size`` (at least 64 ulps of the largest coordinate, for a model far
    from the origin): shared boundaries computed from the same control points agree to rounding (knot
    insertion and ``w P / w`` move a point by a few ulps, ~1e-15 of the model), far below the default,
    while distinct curves of any modelled feature are far above it. Files whose
    surfaces meet only to a modelling tolerance (CAD exports: 1e-6 to 1e-3 of the model; the paper's test
    model had cracks between surfaces and so incomplete adjacency [Kumar1997, sec. 6]) need that tolerance
    passed; the tolerance must stay below half the shortest side of the model (a larger one merges the
    ends of a side). Seams of closed surfaces (a sphere's first and last column, a torus's rows) are found
    like any other shared edge, from the geometry.

    Examples
    --------
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from datasets_synthetic.teapot import newell_teapot
    >>> e = find_edges(bezier_set(newell_teapot()))
    >>> e.counts()
    {'edges': 68, 'open': 16, 'shared': 52, 'nonmanifold': 0, 'collapsed': 8}
    """
    if not isinstance(bezier, BezierSet):
        raise TypeError(f"find_edges needs a BezierSet, got {type(bezier).__name__}.")
    size = bezier.size if bezier.size > 0 else 1.0
    if tol is None:
        reach = np.abs(bezier.bbox).max() if len(bezier) else 0.0
        tol = max(1e-9 * size, 64.0 * np.finfo(float).eps * reach)
    tol = float(tol)
    if not (np.isfinite(tol) and tol >= 0):
        raise ValueError(f"tol must be a finite non-negative length, got {tol!r}.")
    wtol = tol / size
    P = len(bezier)
    collapsed = np.zeros(P * 4, dtype=bool)
    # sides by degree: flat ids, Cartesian points, normalized weights
    buckets: dict = {}
    for g in bezier.groups:
        for k in range(4):
            S = side_curves(g, k)
            X = S[..., :3] / S[..., 3:]
            W = S[..., 3] / S[..., 3].max(axis=1, keepdims=True)
            flat = 4 * g.ids + k
            col = np.abs(X - X[:, :1]).max(axis=(1, 2)) <= tol
            collapsed[flat[col]] = True
            ids, xs, ws = buckets.setdefault(S.shape[1] - 1, ([], [], []))
            ids.append(flat[~col])
            xs.append(X[~col])
            ws.append(W[~col])
    degrees = sorted(buckets)
    flats = [np.concatenate(buckets[n][0]) for n in degrees]
    Xs = [np.concatenate(buckets[n][1]) for n in degrees]
    Ws = [np.concatenate(buckets[n][2]) for n in degrees]
    # end point clusters of all sides at once
    ends = np.concatenate([np.concatenate([X[:, 0], X[:, -1]]) for X in Xs]) if Xs else np.zeros((0, 3))
    labels = cluster_points(ends, tol)
    nlab = int(labels.max()) + 1 if labels.size else 1
    e_first, e_deg, e_len, e_members = [], [], [], []  # per bucket, edges in any order, members edge by edge
    side_rev = np.zeros(P * 4, dtype=bool)
    at = 0
    for n, flat, X, W in zip(degrees, flats, Xs, Ws):
        m = flat.size
        a, b = labels[at:at + m], labels[at + m:at + 2 * m]
        at += 2 * m
        if m == 0:
            continue
        key = np.minimum(a, b) * nlab + np.maximum(a, b)
        order = np.lexsort((flat, key))  # by key, then flat side: a group's first is its lowest side
        key, flat, X, W = key[order], flat[order], X[order], W[order]
        start = np.r_[True, key[1:] != key[:-1]]
        gid = np.cumsum(start) - 1
        rep = np.flatnonzero(start)[gid]
        fwd, rev = _match(X, W, X[rep], W[rep], tol, wtol)
        side_rev[flat] = ~fwd & rev
        bad = np.zeros(gid[-1] + 1, dtype=bool)
        bad[gid[~(fwd | rev)]] = True
        good = ~bad[gid]  # groups whose sides all match their first: one edge each, vectorized
        firsts = np.flatnonzero(start & good)
        e_first.append(flat[firsts])
        e_deg.append(np.full(firsts.size, n))
        e_len.append(np.bincount(gid[good], minlength=gid[-1] + 1)[gid[firsts]])
        e_members.append(flat[good])
        pend = np.flatnonzero(~good)  # same ends and degree, other curves (two halves of a ring): split in
        while pend.size:  # rounds, each taking the sides that match the first one left of their key
            g = gid[pend]
            st = np.r_[True, g[1:] != g[:-1]]
            rep = pend[np.flatnonzero(st)[np.cumsum(st) - 1]]
            f, r = _match(X[pend], W[pend], X[rep], W[rep], tol, wtol)
            hit = f | r  # each first matches itself
            side_rev[flat[pend]] = ~f & r
            e_first.append(flat[pend[st]])
            e_deg.append(np.full(int(st.sum()), n))
            e_len.append(np.add.reduceat(hit.astype(np.int64), np.flatnonzero(st)))
            e_members.append(flat[pend[hit]])
            pend = pend[~hit]
    cat = (lambda parts: np.concatenate(parts).astype(np.int64) if parts else np.zeros(0, dtype=np.int64))
    first, deg, lengths, members = cat(e_first), cat(e_deg), cat(e_len), cat(e_members)
    starts = np.cumsum(lengths) - lengths
    order = np.argsort(first, kind="stable")  # number the edges by their first side
    members = members[_ranges(starts[order], starts[order] + lengths[order])[1]]
    lengths = lengths[order]
    offsets = np.r_[0, np.cumsum(lengths)].astype(np.int64)
    side_edge = np.full(P * 4, -1, dtype=np.int64)
    side_edge[members] = np.repeat(np.arange(order.size), lengths)
    out = dict(side_edge=side_edge.reshape(P, 4), side_reversed=side_rev.reshape(P, 4),
               collapsed=collapsed.reshape(P, 4), edge_side=first[order], edge_degree=deg[order],
               offsets=offsets, members=members)
    for arr in out.values():
        arr.setflags(write=False)
    return Edges(tol=tol, **out)

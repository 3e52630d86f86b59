"""Adaptive tessellation of one (rational) Bezier patch to a proven deviation bound ``delta`` [Kumar1997, sec. 4.1],
with given boundary chains so that neighbours share their boundary vertices exactly [Kumar1997, sec. 4.2].

The algorithm of [Kumar1997, sec. 4.1] on the patch's local domain ``[0, 1]^2``:

1. two triangles, with the diagonal whose larger proven bound (:func:`splinevis.nurbs.lod.bounds.triangle_bounds`)
   is the smaller;
2. every triangle whose bound exceeds its target is split at the point where ``|F - L|`` is largest, found by
   sampling a barycentric grid (edges included): 1 -> 3 at an interior point; at a point of an edge, that edge
   is split and so is the triangle on its other side (1 -> 2 each), so the mesh stays conforming (no
   T-junctions);
3. repeat (all triangles of a round at once: bounds, sampling and splits are array operations; a round's
   splits touching a common triangle are deferred, the one of the larger bound going first) until every
   bound meets its target.

Guards. An interior 1 -> 3 split never shortens the longest edge of a triangle (that edge survives in a child),
so the max-deviation rule alone can leave slivers whose bound never falls: a triangle of quality
``4 sqrt(3) area / sum of squared edges`` below ``quality`` (1 for the equilateral) is instead bisected at
the midpoint of its longest edge (with its neighbour across it); ``quality > 1`` makes every split such a
bisection (on a bicubic bump at ``delta = 1e-2``: 352 triangles against 690 at the default 0.5 and 1132 at
0.1; a uniform grid meeting the same bound needs 450). A triangle at depth ``max_depth`` (splits
since the first two triangles) is no longer split on its own, and the result says it did not converge.

Boundary chains. ``chains`` lists, for the sides ``v = 0``, ``u = 1``, ``v = 1``, ``u = 0`` (the numbering of
:mod:`splinevis.nurbs.lod.adjacency`), a sorted parameter array from 0 to 1 or None. A chain's points are
inserted as the refinement goes: a triangle on an edge of that side with chain points inside is split there,
at the chain point nearest the edge's middle (or, if it is taller than the edge is long, first at the midpoint
of its longest edge: no fans from a far vertex). The chain's segments are never split; edges on a side
without chain are split like any other. When a triangle on a chain segment needs a split at a point of
that segment, it is split 1 -> 3 at the point halfway from there to the opposite vertex instead: the triangle
along the segment halves in height. Its true deviation tends to the segment's chord deviation, its proven
bound to a limit near the segment's curve bound ``b`` (:func:`splinevis.nurbs.lod.bounds.curve_chord_bounds`):
the same for a polynomial patch; for a rational one the ``(D_d w)(D_d L)`` term across the segment adds to it.
So a segment with ``b > delta`` cannot meet ``delta``: the triangles on it, and those at its ends within a band
along the side 1/8 of its length deep (the fans there span sub-arcs of the same curve), get the target
``delta + b``; and a triangle on a chain segment that is thin across it (height at most 1/16 of the segment)
and whose last split lowered its bound by under 1 % is left as it is (its bound has reached what the segment
allows). The result's ``limits`` maps each side whose segments have ``b > delta`` or left a triangle above
``delta`` to the largest such ``b``. :func:`curve_chain` makes chains that meet ``delta``.

A collapsed side (all its control points equal: a pole) maps every point to one point
(:func:`splinevis.nurbs.lod.bounds.patch_points` puts them there exactly): it cannot crack, so it is never
fixed (a chain given for it is ignored; its edges are split as needed); the triangles on it are the segments
in space the pole implies, no others are degenerate.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .bounds import (_chord_bounds_many, _curve_points_rows, _patch_points_many, collapsed_point, side_net,
                     triangle_bounds)

__all__ = ["Tessellation", "curve_chain", "adaptive_tessellation", "barycentric_grid"]

_CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
# side k: (fixed coordinate axis, its value, running coordinate axis); corners (start, end) of its CCW edge
_SIDES = ((1, 0.0, 0), (0, 1.0, 1), (1, 1.0, 0), (0, 0.0, 1))
_SIDE_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0))


class Tessellation(NamedTuple):
    """The result of :func:`adaptive_tessellation`.

    ``uv (K, 2)`` domain points, ``triangles (T, 3)`` vertex indices (counter-clockwise in the domain),
    ``bound (T,)`` each triangle's proven bound of ``|F - L|``; ``limits`` maps a side whose given chain keeps
    the bound above ``delta`` to the largest curve bound of the segments concerned (module docstring);
    ``converged`` is False when a guard (``max_depth``, ``max_triangles``) stopped a triangle above its target.

    >>> t = Tessellation(np.zeros((3, 2)), np.array([[0, 1, 2]]), np.zeros(1), {}, True)
    >>> t.triangles.shape, t.converged
    ((1, 3), True)
    """

    uv: np.ndarray
    triangles: np.ndarray
    bound: np.ndarray
    limits: dict
    converged: bool


def barycentric_grid(n: int) -> np.ndarray:
    """``((n + 1)(n + 2) / 2, 3)`` barycentric coordinates ``(i, j, k) / n``, vertices and edges included.

    >>> barycentric_grid(1).tolist()
    [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
    """
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    k = n - i - j
    ok = k >= 0
    return np.stack([i[ok], j[ok], k[ok]], axis=-1) / float(n)


def curve_chain(Pw_side, delta: float, samples: int = 33, max_depth: int = 40) -> np.ndarray:
    """A sorted parameter array from 0 to 1 along the rational Bezier curve ``Pw_side (p + 1, 4)`` whose chords
    each have a proven bound (:func:`splinevis.nurbs.lod.bounds.curve_chord_bounds`) at most ``delta``: the
    segments above it are split where the sampled chord deviation is largest (kept within the middle 3/4 of
    the segment), recursively. A collapsed side gives ``[0, 1]``.

    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.operations import bezier_patches
    >>> from splinevis.nurbs.lod.bounds import side_net
    >>> Pw = bezier_patches(sphere())[0][0].homogeneous()
    >>> curve_chain(side_net(Pw, 0), 1e-3).tolist(), curve_chain(side_net(Pw, 1), 1e-2).size
    ([0.0, 1.0], 9)
    """
    Pw = np.asarray(Pw_side, dtype=np.float64)
    return _curve_chains(Pw[None], np.array([_check_delta(delta)]), samples, max_depth)[0]


def _curve_chains(nets, delta, samples: int = 33, max_depth: int = 40) -> list:
    """:func:`curve_chain` of the curves ``nets (E, p + 1, 4)`` (one degree) with tolerances ``delta (E,)``, refined
    in lockstep (row by row the same operations: bitwise the chains of one call each)."""
    E = nets.shape[0]
    s = np.arange(1, samples + 1) / (samples + 1.0)
    live = np.array([collapsed_point(C) is None for C in nets], dtype=bool)
    eid, t = np.repeat(np.arange(E), 2), np.tile([0.0, 1.0], E)  # the chains, sorted by (curve, parameter)
    for _ in range(max_depth):
        k = np.flatnonzero((eid[:-1] == eid[1:]) & live[eid[:-1]])  # segments [t[k], t[k + 1]]
        t0, t1, ek = t[k], t[k + 1], eid[k]
        need = (_chord_bounds_many(nets, ek, t0, t1) > delta[ek]) & (t1 - t0 > 4 * np.finfo(float).eps)
        if not need.any():
            break
        t0, t1, ek = t0[need], t1[need], ek[need]
        tt = t0[:, None] + s[None, :] * (t1 - t0)[:, None]
        C = _curve_points_rows(nets[np.repeat(ek, s.size)], tt.ravel()).reshape(tt.shape + (-1,))
        E0, E1 = _curve_points_rows(nets[ek], t0), _curve_points_rows(nets[ek], t1)
        chord = E0[:, None, :] + s[None, :, None] * (E1 - E0)[:, None, :]
        best = np.clip(s[np.argmax(np.linalg.norm(C - chord, axis=-1), axis=1)], 0.125, 0.875)
        eid, t = np.concatenate([eid, ek]), np.concatenate([t, t0 + best * (t1 - t0)])
        order = np.lexsort((t, eid))
        eid, t = eid[order], t[order]
        keep = np.concatenate([[True], (eid[1:] != eid[:-1]) | (t[1:] != t[:-1])])
        eid, t = eid[keep], t[keep]
    return np.split(t, np.cumsum(np.bincount(eid, minlength=E))[:-1])


def _check_delta(delta) -> float:
    d = float(delta)
    if not (np.isfinite(d) and d > 0):
        raise ValueError(f"delta must be a positive finite distance, got {delta!r}.")
    return d


def _check_chains(chains):
    if chains is None:
        return [None] * 4
    chains = list(chains)
    if len(chains) != 4:
        raise ValueError(f"chains must list 4 sides (v=0, u=1, v=1, u=0), got {len(chains)}.")
    out = []
    for k, c in enumerate(chains):
        if c is None:
            out.append(None)
            continue
        c = np.asarray(c, dtype=np.float64).ravel()
        if c.size < 2 or c[0] != 0.0 or c[-1] != 1.0 or not (np.diff(c) > 0).all():
            raise ValueError(f"chains[{k}] must increase strictly from 0.0 to 1.0, got {c.tolist()[:8]}"
                             f"{' ...' if c.size > 8 else ''}.")
        out.append(c)
    return out


def _neighbours(tri: np.ndarray, K: int) -> np.ndarray:
    """``(T, 3)`` flat index ``3 t + k`` of the edge (of triangle t) opposite in orientation to each edge, or -1."""
    a, b = tri, np.roll(tri, -1, axis=1)
    key, rkey = (a * K + b).ravel(), (b * K + a).ravel()
    order = np.argsort(key)
    sk = key[order]
    pos = np.minimum(np.searchsorted(sk, rkey), sk.size - 1)
    return np.where(sk[pos] == rkey, order[pos], -1).reshape(tri.shape)


def _rotate(tri: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Rows ``(v_k, v_(k+1), v_(k+2))``."""
    r = np.arange(tri.shape[0])[:, None]
    return tri[r, (k[:, None] + np.arange(3)) % 3]


def _snap(p, a, b):
    """Points ``p`` on segments ``a b``: a coordinate equal at both ends is that coordinate exactly."""
    return np.where(a == b, a, p)


def _edge_side(uv: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Side (0..3) both vertices of each edge ``(a, b)`` lie on, else -1."""
    out = np.full(a.shape, -1, dtype=np.int64)
    for k, (axis, value, _) in enumerate(_SIDES):
        out[(uv[a, axis] == value) & (uv[b, axis] == value)] = k
    return out


def adaptive_tessellation(Pw, delta: float, chains=None, samples: int = 9, max_depth: int = 40,
                          quality: float = 0.5, max_triangles: int = 200_000) -> Tessellation:
    """Triangles of the patch ``Pw (m + 1, n + 1, 4)`` (homogeneous, local domain ``[0, 1]^2``), each with a
    proven bound of ``|F - L|`` at most ``delta`` (module docstring: algorithm, guards, chains, poles).

    ``samples`` is the barycentric grid resolution of the max-deviation search (``(n + 1)(n + 2) / 2`` points).
    Points in space are :func:`splinevis.nurbs.lod.bounds.patch_points` of ``uv`` (boundary points through the
    side curves: bitwise shared with a neighbour given the same chain and side curve).

    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.operations import bezier_patches
    >>> Pw = bezier_patches(sphere())[0][0].homogeneous()
    >>> t = adaptive_tessellation(Pw, 1e-2)
    >>> t.converged, bool(t.bound.max() <= 1e-2), t.triangles.shape[0] > 8
    (True, True, True)
    """
    Pw = np.asarray(Pw, dtype=np.float64)
    if Pw.ndim != 3 or Pw.shape[2] != 4 or min(Pw.shape[:2]) < 2:
        raise ValueError(f"Pw must be homogeneous control points (m + 1, n + 1, 4) with m, n >= 1, got {Pw.shape}.")
    return _tessellate([(Pw, _check_delta(delta), _check_chains(chains))], samples, max_depth, quality,
                       max_triangles)[0]


class _Chains:
    """The chains of one side over a batch of patches (None where the side is not fixed): lookups of
    ``np.searchsorted(chain[p], x)`` for many ``(p, x)`` at once, exactly (through ranks of the values)."""

    def __init__(self, chains, seg_bound):
        n = len(chains)
        lens = np.array([0 if c is None else c.size for c in chains], dtype=np.int64)
        self.off = np.concatenate([[0], np.cumsum(lens)])
        self.c = np.concatenate([np.zeros(0)] + [c for c in chains if c is not None])
        self.U = np.unique(self.c)
        self.big = self.U.size + 2
        self.key = np.repeat(np.arange(n), lens) * self.big + np.searchsorted(self.U, self.c)
        self.seg = np.concatenate([np.zeros(0)] + [b for b in seg_bound if b is not None])  # segment k of p:
        self.soff = np.concatenate([[0], np.cumsum(np.maximum(lens - 1, 0))])  # seg[soff[p] + k]

    def right(self, p, x):
        r = np.searchsorted(self.U, x, side="right") - 1
        return np.searchsorted(self.key, p * self.big + r, side="right") - self.off[p]

    def left(self, p, x):
        r = np.searchsorted(self.U, x, side="left")
        return np.searchsorted(self.key, p * self.big + r, side="left") - self.off[p]


def _end_targets(uv, vp, tri, ch, delta_t, delta, fixed) -> np.ndarray:
    """``(T,)`` target ``delta + b`` of triangles with a vertex on a fixed chain segment with curve bound
    ``b > delta`` lying in the band along the side as deep as 1/8 of that segment's length, else ``delta``
    (``vp``: the patch of each vertex, ``ch``: the :class:`_Chains` per side, ``delta (I,)`` per patch)."""
    out = delta_t.copy()
    for k, (axis, value, run) in enumerate(_SIDES):
        c = ch[k]
        big = np.zeros(len(delta), dtype=bool)  # patches with a fixed side k and a segment above delta
        if c.seg.size:
            owner = np.repeat(np.arange(len(delta)), np.diff(c.soff))
            np.logical_or.at(big, owner, c.seg > delta[owner])
        big &= fixed[:, k]
        if not big.any():
            continue
        on = np.flatnonzero((uv[:, axis] == value) & big[vp])
        p = vp[on]
        i = c.left(p, uv[on, run])  # the vertex is chain[i] exactly
        first, last = i == 0, i == np.diff(c.off)[p] - 1
        s0 = c.soff[p] + i  # segment i (after the vertex) and i - 1 (before)
        sb0 = np.where(first, -np.inf, c.seg[np.maximum(s0 - 1, 0)])
        sb1 = np.where(last, -np.inf, c.seg[np.minimum(s0, c.seg.size - 1)])
        cc = c.c[c.off[p] + i]
        ln0 = np.where(first, 0.0, cc - c.c[np.maximum(c.off[p] + i - 1, 0)])
        ln1 = np.where(last, 0.0, c.c[np.minimum(c.off[p] + i + 1, c.c.size - 1)] - cc)
        vb, vl = np.full(uv.shape[0], -np.inf), np.zeros(uv.shape[0])
        vb[on] = np.maximum(sb0, sb1)
        vl[on] = np.where(sb0 >= sb1, ln0, ln1)
        depth = np.abs(uv[tri, axis] - value).max(axis=1)
        j = np.argmax(vb[tri], axis=1)
        tb, tl = vb[tri][np.arange(tri.shape[0]), j], vl[tri][np.arange(tri.shape[0]), j]
        out = np.where((tb > delta_t) & (depth <= tl / 8.0), np.maximum(out, delta_t + tb), out)
    return out


def _tessellate(items, samples: int = 9, max_depth: int = 40, quality: float = 0.5,
                max_triangles: int = 200_000) -> list:
    """:func:`adaptive_tessellation` of many patches of one degree at once (``items``: ``(Pw, delta, chains)``,
    checked), refined in lockstep: every array operation works row by row, so each patch's result is bitwise
    the one it gets alone (the order of its vertices and triangles included)."""
    I = len(items)
    Pws = np.stack([it[0] for it in items])
    delta = np.array([it[1] for it in items], dtype=np.float64)
    fixed = np.zeros((I, 4), dtype=bool)
    poles = [(np.zeros(I, dtype=bool), np.zeros((I, 3))) for _ in range(4)]
    side_chains, side_bounds, limits = [[None] * I for _ in range(4)], [[None] * I for _ in range(4)], []
    for p, (Pw, d, chains) in enumerate(items):
        lim = {}
        for k in range(4):
            net = side_net(Pw, k)
            pole = collapsed_point(net)
            if pole is not None:
                poles[k][0][p], poles[k][1][p] = True, pole
            if chains[k] is not None and pole is None:
                fixed[p, k] = True
                side_chains[k][p] = chains[k]
        limits.append(lim)
    for k in range(4):  # the curve bounds of every fixed side's chain segments, all patches at once
        rows = np.flatnonzero(fixed[:, k])
        if rows.size:
            lens = np.array([side_chains[k][p].size - 1 for p in rows])
            t = np.concatenate([side_chains[k][p] for p in rows])
            start = np.ones(t.size - 1, dtype=bool)
            start[np.cumsum(lens + 1)[:-1] - 1] = False  # no segment from one chain's end to the next one's start
            b = _chord_bounds_many(np.stack([side_net(Pws[p], k) for p in rows]), np.repeat(np.arange(rows.size), lens),
                                   t[:-1][start], t[1:][start])
            for p, bp in zip(rows, np.split(b, np.cumsum(lens)[:-1])):
                side_bounds[k][p] = bp
    for p in range(I):
        for k in range(4):
            b = side_bounds[k][p]
            if b is not None and b.max() > delta[p]:
                limits[p][k] = float(b.max())
    ch = [_Chains(side_chains[k], side_bounds[k]) for k in range(4)]
    results = [None] * I

    # 1. two triangles, the diagonal with the smaller larger bound
    options = np.array([[[0, 1, 2], [0, 2, 3]], [[0, 1, 3], [1, 2, 3]]])
    X = _patch_points_many(Pws, poles, np.repeat(np.arange(I), 4), np.tile(_CORNERS, (I, 1)))
    t4 = (np.arange(I)[:, None, None, None] * 4 + options[None]).reshape(-1, 3)  # (I * 4, 3): option, triangle
    worst = triangle_bounds(Pws[np.repeat(np.arange(I), 4)], np.tile(_CORNERS, (I, 1))[t4], X[t4])
    choice = np.argmin(worst.reshape(I, 2, 2).max(axis=2), axis=1)
    m = _BatchMesh(Pws, np.tile(_CORNERS, (I, 1)), X, np.repeat(np.arange(I), 4),
                   (np.arange(I)[:, None, None] * 4 + options[choice]).reshape(-1, 3), np.repeat(np.arange(I), 2),
                   poles)

    grid = barycentric_grid(samples)
    while m.tri.shape[0]:
        m.update_bounds()
        tri, uv, tp = m.tri, m.uv, m.tp
        T = tri.shape[0]
        delta_t = delta[tp]
        count = np.bincount(tp, minlength=I)[tp]
        a, b = tri, np.roll(tri, -1, axis=1)
        side = _edge_side(uv, a, b)  # (T, 3)
        is_fixed = np.zeros_like(side, dtype=bool)  # on a chain segment (final)
        pend = np.zeros_like(side, dtype=bool)  # on a fixed side, chain points still inside
        pend_t = np.zeros(side.shape)  # the chain point nearest the middle of a pending edge
        seg = np.full(side.shape, -np.inf)  # the curve bound of each fixed edge's chain segment
        for k in range(4):
            on = (side == k) & fixed[tp, k][:, None]
            if on.any():
                run, c = _SIDES[k][2], ch[k]
                p = np.broadcast_to(tp[:, None], side.shape)[on]
                lo = np.minimum(uv[a[on], run], uv[b[on], run])
                hi = np.maximum(uv[a[on], run], uv[b[on], run])
                i_lo, i_hi = c.right(p, lo), c.left(p, hi)
                inside = i_hi > i_lo  # chain points c[i_lo:i_hi] lie strictly inside the edge
                mid = 0.5 * (lo + hi)
                j = np.clip(c.left(p, mid), i_lo, np.maximum(i_hi - 1, i_lo))  # first >= mid, or the last
                o = c.off[p]
                j = np.where((j > i_lo) & (np.abs(c.c[np.maximum(o + j - 1, 0)] - mid) < np.abs(c.c[o + j] - mid)),
                             j - 1, j)
                pend[on], is_fixed[on] = inside, ~inside
                pend_t[on] = c.c[o + j]
                seg[on] = np.where(inside, -np.inf, c.seg[np.minimum(c.soff[p] + np.maximum(i_lo - 1, 0),
                                                                     max(c.seg.size - 1, 0))])
        # delta + b on and at the ends of a too coarse segment (b > delta): the region along it cannot do better
        target = np.maximum(delta_t, np.where(seg > delta_t[:, None], delta_t[:, None] + seg,
                                              delta_t[:, None]).max(axis=1))
        target = np.maximum(target, _end_targets(uv, m.vp, tri, ch, delta_t, delta, fixed))
        # a triangle on a fixed segment, already thin across it, whose last split gained under 1 %: its bound
        # has reached what the segment allows
        V = uv[tri]
        e = np.roll(V, -1, axis=1) - V
        l2 = np.einsum("tki,tki->tk", e, e)
        area2 = np.abs(e[:, 0, 0] * e[:, 1, 1] - e[:, 0, 1] * e[:, 1, 0])
        thin = (is_fixed & (area2[:, None] <= l2 / 16.0)).any(axis=1)  # height <= |edge| / 16
        stuck = thin & (m.bound >= 0.99 * m.prev) & (m.bound > target)
        over = (m.bound > target) & ~stuck
        pending = pend.any(axis=1)
        needs = (over & (m.depth < max_depth) & (count < max_triangles)) | pending
        busy = np.zeros(I, dtype=bool)
        busy[tp[needs]] = True
        present = np.zeros(I, dtype=bool)
        present[tp] = True
        finished = np.flatnonzero(present & ~busy)
        if finished.size:
            done = stuck | (m.bound > delta_t)
            for q in finished:
                rows = np.flatnonzero(tp == q)
                lim = limits[q]
                for k in range(4):
                    hit = (side[rows] == k) & done[rows][:, None] & is_fixed[rows]
                    if hit.any():
                        lim[k] = max(lim.get(k, -np.inf), float(seg[rows][hit].max()))
                results[q] = Tessellation(*m.extract(q, rows), lim, not over[rows].any())
            keep = busy[tp]
            m.drop(keep)
            if not keep.any():
                break
            sel = np.flatnonzero(keep)
            tri, uv, tp = m.tri, m.uv, m.tp
            T = tri.shape[0]
            side, is_fixed, pend, pend_t = side[sel], is_fixed[sel], pend[sel], pend_t[sel]
            pending, needs, l2 = pending[sel], needs[sel], l2[sel]
        need = np.flatnonzero(needs)
        # 2. the point of largest sampled deviation of each triangle that needs a split
        # (a triangle keeps its sample while it is not split: it depends on its vertices only)
        V = uv[tri[need]]  # (N, 3, 2)
        new = need[m.best[need] < 0]
        if new.size:
            P = grid @ uv[tri[new]]  # (N, S, 2)
            F = _patch_points_many(Pws, poles, np.repeat(tp[new], grid.shape[0]),
                                   P.reshape(-1, 2)).reshape(P.shape[:2] + (3,))
            dev = np.linalg.norm(F - grid @ m.X[tri[new]], axis=-1)
            m.best[new] = np.argmax(dev, axis=1)
        bc = grid[m.best[need]]  # (N, 3)
        zero = bc == 0
        nz = zero.sum(axis=1)
        kind_edge = nz == 1
        edge = np.where(kind_edge, (np.argmax(zero, axis=1) + 1) % 3, 0)  # edge k = (v_k, v_(k+1)) opposite v_(k+2)
        bc = np.where((nz == 2)[:, None], 1.0 / 3.0, bc)  # a vertex (deviation 0: rounding noise): centroid
        # slivers: the longest edge's midpoint instead
        e = np.roll(V, -1, axis=1) - V  # edge vectors (N, 3, 2)
        l2 = np.einsum("nki,nki->nk", e, e)
        area = 0.5 * np.abs(e[:, 0, 0] * e[:, 1, 1] - e[:, 0, 1] * e[:, 1, 0])
        sliver = 4.0 * np.sqrt(3.0) * area < quality * l2.sum(axis=1)
        longest = np.argmax(l2, axis=1)
        edge = np.where(sliver, longest, edge)
        kind_edge = kind_edge | sliver
        r = np.arange(need.size)
        wa = np.where(sliver, 0.5, bc[r, edge])  # weight of v_k on edge k
        va, vb, vc = V[r, edge], V[r, (edge + 1) % 3], V[r, (edge + 2) % 3]
        on_edge = _snap(wa[:, None] * va + (1.0 - wa[:, None]) * vb, va, vb)
        fixed_edge = kind_edge & is_fixed[need, edge]
        inside = np.einsum("nk,nki->ni", bc, V)
        point = np.where(kind_edge[:, None], on_edge, inside)
        point = np.where(fixed_edge[:, None], 0.5 * (on_edge + vc), point)
        kind_edge &= ~fixed_edge
        # chain points first: a triangle on an edge with chain points inside is split at the one nearest the
        # middle, unless it is taller than that edge is long (then its longest edge, never a fixed one, is
        # bisected first: the chain's points do not fan out from a far vertex)
        pn = pending[need]
        if pn.any():
            kp = np.argmax(pend[need], axis=1)
            tall = pn & (2.0 * area > l2[r, kp])
            chain_split = pn & ~tall
            edge = np.where(tall, longest, np.where(chain_split, kp, edge))
            kind_edge = kind_edge | pn
            va, vb = V[r, edge], V[r, (edge + 1) % 3]
            mid = _snap(0.5 * (va + vb), va, vb)
            at = _snap(np.where(np.abs(vb - va) > 0, pend_t[need, kp][:, None], va), va, vb)
            point = np.where(tall[:, None], mid, np.where(chain_split[:, None], at, point))
        # 3. a conflict-free subset: each request goes if it comes first at every triangle it touches (requests
        # of different patches never touch a common triangle: the global order is each patch's own)
        nb = _neighbours(tri, uv.shape[0])[need, edge]
        other = np.where(kind_edge & (nb >= 0), nb // 3, -1)
        order = np.argsort(np.where(pn, -np.inf, -m.bound[need]), kind="stable")
        rank = np.empty(need.size, dtype=np.int64)
        rank[order] = np.arange(need.size)
        first = np.full(T, need.size, dtype=np.int64)
        np.minimum.at(first, need, rank)
        has = other >= 0
        np.minimum.at(first, other[has], rank[has])
        go = (first[need] == rank) & (~has | (first[np.maximum(other, 0)] == rank))
        _apply(m, need[go], edge[go], kind_edge[go], other[go], np.where(has[go], nb[go] % 3, 0), point[go])
    return results


class _BatchMesh:
    """The growing meshes of a batch of patches: vertices (domain points, points in space, patch ``vp``) and
    triangles (global vertex ids, patch ``tp``, depth, bound, the bound of the triangle split into it)."""

    def __init__(self, Pws, uv, X, vp, tri, tp, poles=None):
        self.Pws, self.poles = Pws, poles
        self.uv, self.X, self.vp = uv, X, vp
        self.tri, self.tp = tri.astype(np.int64), tp
        self.depth = np.zeros(tri.shape[0], dtype=np.int64)
        self.bound = np.full(tri.shape[0], np.nan)
        self.prev = np.full(tri.shape[0], np.inf)
        self.best = np.full(tri.shape[0], -1, dtype=np.int64)  # the sample of largest deviation, -1: not yet

    def add_points(self, uv, X, vp):
        start = self.uv.shape[0]
        self.uv, self.X = np.concatenate([self.uv, uv]), np.concatenate([self.X, X])
        self.vp = np.concatenate([self.vp, vp])
        return start + np.arange(uv.shape[0])

    def replace(self, rows, first, extra, depth):
        """Triangles ``rows`` become ``first``; ``extra`` (list of arrays) are appended; all get ``depth``."""
        parent = self.bound[rows].copy()
        self.tri[rows] = first
        self.depth[rows] = depth
        self.bound[rows] = np.nan
        self.prev[rows] = parent
        self.best[rows] = -1
        tp = self.tp[rows]
        for e in extra:
            self.tri = np.concatenate([self.tri, e])
            self.best = np.concatenate([self.best, np.full(e.shape[0], -1, dtype=np.int64)])
            self.tp = np.concatenate([self.tp, tp])
            self.depth = np.concatenate([self.depth, depth])
            self.bound = np.concatenate([self.bound, np.full(e.shape[0], np.nan)])
            self.prev = np.concatenate([self.prev, parent])

    def update_bounds(self, chunk: int = 1 << 14):
        todo = np.flatnonzero(np.isnan(self.bound))
        for a in range(0, todo.size, chunk):
            rows = todo[a:a + chunk]
            t = self.tri[rows]
            self.bound[rows] = triangle_bounds(self.Pws[self.tp[rows]], self.uv[t], self.X[t])

    def extract(self, q, rows):
        """``(uv, triangles, bound)`` of patch ``q`` (its triangles ``rows``) in its own vertex numbering."""
        verts = np.flatnonzero(self.vp == q)
        local = np.full(self.uv.shape[0], -1, dtype=np.int64)
        local[verts] = np.arange(verts.size)
        return self.uv[verts], local[self.tri[rows]], self.bound[rows]

    def drop(self, keep):
        """Keep the triangles ``keep`` (whole patches) and their patches' vertices."""
        alive = np.zeros(self.Pws.shape[0], dtype=bool)
        alive[self.tp[keep]] = True
        vkeep = alive[self.vp]
        new = np.cumsum(vkeep) - 1
        self.uv, self.X, self.vp = self.uv[vkeep], self.X[vkeep], self.vp[vkeep]
        self.tri = new[self.tri[keep]]
        for name in ("tp", "depth", "bound", "prev", "best"):
            setattr(self, name, getattr(self, name)[keep])


def _apply(mesh: _BatchMesh, rows, edge, kind_edge, other, other_edge, point):
    """Split: interior points 1 -> 3, edge points 1 -> 2 on both sides of the edge."""
    vp = mesh.tp[rows]
    ids = mesh.add_points(point, _patch_points_many(mesh.Pws, mesh.poles, vp, point), vp)
    d = mesh.depth[rows] + 1
    tri = mesh.tri
    inner = ~kind_edge
    if inner.any():
        v, p = tri[rows[inner]], ids[inner]
        mesh.replace(rows[inner], np.column_stack([v[:, 0], v[:, 1], p]),
                     [np.column_stack([v[:, 1], v[:, 2], p]), np.column_stack([v[:, 2], v[:, 0], p])], d[inner])
    if kind_edge.any():
        sel = np.flatnonzero(kind_edge)
        v, p = _rotate(tri[rows[sel]], edge[sel]), ids[sel]
        mesh.replace(rows[sel], np.column_stack([v[:, 0], p, v[:, 2]]), [np.column_stack([p, v[:, 1], v[:, 2]])],
                     d[sel])
        two = other[sel] >= 0
        if two.any():
            o, oe = other[sel][two], other_edge[sel][two]
            w, q = _rotate(mesh.tri[o], oe), p[two]
            mesh.replace(o, np.column_stack([w[:, 0], q, w[:, 2]]), [np.column_stack([q, w[:, 1], w[:, 2]])],
                         mesh.depth[o] + 1)

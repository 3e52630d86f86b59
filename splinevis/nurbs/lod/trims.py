"""Trim loops in the levels of detail: each trimmed patch tessellated up to its trim curves within the level's
bound [Kumar1997, sec. 4.1: trimmed patches are tessellated with their trim curves].

**The bound.** A model with trims is tessellated with the triangle bound ``delta_l - delta_trim`` at level
``l`` (:func:`splinevis.nurbs.lod.levels.build_lod`), and every trim curve is replaced by a polyline in the
parameter domain whose chords deviate from the curve by at most ``h = delta_trim / Lip`` (the curve's proven
chord bound, :func:`splinevis.nurbs.lod.bounds.curve_chord_bounds`), ``Lip`` a proven bound of ``|grad F|`` over
the surface (:func:`gradient_bound`). A point ``x`` of the true trimmed domain outside the polyline's region
lies within ``h`` of a polyline point ``x'``, which a triangle ``T`` of the mesh holds: ``|F(x) - L_T(x')| <=
Lip h + (delta_l - delta_trim) = delta_l``. A mesh point ``L_T(x)`` with ``x`` outside the true domain is within
``h`` of a curve point ``x''``: ``|L_T(x) - F(x'')| <= (delta_l - delta_trim) + Lip h = delta_l``. So the level
keeps ``delta_l`` both ways (surface to mesh and mesh to surface), trims included. The polylines are built
once, at the finest tolerance, and serve every level (trim vertices are not nested across levels).

**The tessellation.** A patch wholly inside its surface's trimmed region is tessellated as without trims; a
patch wholly outside is not drawn. A patch the region's boundary crosses is tessellated as usual (its sides'
chains hold every point where a trim polyline crosses the side, for both patches on that side: no crack), then
clipped: each triangle the region's boundary meets is intersected with the region and the pieces are
triangulated (GEOS's constrained Delaunay triangulation, through shapely). Each piece lies in its triangle, and
its own proven bound (:func:`~splinevis.nurbs.lod.bounds.triangle_bounds`) is computed and held to the target;
vertices on a shared triangle side are welded and T-junctions fanned, so the patch mesh stays conforming.

Why our own code: no library tessellates trimmed rational Bezier patches to a proven bound with boundary
chains shared with neighbours; the planar geometry (region, intersection, constrained triangulation) is
shapely's.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .adaptive import _curve_chains
from .bounds import _curve_points_rows

__all__ = ["TrimPlan", "face_rings", "split_segments", "trim_plan", "gradient_bound", "trim_polylines",
           "merge_params", "local_rings"]

_WELD = 1e-11  # local-domain distance under which two computed points are one vertex (rounding of intersections)


def gradient_bound(Pw, rect) -> float:
    """A proven bound of ``|grad F|`` (operator norm, parent parameters) of the patch ``Pw (m + 1, n + 1, 4)`` on
    the rectangle ``rect = (u0, u1, v0, v1)`` of its parent's domain: ``sqrt(Lu^2 + Lv^2)`` with ``Lu = m max |P_(i+1)j
    - P_ij| / (u1 - u0)`` for a polynomial patch, ``2 m w_max diam / (w_min (u1 - u0))`` for a rational one
    (``F_u = (A_u - F w_u) / w`` and ``|A_u - F w_u| <= m max_i (w_(i+1) |P_(i+1) - F| + w_i |P_i - F|)``), likewise
    in ``v``.

    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> bs = bezier_set(saddle())
    >>> L = gradient_bound(bs.control(0), bs.rect[0])  # 2 sqrt(5) in u and in v
    >>> from splinevis.nurbs.lod.bezier import evaluate
    >>> g = np.linspace(0, 1, 21)
    >>> u, v = [a.ravel() for a in np.meshgrid(g, g)]
    >>> _, Su, Sv = evaluate(bs, np.zeros(u.size, int), u, v, derivatives=True)
    >>> round(L, 6), bool(L >= np.linalg.norm(np.stack([Su, Sv], -1), ord=2, axis=(1, 2)).max())
    (6.324555, True)
    """
    Pw = np.asarray(Pw, dtype=np.float64)
    w = Pw[..., 3]
    P = Pw[..., :3] / w[..., None]
    m, n = Pw.shape[0] - 1, Pw.shape[1] - 1
    du, dv = float(rect[1] - rect[0]), float(rect[3] - rect[2])
    if (w == w.flat[0]).all():
        Lu = m * float(np.linalg.norm(np.diff(P, axis=0), axis=-1).max()) if m else 0.0
        Lv = n * float(np.linalg.norm(np.diff(P, axis=1), axis=-1).max()) if n else 0.0
    else:
        flat = P.reshape(-1, 3)
        diam = float(np.linalg.norm(flat[:, None] - flat[None], axis=-1).max())
        ratio = 2.0 * float(w.max()) * diam / float(w.min())
        Lu, Lv = m * ratio, n * ratio
    return float(np.hypot(Lu / du, Lv / dv))


def trim_polylines(loops, h: float) -> list:
    """Closed polylines ``(K, 2)`` (first point not repeated) of trim ``loops`` (lists of
    :class:`~splinevis.nurbs.model.TrimCurve`), each chord within ``h`` of its curve (proven: the curve's Bezier
    segments split by :func:`splinevis.nurbs.lod.adaptive.curve_chain`'s rule).

    >>> from splinevis.nurbs.exact import CIRCLE_KNOTS, circle_net
    >>> from splinevis.nurbs.model import TrimCurve
    >>> xy, w = circle_net()
    >>> ring = trim_polylines([[TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.25 * xy, w)]], 1e-4)[0]
    >>> r = np.linalg.norm(ring - 0.5, axis=1)  # vertices on the circle, chords' sagitta within 1e-4
    >>> bool(np.abs(r - 0.25).max() < 1e-12), ring.shape[0] > 8
    (True, True)
    """
    from ..trim import _bezier_segments

    out = []
    for loop in loops:
        segs = [s for curve in loop for s in _bezier_segments(curve)]
        pts = []
        by_degree: dict = {}
        for k, s in enumerate(segs):  # (p + 1, 3) homogeneous (u w, v w, w) -> (p + 1, 4) with z = 0
            by_degree.setdefault(s.shape[0], []).append(k)
        params = [None] * len(segs)
        for group in by_degree.values():
            nets = np.stack([np.column_stack([segs[k][:, :2], np.zeros(len(segs[k])), segs[k][:, 2]])
                             for k in group])
            for k, t in zip(group, _curve_chains(nets, np.full(len(group), float(h)))):
                params[k] = t
        for s, t in zip(segs, params):
            C = np.column_stack([s[:, :2], s[:, 2]])
            pts.append(_curve_points_rows(np.repeat(C[None], t.size, axis=0), t))  # end points included
        ring = _chain_pieces(pts)
        keep = np.ones(len(ring), dtype=bool)
        keep[1:] = np.linalg.norm(np.diff(ring, axis=0), axis=1) > 0
        out.append(ring[keep])
    return out


def _polygonal(geom):
    """The polygons of ``geom`` (overlays leave lines and points where boundaries coincide) as one geometry."""
    import shapely

    parts = shapely.get_parts(geom)
    parts = parts[np.isin(shapely.get_type_id(parts), (3, 6))] if parts.size else parts
    parts = parts[shapely.area(parts) > 0] if parts.size else parts
    return shapely.union_all(parts) if parts.size else shapely.Polygon()


def _chain_pieces(pieces):
    """One closed polyline from polyline pieces given in any order and direction (files list a loop's edges
    so, e.g. OpenCASCADE's wires of a seam face): each next piece is the one with an end nearest the current
    end, reversed if need be; the joints' duplicate points are dropped."""
    todo = [np.asarray(p, dtype=np.float64) for p in pieces]
    ring = [todo.pop(0)]
    while todo:
        end = ring[-1][-1]
        d0 = [float(np.linalg.norm(p[0] - end)) for p in todo]
        d1 = [float(np.linalg.norm(p[-1] - end)) for p in todo]
        k0, k1 = int(np.argmin(d0)), int(np.argmin(d1))
        ring.append(todo.pop(k0) if d0[k0] <= d1[k1] else todo.pop(k1)[::-1])
    out = np.concatenate([r[:-1] for r in ring])  # each piece's last point is the next one's first
    return out


def _region(rings):
    """The even-odd region of closed ``rings`` (shapely geometry)."""
    import shapely

    geoms = [shapely.make_valid(shapely.Polygon(r)) for r in rings if len(r) >= 3]
    if not geoms:
        return shapely.Polygon()
    region = geoms[0]
    for g in geoms[1:]:
        region = _polygonal(shapely.symmetric_difference(region, g))
    return _polygonal(region)


class TrimPlan(NamedTuple):
    """What :func:`trim_plan` decides for a model: ``status (P,)`` per Bezier patch (0 untrimmed or wholly inside,
    1 crossed by a trim boundary, -1 wholly outside: not drawn), ``local (P,)`` each crossed patch's region in its
    local domain (shapely, else None), ``edge_params`` (edge id -> parameters along the edge where a trim
    polyline crosses it), ``delta_trim`` and the polylines' uv tolerance per surface ``h``.

    >>> TrimPlan(np.zeros(1, int), [None], {}, 0.0, {}).status.tolist()
    [0]
    """

    status: np.ndarray
    local: list
    edge_params: dict
    delta_trim: float
    h: dict


_SIDE_LINES = (((0.0, 0.0), (1.0, 0.0)), ((1.0, 0.0), (1.0, 1.0)), ((0.0, 1.0), (1.0, 1.0)), ((0.0, 0.0), (0.0, 1.0)))


def face_rings(bs, trims, delta_trim: float, chord=None, side_near=None) -> dict:
    """Per trimmed surface ``f`` of the model: ``(rings, h)``, its trim loops as closed polylines in its parameter
    domain (:func:`trim_polylines`) with the domain tolerance ``h = delta_trim / Lip``, ``Lip`` the largest
    :func:`gradient_bound` of its patches. The polylines hold every point where they cross a knot line, and with
    ``chord`` their segments are halved until the surface over each deviates from its chord by at most ``chord``
    (:func:`split_segments`): a polyline edge is a mesh edge, and a long one over a curved surface could not be.

    >>> from splinevis.nurbs.exact import saddle, CIRCLE_KNOTS, circle_net
    >>> from splinevis.nurbs.model import NurbsModel, TrimCurve
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> xy, w = circle_net()
    >>> m = NurbsModel([saddle()], trims=[[[TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.25 * xy, w)]]])
    >>> rings, h = face_rings(bezier_set(m), m.trims, 1e-3)[0]
    >>> len(rings), round(h, 8)  # Lip = 2 sqrt(10): the saddle's net over [0, 1]^2
    (1, 0.00015811)
    """
    out = {}
    parents = np.unique(bs.parent[bs.trimmed]) if bs.trimmed.any() else np.zeros(0, dtype=np.int64)
    for f in parents:
        ids = np.flatnonzero(bs.parent == f)
        lip = max(gradient_bound(bs.control(int(i)), bs.rect[i]) for i in ids)
        h = float(delta_trim) / max(lip, np.finfo(float).tiny)
        # polylines within 0.999 h of their curves, then points within 0.001 h of the domain's border put on it:
        # files give a loop along a surface's own border a hair inside it (OpenCASCADE: 1e-13 to 1e-10), and such
        # a loop is the border (drawn by the sides' chains, shared with the neighbour), not a trim
        dom = (bs.rect[ids, 0].min(), bs.rect[ids, 1].max(), bs.rect[ids, 2].min(), bs.rect[ids, 3].max())
        near = 0.25 * float(delta_trim) if side_near is None else float(side_near)
        loops = [[_side_curve(bs, int(f), c, dom, near, 0.25 * float(delta_trim)) for c in loop]
                 for loop in trims[int(f)]]
        rings = [split_segments(bs, int(f), _snap_border(r, dom, 1e-3 * h), chord)
                 for r in trim_polylines(loops, 0.999 * h)]
        out[int(f)] = (rings, h)
    return out


def _side_curve(bs, f, curve, dom, near, quiet=np.inf, samples: int = 65):
    """``curve`` (a TrimCurve of surface ``f``), or the straight piece of a side of the domain ``dom`` it follows in
    space: when the curve is off that side in the domain but at every one of ``samples`` points its surface point
    lies within ``near`` of the surface point on the side with the same other parameter (a side that is not a
    pole). OpenCASCADE gives the trim of a fillet's corner sphere along the sphere's side off it by up to 0.0125 in
    u near the pole, 1.6e-5 to 1.4e-3 in space: that trim is the side, drawn by the sides' chains and shared with
    the neighbour (checked at the samples, not proven); a gap above ``quiet`` is reported in a warning."""
    from ..model import TrimCurve
    from .bezier import evaluate, locate

    def points(q):
        p, st = locate(bs, f, q)
        return evaluate(bs, p, st[:, 0], st[:, 1])

    t = np.linspace(*curve.domain, samples)
    uv = curve.evaluate(t)
    X = points(uv)
    size = float(np.linalg.norm(X.max(axis=0) - X.min(axis=0)))
    if size == 0.0:
        return curve
    span = max(dom[1] - dom[0], dom[3] - dom[2])
    for axis, value in ((0, dom[0]), (0, dom[1]), (1, dom[2]), (1, dom[3])):
        off = np.abs(uv[:, axis] - value)
        if off.max() <= 1e-11 * span or off.min() > 1e-9 * span:
            continue  # on the side already (to rounding), or not touching it: no trim of this kind
        q = uv.copy()
        q[:, axis] = value
        Q = points(q)
        if np.linalg.norm(Q.max(axis=0) - Q.min(axis=0)) <= 0.5 * size:
            continue  # the side collapses here (a pole)
        gap = float(np.linalg.norm(Q - X, axis=1).max())
        if gap <= near:
            if gap > quiet:
                import warnings

                warnings.warn(f"surface {f}: a trim curve that touches the side {'uv'[axis]} = {value:.6g} of its "
                              f"domain runs {gap:.3g} off that side in space (more than the trims' share of the bound, "
                              f"{quiet:.3g}): it is taken as the side, so the mesh there is within the level's bound "
                              f"plus {gap:.3g} of the file's trim (the faces of the file disagree by as much).",
                              UserWarning, stacklevel=2)
            return TrimCurve(1, [0.0, 0.0, 1.0, 1.0], q[[0, -1]])
    return curve


def _snap_border(ring, dom, near):
    """Coordinates of ``ring`` within ``near`` of the domain ``dom`` (u0, u1, v0, v1)'s border set onto it."""
    ring = np.array(ring, dtype=np.float64)
    for axis, value in ((0, dom[0]), (0, dom[1]), (1, dom[2]), (1, dom[3])):
        on = np.abs(ring[:, axis] - value) <= near
        ring[on, axis] = value
    keep = np.linalg.norm(ring - np.roll(ring, -1, axis=0), axis=1) > 0
    return ring[keep] if keep.any() else ring


def split_segments(bs, f: int, ring, chord=None, rounds: int = 40):
    """The closed polyline ``ring`` of surface ``f``'s domain with the points where it crosses the patches' knot
    lines put in (exactly on them), then, with ``chord``, each segment halved while the proven bound of
    ``|F - L|`` on a triangle having the segment as a side (:func:`splinevis.nurbs.lod.bounds.triangle_bounds`;
    on that side ``L`` is the chord) exceeds ``chord``. The polyline's shape is unchanged (points on its
    segments).

    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> line = np.array([[0.6, 0.0], [0.6, 1.0], [0.0, 1.0], [0.0, 0.0]])
    >>> r = split_segments(bezier_set(saddle()), 0, line, chord=0.01)
    >>> r.shape[0] > 20, bool(np.isin(line, r).all(axis=1).all())
    (True, True)
    """
    from .bounds import triangle_bounds

    ids = np.flatnonzero(bs.parent == f)
    rect = bs.rect[ids]
    ku, kv = np.unique(rect[:, :2]), np.unique(rect[:, 2:])
    ring = np.asarray(ring, dtype=np.float64)
    pts = []
    for a, b in zip(ring, np.roll(ring, -1, axis=0)):  # knot-line crossings, exact on the lines
        pts.append(a[None])
        cuts = []
        for axis, knots in ((0, ku), (1, kv)):
            lo, hi = min(a[axis], b[axis]), max(a[axis], b[axis])
            for k in knots[(knots > lo) & (knots < hi)]:
                s = (k - a[axis]) / (b[axis] - a[axis])
                q = a + s * (b - a)
                q[axis] = k
                cuts.append((s, q))
        pts.extend(q[None] for _, q in sorted(cuts, key=lambda c: c[0]))
    ring = np.concatenate(pts)
    span = max(float(np.ptp(rect[:, :2])), float(np.ptp(rect[:, 2:])))
    same = np.linalg.norm(ring - np.roll(ring, -1, axis=0), axis=1) <= 1e-14 * span  # repeated points: one
    if same.any() and not same.all():
        ring = ring[~same]
    if chord is None:
        return ring
    from .bezier import locate as _locate

    for _ in range(int(rounds)):
        a, b = ring, np.roll(ring, -1, axis=0)
        p, st = _locate(bs, f, 0.5 * (a + b))
        r = bs.rect[p]
        la = np.column_stack([(a[:, 0] - r[:, 0]) / (r[:, 1] - r[:, 0]), (a[:, 1] - r[:, 2]) / (r[:, 3] - r[:, 2])])
        lb = np.column_stack([(b[:, 0] - r[:, 0]) / (r[:, 1] - r[:, 0]), (b[:, 1] - r[:, 2]) / (r[:, 3] - r[:, 2])])
        d = lb - la
        n = np.column_stack([-d[:, 1], d[:, 0]])
        n *= np.where(np.einsum("ki,ki->k", n, 0.5 - st) < 0, -0.5, 0.5)[:, None]
        c = np.clip(st + n, 0.0, 1.0)
        Pw = np.stack([bs.control(int(i)) for i in p])
        with np.errstate(invalid="ignore", divide="ignore"):
            bound = triangle_bounds(Pw, np.stack([la, lb, c], axis=1))
        # segments down to 1e-9 of the domain: shorter ones are left (their chord is the surface to rounding)
        split = (bound > float(chord)) & (np.linalg.norm(b - a, axis=1) > 1e-9 * span)
        if ring.shape[0] + int(split.sum()) > 2_000_000:
            raise RuntimeError(f"surface {f}: splitting a trim polyline to the chord bound {chord:.3g} would pass "
                               "2,000,000 points; the trim lies where the surface bends too sharply for this delta")
        if not split.any():
            break
        mids = 0.5 * (a + b)
        out = np.empty((ring.shape[0] + int(split.sum()), 2))
        pos = np.arange(ring.shape[0]) + np.concatenate([[0], np.cumsum(split)[:-1]])
        out[pos] = ring
        out[pos[split] + 1] = mids[split]
        ring = out
    return ring


def trim_plan(bs, edges, rings: dict, delta_trim: float) -> TrimPlan:
    """What the trim polylines ``rings`` (:func:`face_rings`) do to each Bezier patch of ``bs`` (module
    docstring): wholly inside, crossed (its region in its local domain, and where the polylines cross its sides,
    as parameters along the edges), or wholly outside.

    >>> from splinevis.nurbs.exact import saddle, CIRCLE_KNOTS, circle_net
    >>> from splinevis.nurbs.model import NurbsModel, TrimCurve
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.lod.adjacency import find_edges
    >>> xy, w = circle_net()
    >>> border = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in [((0, 0), (1, 0)), ((1, 0), (1, 1)),
    ...                                                         ((1, 1), (0, 1)), ((0, 1), (0, 0))]]
    >>> m = NurbsModel([saddle()], trims=[[border, [TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.25 * xy, w)]]])
    >>> bs = bezier_set(m)
    >>> plan = trim_plan(bs, find_edges(bs), face_rings(bs, m.trims, 1e-3), 1e-3)
    >>> plan.status.tolist(), plan.edge_params, round(plan.local[0].area, 4)  # 1 - pi / 16
    ([1], {}, 0.8037)
    """
    import shapely

    P = len(bs)
    status = np.zeros(P, dtype=np.int64)
    local: list = [None] * P
    edge_params: dict = {}
    for f, (face, h) in rings.items():
        region = _region(face)
        shapely.prepare(region)
        for i in np.flatnonzero(bs.parent == f):
            u0, u1, v0, v1 = bs.rect[i]
            rect = shapely.box(u0, v0, u1, v1)
            if region.contains(rect):
                continue  # wholly inside (its border may lie on the region's)
            inter = shapely.intersection(region, rect)
            if inter.area <= 1e-12 * rect.area:  # overlay rounding leaves slivers along boundaries on knot lines
                status[i] = -1
                continue
            status[i] = 1
            # the region in the local domain, clipped to the unit square
            A = [1.0 / (u1 - u0), 0.0, 0.0, 1.0 / (v1 - v0), -u0 / (u1 - u0), -v0 / (v1 - v0)]
            loc = _polygonal(shapely.intersection(_affine(region, A), shapely.box(0.0, 0.0, 1.0, 1.0)))
            local[i] = loc
            lb = loc.boundary
            for k, (a, b) in enumerate(_SIDE_LINES):
                e = int(edges.side_edge[i, k])
                if e < 0:
                    continue
                pts = shapely.get_coordinates(shapely.intersection(lb, shapely.LineString([a, b])))
                t = pts[:, 0 if k in (0, 2) else 1] if pts.size else np.zeros(0)
                t = t[(t > _WELD) & (t < 1.0 - _WELD)]
                if t.size:
                    if edges.side_reversed[i, k]:
                        t = 1.0 - t
                    edge_params.setdefault(e, []).extend(t.tolist())
    edge_params = {e: np.unique(np.asarray(v)) for e, v in edge_params.items()}
    return TrimPlan(status, local, edge_params, float(delta_trim), {f: h for f, (_, h) in rings.items()})


def _affine(geom, A):
    from shapely import affinity

    return affinity.affine_transform(geom, A)


def merge_params(t, extra):
    """``t`` (a sorted chain) with ``extra`` parameters inserted, those within ``1e-11`` of a chain point or of
    each other dropped; returns the merged chain and a mask of the inserted points.

    >>> c, new = merge_params(np.array([0.0, 0.5, 1.0]), np.array([0.25, 0.5 + 1e-15]))
    >>> c.tolist(), new.tolist()
    ([0.0, 0.25, 0.5, 1.0], [False, True, False, False])
    """
    t = np.asarray(t, dtype=np.float64)
    keep = []
    for x in np.sort(np.asarray(extra, dtype=np.float64)):
        if np.abs(t - x).min() > _WELD and (not keep or x - keep[-1] > _WELD):
            keep.append(x)
    merged = np.concatenate([t, keep])
    order = np.argsort(merged, kind="stable")
    new = np.concatenate([np.zeros(t.size, dtype=bool), np.ones(len(keep), dtype=bool)])
    return merged[order], new[order]


def local_rings(rings, rect) -> list:
    """Polylines ``rings`` of a surface's domain in the local domain of the patch with ``rect`` (u0, u1, v0, v1).

    >>> local_rings([np.array([[1.0, 2.0], [3.0, 2.0]])], (1.0, 3.0, 2.0, 4.0))[0].tolist()
    [[0.0, 0.0], [1.0, 0.0]]
    """
    u0, u1, v0, v1 = (float(x) for x in rect)
    return [np.column_stack([(r[:, 0] - u0) / (u1 - u0), (r[:, 1] - v0) / (v1 - v0)]) for r in rings]

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

from .adaptive import Tessellation, _curve_chains
from .bounds import _curve_points_rows, patch_points, triangle_bounds

__all__ = ["TrimPlan", "trim_plan", "gradient_bound", "trim_polylines", "merge_params", "clip_tessellation", "clip_patch"]

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
            pts.append(_curve_points_rows(np.repeat(C[None], t.size - 1, axis=0), t[:-1]))
        ring = np.concatenate(pts)
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


def trim_plan(bs, edges, trims, delta_trim: float) -> TrimPlan:
    """The trim polylines of every trimmed surface at ``delta_trim`` and what they do to each Bezier patch of
    ``bs`` (module docstring). ``trims``: the model's per-surface loops (None: untrimmed).

    >>> from splinevis.nurbs.exact import saddle, CIRCLE_KNOTS, circle_net
    >>> from splinevis.nurbs.model import NurbsModel, TrimCurve
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.lod.adjacency import find_edges
    >>> xy, w = circle_net()
    >>> border = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in [((0, 0), (1, 0)), ((1, 0), (1, 1)),
    ...                                                         ((1, 1), (0, 1)), ((0, 1), (0, 0))]]
    >>> m = NurbsModel([saddle()], trims=[[border, [TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.25 * xy, w)]]])
    >>> bs = bezier_set(m)
    >>> plan = trim_plan(bs, find_edges(bs), m.trims, 1e-3)
    >>> plan.status.tolist(), plan.edge_params
    ([1], {})
    """
    import shapely

    P = len(bs)
    status = np.zeros(P, dtype=np.int64)
    local: list = [None] * P
    edge_params: dict = {}
    hs: dict = {}
    parents = np.unique(bs.parent[bs.trimmed]) if bs.trimmed.any() else np.zeros(0, dtype=np.int64)
    for f in parents:
        loops = trims[int(f)]
        ids = np.flatnonzero(bs.parent == f)
        lip = max(gradient_bound(bs.control(int(i)), bs.rect[i]) for i in ids)
        h = float(delta_trim) / max(lip, np.finfo(float).tiny)
        hs[int(f)] = h
        region = _region(trim_polylines(loops, h))
        shapely.prepare(region)
        for i in ids:
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
                hit = shapely.intersection(lb, shapely.LineString([a, b]))
                pts = shapely.get_coordinates(hit)
                run = 0 if k in (0, 2) else 1
                t = pts[:, run] if pts.size else np.zeros(0)
                t = t[(t > _WELD) & (t < 1.0 - _WELD)]
                if t.size:
                    if edges.side_reversed[i, k]:
                        t = 1.0 - t
                    edge_params.setdefault(e, []).extend(t.tolist())
    edge_params = {e: np.unique(np.asarray(v)) for e, v in edge_params.items()}
    return TrimPlan(status, local, edge_params, float(delta_trim), hs)


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


def clip_tessellation(tess: Tessellation, Pw, region, chains, target: float) -> Tessellation:
    """The tessellation ``tess`` of a patch (local domain) clipped to ``region`` (shapely, local domain): triangles
    the region's boundary meets are intersected with it and triangulated, their vertices on the patch's sides
    snapped to the side ``chains`` (4 sorted parameter arrays, as the patch sees them; a side vertex off its chain
    raises), T-junctions fanned. ``bound`` is each triangle's proven bound; ``converged`` is False when a piece's
    bound exceeds both ``target`` and the bound of the triangle it was cut from.

    >>> import shapely
    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.lod.adaptive import adaptive_tessellation
    >>> Pw = bezier_set(saddle()).control(0)
    >>> t = adaptive_tessellation(Pw, 0.05)
    >>> hole = shapely.box(0, 0, 1, 1).difference(shapely.Point(0.5, 0.5).buffer(0.2, 64))
    >>> c = clip_tessellation(t, Pw, hole, [[0.0, 1.0]] * 4, 0.05)
    >>> cen = c.uv[c.triangles].mean(axis=1)
    >>> bool((np.linalg.norm(cen - 0.5, axis=1) > 0.19).all()), c.converged, bool(c.bound.max() <= 0.05)
    (True, True, True)
    """
    import shapely

    uv, tri = tess.uv, tess.triangles
    polys = shapely.polygons(np.concatenate([uv[tri], uv[tri][:, :1]], axis=1))
    shapely.prepare(region)
    meets = shapely.intersects(polys, region.boundary)
    keep_whole = np.flatnonzero(~meets & shapely.intersects(polys, region))  # wholly inside
    cut = np.flatnonzero(meets)
    tris, parent = shapely.get_parts(shapely.constrained_delaunay_triangles(shapely.intersection(polys[cut], region)),
                                     return_index=True)
    ok = (shapely.get_type_id(tris) == 3) & (shapely.area(tris) > 0) if tris.size else np.zeros(0, dtype=bool)
    tris, parent = tris[ok], cut[parent[ok]]
    coords = shapely.get_coordinates(tris).reshape(-1, 4, 2)[:, :3] if tris.size else np.zeros((0, 3, 2))
    P, index = _weld(uv, coords.reshape(-1, 2), chains)
    piece = index.reshape(-1, 3)
    allowed = np.maximum(float(target), tess.bound)  # what each triangle of tess was accepted with
    all_tri = np.concatenate([tri[keep_whole], piece])
    origin = np.concatenate([keep_whole, parent])
    A = _signed_area(P[all_tri])
    all_tri, origin, A = all_tri[A != 0.0], origin[A != 0.0], A[A != 0.0]
    all_tri[A < 0] = all_tri[A < 0][:, ::-1]
    all_tri, origin = _fan_t_junctions(P, all_tri, origin, np.unique(piece))
    used = np.unique(all_tri)
    remap = np.full(P.shape[0], -1, dtype=np.int64)
    remap[used] = np.arange(used.size)
    out_uv, out_tri = P[used], remap[all_tri]
    X = patch_points(Pw, out_uv)
    bound = triangle_bounds(Pw, out_uv[out_tri], X[out_tri]) if out_tri.size else np.zeros(0)
    # a piece that is its whole triangle (listed in another vertex order) differs in the last bits of its bound
    return Tessellation(out_uv, out_tri, bound, dict(tess.limits),
                        bool(tess.converged and (bound <= allowed[origin] * (1.0 + 1e-9)).all()))


def _signed_area(T):
    e1, e2 = T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]
    return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


def _weld(uv, new, chains) -> tuple:
    """Points ``new (N, 2)`` as vertex ids ``(points, index)``: an existing vertex of ``uv`` within ``_WELD``, else
    a side chain point (snapped exactly), else one new vertex per cluster of points within ``_WELD``."""
    from scipy.spatial import cKDTree

    index = np.full(new.shape[0], -1, dtype=np.int64)
    if new.size == 0:
        return uv, index
    d, j = cKDTree(uv).query(new, distance_upper_bound=_WELD)
    hit = np.isfinite(d)
    index[hit] = j[hit]
    rest = np.flatnonzero(~hit)
    q = new[rest].copy()
    # snap to the sides: a point within _WELD of a side lies on it, at a chain point
    for k, (axis, value, run) in enumerate(((1, 0.0, 0), (0, 1.0, 1), (1, 1.0, 0), (0, 0.0, 1))):
        on = np.abs(q[:, axis] - value) <= _WELD
        if on.any():
            c = np.asarray(chains[k], dtype=np.float64)
            pos = np.clip(np.searchsorted(c, q[on, run]), 1, c.size - 1)
            near = np.where(np.abs(c[pos - 1] - q[on, run]) <= np.abs(c[pos] - q[on, run]), c[pos - 1], c[pos])
            if (np.abs(near - q[on, run]) > 1e-9).any():
                bad = q[on][np.argmax(np.abs(near - q[on, run]))]
                raise RuntimeError(f"a trim vertex {bad.tolist()} lies on side {k} of the patch but not at a point of "
                                   "its chain: the chains must hold every trim crossing (a crack otherwise)")
            q[np.flatnonzero(on), run] = near
            q[np.flatnonzero(on), axis] = value
    # exact side points may now equal existing vertices
    if rest.size:
        d2, j2 = cKDTree(uv).query(q, distance_upper_bound=1e-15)
        same = np.isfinite(d2)
        index[rest[same]] = j2[same]
        rest, q = rest[~same], q[~same]
    if rest.size:
        pairs = cKDTree(q).query_pairs(_WELD, output_type="ndarray")
        root = np.arange(q.shape[0])
        for a, b in pairs[np.argsort(pairs[:, 0])] if pairs.size else ():
            ra, rb = _find(root, a), _find(root, b)
            if ra != rb:
                root[max(ra, rb)] = min(ra, rb)
        root = np.array([_find(root, k) for k in range(q.shape[0])])
        reps, inv = np.unique(root, return_inverse=True)
        index[rest] = uv.shape[0] + inv
        uv = np.concatenate([uv, q[reps]])
    return uv, index


def _find(root, a):
    while root[a] != a:
        root[a] = root[root[a]]
        a = root[a]
    return a


def _fan_t_junctions(P, tri, origin, candidates):
    """Split triangles having a ``candidates`` vertex strictly inside one of their sides (a fan through it),
    until none has; ``origin`` follows the pieces."""
    cand = np.asarray(candidates, dtype=np.int64)
    for _ in range(64):
        if cand.size == 0 or tri.size == 0:
            return tri, origin
        T = P[tri]  # (N, 3, 2)
        a = T
        e = np.roll(T, -1, axis=1) - T  # side k from vertex k to k + 1
        L2 = np.einsum("nki,nki->nk", e, e)
        rel = P[cand][None, None, :, :] - a[:, :, None, :]  # (N, 3, C, 2)
        s = np.einsum("nkci,nki->nkc", rel, e)
        cross = e[:, :, None, 0] * rel[..., 1] - e[:, :, None, 1] * rel[..., 0]
        on = (np.abs(cross) <= 1e-12 * L2[..., None]) & (s > 1e-12 * L2[..., None]) & (s < (1 - 1e-12) * L2[..., None])
        on &= (cand[None, None, :] != tri[:, :, None]).all(axis=1, keepdims=True)
        hit = on.any(axis=2)
        rows = np.flatnonzero(hit.any(axis=1))
        if rows.size == 0:
            return tri, origin
        k = np.argmax(hit[rows], axis=1)
        sk = np.where(on[rows, k], s[rows, k], np.inf)
        c = cand[np.argmin(sk, axis=1)]  # the point nearest the side's start
        v = tri[rows]
        p, q, r = v[np.arange(rows.size), k], v[np.arange(rows.size), (k + 1) % 3], v[np.arange(rows.size), (k + 2) % 3]
        keep = np.ones(tri.shape[0], dtype=bool)
        keep[rows] = False
        tri = np.concatenate([tri[keep], np.column_stack([p, c, r]), np.column_stack([c, q, r])])
        origin = np.concatenate([origin[keep], origin[rows], origin[rows]])
    raise RuntimeError("T-junction fanning did not settle after 64 rounds")


def clip_patch(Pw, region, chains, target: float, tess: Tessellation, retries: int = 3) -> Tessellation:
    """:func:`clip_tessellation` of a crossed patch's tessellation ``tess`` (made with ``chains`` at ``target``);
    where a piece's proven bound exceeds what its triangle was accepted with, the patch is tessellated again at
    half the target (same chains) and clipped again, up to ``retries`` times (``converged`` says if it held).

    >>> import shapely
    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.lod.adaptive import adaptive_tessellation
    >>> Pw = bezier_set(saddle()).control(0)
    >>> half = shapely.box(0.0, 0.0, 0.6, 1.0)
    >>> c = clip_patch(Pw, half, [[0.0, 0.6, 1.0], [0.0, 1.0], [0.0, 0.6, 1.0], [0.0, 1.0]], 0.02,
    ...                adaptive_tessellation(Pw, 0.02, [[0.0, 0.6, 1.0], None, [0.0, 0.6, 1.0], None]))
    >>> c.converged, bool(c.uv[:, 0].max() == 0.6)
    (True, True)
    """
    from .adaptive import adaptive_tessellation

    out = clip_tessellation(tess, Pw, region, chains, target)
    t = float(target)
    for _ in range(int(retries)):
        if out.converged:
            break
        t *= 0.5
        again = adaptive_tessellation(Pw, t, chains)
        out = clip_tessellation(again, Pw, region, chains, float(target))
    return out

"""A patch's tessellation cut to its trim polylines by a constrained Delaunay triangulation [Kumar1997, sec. 4.1].

The adaptive tessellation of a crossed patch (:mod:`.adaptive`, with its sides' chains) is cut to the region of
its trims (:mod:`.trims`) so that the trim polylines are edges of the mesh, exactly, vertex for vertex:

1. triangles the polylines do not meet are kept whole where they lie inside the region (all three of their
   edges become constraints, so the triangulation keeps them), or dropped outside it;
2. the band of triangles the polylines meet is triangulated anew: the constrained Delaunay triangulation
   (PythonCDT, the CDT library [Amirkhanov2026]) of the kept triangles' edges, the polylines' pieces inside the
   patch (their ends on the patch's sides snapped to the sides' chains) and the sides' chain segments, with the
   band's own vertices inside the region; triangles whose centroid lies outside the region are dropped;
3. each new triangle's proven bound (:func:`~splinevis.nurbs.lod.bounds.triangle_bounds`) is held to the larger
   of the target and the bound of the band triangle it lies in: where it is not, its centroid is added and the
   band triangulated again.

So the mesh's border along a trim is the polyline itself, with no other vertex: a surface stitched to it
(:mod:`.stitch`) that has the same polyline vertices meets it without a crack. Vertices on the patch's sides
are chain points, shared with the neighbour.

Why our own code: the triangulation is the CDT library's; no library cuts a bounded tessellation to trims while
keeping shared chains.
"""

from __future__ import annotations

import re

import numpy as np

from .adaptive import Tessellation
from .bounds import patch_points, triangle_bounds

__all__ = ["clip_tessellation", "clip_patch", "ring_pieces"]

_WELD = 1e-11  # local-domain distance under which two computed points are one vertex
_SIDES = ((1, 0.0, 0), (0, 1.0, 1), (1, 1.0, 0), (0, 0.0, 1))  # side k: fixed axis, its value, running axis


def _snap_sides(q, chains):
    """Points within ``_WELD`` of a side put on it exactly, at the nearest point of its chain (which must be
    within ``1e-9``: a trim crossing a side is a chain point, else the neighbour would not share it)."""
    q = np.array(q, dtype=np.float64).reshape(-1, 2)
    for k, (axis, value, run) in enumerate(_SIDES):
        on = np.flatnonzero(np.abs(q[:, axis] - value) <= _WELD)
        if on.size:
            c = np.asarray(chains[k], dtype=np.float64)
            pos = np.clip(np.searchsorted(c, q[on, run]), 1, c.size - 1)
            near = np.where(np.abs(c[pos - 1] - q[on, run]) <= np.abs(c[pos] - q[on, run]), c[pos - 1], c[pos])
            bad = np.abs(near - q[on, run]) > 1e-9
            if bad.any():
                x = q[on[np.argmax(bad)]]
                raise RuntimeError(f"a trim point {x.tolist()} lies on side {k} of the patch but not at a point of its "
                                   "chain: the chains must hold every trim crossing (a crack otherwise)")
            q[on, run], q[on, axis] = near, value
    return q


def ring_pieces(rings, chains) -> list:
    """The parts ``(M, 2)`` of closed polylines ``rings`` (local domain) inside the unit square, their ends on
    the sides snapped to the ``chains``; parts lying along a side are left out (the side's chain is the border
    there).

    >>> ring = np.array([[0.5, -0.2], [1.2, 0.5], [0.5, 1.2], [-0.2, 0.5]])  # a diamond cutting the corners off
    >>> [np.round(p, 12).tolist() for p in ring_pieces([ring], [[0.0, 0.3, 0.7, 1.0]] * 4)][:2]
    [[[0.0, 0.3], [0.3, 0.0]], [[0.3, 1.0], [0.0, 0.7]]]
    """
    import shapely

    square = shapely.box(0.0, 0.0, 1.0, 1.0)
    out = []
    for ring in rings:
        line = shapely.LineString(np.vstack([ring, ring[:1]]))
        for part in shapely.get_parts(shapely.line_merge(shapely.intersection(line, square))):
            if shapely.get_type_id(part) != 1:
                continue
            P = shapely.get_coordinates(part)
            near = [np.abs(P[:, axis] - value) <= _WELD for axis, value, _ in _SIDES]
            along = np.zeros(P.shape[0] - 1, dtype=bool)  # segments lying on a side: the side's chain is there
            for on in near:
                along |= on[:-1] & on[1:]
            start = 0
            for k in list(np.flatnonzero(along)) + [P.shape[0] - 1]:
                run = P[start:k + 1]
                start = k + 1
                if run.shape[0] < 2:
                    continue
                run = _snap_sides(run, chains)
                run = run[np.concatenate([[True], np.linalg.norm(np.diff(run, axis=0), axis=1) > 0])]
                if run.shape[0] >= 2:
                    out.append(run)
    return out


def _unique_points(P):
    """Indices ``(N,)`` mapping each point to the first one within ``1e-12``, and the unique rows."""
    from scipy.spatial import cKDTree

    if P.shape[0] == 0:
        return np.zeros(0, dtype=np.int64), P
    pairs = cKDTree(P).query_pairs(1e-12, output_type="ndarray")
    root = np.arange(P.shape[0])
    for a, b in sorted(map(tuple, pairs)) if pairs.size else ():
        ra, rb = root[a], root[b]
        while root[ra] != ra:
            ra = root[ra]
        while root[rb] != rb:
            rb = root[rb]
        if ra != rb:
            root[max(ra, rb)] = min(ra, rb)
    for k in range(P.shape[0]):
        r = k
        while root[r] != r:
            r = root[r]
        root[k] = r
    reps, inv = np.unique(root, return_inverse=True)
    return inv, P[reps]


def _cdt(points, edges):
    import pythoncdt as cdt

    t = cdt.Triangulation(cdt.VertexInsertionOrder.AS_PROVIDED, cdt.IntersectingConstraintEdges.TRY_RESOLVE, 0.0)
    t.insert_vertices(np.ascontiguousarray(points, dtype=np.float64))
    if len(edges):
        t.insert_edges(np.ascontiguousarray(edges, dtype=np.uintc))
    t.erase_super_triangle()
    v = t.vertices_array()
    return np.column_stack([v["x"], v["y"]]), np.asarray(t.triangles_array()["vertices"], dtype=np.int64)


def clip_tessellation(tess: Tessellation, Pw, region, chains, target: float, rings=None,
                      rounds: int = 8) -> Tessellation:
    """The tessellation ``tess`` of a patch (local domain) cut to ``region`` (shapely, local domain) whose trim
    polylines are ``rings`` (closed ``(K, 2)`` in the local domain; default: the region's boundary) by the
    method of the module docstring; ``chains``: the 4 sides' chains as the patch sees them. ``converged`` is
    False when a new triangle's bound stays above what it may have after ``rounds`` refinements.

    >>> import shapely
    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.lod.adaptive import adaptive_tessellation
    >>> Pw = bezier_set(saddle()).control(0)
    >>> t = adaptive_tessellation(Pw, 0.05)
    >>> a = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    >>> ring = 0.5 + 0.2 * np.column_stack([np.cos(a), np.sin(a)])
    >>> hole = shapely.box(0, 0, 1, 1).difference(shapely.Polygon(ring))
    >>> c = clip_tessellation(t, Pw, hole, [[0.0, 1.0]] * 4, 0.05, rings=[ring])
    >>> cen = c.uv[c.triangles].mean(axis=1)
    >>> bool((np.linalg.norm(cen - 0.5, axis=1) > 0.19).all()), c.converged, bool(c.bound.max() <= 0.05)
    (True, True, True)
    >>> e = np.sort(np.concatenate([c.triangles[:, [0, 1]], c.triangles[:, [1, 2]], c.triangles[:, [2, 0]]]), axis=1)
    >>> u, n = np.unique(e, axis=0, return_counts=True)
    >>> inner = u[n == 1][np.linalg.norm(c.uv[u[n == 1]].mean(axis=1) - 0.5, axis=1) < 0.3]
    >>> inner.shape[0], bool(np.isin(c.uv[inner].reshape(-1, 2), ring).all(axis=1).all())  # the hole: its 64 chords
    (64, True)
    """
    import shapely

    if rings is None:
        rings = [shapely.get_coordinates(r)[:-1] for r in shapely.get_rings(region)]
    uv, tri = tess.uv, tess.triangles
    polys = shapely.polygons(np.concatenate([uv[tri], uv[tri][:, :1]], axis=1))
    pieces = ring_pieces(rings, chains)
    lines = shapely.multilinestrings([shapely.LineString(p) for p in pieces]) if pieces else None
    meets = shapely.intersects(polys, lines) if lines is not None else np.zeros(len(tri), dtype=bool)
    cen = uv[tri].mean(axis=1)
    shapely.prepare(region)
    whole = np.flatnonzero(~meets & shapely.contains_xy(region, cen[:, 0], cen[:, 1]))
    band = np.flatnonzero(meets)
    # the band's own vertices inside the region, off the polylines (a vertex on a side is a chain point: kept)
    bv = np.setdiff1d(np.unique(tri[band]), np.unique(tri[whole]))
    q = uv[bv]
    on_side = (q[:, 0] == 0.0) | (q[:, 0] == 1.0) | (q[:, 1] == 0.0) | (q[:, 1] == 1.0)
    off_line = shapely.distance(shapely.points(q), lines) > 1e-9 if lines is not None else np.ones(len(q), dtype=bool)
    # in the region or on its border (within rounding: the region was mapped to the patch's domain)
    keep = shapely.dwithin(region, shapely.points(q), 1e-12) & (on_side | off_line)
    base = np.concatenate([np.unique(tri[whole]), bv[keep]])
    ring_pts = np.concatenate(pieces) if pieces else np.zeros((0, 2))
    allowed_t = np.maximum(float(target), tess.bound)
    tree = shapely.STRtree(polys[band]) if band.size else None
    extra = np.zeros((0, 2))
    refined = retried = 0
    while True:
        inv, P = _unique_points(np.concatenate([uv[base], ring_pts, extra]))
        gid = np.full(uv.shape[0], -1, dtype=np.int64)
        gid[base] = inv[:base.size]
        edges = [np.sort(gid[tri[whole]][:, [a, b]], axis=1) for a, b in ((0, 1), (1, 2), (2, 0))]
        off = base.size
        for p in pieces:
            ids = inv[off:off + len(p)]
            edges.append(np.column_stack([ids[:-1], ids[1:]]))
            off += len(p)
        for k, (axis, value, run) in enumerate(_SIDES):  # the sides' chain segments between vertices in use
            at = np.flatnonzero(P[:, axis] == value)
            at = at[np.argsort(P[at, run])]
            c = np.asarray(chains[k], dtype=np.float64)
            seg = np.column_stack([at[:-1], at[1:]])
            ok = np.isin(P[at[:-1], run], c) & np.isin(P[at[1:], run], c)
            edges.append(seg[ok])
        E = np.unique(np.sort(np.concatenate(edges), axis=1), axis=0)
        E = E[E[:, 0] != E[:, 1]]
        try:
            V, T = _cdt(P, E)
        except RuntimeError as err:  # kept triangles of the tessellation that cross (a sliver folded by rounding)
            named = [tuple(map(int, m)) for m in re.findall(r"\((\d+), (\d+)\)", str(err))]
            g = gid[tri[whole]]
            hit = np.zeros(whole.size, dtype=bool)
            for a, b in named:
                hit |= (g == a).any(axis=1) & (g == b).any(axis=1)
            if not hit.any() or retried >= 64:
                raise
            band, whole = np.concatenate([band, whole[hit]]), whole[~hit]  # triangulated anew instead
            tree = shapely.STRtree(polys[band])
            retried += 1
            continue
        c2 = V[T].mean(axis=1)
        T = T[shapely.contains_xy(region, c2[:, 0], c2[:, 1])]
        keys = [tuple(sorted(t)) for t in T.tolist()]
        gmap = {tuple(sorted(g)): n for n, g in enumerate(gid[tri[whole]].tolist())}
        is_whole = np.array([k in gmap for k in keys], dtype=bool)
        X = patch_points(Pw, V)
        bound = triangle_bounds(Pw, V[T], X[T]) if T.size else np.zeros(0)
        allowed = np.full(T.shape[0], float(target))
        allowed[is_whole] = allowed_t[whole[[gmap[k] for k, w in zip(keys, is_whole) if w]]]
        new = np.flatnonzero(~is_whole)
        if new.size and tree is not None:
            c3 = V[T[new]].mean(axis=1)
            hit_pt, hit_poly = tree.query(shapely.points(c3), predicate="intersects")
            best = np.full(new.size, float(target))
            np.maximum.at(best, hit_pt, allowed_t[band[hit_poly]])
            allowed[new] = best
        over = np.flatnonzero(bound > allowed * (1.0 + 1e-9))
        if over.size == 0 or refined >= int(rounds):
            break
        refined += 1
        extra = np.concatenate([extra, V[T[over]].mean(axis=1)])
    return Tessellation(V, T, bound, dict(tess.limits), bool(tess.converged and over.size == 0))


def clip_patch(Pw, region, chains, target: float, tess: Tessellation, rings=None, retries: int = 3) -> Tessellation:
    """:func:`clip_tessellation` of a crossed patch's tessellation ``tess`` (made with ``chains`` at ``target``);
    if it does not converge the patch is tessellated again at half the target (same chains) and cut again, up
    to ``retries`` times (``converged`` says if it held).

    >>> import shapely
    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.lod.adaptive import adaptive_tessellation
    >>> Pw = bezier_set(saddle()).control(0)
    >>> half = shapely.box(0.0, 0.0, 0.6, 1.0)
    >>> chains = [[0.0, 0.3, 0.6, 1.0], [0.0, 1.0], [0.0, 0.3, 0.6, 1.0], [0.0, 1.0]]
    >>> t = adaptive_tessellation(Pw, 0.02, [chains[0], None, chains[2], None])
    >>> from splinevis.nurbs.lod.trims import split_segments
    >>> ring = split_segments(bezier_set(saddle()), 0, np.array([[0.6, 0], [0.6, 1], [0, 1], [0, 0.0]]), chord=0.01)
    >>> c = clip_patch(Pw, half, chains, 0.02, t, rings=[ring])
    >>> c.converged, bool(c.uv[:, 0].max() == 0.6)
    (True, True)
    """
    from .adaptive import adaptive_tessellation

    out = clip_tessellation(tess, Pw, region, chains, target, rings)
    t = float(target)
    for _ in range(int(retries)):
        if out.converged:
            break
        t *= 0.5
        out = clip_tessellation(adaptive_tessellation(Pw, t, chains), Pw, region, chains, float(target), rings)
    return out

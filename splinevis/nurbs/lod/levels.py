"""Levels of detail of a NURBS model, each with a proven deviation bound, assembled without cracks at any
combination of levels [Kumar1997, sec. 4].

Construction (:func:`build_lod`)
--------------------------------
1. The model's Bezier patches (:mod:`.bezier`), their shared sides (:mod:`.adjacency`), per-patch normal cones
   of the pseudo-Gauss map and the super-surfaces grown under the span bound ``alpha`` (:mod:`.gauss`), a BVH
   over the super-surfaces' boxes (:mod:`.bvh`).
2. Level ``l`` has the tolerance ``delta_l = delta * ratio**l`` (level 0 the finest).
3. **Edges are tessellated once for both sides.** Every edge (a boundary curve shared by two patches, or an
   open one) gets its chain of parameters at each level from :func:`.adaptive.curve_chain` on the edge's first
   side. The chains are *nested*: a segment is split where its sampled chord deviation is largest, and that
   point depends on the segment only, so the chain for a smaller tolerance refines the chain for a larger one
   (``chain(delta_k) ⊇ chain(delta_l)`` for ``k < l``). Each point of the finest chain is one vertex of the
   model, evaluated once from the edge's curve; its *birth* is the coarsest level whose chain holds it.
   Patch corners are clustered (:func:`.adjacency.cluster_points`) so the patches meeting at a corner share
   one vertex, poles included.
4. Each patch of a super-surface is tessellated at level ``l`` by :func:`.adaptive.adaptive_tessellation` with
   its four sides' chains at level ``l`` fixed (never split), so every triangle's proven bound is at most
   ``delta_l``, and the patch's boundary vertices are the edges' shared vertices.

Assembly (:func:`assemble`)
---------------------------
Given a level per super-surface (or -1: not drawn), every edge between two super-surfaces drawn at levels
``k < l`` is drawn at the finer ``k`` (the paper picks the smaller of the two errors for a boundary curve,
sec. 4.2). The coarser side's triangles along that edge are split into fans at the extra chain points: a
triangle ``(a, b, c)`` whose side ``a b`` lies on the edge becomes ``(a, x_1, c), (x_1, x_2, c), ...,
(x_k, b, c)``. In the patch's parameter domain the chain points lie on the straight side between ``a`` and
``b``, so the fan partitions the old domain triangle; each new triangle lies in the old one's smallest
enclosing disc, so the old triangle's proven bound (``1/2 R^2 max |D^2_d F|`` [Waldron1998]) holds for every
piece. Every vertex on a drawn edge is then used by both sides: no T-junction, no crack, at every combination
of levels (tested by vertices and by pixels).

Normals: every vertex carries the exact unit normal of one patch (:func:`vertex_normals`); the angle between the
interpolated normals of each level and the surface's is bounded per super-surface and level
(``LodModel.normal_bounds``, :mod:`splinevis.nurbs.normal_bounds`, the seams and fans included).
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from .adaptive import _check_chains, _curve_chains, _tessellate, curve_chain
from .adjacency import Edges, cluster_points, find_edges
from .bezier import BezierSet, bezier_set
from .bounds import curve_points, patch_points, side_net
from .bvh import BVH, build_bvh
from .gauss import SuperSurfaces, grow_super_surfaces, normal_cone, pseudo_gauss_net

__all__ = ["LodModel", "build_lod", "assemble", "vertex_normals"]

_CORNER_UV = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
# the corners at the ends of each side (in the side's increasing parameter): side k runs from
# _SIDE_ENDS[k][0] to _SIDE_ENDS[k][1] (corner numbers as _CORNER_UV)
_SIDE_ENDS = ((0, 1), (1, 2), (3, 2), (0, 3))
_BATCH = 512  # patches tessellated together (lockstep): fewer array operations, bounded memory


@dataclasses.dataclass(frozen=True, eq=False)
class LodModel:
    """A model's levels of detail (build with :func:`build_lod`; draw with :func:`assemble`).

    Attributes
    ----------
    bezier, edges, supers, bvh
        The Bezier patches, their edges, the super-surfaces (``supers.labels (P,)``, cones ``axis``,
        ``half_angle``, ``members``) and the BVH over ``boxes``.
    boxes : (S, 6) array
        Each super-surface's box ``(xmin, xmax, ymin, ymax, zmin, zmax)`` (from control points: it holds
        the surface and every level's mesh, whose vertices lie on the surface).
    tolerance : (L,) array
        The bound of each level, finest first: ``delta * ratio**l`` (proven), plus ``eps_l`` where the level
        was simplified (held by measurement; ``simplified`` has the measured distances).
    triangles : (S, L) int array
        Triangle count of each super-surface's level (before the fans of the assembly).
    size : float
        The model's diagonal.
    vertices : (V, 3) array
        Every shared vertex (corners and edge chains at the finest level) then every patch-interior vertex.
    normal_bounds : (S, L) array
        Radians: the proven angle between the normals each super-surface's level shades with (``normals``,
        interpolated) and the surface's (:func:`splinevis.nurbs.normal_bounds.lod_normal_bounds`); inf where none
        holds (a crease, a simplified level, trimmed patches).

    Examples
    --------
    >>> from splinevis.nurbs.exact import sphere
    >>> lod = build_lod(sphere(), 0.05, levels=2, progress=False)
    >>> len(lod.bezier), len(lod.supers.members), lod.triangles.shape
    (8, 8, (8, 2))
    """

    bezier: BezierSet
    edges: Edges
    supers: SuperSurfaces
    bvh: BVH
    boxes: np.ndarray
    tolerance: np.ndarray
    triangles: np.ndarray
    size: float
    vertices: np.ndarray
    edge_ids: tuple  # per edge: global vertex ids of its finest chain
    edge_birth: tuple  # per edge: coarsest level holding each chain point
    meshes: tuple  # [s][l]: (triangles (T, 3) global ids, fan rows (F, 5): tri, edge, a, b, position of c)
    super_edges: tuple  # per super-surface: the edges on its border shared with another super-surface
    simplified: np.ndarray  # (S, L) measured distance added by simplification (0: not simplified)
    normals: np.ndarray = None  # (V, 3) the surface's unit normal S_u x S_v at every vertex (vertex_normals)
    delta_trim: float = 0.0  # the share of each level's bound taken by the trim polylines (0: no trims)
    vertex_patch: np.ndarray = None  # (V,) a Bezier patch each vertex lies on (a shared one: the edge's first side)
    vertex_uv: np.ndarray = None  # (V, 2) its local parameters there
    trims: tuple = None  # per surface of the model: its trim loops (TrimCurve lists) or None
    status: np.ndarray = None  # (P,) per Bezier patch: 0 untrimmed or inside its trims, 1 clipped, -1 trimmed away
    normal_bounds: np.ndarray = None  # (S, L) radians: the shading normals' proven angle to the surface's (inf: none)

    @property
    def levels(self) -> int:
        """Number of levels.

        >>> from splinevis.nurbs.exact import sphere
        >>> build_lod(sphere(), 0.05, levels=2, progress=False).levels
        2
        """
        return int(self.tolerance.size)


def _patch_cones(bs: BezierSet):
    axis = np.zeros((len(bs), 3))
    half = np.full(len(bs), np.pi)
    for g in bs.groups:
        G = pseudo_gauss_net(g.control)
        a, h = normal_cone(G.reshape(len(g), -1, 3))
        axis[g.ids], half[g.ids] = a, h
    return axis, half


def _neighbours(edges: Edges) -> np.ndarray:
    mate = edges.mate
    return np.where(mate >= 0, mate // 4, -1)


def _corner_labels(bs, edges):
    """``(P, 4)`` one label per cluster of patch corners (corner order as ``_CORNER_UV``) and the points."""
    P = len(bs)
    corners = np.empty((P, 4, 3))
    for g in bs.groups:
        C = g.control
        for k, (i, j) in enumerate(((0, 0), (-1, 0), (-1, -1), (0, -1))):
            corners[g.ids, k] = C[:, i, j, :3] / C[:, i, j, 3:]
    return cluster_points(corners.reshape(-1, 3), edges.tol).reshape(P, 4), corners


def _edge_chains(bs, edges, deltas, corner_label):
    """Per edge: the finest chain (parameters along the edge's first side) and each point's birth level.

    Two edges between the same two corners (the two halves of a handle's ring) would both be one chord where
    their chains are just the end points: a fold. Such an edge keeps, at every level, the point its first
    split puts in (the split of [0, 1] at the largest sampled deviation, which every finer chain holds)."""
    from .bounds import curve_chord_bounds

    ends = np.empty((len(edges), 2), dtype=np.int64)
    for e in range(len(edges)):
        f = int(edges.edge_side[e])
        ends[e] = sorted(corner_label[f // 4, list(_SIDE_ENDS[f % 4])])
    _, inv, n = np.unique(ends, axis=0, return_inverse=True, return_counts=True)
    twin = n[inv.ravel()] > 1
    out_t, out_birth = [], []
    nets = [side_net(bs.control(int(f) // 4), int(f) % 4) for f in edges.edge_side[:len(edges)]]
    L = deltas.size
    level_chains = [None] * len(edges)
    by_shape: dict = {}
    for e, net in enumerate(nets):
        by_shape.setdefault(net.shape, []).append(e)
    for group in by_shape.values():  # every edge at every level at once (bitwise the chains of curve_chain)
        got = _curve_chains(np.repeat(np.stack([nets[e] for e in group]), L, axis=0), np.tile(deltas, len(group)))
        for n, e in enumerate(group):
            level_chains[e] = got[n * L:(n + 1) * L]
    for e in range(len(edges)):
        net = nets[e]
        t = level_chains[e][0]
        birth = np.zeros(t.size, dtype=np.int64)
        for level in range(1, deltas.size):
            birth[np.isin(t, level_chains[e][level])] = level
        if twin[e] and t.size > 2:
            first = curve_chain(net, 0.99 * float(curve_chord_bounds(net, np.array([0.0, 1.0]))[0]))
            birth[np.isin(t, first)] = deltas.size - 1
        out_t.append(t)
        out_birth.append(birth)
    return out_t, out_birth


def _shared_vertices(bs, edges, chains, label, corners):
    """Global vertices: corner clusters, then every edge's interior chain points (evaluated once, from the
    edge's first side). Returns points and per edge the global ids of its chain."""
    n_corner = int(label.max()) + 1 if label.size else 0
    points = [np.zeros((n_corner, 3))]
    points[0][label.ravel()] = corners.reshape(-1, 3)  # one representative per cluster
    # where each vertex is on the surface, (patch, u, v): for normals
    first = np.unique(label.ravel(), return_index=True)[1]
    where = [(first // 4, _CORNER_UV[first % 4])]
    ids, next_id = [], n_corner
    for e, t in enumerate(chains):
        f = int(edges.edge_side[e])
        i, k = divmod(f, 4)
        a, b = label[i, _SIDE_ENDS[k][0]], label[i, _SIDE_ENDS[k][1]]
        inner = curve_points(side_net(bs.control(i), k), t[1:-1])
        ids.append(np.concatenate([[a], next_id + np.arange(t.size - 2), [b]]).astype(np.int64))
        points.append(inner)
        tt = t[1:-1]
        uv = np.column_stack([tt, np.zeros_like(tt)] if k == 0 else [np.ones_like(tt), tt] if k == 1 else
                             [tt, np.ones_like(tt)] if k == 2 else [np.zeros_like(tt), tt])
        where.append((np.full(tt.size, i), uv))
        next_id += t.size - 2
    return np.concatenate(points), ids, where


def _patch_sides(edges, i, level, chains, births, edge_ids, corner_label):
    """The chains (parameters along each side) of patch ``i`` at ``level`` and their global vertex ids."""
    side_chain, side_ids = [], []
    for k in range(4):
        e = int(edges.side_edge[i, k])
        if e < 0:  # collapsed (a pole): its two ends are one corner vertex
            side_chain.append(np.array([0.0, 1.0]))
            side_ids.append(np.array([corner_label[i, _SIDE_ENDS[k][0]], corner_label[i, _SIDE_ENDS[k][1]]]))
            continue
        keep = births[e] >= level
        t, g = chains[e][keep], edge_ids[e][keep]
        if edges.side_reversed[i, k]:
            t, g = 1.0 - t[::-1], g[::-1]
        side_chain.append(t)
        side_ids.append(g)
    return side_chain, side_ids


def _patch_finish(bs, edges, i, tess, side_chain, side_ids, next_id, fixed=None, joins=None, kept=None):
    """The tessellation ``tess`` of patch ``i`` in global ids: (new interior points, triangles, next free id).
    ``fixed``: a global id for some vertices (stitched trim vertices, :mod:`.stitch`), -1 elsewhere; where such a
    vertex lies on a side, the pair (its id, the chain vertex's id) is appended to ``joins``; ``kept``: a list the
    local triangles kept (not degenerate at a pole) are appended to."""
    Pw = bs.control(i)
    uv = tess.uv
    gid = np.full(uv.shape[0], -1, dtype=np.int64) if fixed is None else np.array(fixed, dtype=np.int64)
    on_side = ((uv[:, 1] == 0.0), (uv[:, 0] == 1.0), (uv[:, 1] == 1.0), (uv[:, 0] == 0.0))
    along = (uv[:, 0], uv[:, 1], uv[:, 0], uv[:, 1])
    for k in range(4):
        rows = np.flatnonzero(on_side[k])
        if edges.side_edge[i, k] < 0:  # a pole: every vertex on the side is the one pole vertex
            gid[rows] = side_ids[k][0]
            continue
        pos = np.searchsorted(side_chain[k], along[k][rows])
        pos = np.clip(pos, 0, side_chain[k].size - 1)
        if not np.array_equal(side_chain[k][pos], along[k][rows]):
            raise RuntimeError(f"patch {i} side {k}: a boundary vertex off its chain (the tessellation must keep "
                               "given chains exactly)")
        gid[rows] = side_ids[k][pos]
    if fixed is not None:  # a stitched trim vertex on a side (a knot-line crossing) is that side's chain vertex
        both = np.flatnonzero((np.asarray(fixed) >= 0) & (gid != np.asarray(fixed)))
        joins.extend(zip(np.asarray(fixed)[both].tolist(), gid[both].tolist()))
    inner = np.flatnonzero(gid < 0)
    gid[inner] = next_id + np.arange(inner.size)
    new_points = patch_points(Pw, uv[inner]) if inner.size else np.zeros((0, 3))
    tri = gid[tess.triangles]
    # a triangle with two corners on a pole's side has two vertices that are the one pole vertex: no area
    keep = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 2] != tri[:, 0])
    if kept is not None:
        kept.append(tess.triangles[keep])
    return new_points, tri[keep], next_id + inner.size, uv[inner]


def _borders(edges, label, S):
    """Per super-surface: the edges on its border shared with another super-surface."""
    mate = edges.mate
    out = [[] for _ in range(S)]
    sides = np.flatnonzero((mate.ravel() >= 0) & (edges.side_edge.ravel() >= 0))
    mine, other = label[sides // 4], label[mate.ravel()[sides] // 4]
    for s, e in zip(mine[mine != other], edges.side_edge.ravel()[sides][mine != other]):
        out[s].append(e)
    return [np.unique(np.asarray(b, dtype=np.int64)) for b in out]


def _fan_rows(tri, border, edge_ids, births, level):
    """Rows ``(triangle, edge, a, b, c)``: triangles with a side ``a -> b`` (their orientation) that is one
    segment of a border edge's chain at ``level``, ``c`` the opposite vertex."""
    keys, owner = [], []
    for e in border:
        g = edge_ids[e][births[e] >= level]
        lo, hi = np.minimum(g[:-1], g[1:]), np.maximum(g[:-1], g[1:])
        keys.append(lo * (1 << 31) + hi)
        owner.append(np.full(lo.size, e))
    if not keys:
        return np.zeros((0, 5), dtype=np.int64)
    keys, owner = np.concatenate(keys), np.concatenate(owner)
    order = np.argsort(keys)
    keys, owner = keys[order], owner[order]
    rows = []
    for r in range(3):
        a, b, c = tri[:, r], tri[:, (r + 1) % 3], tri[:, (r + 2) % 3]
        k = np.minimum(a, b) * (1 << 31) + np.maximum(a, b)
        pos = np.clip(np.searchsorted(keys, k), 0, keys.size - 1)
        hit = np.flatnonzero(keys[pos] == k)
        rows.append(np.column_stack([hit, owner[pos[hit]], a[hit], b[hit], c[hit]]))
    return np.concatenate(rows).astype(np.int64)


def vertex_normals(bezier, patch, uv) -> np.ndarray:
    """Unit normals ``S_u x S_v`` of the Bezier patches ``patch (n,)`` at local ``uv (n, 2)``: exact, not
    averaged from triangles (a vertex shared by patches takes the first patch's; at a G1 or G2 seam they
    agree). Where ``S_u x S_v`` vanishes (a pole) the normal is taken ``1e-6`` of the domain inside, towards the
    patch's centre (the limit, to ~1e-6).

    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.lod.bezier import bezier_set, evaluate
    >>> bs = bezier_set(sphere())
    >>> uv = np.array([[0.0, 0.0], [0.3, 0.6]])  # patch 0's corner (0, 0) is the south pole
    >>> n = vertex_normals(bs, np.array([0, 0]), uv)
    >>> (np.round(n, 5) + 0.0).tolist()[0], bool(abs(n[1] @ evaluate(bs, [0], [0.3], [0.6])[0] - 1) < 1e-12)
    ([0.0, 0.0, -1.0], True)
    """
    return _vertex_normals(bezier, patch, uv)[0]


def _vertex_normals(bezier, patch, uv):
    """:func:`vertex_normals` and where the normal was taken inside (``(n,)`` bool: nudged)."""
    from .bezier import evaluate

    patch, uv = np.asarray(patch, dtype=np.int64), np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    out = np.zeros((patch.size, 3))
    todo = np.arange(patch.size)
    nudged = np.zeros(patch.size, dtype=bool)
    for nudge in (0.0, 1e-6, 1e-4):
        if todo.size == 0:
            break
        q = uv[todo] + nudge * (0.5 - uv[todo])
        _, Su, Sv = evaluate(bezier, patch[todo], q[:, 0], q[:, 1], derivatives=True)
        n = np.cross(Su, Sv)
        size = np.linalg.norm(n, axis=1)
        scale = np.linalg.norm(Su, axis=1) * np.linalg.norm(Sv, axis=1)
        ok = size > 1e-10 * np.maximum(scale, np.finfo(float).tiny)
        out[todo[ok]] = n[ok] / size[ok, None]
        nudged[todo[ok]] = nudge > 0.0
        todo = todo[~ok]
    nudged[todo] = True
    return out, nudged


def build_lod(model, delta: float, *, levels: int = 4, ratio: float = 4.0, alpha: float = np.radians(30.0),
              simplify=None, progress: bool = True, workers=None, trim_share: float = 0.125,
              tol=None) -> LodModel:
    """Levels of detail of ``model`` (a :class:`~splinevis.nurbs.model.NurbsModel` or one surface) with proven
    bounds ``delta * ratio**l``, ``l = 0..levels-1`` (module docstring). With ``simplify`` (a
    :class:`~splinevis.nurbs.lod.simplify.Simplifier`) the levels ``l > 0`` are decimated across patch edges
    and held to ``delta_l + eps_l`` by measurement. Trim loops are applied (:mod:`.trims`): in a model with trims
    the share ``trim_share`` of ``delta`` goes to the trim polylines and ``delta_l - trim_share * delta`` to the
    triangles, so each level keeps ``delta_l`` with its trims; surfaces meeting along trim curves share their
    border vertices (:mod:`.stitch`; ``tol``: the model's tolerance, default ``1e-6`` of its size, added to the
    bound where stitched vertices move). ``workers`` processes tessellate batches of
    patches (None: ``os.cpu_count()``; 1: in this process); the result is the same for any number.

    >>> from splinevis.nurbs.exact import torus
    >>> lod = build_lod(torus(), 0.02, levels=3, progress=False)
    >>> lod.tolerance.tolist(), bool(lod.triangles.sum(axis=0)[0] > lod.triangles.sum(axis=0)[2])
    ([0.02, 0.08, 0.32], True)
    """
    from tqdm.auto import tqdm

    if not (np.isfinite(delta) and delta > 0):
        raise ValueError(f"delta must be a positive distance, got {delta!r}.")
    if int(levels) < 1 or not ratio > 1:
        raise ValueError(f"levels must be >= 1 and ratio > 1, got levels={levels!r}, ratio={ratio!r}.")
    bs = bezier_set(model)
    trimmed = bool(bs.trimmed.any())
    if trimmed and not 0.0 < float(trim_share) < 1.0:
        raise ValueError(f"trim_share must lie in (0, 1), got {trim_share!r}.")
    tol = 1e-7 * bs.size if tol is None else float(tol)
    # a trimmed model comes from a CAD file: its surfaces' shared sides agree to the file's tolerance only
    edges = find_edges(bs, tol=tol) if trimmed else find_edges(bs)
    axis, half = _patch_cones(bs)
    supers = grow_super_surfaces((axis, half), _neighbours(edges), float(alpha))
    deltas = float(delta) * float(ratio) ** np.arange(int(levels))
    delta_trim = float(trim_share) * float(delta) if trimmed else 0.0
    corner_label, corners = _corner_labels(bs, edges)
    chains, births = _edge_chains(bs, edges, deltas - delta_trim, corner_label)
    status = np.zeros(len(bs), dtype=np.int64)
    if trimmed:
        from .stitch import stitch_borders, update_chains
        from .trims import face_rings, merge_params, trim_plan

        # a trim that touches its surface's side and stays within delta / 2 of it in space is that side
        rings = face_rings(bs, model.trims, delta_trim, chord=0.5 * float(deltas[0] - delta_trim),
                           side_near=0.5 * float(delta))
        stitch = stitch_borders(bs, edges, rings, chains, float(deltas[0]), tol)
        update_chains(stitch, chains, births, deltas.size)
        plan = trim_plan(bs, edges, stitch.rings, delta_trim)
        status = plan.status
        for e, extra in plan.edge_params.items():  # trim crossings: in every level's chain of the edge
            t, new = merge_params(chains[e], extra)
            b = np.full(t.size, deltas.size - 1, dtype=np.int64)
            b[~new] = births[e]
            chains[e], births[e] = t, b
    points, edge_ids, where = _shared_vertices(bs, edges, chains, corner_label, corners)
    if trimmed:  # stitched trim vertices: an edge's vertex, or one new vertex per class
        from .stitch import fixed_ids, resolve

        node_gid, joined, joined_patch, joined_uv = resolve(stitch, chains, edge_ids, points.shape[0])
        points = np.concatenate([points, joined])
        where.append((joined_patch, joined_uv))
    label = supers.labels
    S = len(supers.members)
    all_points, next_id = [points], points.shape[0]
    meshes, counts = [], np.zeros((S, deltas.size), dtype=np.int64)
    border = _borders(edges, label, S)
    # every patch at every level, tessellated in batches of one degree (lockstep refinement: bitwise the
    # results of one adaptive_tessellation call each), then numbered in the order super-surface, level, patch
    drawn = [[int(i) for i in supers.members[s] if status[i] >= 0] for s in range(S)]  # not wholly trimmed away
    jobs = [(i, level) + _patch_sides(edges, i, level, chains, births, edge_ids, corner_label)
            for s in range(S) for level in range(deltas.size) for i in drawn[s]]
    by_degree: dict = {}
    for n, (i, level, side_chain, _) in enumerate(jobs):
        by_degree.setdefault(int(bs.group[i]), []).append(n)
    tess = [None] * len(jobs)
    workers = max(1, int(os.cpu_count() or 1) if workers is None else int(workers))
    if len(jobs) < 2 * _BATCH:
        workers = 1  # not worth starting processes
    size = max(64, min(_BATCH, -(-len(jobs) // (2 * workers))))
    parts = [group[a:a + size] for group in by_degree.values() for a in range(0, len(group), size)]
    batches = ([(bs.control(jobs[n][0]), float(deltas[jobs[n][1]] - delta_trim), _check_chains(jobs[n][2]))
                for n in part] for part in parts)
    bar = tqdm(total=len(jobs), desc="lod: tessellation", disable=not progress, unit="patch")
    with (ProcessPoolExecutor(workers) if workers > 1 else contextlib.nullcontext()) as pool:
        for part, got in zip(parts, pool.map(_tessellate, batches) if pool else map(_tessellate, batches)):
            for n, t in zip(part, got):
                tess[n] = t
            bar.update(len(part))
    bar.close()
    if trimmed:
        from .clip import clip_patch
        from .trims import local_rings

        for n, (i, level, side_chain, _) in enumerate(jobs):
            if status[i] == 1:
                tess[n] = clip_patch(bs.control(i), plan.local[i], side_chain, float(deltas[level] - delta_trim),
                                     tess[n], local_rings(stitch.rings[int(bs.parent[i])][0], bs.rect[i]))
    raw, n, joins, local = [], 0, [], {}  # local[s, level]: each triangle's patch, its vertices' local (u, v)
    for s in range(S):
        per_level = []
        for level in range(deltas.size):
            tris, kept = [], []
            for _ in drawn[s]:
                i, _, side_chain, side_ids = jobs[n]
                fixed = (fixed_ids(stitch, node_gid, bs.rect[i], int(bs.parent[i]), tess[n].uv)
                         if trimmed and status[i] == 1 else None)
                new, tri, next_id, uv = _patch_finish(bs, edges, i, tess[n], side_chain, side_ids, next_id, fixed,
                                                      joins, kept)
                kept[-1] = (np.full(len(tri), i), tess[n].uv[kept[-1]])
                n += 1
                all_points.append(new)
                where.append((np.full(len(uv), i), uv))
                tris.append(tri)
            per_level.append(np.concatenate(tris) if tris else np.zeros((0, 3), dtype=np.int64))
            if kept and not (status[drawn[s]] == 1).any() and (simplify is None or level == 0):  # else unbounded
                local[s, level] = tuple(np.concatenate(x) for x in zip(*kept))
        raw.append(per_level)
    vertices = np.concatenate(all_points)
    if joins:  # stitched vertices that are chain vertices of their own surface: one vertex, the chain's
        remap = np.arange(vertices.shape[0])
        for a, b in joins:
            remap[a] = b
        raw = [[remap[t] for t in per_level] for per_level in raw]
    vertex_patch = np.concatenate([w[0] for w in where]).astype(np.int64)
    vertex_uv = np.concatenate([w[1] for w in where])
    normals, nudged = _vertex_normals(bs, vertex_patch, vertex_uv)
    tolerance = deltas.copy()
    simplified = np.zeros((S, deltas.size))
    if simplify is not None:
        tolerance[1:] += [simplify.eps(d) for d in deltas[1:]]
    for s in tqdm(range(S), desc="lod: levels", disable=not progress or simplify is None, unit="super-surface"):
        per_level = []
        for level, tri in enumerate(raw[s]):
            if simplify is not None and level > 0:
                tri, simplified[s, level] = simplify(bs, vertices, tri, supers.members[s], deltas[level])
            per_level.append((tri, _fan_rows(tri, border[s], edge_ids, births, level)))
            counts[s, level] = tri.shape[0]
        meshes.append(tuple(per_level))
    from ..normal_bounds import lod_normal_bounds

    records = [(s, level, meshes[s][level][0], *local[s, level], meshes[s][level][1]) for s, level in local]
    normal_bounds = lod_normal_bounds(bs, edges, corner_label, edge_ids, normals, nudged, records, counts.shape)
    boxes = np.empty((S, 6))
    for s in range(S):
        b = bs.bbox[np.asarray(supers.members[s])]
        boxes[s] = [b[:, 0].min(), b[:, 1].max(), b[:, 2].min(), b[:, 3].max(), b[:, 4].min(), b[:, 5].max()]
    return LodModel(bs, edges, supers, build_bvh(boxes), boxes, tolerance, counts, bs.size, vertices,
                    tuple(edge_ids), tuple(births), tuple(meshes), tuple(border), simplified, normals,
                    delta_trim=delta_trim, status=status, vertex_patch=vertex_patch, vertex_uv=vertex_uv,
                    trims=tuple(model.trims) if trimmed else None, normal_bounds=normal_bounds)


def _between(lod, eid, a, b, level):
    """The chain points of edge ``eid`` strictly between its vertices ``a`` and ``b`` held by ``level``'s chain,
    in the order from ``a`` to ``b``."""
    ids, birth = lod.edge_ids[eid], lod.edge_birth[eid]
    ia, ib = int(np.flatnonzero(ids == a)[0]), int(np.flatnonzero(ids == b)[0])
    mid = np.arange(min(ia, ib) + 1, max(ia, ib))
    mid = mid[birth[mid] >= level]
    return ids[mid[::-1] if ia > ib else mid]


def _split_side(pieces, a, b, inner):
    """Replace the piece holding the side ``a -> b`` by the fan from its third vertex through ``inner``. A
    triangle with sides on two edges is split twice: the second side lies in exactly one piece of the first
    fan, whose third vertex is off that side (it is on the first edge), so no piece is degenerate."""
    if inner.size == 0:
        return pieces
    for n, (x, y, z) in enumerate(pieces):
        for p, q, c in ((x, y, z), (y, z, x), (z, x, y)):
            if (p, q) == (a, b) or (p, q) == (b, a):
                chain = np.concatenate([[p], inner if (p, q) == (a, b) else inner[::-1], [q]])
                fan = [(int(u), int(w), int(c)) for u, w in zip(chain[:-1], chain[1:])]
                return pieces[:n] + fan + pieces[n + 1:]
    raise RuntimeError(f"no piece holds the side {a}-{b}")


def _fan_split(tri, rows, between) -> tuple:
    """``tri`` with each triangle of ``rows`` (fan rows: triangle, edge, a, b, c) split into fans through
    ``between(edge, a, b)``, the finer chain's points on its side ``a b``; returns (triangles, count split)."""
    keep = np.ones(tri.shape[0], dtype=bool)
    extra = []
    split = np.unique(rows[:, 0])
    for t in split:
        pieces = [tuple(tri[t])]
        for _, eid, a, b, _c in rows[rows[:, 0] == t]:
            pieces = _split_side(pieces, a, b, between(int(eid), a, b))
        keep[t] = False
        extra.append(np.array(pieces, dtype=np.int64))
    return np.concatenate([tri[keep]] + extra), int(split.size)


def assemble(lod: LodModel, level) -> tuple:
    """One crack-free mesh of the super-surfaces at ``level (S,)`` (-1: not drawn): ``(points (V, 3),
    triangles (T, 3), info)``; every edge between two drawn super-surfaces at levels ``k < l`` is drawn at
    ``k``, the coarser side's triangles along it split into fans (module docstring). ``info``: triangles,
    fan-split triangles, the largest proven bound drawn.

    >>> from splinevis.nurbs.exact import sphere
    >>> lod = build_lod(sphere(), 0.05, levels=2, progress=False)
    >>> pts, tri, info = assemble(lod, np.zeros(len(lod.supers.members), dtype=int))
    >>> tri.shape[0] == info["triangles"], info["fans"]
    (True, 0)
    """
    level = np.asarray(level, dtype=np.int64)
    S = len(lod.supers.members)
    if level.shape != (S,) or level.max(initial=-1) >= lod.levels or level.min(initial=0) < -1:
        raise ValueError(f"level must be {S} integers in -1..{lod.levels - 1}, got shape {level.shape}.")
    edges, label = lod.edges, lod.supers.labels
    # the level each edge is drawn at: the finest of the drawn super-surfaces on it
    edge_level = np.full(len(edges), np.iinfo(np.int64).max)
    side_super = np.repeat(label, 4).reshape(-1, 4)
    drawn_sides = level[side_super] >= 0
    e = edges.side_edge[drawn_sides & (edges.side_edge >= 0)]
    np.minimum.at(edge_level, e, level[side_super][drawn_sides & (edges.side_edge >= 0)])
    out, fanned = [], 0
    for s in np.flatnonzero(level >= 0):
        tri, fans = lod.meshes[s][level[s]]
        if fans.size:
            need = edge_level[fans[:, 1]] < level[s]
            if need.any():
                tri, k = _fan_split(tri, fans[need], lambda eid, a, b: _between(lod, eid, a, b, edge_level[eid]))
                fanned += k
        out.append(tri)
    tri = np.concatenate(out) if out else np.zeros((0, 3), dtype=np.int64)
    drawn = level[level >= 0]
    info = {"triangles": int(tri.shape[0]), "fans": fanned,
            "bound": float(lod.tolerance[drawn].max()) if drawn.size else 0.0}
    return lod.vertices, tri, info

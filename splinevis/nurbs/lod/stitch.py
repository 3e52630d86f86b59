"""Faces that meet along a trim curve share one tessellation of it [Kumar1997, sec. 4.2: a boundary curve is
tessellated once for both sides], so a trimmed solid read from a CAD file has no crack there.

Two surfaces of a B-rep meet along a curve that is, on each side, either a trim curve (a polyline of
:mod:`.trims`) or a natural side of a Bezier patch with no neighbour (an *open edge*, with its chain of
:mod:`.levels`). Each side approximates the curve by its own points, so the two borders differ by up to the
level's bound: a crack. Here both sides get the union of the points:

1. **Matching.** A border point ``p`` of one surface (a trim polyline vertex, or an open edge's chain point) is
   near another surface's border when it lies within ``delta + tol`` of that border's chords (``delta`` bounds
   how far chords lie from the curve); it is then put onto the other surface exactly: Newton's method on the
   other edge's curve, or Gauss-Newton on the other surface near its trim polyline, accepted when the found
   point is within ``tol`` of ``p`` in space (and, on a trim, within ``2 h`` of that polyline in the domain: on
   the trim curve, not elsewhere on the surface). ``tol`` is the model's tolerance (how far the files' two
   descriptions of one curve may differ; default ``1e-6`` of the model's size).
2. **Union.** The found point is inserted into the other border (a trim polyline gains the domain point, an open
   edge's chain the parameter, in every level), and the two points become one vertex of the mesh (a union-find
   over all border points; an edge's chain vertex is the class's position where the class has one, else the
   first trim point's). A point moves by at most ``tol``, so each level's bound grows by ``tol`` at most.
3. Points of a trim polyline on its own surface's domain border are left out of the matching: there the mesh's
   border is the patches' sides, stitched by the edges of :mod:`.adjacency` or as open edges.

A trim polyline with extra points on its curve stays within ``h`` of it (each new chord spans a sub-arc of an
old one), so the bounds of :mod:`.trims` hold. Stitched open edges keep every chain point in every level.

Why our own code: no library sews trimmed NURBS tessellations with a proven bound; kept libraries do the
geometry (scipy's KD-tree).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .bezier import evaluate, locate as _locate
from .bounds import curve_points, side_net

__all__ = ["Stitch", "stitch_borders", "open_edges", "update_chains", "resolve", "fixed_ids"]


class Stitch(NamedTuple):
    """The result of :func:`stitch_borders`.

    ``rings``: face -> (list of closed polylines ``(K, 2)`` in the face's domain, with the points put in, ``h``);
    ``nodes``: face -> list of ``(K,)`` node ids of those polylines' vertices; ``cls (N,)`` the class of each
    node (nodes of one class are one mesh vertex); ``node_edge (N, 2)`` the (edge, index into ``edge_t``) of an
    edge-chain node, else -1; ``node_point (N, 3)``, ``node_patch (N,)``, ``node_uv (N, 2)`` a trim node's
    point and where it lies (local to the patch); ``edge_t``: edge -> all parameters of its chain's nodes;
    ``stitched``: the edges that met another surface's border; ``matched``: counts.

    >>> s = Stitch({}, {}, np.zeros(0, int), np.zeros((0, 2), int), np.zeros((0, 3)), np.zeros(0, int),
    ...            np.zeros((0, 2)), {}, set(), {"points": 0})
    >>> s.matched
    {'points': 0}
    """

    rings: dict
    nodes: dict
    cls: np.ndarray
    node_edge: np.ndarray
    node_point: np.ndarray
    node_patch: np.ndarray
    node_uv: np.ndarray
    edge_t: dict
    stitched: set
    matched: dict


def open_edges(edges) -> np.ndarray:
    """Edges with one side only (not a pole).

    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.lod.adjacency import find_edges
    >>> open_edges(find_edges(bezier_set(saddle()))).tolist()
    [0, 1, 2, 3]
    """
    n = np.diff(edges.offsets)[:len(edges)]
    return np.flatnonzero(n == 1)


def _face_points(bs, f, uv):
    p, st = _locate(bs, f, uv)
    return evaluate(bs, p, st[:, 0], st[:, 1]) if len(p) else np.zeros((0, 3)), p, st


def _invert_on_face(bs, f, uv0, target, domain, iterations=30):
    """Gauss-Newton for ``F_f(x) = target`` from ``uv0`` (rows), kept in ``domain`` (u0, u1, v0, v1)."""
    x = np.array(uv0, dtype=np.float64).reshape(-1, 2)
    target = np.asarray(target, dtype=np.float64).reshape(-1, 3)
    for _ in range(iterations):
        p, st = _locate(bs, f, x)
        S, Su, Sv = evaluate(bs, p, st[:, 0], st[:, 1], derivatives=True)
        r = bs.rect[p]
        Su, Sv = Su / (r[:, 1] - r[:, 0])[:, None], Sv / (r[:, 3] - r[:, 2])[:, None]
        J = np.stack([Su, Sv], axis=-1)  # (K, 3, 2)
        g = np.einsum("kci,kc->ki", J, target - S)
        H = np.einsum("kci,kcj->kij", J, J)
        lam = 1e-12 * np.trace(H, axis1=1, axis2=2) + 1e-300  # damped at poles, where S_u or S_v vanishes
        H = H + lam[:, None, None] * np.eye(2)
        step = np.linalg.solve(H, g[..., None])[..., 0]
        x = np.column_stack([np.clip(x[:, 0] + step[:, 0], domain[0], domain[1]),
                             np.clip(x[:, 1] + step[:, 1], domain[2], domain[3])])
        if np.abs(step).max(initial=0.0) < 1e-15:
            break
    F, _, _ = _face_points(bs, f, x)
    return x, np.linalg.norm(F - target, axis=1)


def _curve_derivative(net, t):
    """``C(t), C'(t)`` of the rational Bezier curve ``net (p + 1, 4)``."""
    net = np.asarray(net, dtype=np.float64)
    p = net.shape[0] - 1
    A = curve_points(np.column_stack([net, np.ones(p + 1)]), t)  # homogeneous sum / 1: (N, 4)
    dA = p * curve_points(np.column_stack([np.diff(net, axis=0), np.ones(p)]), t)
    C = A[:, :3] / A[:, 3:]
    return C, (dA[:, :3] - C * dA[:, 3:]) / A[:, 3:]


def _invert_on_curve(net, t0, target, iterations=40):
    t = np.array(t0, dtype=np.float64).ravel()
    target = np.asarray(target, dtype=np.float64).reshape(-1, 3)
    for _ in range(iterations):
        C, dC = _curve_derivative(net, t)
        step = np.einsum("kc,kc->k", dC, target - C) / np.maximum(np.einsum("kc,kc->k", dC, dC), 1e-300)
        t = np.clip(t + step, 0.0, 1.0)
        if np.abs(step).max(initial=0.0) < 1e-16:
            break
    return t, np.linalg.norm(curve_points(net, t) - target, axis=1)


def _segment_distance(P, A, B):
    """Distances ``(K, M)`` of points ``P (K, 3)`` to segments ``A B (M, 3)`` and the parameters along them."""
    d = B - A
    L2 = np.maximum(np.einsum("mc,mc->m", d, d), 1e-300)
    s = np.clip(np.einsum("kmc,mc->km", P[:, None, :] - A[None], d) / L2, 0.0, 1.0)
    Q = A[None] + s[..., None] * d[None]
    return np.linalg.norm(P[:, None, :] - Q, axis=-1), s


def _onto_trim(bs, f, F, R, P, k, j, s, tol) -> list:
    """Points ``P[k]`` near segments ``j`` (at ``s`` along them, in space) of the trim ring ``R`` of surface ``f``
    (its record ``F``) put onto the surface by Gauss-Newton from the matching domain points: ``(k, segment,
    domain point)`` of those that land within ``tol`` in space and within ``2 h`` of the ring in the domain
    (segments along the domain's border left out)."""
    if len(k) == 0:
        return []
    segs = np.asarray(R["uv"])
    ok = R["free_seg"][j]
    k, j, s = k[ok], j[ok], s[ok]
    x0 = segs[j] + s[:, None] * (segs[(j + 1) % len(segs)] - segs[j])
    x, gap = _invert_on_face(bs, f, x0, P[k], F["dom"])
    off = _polyline_gap(x, segs, j)
    keep = (gap <= tol) & (off <= 2.0 * F["h"] + 1e-12)
    return [(int(kk), int(jj), tuple(xx)) for kk, jj, xx in zip(k[keep], j[keep], x[keep])]


def _polyline_gap(x, ring, j):
    """Distances in the domain from points ``x (K, 2)`` to the closed polyline ``ring`` near segment ``j (K,)``
    (segments ``j - 1, j, j + 1``)."""
    n = len(ring)
    best = np.full(len(x), np.inf)
    for d in (-1, 0, 1):
        a, b = ring[(j + d) % n], ring[(j + d + 1) % n]
        e = b - a
        s = np.clip(np.einsum("ki,ki->k", x - a, e) / np.maximum(np.einsum("ki,ki->k", e, e), 1e-300), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(x - (a + s[:, None] * e), axis=1))
    return best


class _Find:
    def __init__(self):
        self.root = []

    def add(self):
        self.root.append(len(self.root))
        return len(self.root) - 1

    def find(self, a):
        r = self.root
        while r[a] != a:
            r[a] = r[r[a]]
            a = r[a]
        return a

    def union(self, a, b):
        a, b = self.find(a), self.find(b)
        if a != b:
            self.root[max(a, b)] = min(a, b)


def stitch_borders(bs, edges, rings: dict, chains, delta: float, tol: float) -> Stitch:
    """Match and unite the borders of different surfaces (module docstring): the trim polylines ``rings``
    (face -> (list of ``(K, 2)``, ``h``), :func:`splinevis.nurbs.lod.trims.face_rings`) and the open edges' finest
    ``chains``; ``delta`` bounds the borders' distance from their curves, ``tol`` the model's tolerance.

    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.lod.bezier import bezier_set
    >>> from splinevis.nurbs.lod.adjacency import find_edges
    >>> bs = bezier_set(saddle())
    >>> s = stitch_borders(bs, find_edges(bs), {}, [np.array([0.0, 1.0])] * 4, 1e-3, 1e-9)
    >>> s.matched["points"], s.stitched
    (0, set())
    """
    uf = _Find()
    node_edge, node_point, node_patch, node_uv = [], [], [], []

    def new_node(edge=(-1, -1), point=np.zeros(3), patch=-1, uv=(np.nan, np.nan)):
        node_edge.append(edge)
        node_point.append(point)
        node_patch.append(patch)
        node_uv.append(uv)
        return uf.add()

    # trim polylines: points, nodes, which vertices may match (not on their own domain border)
    faces = {}
    for f, (face, h) in rings.items():
        ids = np.flatnonzero(bs.parent == f)
        dom = (bs.rect[ids, 0].min(), bs.rect[ids, 1].max(), bs.rect[ids, 2].min(), bs.rect[ids, 3].max())
        out = []
        for ring in face:
            X, p, st = _face_points(bs, f, ring)
            nodes = [new_node(point=X[k], patch=int(p[k]), uv=st[k]) for k in range(len(ring))]
            nxt = np.roll(ring, -1, axis=0)
            along = np.zeros(len(ring), dtype=bool)  # segment k (k -> k + 1) lies on the domain's border
            near = 1e-11 * max(dom[1] - dom[0], dom[3] - dom[2])  # as ring_pieces of .clip: a side within rounding
            for axis, value in ((0, dom[0]), (0, dom[1]), (1, dom[2]), (1, dom[3])):
                along |= (np.abs(ring[:, axis] - value) <= near) & (np.abs(nxt[:, axis] - value) <= near)
            free_seg = ~along
            out.append({"uv": [tuple(q) for q in ring], "X": [x for x in X], "nodes": nodes,
                        "free": free_seg | np.roll(free_seg, 1), "free_seg": free_seg, "insert": []})
        faces[f] = {"rings": out, "h": h, "dom": dom}
    # open edges: chain nodes
    ed = {}
    # the edges a trim may lie along: open ones, and those with a side on a trimmed surface (its trim may run just
    # inside that side, so the side is not drawn there while its neighbour's is)
    n_sides = np.diff(edges.offsets)[:len(edges)]
    side_patch = edges.members // 4
    trimmed_side = np.zeros(len(edges), dtype=bool)
    np.logical_or.at(trimmed_side, np.repeat(np.arange(len(edges)), n_sides), bs.trimmed[side_patch])
    for e in np.flatnonzero((n_sides == 1) | trimmed_side):
        side = int(edges.edge_side[e])
        i, k = divmod(side, 4)
        net = side_net(bs.control(i), k)
        t = np.asarray(chains[e], dtype=np.float64)
        X = curve_points(net, t)
        faces_of = set(bs.parent[side_patch[edges.offsets[e]:edges.offsets[e + 1]]].tolist())
        ed[int(e)] = {"faces": faces_of, "net": net, "t": list(t), "X": list(X),
                      "nodes": [new_node(edge=(int(e), n)) for n in range(t.size)], "insert": []}
    slack = float(delta) + float(tol)
    matched = 0
    stitched = set()

    def near(P, Q, closed):
        """For points P, the nearest segment of the polyline Q (closed or not) within slack."""
        A = np.asarray(Q)
        B = np.roll(A, -1, axis=0) if closed else A[1:]
        A = A if closed else A[:-1]
        if A.shape[0] == 0 or P.shape[0] == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0)
        lo, hi = np.minimum(A, B).min(axis=0) - slack, np.maximum(A, B).max(axis=0) + slack
        cand = np.flatnonzero(((P >= lo) & (P <= hi)).all(axis=1))
        if cand.size == 0:
            return cand, cand, np.zeros(0)
        d, s = _segment_distance(P[cand], A, B)
        j = np.argmin(d, axis=1)
        ok = d[np.arange(cand.size), j] <= slack
        return cand[ok], j[ok], s[np.arange(cand.size), j][ok]

    # which borders may meet: boxes (grown by the slack) that overlap, found in chunks (no all-pairs loop)
    curves = [("r", f, r) for f, F in faces.items() for r in range(len(F["rings"]))] + [("e", e, 0) for e in ed]
    pts = [np.asarray(faces[a]["rings"][b]["X"]) if kind == "r" else np.asarray(ed[a]["X"]) for kind, a, b in curves]
    lo = np.array([p.min(axis=0) for p in pts]).reshape(-1, 3) - slack
    hi = np.array([p.max(axis=0) for p in pts]).reshape(-1, 3) + slack
    owner = np.array([a if kind == "r" else -1 for kind, a, _ in curves], dtype=np.int64)  # edges: any face
    meets = [[] for _ in curves]
    for a in range(0, len(curves), 512):
        ov = ((lo[a:a + 512, None, :] <= hi[None, :, :]) & (hi[a:a + 512, None, :] >= lo[None, :, :])).all(axis=2)
        ov &= owner[a:a + 512, None] != owner[None, :]  # other surfaces only
        for i, j in zip(*np.nonzero(ov)):
            meets[a + i].append(j)
    index = {c: n for n, c in enumerate(curves)}

    def partners(kind, a, b, want):
        return [curves[j] for j in meets[index[(kind, a, b)]] if curves[j][0] == want]

    # 1. trim vertices onto open edges and onto other surfaces' trims
    for f, F in faces.items():
        for r, R in enumerate(F["rings"]):
            P = np.asarray(R["X"])
            free = np.flatnonzero(R["free"])
            for _, e, _ in partners("r", f, r, "e"):
                E = ed[e]
                if E["faces"] == {f}:  # an edge of this surface alone
                    continue
                k, j, s = near(P[free], E["X"], closed=False)
                if k.size == 0:
                    continue
                k = free[k]
                t0 = np.asarray(E["t"])[j] + s * (np.asarray(E["t"])[j + 1] - np.asarray(E["t"])[j])
                t, gap = _invert_on_curve(E["net"], t0, P[k])
                for kk, tt, g in zip(k, t, gap):
                    if g <= tol:
                        E["insert"].append((float(tt), R["nodes"][kk]))
                        stitched.add(e)
                        matched += 1
            for _, g_, si in partners("r", f, r, "r"):
                G = faces[g_]
                S = G["rings"][si]
                Q = np.asarray(S["X"])
                k, j, s = near(P[free], Q, closed=True)
                for kk, jj, xx in _onto_trim(bs, g_, G, S, P, free[k], j, s, tol):
                    S["insert"].append((jj, xx, R["nodes"][kk], P[kk]))
                    matched += 1
    # 2. open edges' chain points onto trims
    for e, E in ed.items():
        Pe = np.asarray(E["X"])
        for _, f, ri in partners("e", e, 0, "r"):
            if E["faces"] == {f}:
                continue
            F = faces[f]
            R = F["rings"][ri]
            k, j, s = near(Pe, R["X"], closed=True)
            for kk, jj, xx in _onto_trim(bs, f, F, R, Pe, k, j, s, tol):
                R["insert"].append((jj, xx, E["nodes"][kk], Pe[kk]))
                stitched.add(e)
                matched += 1
    # 3. apply: edges gain parameters (a point within tol of a chain point is that point), rings gain points
    edge_t = {}
    for e, E in ed.items():
        t = list(E["t"])
        nodes = list(E["nodes"])
        X = list(E["X"])
        for tt, other in sorted(E["insert"]):
            x = curve_points(E["net"], [tt])[0]
            d = np.linalg.norm(np.asarray(X) - x, axis=1)
            if d.min() <= tol:
                uf.union(nodes[int(np.argmin(d))], other)
                continue
            n = new_node(edge=(e, len(t)))
            t.append(tt)
            X.append(x)
            nodes.append(n)
            uf.union(n, other)
        order = np.argsort(t, kind="stable")
        for pos, n in enumerate(np.asarray(nodes)[order]):
            node_edge[n] = (e, pos)
        edge_t[e] = np.asarray(t)[order]
    out_rings, out_nodes = {}, {}
    for f, F in faces.items():
        rs, ns = [], []
        for R in F["rings"]:
            uv, nodes, X = list(R["uv"]), list(R["nodes"]), np.asarray(R["X"])
            ring = np.asarray(uv, dtype=np.float64)
            seg = np.roll(ring, -1, axis=0) - ring
            cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(seg, axis=1))])
            # every point at its place along the polyline: arclength of its projection on the nearest of the
            # segments around the one it was matched on (sorting by it: no zigzag)
            keys = [(float(cum[k]), 0, k) for k in range(len(uv))]
            extra = []
            for jj, xx, other, p in R["insert"]:
                d = np.linalg.norm(X - p, axis=1)
                if d.min() <= tol:  # the ring already has this point
                    uf.union(nodes[int(np.argmin(d))], other)
                    continue
                x = np.asarray(xx)
                best = None
                for j in ((jj - 1) % len(uv), jj, (jj + 1) % len(uv)):
                    L2 = float(seg[j] @ seg[j])
                    t = min(max(float((x - ring[j]) @ seg[j]) / L2, 0.0), 1.0) if L2 > 0 else 0.0
                    dist = float(np.linalg.norm(ring[j] + t * seg[j] - x))
                    if best is None or dist < best[0]:
                        best = (dist, float(cum[j] + t * (cum[j + 1] - cum[j])))
                keys.append((best[1], 1, len(extra)))
                extra.append((xx, other, p))
            new_uv, new_nodes = [], []
            for _, kind, k in sorted(keys):
                if kind == 0:
                    new_uv.append(uv[k])
                    new_nodes.append(nodes[k])
                    continue
                xx, other, p = extra[k]
                if new_uv and np.linalg.norm(np.asarray(xx) - np.asarray(new_uv[-1])) == 0.0:
                    uf.union(new_nodes[-1], other)
                    continue
                _, pp, st = _face_points(bs, f, np.asarray([xx]))
                n = new_node(point=p, patch=int(pp[0]), uv=st[0])
                uf.union(n, other)
                new_uv.append(xx)
                new_nodes.append(n)
            rs.append(np.asarray(new_uv, dtype=np.float64))
            ns.append(np.asarray(new_nodes, dtype=np.int64))
        out_rings[f] = (rs, F["h"])
        out_nodes[f] = ns
    cls = np.array([uf.find(a) for a in range(len(uf.root))], dtype=np.int64)
    return Stitch(out_rings, out_nodes, cls, np.asarray(node_edge, dtype=np.int64).reshape(-1, 2),
                  np.asarray(node_point, dtype=np.float64).reshape(-1, 3), np.asarray(node_patch, dtype=np.int64),
                  np.asarray(node_uv, dtype=np.float64).reshape(-1, 2), edge_t, stitched,
                  {"points": matched, "edges": len(stitched)})


def update_chains(stitch: Stitch, chains, births, levels: int) -> None:
    """Put the stitched parameters into the edges' ``chains`` (in place), born at the coarsest level; a stitched
    edge keeps every chain point at every level (its other side, a trim polyline, has them all).

    >>> s = Stitch({}, {}, np.zeros(0, int), np.zeros((0, 2), int), np.zeros((0, 3)), np.zeros(0, int),
    ...            np.zeros((0, 2)), {0: np.array([0.0, 0.3, 0.5, 1.0])}, {0}, {})
    >>> chains, births = [np.array([0.0, 0.5, 1.0])], [np.array([3, 0, 3])]
    >>> update_chains(s, chains, births, 4)
    >>> chains[0].tolist(), births[0].tolist()
    ([0.0, 0.3, 0.5, 1.0], [3, 3, 3, 3])
    """
    for e, t in stitch.edge_t.items():
        old_t, old_b = chains[e], births[e]
        b = np.full(t.size, levels - 1, dtype=np.int64)
        pos = np.searchsorted(old_t, t)
        same = (pos < old_t.size) & (old_t[np.minimum(pos, old_t.size - 1)] == t)
        b[same] = old_b[pos[same]]
        if e in stitch.stitched:
            b[:] = levels - 1
        chains[e], births[e] = t, b


def resolve(stitch: Stitch, chains, edge_ids, first_id: int) -> tuple:
    """Global vertex ids of the stitched nodes: ``(node_gid (N,), points (M, 3), patch (M,), uv (M, 2))``; a class
    holding an edge's chain point is that edge vertex, any other class of two or more nodes a new vertex (ids
    from ``first_id``) at its first node's point; a node alone is -1 (its patch's own vertex).

    >>> s = Stitch({}, {}, np.array([0, 0, 2]), np.array([[-1, -1], [-1, -1], [-1, -1]]), np.eye(3),
    ...            np.array([4, 5, 6]), np.zeros((3, 2)), {}, set(), {})
    >>> gid, pts, patch, uv = resolve(s, [], [], 10)
    >>> gid.tolist(), pts.tolist(), patch.tolist()
    ([10, 10, -1], [[1.0, 0.0, 0.0]], [4])
    """
    N = stitch.cls.size
    gid = np.full(N, -1, dtype=np.int64)
    size = np.bincount(stitch.cls, minlength=N)
    root_gid = np.full(N, -1, dtype=np.int64)
    for n in np.flatnonzero(stitch.node_edge[:, 0] >= 0):
        e, pos = stitch.node_edge[n]
        t = stitch.edge_t[int(e)][pos]
        k = int(np.searchsorted(chains[e], t))
        if k >= chains[e].size or chains[e][k] != t:
            raise RuntimeError(f"edge {e}: a stitched parameter {t!r} is missing from its chain")
        root_gid[stitch.cls[n]] = edge_ids[e][k]
    roots = np.flatnonzero((size >= 2) & (root_gid < 0))
    root_gid[roots] = first_id + np.arange(roots.size)
    gid = np.where(size[stitch.cls] >= 2, root_gid[stitch.cls], -1)
    return gid, stitch.node_point[roots], stitch.node_patch[roots], stitch.node_uv[roots]


def fixed_ids(stitch: Stitch, node_gid, rect, f: int, uv_local) -> np.ndarray:
    """``(K,)`` the global id of each point of ``uv_local`` (a patch of surface ``f`` with ``rect``) that is a
    stitched trim vertex (within ``1e-12``), else -1.

    >>> s = Stitch({0: ([np.array([[0.5, 0.5], [0.6, 0.5]])], 0.1)}, {0: [np.array([0, 1])]}, np.array([0, 1]),
    ...            np.full((2, 2), -1), np.zeros((2, 3)), np.zeros(2, int), np.zeros((2, 2)), {}, set(), {})
    >>> fixed_ids(s, np.array([7, -1]), (0.0, 2.0, 0.0, 1.0), 0, np.array([[0.25, 0.5], [0.3, 0.5]])).tolist()
    [7, -1]
    """
    from scipy.spatial import cKDTree

    out = np.full(len(uv_local), -1, dtype=np.int64)
    if f not in stitch.rings or len(uv_local) == 0:
        return out
    from .trims import local_rings

    for loc, nodes in zip(local_rings(stitch.rings[f][0], rect), stitch.nodes[f]):
        g = node_gid[nodes]
        if not (g >= 0).any():
            continue
        d, j = cKDTree(loc).query(uv_local, distance_upper_bound=1e-12)
        hit = np.isfinite(d)
        out[hit] = np.where(g[j[hit]] >= 0, g[j[hit]], out[hit])
    return out

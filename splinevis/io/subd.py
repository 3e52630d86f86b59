"""Catmull–Clark subdivision surfaces (Rhino SubD objects) as bicubic B-spline patches.

A control net (vertices, polygonal faces, optional crease edges) becomes bicubic
:class:`~splinevis.nurbs.NurbsSurface` patches in Bézier form (knots ``[0,0,0,0,1,1,1,1]``):

* **Exact patches.** A quad whose corners are regular (a smooth vertex of valence 4 among four quads, or
  a crease or boundary vertex with two quads on each side of its crease) and whose corner edges follow the
  standard rule is, on the limit surface, exactly the uniform bicubic B-spline patch of its 4 x 4
  neighbourhood [CatmullClark1978; Stam1998]; across a crease the missing row is the phantom
  ``2 P_crease - P_inner``, with which the B-spline rules are the crease rules (a crease is the cubic
  B-spline of its vertices [DeRose1998]). ``M N M^T`` turns the B-spline net into Bézier points.
* **Adaptive subdivision.** ``levels`` vectorized Catmull–Clark steps [CatmullClark1978] (after one, every
  face is a quad); a face exact at level ``l`` is emitted there, its descendants are not. After ``k``
  levels the irregular region around an extraordinary (or irregular crease) vertex covers 4^-k of the
  parameter area of its faces and shrinks in space like ``lambda_n^k`` (the subdominant eigenvalue of
  the valence-``n`` subdivision matrix [Stam1998]: 0.41 for n = 3, 0.55 for n = 5); so does the measured
  deviation of the approximate patches.
* **Approximate patches.** Each remaining level-``k`` face gets a bicubic patch whose corners are the
  limit points of its vertices [HalsteadKass1993] (``(n^2 V + 4 sum E + sum D) / (n (n + 5))``; on a
  crease ``(4 V + A1 + A2) / 6``); each side's inner Bézier points are the least-squares fit to the limit
  points along that side ``fit_depth`` levels deeper, computed once per edge so that neighbours share the
  side bit for bit (no cracks); the four inner points are fitted to the limit points inside. This is an
  alternative to the mask-based patches of [LoopSchaefer2008] (which have no rule for irregular crease
  sectors): the same corners, C0 joins, and a measured rather than assumed distance to the limit surface.
* **Measurement.** :func:`subd_patches` compares every patch with the limit points (where the formula is
  exact) ``fit_depth + 1`` levels below it, and measures the gaps at every shared boundary sample.

Rules, those of Rhino's SubD tags [McNeel2024]: face point = centroid; smooth edge point
``(A + B + C_f1 + C_f2) / 4``, but at a crease vertex whose sector has ``F`` faces ``3/4 (w C + (1 - w) P)``
replaces ``3/8 (C + P)``, ``w = 1/2 + cos(pi / F) / 3`` in [1/6, 5/6] [Biermann2000] (the plain rule for an
edge between two crease vertices at the first step); crease edge point = midpoint; smooth vertex
``(n - 2)/n V + (sum E + sum C_f) / n^2``; crease vertex ``(6 V + A1 + A2) / 8``. Boundary edges are
creases. Dart and corner vertices (one, or three or more, crease edges), non-manifold nets and Rhino's
semi-sharp edges are refused with a message. rhino3dm 8 computes the smooth edge point next to non-quad
faces differently (``rule="rhino"`` of :func:`catmull_clark`). Checked on the six SubD objects of
Rhino's logo file: :func:`catmull_clark` gives rhino3dm's ``Subdivide`` (two steps) and
:func:`limit_points` its vertex ``SurfacePoint`` (five levels down) to 1e-15 of the model size, except
next to irregular crease sectors where our vertex formula is not exact (5e-5 apart; such vertices are
left out of the measurements).

Why our own code: no package on PyPI converts a Catmull–Clark net into B-spline patches (searched in the
index's names and summaries and in package documentation): pyOpenSubdiv wraps OpenSubdiv's topology
refiner (refined meshes only), subdivision-hole-filler fills holes in meshes; OpenSubdiv's patch tables
and Embree's subdivision kernels, which extract such patches, are C++ with no Python binding for it; and
rhino3dm exposes a SubD's control net, ``Subdivide`` and vertex limit points but no NURBS conversion.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..nurbs import NurbsSurface

__all__ = ["SubdNet", "make_net", "catmull_clark", "limit_points", "subd_to_surfaces", "subd_patches",
           "SubdPatches", "subd_net_from_rhino", "subd_object_surfaces", "read_subd_objects"]

_BEZIER_KNOTS = (0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0)
#: B-spline to Bézier points of one uniform cubic span: ``b = M p``.
_M = np.array([[1.0, 4.0, 1.0, 0.0], [0.0, 4.0, 2.0, 0.0], [0.0, 2.0, 4.0, 0.0], [0.0, 1.0, 4.0, 1.0]]) / 6.0


def _sector_coefficient(F: np.ndarray) -> np.ndarray:
    """``w = 1/2 + cos(pi / F) / 3`` clamped to [1/6, 5/6], cosines near 0, +-1/2, +-1 snapped [Biermann2000].

    >>> np.round(_sector_coefficient(np.array([1, 2, 3])), 12).tolist()
    [0.166666666667, 0.5, 0.666666666667]
    """
    c = np.cos(np.pi / np.asarray(F, dtype=np.float64))
    for v in (0.0, 0.5, -0.5, 1.0, -1.0):
        c = np.where(np.abs(c - v) <= 1e-6, v, c)
    return np.clip(0.5 + c / 3.0, 1.0 / 6.0, 5.0 / 6.0)


class SubdNet:
    """A Catmull–Clark control net with its half-edge topology, crease tags and sector coefficients, built
    by :func:`make_net` and :func:`catmull_clark` (its arrays are those ``_build`` names).

    >>> net = make_net(*_cube())
    >>> net.points.shape, net.fsize.tolist(), net.all_quads
    ((8, 3), [4, 4, 4, 4, 4, 4], True)
    """

    def __init__(self, **arrays):
        self.__dict__.update(arrays)


def _edge_keys(a, b, nv):
    a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    return np.minimum(a, b) * nv + np.maximum(a, b)


def _build(points, fv, fsize, crease_keys, w_keys=None) -> SubdNet:
    """Topology, tags and sector coefficients of a net; ``crease_keys`` edge keys of creases;
    ``w_keys`` ``(keys, low-end w, high-end w)`` inherited coefficients (None: computed from the sectors)."""
    P, fv, fsize = np.ascontiguousarray(points, dtype=np.float64), np.asarray(fv, np.int64), np.asarray(fsize, np.int64)
    nv = P.shape[0]
    if P.ndim != 2 or P.shape[1] != 3 or not np.isfinite(P).all():
        raise ValueError(f"vertices must be finite and of shape (n, 3), got shape {P.shape}.")
    if fsize.size == 0 or fsize.min() < 3:
        raise ValueError("every face needs at least 3 vertices (and there must be faces).")
    if fv.size != fsize.sum() or fv.min() < 0 or fv.max() >= nv:
        raise ValueError(f"face vertex indices must lie in 0..{nv - 1}.")
    fstart = np.concatenate([[0], np.cumsum(fsize)[:-1]])
    cf = np.repeat(np.arange(fsize.size), fsize)  # corner (= half-edge from its vertex to the next) -> face
    pos = np.arange(fv.size) - fstart[cf]
    nx, pv = fstart[cf] + (pos + 1) % fsize[cf], fstart[cf] + (pos - 1) % fsize[cf]
    if (fv == fv[nx]).any():
        raise ValueError("a face repeats a vertex along an edge (degenerate edge).")
    ukeys, he_edge, counts = np.unique(_edge_keys(fv, fv[nx], nv), return_inverse=True, return_counts=True)
    if counts.max() > 2:
        e = int(np.argmax(counts))
        raise ValueError(f"non-manifold edge ({ukeys[e] // nv}, {ukeys[e] % nv}) has {counts[e]} faces; "
                         "Catmull–Clark patches need at most two faces per edge.")
    ne = ukeys.size
    edges = np.stack([ukeys // nv, ukeys % nv], axis=1)
    order = np.argsort(he_edge, kind="stable")
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    edge_he, two = np.full((ne, 2), -1, dtype=np.int64), counts == 2
    edge_he[:, 0] = order[first]
    edge_he[two, 1] = order[first[two] + 1]
    twin = np.full(fv.size, -1, dtype=np.int64)
    h0, h1 = edge_he[two, 0], edge_he[two, 1]
    twin[h0], twin[h1] = h1, h0
    if (fv[h0] != fv[nx[h1]]).any():
        raise ValueError("the faces are not consistently oriented (an edge is used twice in the same direction).")
    crease = ~two
    if len(crease_keys):
        idx = np.searchsorted(ukeys, crease_keys)
        ok = (idx < ne) & (ukeys[np.minimum(idx, ne - 1)] == crease_keys)
        if not ok.all():
            k = np.asarray(crease_keys)[~ok][0]
            raise ValueError(f"crease ({k // nv}, {k % nv}) is not an edge of the net.")
        crease[idx] = True
    n_crease = np.bincount(edges[crease].ravel(), minlength=nv)
    valence = np.bincount(edges.ravel(), minlength=nv)
    bad = (n_crease == 1) | (n_crease >= 3)
    if bad.any():
        v = int(np.argmax(bad))
        kind = "dart" if n_crease[v] == 1 else "corner"
        raise ValueError(f"vertex {v} has {n_crease[v]} crease edge(s) (a {kind} vertex); only smooth vertices and "
                         "crease vertices (exactly two crease edges, boundaries included) are supported.")
    # sectors: corners at a vertex joined across smooth edges
    sm = np.flatnonzero(~crease)
    ha, hb = edge_he[sm, 0], edge_he[sm, 1]
    rows, cols = np.concatenate([ha, nx[ha]]), np.concatenate([nx[hb], hb])
    _, label = connected_components(coo_matrix((np.ones(rows.size), (rows, cols)), shape=(fv.size,) * 2), False)
    sector_size = np.bincount(label)
    nsec = np.bincount(np.unique(np.stack([fv, label], axis=1), axis=0)[:, 0], minlength=nv)  # fans per vertex
    want = np.where(n_crease == 2, np.bincount(edges[crease & two].ravel(), minlength=nv) // 2 + 1, 1)
    wrong = (np.bincount(fv, minlength=nv) > 0) & (nsec != want)
    if wrong.any():
        v = int(np.argmax(wrong))
        raise ValueError(f"vertex {v} is non-manifold (its faces form {nsec[v]} fans, expected {want[v]}).")
    isc = n_crease == 2
    smoothx = np.zeros(ne, dtype=bool)  # smooth edges between two crease vertices: plain rule at first
    w = np.full((ne, 2), 0.5)
    if w_keys is None:
        for end in (0, 1):
            v_end, h = edges[sm, end], edge_he[sm, 0]
            c = np.where(fv[h] == v_end, h, nx[h])  # the corner at v_end in the face of half-edge h
            w[sm, end] = np.where(isc[v_end], _sector_coefficient(sector_size[label[c]]), 0.5)
        smoothx[sm] = isc[edges[sm, 0]] & isc[edges[sm, 1]]
    elif len(w_keys[0]):
        idx = np.searchsorted(ukeys, w_keys[0])
        w[idx, 0], w[idx, 1] = w_keys[1], w_keys[2]
    return SubdNet(points=P, fv=fv, fsize=fsize, edges=edges, crease=crease, w=w, fstart=fstart, cf=cf, nx=nx,
                   pv=pv, he_edge=he_edge, twin=twin, edge_he=edge_he, sector=label, sector_size=sector_size,
                   n_crease=n_crease, valence=valence, smoothx=smoothx, is_crease_vertex=isc,
                   all_quads=bool((fsize == 4).all()))


def make_net(vertices, faces, creases=None) -> SubdNet:
    """A :class:`SubdNet` from vertices ``(n, 3)``, faces (lists of vertex indices) and crease edges.

    >>> net = make_net(*_cube())
    >>> net.edges.shape, int(net.valence.min()), net.all_quads
    ((12, 2), 3, True)
    """
    P, faces = np.asarray(vertices, dtype=np.float64), [list(map(int, f)) for f in faces]
    c = np.asarray(creases if creases is not None else [], dtype=np.int64).reshape(-1, 2)
    return _build(P, [v for f in faces for v in f], [len(f) for f in faces],
                  np.unique(_edge_keys(c[:, 0], c[:, 1], P.shape[0])))


def catmull_clark(net: SubdNet, rule: str = "standard") -> SubdNet:
    """One Catmull–Clark step with the crease and sector rules of the module notes.

    ``rule`` is the smooth edge rule next to non-quad faces: ``"standard"`` ``(A + B + C_f1 + C_f2) / 4``
    [CatmullClark1978], or ``"rhino"``: ``3/8 (A + B) + sum_f S_f / (8 (n_f - 2))`` with ``S_f`` the sum of
    the ``n_f - 2`` other vertices of face ``f`` (what rhino3dm 8's ``SubD.Subdivide`` computes, checked on
    the logo file to 1e-15; the two agree on quads, so only the first step differs).

    New vertices: the old vertices' points, then one per edge, then one per face; new face ``c`` (one per
    corner ``c`` of the old net, in corner order) is ``(v, E(edge c), F(face), E(edge before c))``.

    >>> net = catmull_clark(make_net(*_cube()))
    >>> net.points.shape, net.fsize.size, net.all_quads
    ((26, 3), 24, True)
    """
    P, fv, cf = net.points, net.fv, net.cf
    nv, ne = P.shape[0], net.edges.shape[0]
    C = np.add.reduceat(P[fv], net.fstart, axis=0) / net.fsize[:, None]
    A, B = P[net.edges[:, 0]], P[net.edges[:, 1]]
    sm = ~net.crease
    E = 0.5 * (A + B)
    f1, f2 = cf[net.edge_he[sm, 0]], cf[net.edge_he[sm, 1]]
    corr = 0.75 * ((net.w[sm, 0] - 0.5)[:, None] * (A[sm] - B[sm]) + (net.w[sm, 1] - 0.5)[:, None] * (B[sm] - A[sm]))
    corr[net.smoothx[sm]] = 0.0
    if rule == "standard":
        E[sm] = 0.25 * (A[sm] + B[sm] + C[f1] + C[f2]) + corr
    elif rule == "rhino":
        n1, n2 = net.fsize[f1][:, None].astype(float), net.fsize[f2][:, None].astype(float)
        AB = A[sm] + B[sm]
        E[sm] = 0.375 * AB + (n1 * C[f1] - AB) / (8 * (n1 - 2)) + (n2 * C[f2] - AB) / (8 * (n2 - 2)) + corr
    else:
        raise ValueError(f"rule must be 'standard' or 'rhino', got {rule!r}.")
    n, nbr, cn = _neighbour_sums(net)
    fsum = np.zeros_like(P)
    np.add.at(fsum, fv, C[cf])
    with np.errstate(divide="ignore", invalid="ignore"):
        V = ((n - 2.0) / n)[:, None] * P + (nbr + fsum) / (n * n)[:, None]
    isc, unused = net.is_crease_vertex, net.valence == 0
    V[isc] = (6.0 * P[isc] + cn[isc]) / 8.0
    V[unused] = P[unused]
    newP = np.concatenate([V, E, C])
    quads = np.stack([fv, nv + net.he_edge, nv + ne + cf, nv + net.he_edge[net.pv]], axis=1)
    nv2 = newP.shape[0]

    def halves(idx):  # keys of the two halves of edges idx: (old end, edge point), the old end the lower
        return np.concatenate([_edge_keys(net.edges[idx, k], nv + idx, nv2) for k in (0, 1)])

    # inherited sector coefficients: the half at a tagged end keeps that end's w
    ti = np.flatnonzero(sm & (net.w != 0.5).any(axis=1))
    keys, wl = halves(ti), np.concatenate([net.w[ti, 0], net.w[ti, 1]])
    order = np.argsort(keys)
    return _build(newP, quads.ravel(), np.full(quads.shape[0], 4), np.sort(halves(np.flatnonzero(net.crease))),
                  (keys[order], wl[order], np.full(keys.size, 0.5)))


def limit_points(net: SubdNet) -> tuple:
    """Limit points of the vertices of an all-quad net, and where the formula is exact.

    Smooth vertex of valence ``n``: ``(n^2 V + 4 sum E + sum D) / (n (n + 5))`` [HalsteadKass1993];
    crease vertex: ``(4 V + A1 + A2) / 6``. The formula is exact where the edges at the vertex all follow the
    standard rule at both ends (``exact``); next to an irregular crease sector it is the approximation
    Rhino's SubD also uses.

    >>> L, exact = limit_points(make_net(*_torus(6, 8)))
    >>> bool(exact.all())
    True
    """
    if not net.all_quads:
        raise ValueError("limit points need an all-quad net (subdivide once first).")
    P, fv, nx = net.points, net.fv, net.nx
    n, nbr, cn = _neighbour_sums(net)
    dia = np.zeros_like(P)
    np.add.at(dia, fv, P[fv[nx[nx]]])
    with np.errstate(divide="ignore", invalid="ignore"):
        L = ((n * n)[:, None] * P + 4.0 * nbr + dia) / (n * (n + 5.0))[:, None]
    isc, unused = net.is_crease_vertex, net.valence == 0
    L[isc] = (4.0 * P[isc] + cn[isc]) / 6.0
    L[unused] = P[unused]
    return L, (_standard_vertices(net) | isc) & ~unused


def _neighbour_sums(net: SubdNet) -> tuple:
    """Valences, sums of the edge neighbours and sums of the crease neighbours of each vertex."""
    P, E = net.points, net.edges
    nbr, cn = np.zeros_like(P), np.zeros_like(P)
    np.add.at(nbr, E, P[E[:, ::-1]])
    np.add.at(cn, E[net.crease], P[E[net.crease][:, ::-1]])
    return net.valence.astype(np.float64), nbr, cn


def _standard_vertices(net: SubdNet) -> np.ndarray:
    """Vertices all of whose edges follow the standard smooth rule at both ends (w = 1/2)."""
    std = np.ones(net.points.shape[0], dtype=bool)
    std[net.edges[(net.w != 0.5).any(axis=1)].ravel()] = False
    return std


def _regular_faces(net: SubdNet) -> np.ndarray:
    """Quads whose 4 x 4 neighbourhood is a uniform bicubic B-spline net (phantom rows at creases)."""
    nv = net.points.shape[0]
    fc = np.bincount(net.fv, minlength=nv)
    quads_at = np.bincount(net.fv, weights=(net.fsize[net.cf] == 4).astype(float), minlength=nv)
    smooth_reg = (net.n_crease == 0) & (net.valence == 4) & (fc == 4) & (quads_at == 4)
    # regular crease (or boundary) vertex: every sector has two quads (w = 1/2)
    sec2 = np.bincount(net.fv, weights=(net.sector_size[net.sector] == 2).astype(float), minlength=nv)
    crease_reg = net.is_crease_vertex & (fc > 0) & (sec2 == fc) & (quads_at == fc)
    # a corner is fine if regular and every edge at it follows the standard rule at both ends
    ok_v = (smooth_reg | crease_reg) & _standard_vertices(net)
    return np.logical_and.reduceat(ok_v[net.fv], net.fstart) & (net.fsize == 4)


def _bspline_nets(net: SubdNet, faces: np.ndarray) -> np.ndarray:
    """The (len(faces), 4, 4, 3) B-spline nets of regular quads, ``N[s, t]``, the face at [1:3, 1:3]."""
    fv, nx, pv, twin, P = net.fv, net.nx, net.pv, net.twin, net.points
    c = net.fstart[faces][:, None] + np.arange(4)  # corners c_i at v_i, half-edge c_i: v_i -> v_{i+1}
    crease_side = net.crease[net.he_edge[c]]
    t = np.where(crease_side, c, twin[c])  # (safe index where crease: itself, fixed below)
    x = fv[nx[nx[t]]]  # outer neighbour of v_i across side i
    y = fv[pv[t]]  # outer neighbour of v_{i+1} across side i
    tt = twin[nx[t]]
    d = fv[pv[np.where(tt >= 0, tt, t)]]  # diagonal at v_i (valid when sides i-1 and i are smooth)
    I, v = np.empty((faces.size, 4, 4), dtype=np.int64), fv[c]
    # corners v_i at (1,1) (2,1) (2,2) (1,2); x_i, y_i outside side i; d_i the diagonal outside corner i
    for k, (a, b) in enumerate([(1, 1), (2, 1), (2, 2), (1, 2), (1, 0), (3, 1), (2, 3), (0, 2), (2, 0), (3, 2),
                                (1, 3), (0, 1), (0, 0), (3, 0), (3, 3), (0, 3)]):
        I[:, a, b] = (v, x, y, d)[k // 4][:, k % 4]
    N, side = P[I], [crease_side[:, i][:, None, None] for i in range(4)]
    # phantom rows across crease (or boundary) sides; at most one of two adjacent sides is a crease
    N[:, :, 0] = np.where(side[0], 2 * N[:, :, 1] - N[:, :, 2], N[:, :, 0])
    N[:, :, 3] = np.where(side[2], 2 * N[:, :, 2] - N[:, :, 1], N[:, :, 3])
    N[:, 3, :] = np.where(side[1], 2 * N[:, 2, :] - N[:, 1, :], N[:, 3, :])
    N[:, 0, :] = np.where(side[3], 2 * N[:, 1, :] - N[:, 2, :], N[:, 0, :])
    return N


def _child_grids(net: SubdNet, G: np.ndarray) -> np.ndarray:
    """Grids of fine vertex indices of this net's quads from those of its children (one level finer)."""
    m, quads = G.shape[1] - 1, np.flatnonzero(net.fsize == 4)
    out = np.full((net.fsize.size, 2 * m + 1, 2 * m + 1), -1, dtype=np.int64)
    ii, jj = np.meshgrid(np.arange(m + 1), np.arange(m + 1), indexing="ij")
    ch, sub = net.fstart[quads], out[quads]  # child i of a quad sits at its corner i, turned by i quarters
    sub[:, ii, jj] = G[ch]
    sub[:, 2 * m - jj, ii] = G[ch + 1]
    sub[:, 2 * m - ii, 2 * m - jj] = G[ch + 2]
    sub[:, jj, 2 * m - ii] = G[ch + 3]
    out[quads] = sub
    return out


def _bernstein(t: np.ndarray) -> np.ndarray:
    t = np.asarray(t, dtype=np.float64)
    s = 1.0 - t  # cubic Bernstein polynomials
    return np.stack([s ** 3, 3 * s * s * t, 3 * s * t * t, t ** 3], axis=-1)


def _evaluate_bezier(Bz: np.ndarray, m: int) -> np.ndarray:
    """Bicubic Bézier patches ``(n, 4, 4, 3)`` at the ``(m + 1)^2`` grid ``(i/m, j/m)``."""
    Bt = _bernstein(np.arange(m + 1) / m)
    return np.einsum("ia,nabk,jb->nijk", Bt, Bz, Bt)


@dataclass(frozen=True, eq=False)
class SubdPatches:
    """The result of :func:`subd_patches`: patches, which are exact, and the measurements.

    ``deviation`` per patch: max distance from the limit points at its sample grid; ``gap``: the largest
    distance between two patches at a shared boundary sample; ``open_samples``: boundary samples of one
    patch only (0 for a closed net); ``diagonal``: the limit points' bounding-box diagonal.

    >>> r = subd_patches(*_cube(), levels=1)
    >>> r.summary().split(";")[0]
    '24 patches (0 exact, 24 approximate)'
    """

    surfaces: list
    exact: np.ndarray
    level: np.ndarray
    deviation: np.ndarray
    gap_exact: float
    gap: float
    open_samples: int
    diagonal: float
    seconds: float

    def summary(self) -> str:
        """One line: counts, deviations and gaps relative to the diagonal, time.

        >>> "gaps" in subd_patches(*_torus(4, 5), levels=1).summary()
        True
        """
        d = self.diagonal
        ex, ap = self.deviation[self.exact], self.deviation[~self.exact]
        return (f"{len(self.surfaces)} patches ({int(self.exact.sum())} exact, {int((~self.exact).sum())} approximate)"
                f"; deviation from the limit surface: exact max {ex.max(initial=0) / d:.2e}, approximate max "
                f"{ap.max(initial=0) / d:.2e} rms {np.sqrt(np.mean(ap ** 2)) / d if ap.size else 0.0:.2e} of the "
                f"diagonal; gaps {self.gap / d:.2e} (between exact patches {self.gap_exact / d:.2e}); "
                f"{self.open_samples} open boundary samples; {self.seconds:.2f} s")


def subd_patches(vertices, faces, creases=None, levels: int = 2, fit_depth: int = 2, name: str = "subd",
                 measure: bool = True, rule: str = "standard") -> SubdPatches:
    """Bicubic patches of the Catmull–Clark limit surface of a control net, with measurements.

    ``vertices`` (n, 3); ``faces`` vertex-index lists (any polygons, counter-clockwise from outside);
    ``creases`` (m, 2) vertex pairs (boundary edges are creases anyway); ``levels`` >= 1 subdivision steps
    before the remaining irregular faces are approximated, fitted to limit points ``fit_depth`` >= 2 levels
    deeper; ``measure``: deviation (``fit_depth + 1`` levels below each patch) and gaps; ``rule``: the
    edge rule next to non-quad faces (see :func:`catmull_clark`).

    >>> r = subd_patches(*_torus(6, 8), levels=1)
    >>> len(r.surfaces), bool(r.exact.all()), bool(r.deviation.max() < 1e-12 * r.diagonal), r.open_samples
    (48, True, True, 0)
    """
    t0 = time.perf_counter()
    for what, val, low in (("levels", levels, 1), ("fit_depth", fit_depth, 2)):
        if isinstance(val, bool) or not isinstance(val, (int, np.integer)) or val < low:
            raise ValueError(f"{what} must be an integer >= {low}, got {val!r}.")
    k, nets = int(levels), [make_net(vertices, faces, creases)]
    depth = k + fit_depth + (1 if measure else 0)
    for _ in range(depth):
        nets.append(catmull_clark(nets[-1], rule))
    covered, emit = np.zeros(nets[0].fsize.size, dtype=bool), []  # which faces are emitted where
    for lev in range(k + 1):
        reg = _regular_faces(nets[lev]) & ~covered
        emit.append((reg, (~covered & ~reg) if lev == k else np.zeros_like(reg)))
        covered = (covered | reg)[nets[lev].cf]  # child face c (one per corner c) lies in face cf[c]
    G, nd = [None] * (depth + 1), nets[depth]  # G[lev]: grids of level-lev faces in level-depth vertices
    G[depth] = nd.fv[nd.fstart[:, None, None] + np.array([[0, 3], [1, 2]])]
    for lev in range(depth - 1, -1, -1):
        G[lev] = _child_grids(nets[lev], G[lev + 1])
    Lp, Lexact = limit_points(nd)
    diag = float(np.linalg.norm(np.ptp(Lp[np.bincount(nd.fv, minlength=Lp.shape[0]) > 0], axis=0)))
    exact, level, beziers, grids = [], [], [], []
    for lev in range(k + 1):
        for is_exact, mask in zip((True, False), emit[lev]):
            f = np.flatnonzero(mask)
            if not f.size:
                continue
            step = 2 ** (depth - lev - fit_depth)  # the grids of level lev + fit_depth
            beziers.append(np.einsum("ia,nabk,jb->nijk", _M, _bspline_nets(nets[lev], f), _M) if is_exact else
                           _fit_patches(nets[lev], f, nets[lev + fit_depth], G[lev][f][:, ::step, ::step]))
            grids.append(G[lev][f])
            exact += [is_exact] * f.size
            level += [lev] * f.size
    exact, level = np.array(exact, dtype=bool), np.array(level, dtype=np.int64)
    Ball = np.concatenate(beziers) if beziers else np.zeros((0, 4, 4, 3))
    surfaces = [NurbsSurface((3, 3), (_BEZIER_KNOTS,) * 2, Bz, name=f"{name} {'exact' if e else 'approx'} {i}")
                for i, (Bz, e) in enumerate(zip(Ball, exact))]
    deviation, gap, gap_exact, open_samples = np.zeros(len(surfaces)), 0.0, 0.0, 0
    if measure and len(surfaces):
        deviation, gap, gap_exact, open_samples = _measure(Ball, grids, exact, Lp, Lexact)
    return SubdPatches(surfaces, exact, level, deviation, gap_exact, gap, open_samples, diag,
                       time.perf_counter() - t0)


def _fit_patches(net: SubdNet, faces: np.ndarray, fine: SubdNet, g: np.ndarray) -> np.ndarray:
    """Bézier points of approximate patches: corners = limit points, sides and inside fitted (least squares);
    ``g`` the faces' grids of vertex indices of the ``fine`` net."""
    Lf, Lf_exact = limit_points(fine)
    m = g.shape[1] - 1
    X, Wt, Bt = Lf[g], Lf_exact[g].astype(np.float64), _bernstein(np.arange(m + 1) / m)
    Bz = np.zeros((faces.size, 4, 4, 3))
    Bz[:, 0, 0], Bz[:, 3, 0], Bz[:, 3, 3], Bz[:, 0, 3] = X[:, 0, 0], X[:, m, 0], X[:, m, m], X[:, 0, m]
    # sides, fitted once per edge in the direction low vertex -> high vertex
    c = net.fstart[faces][:, None] + np.arange(4)
    e = net.he_edge[c]  # (n, 4)
    S, SW = (np.stack([Y[:, :, 0], Y[:, m, :], Y[:, ::-1, m], Y[:, 0, ::-1]], axis=1) for Y in (X, Wt))
    forward = net.fv[c] == net.edges[e, 0]  # side runs low -> high (sides v0v1, v1v2, v2v3, v3v0)
    S = np.where(forward[..., None, None], S, S[:, :, ::-1])
    SW = np.where(forward[..., None], SW, SW[:, :, ::-1])
    ue, first = np.unique(e.ravel(), return_index=True)
    Se, We = S.reshape(-1, m + 1, 3)[first], SW.reshape(-1, m + 1)[first]
    We[:, [0, m]] = 0.0
    We[We[:, 1:m].sum(axis=1) < 2, 1:m] = 1.0  # too few exact samples: use every one
    r = Se - Bt[None, :, 0, None] * Se[:, :1] - Bt[None, :, 3, None] * Se[:, m:]
    Bi = Bt[:, 1:3]
    A, rhs = np.einsum("ej,ja,jb->eab", We, Bi, Bi), np.einsum("ej,ja,ejk->eak", We, Bi, r)
    inner = np.linalg.pinv(A) @ rhs  # (ne, 2, 3); pinv: safe if few samples are exact
    cv = np.concatenate([Se[:, :1], inner, Se[:, m:]], axis=1)[np.searchsorted(ue, e)]  # (n, 4, 4, 3)
    cv = np.where(forward[..., None, None], cv, cv[:, :, ::-1])
    Bz[:, :, 0], Bz[:, 3, :], Bz[:, ::-1, 3], Bz[:, 0, ::-1] = cv[:, 0], cv[:, 1], cv[:, 2], cv[:, 3]
    # inside: least squares over the interior samples with the boundary fixed
    basis = np.einsum("ia,jb->ijab", Bt, Bt)  # (m+1, m+1, 4, 4)
    fixed = np.ones((4, 4), dtype=bool)
    fixed[1:3, 1:3] = False
    rI = X - np.einsum("ijab,nabk->nijk", basis * fixed, Bz)
    Wi = np.zeros_like(Wt)
    Wi[:, 1:m, 1:m] = Wt[:, 1:m, 1:m]
    Wi[Wi.sum(axis=(1, 2)) < 4, 1:m, 1:m] = 1.0
    Q = basis[:, :, 1:3, 1:3].reshape(m + 1, m + 1, 4)
    A, rhs = np.einsum("nij,ija,ijb->nab", Wi, Q, Q), np.einsum("nij,ija,nijk->nak", Wi, Q, rI)
    Bz[:, 1:3, 1:3] = (np.linalg.pinv(A) @ rhs).reshape(-1, 2, 2, 3)
    return Bz


def _measure(Ball, grids, exact, Lp, Lexact):
    """Deviation per patch (at limit points one level below the fit) and gaps at shared boundary samples."""
    dev, ids, pts, ex, start = np.zeros(Ball.shape[0]), [], [], [], 0
    for g in grids:
        n, m = g.shape[0], g.shape[1] - 1
        S = _evaluate_bezier(Ball[start:start + n], m)
        d = np.where(Lexact[g], np.linalg.norm(S - Lp[g], axis=-1), 0.0)
        dev[start:start + n] = d.reshape(n, -1).max(axis=1)
        border = np.ones((m + 1, m + 1), dtype=bool)
        border[1:m, 1:m] = False
        ids.append(g[:, border].ravel())
        pts.append(S[:, border].reshape(-1, 3))
        ex.append(np.repeat(exact[start:start + n], border.sum()))
        start += n
    ids, pts, ex = np.concatenate(ids), np.concatenate(pts), np.concatenate(ex)
    order = np.argsort(ids, kind="stable")
    ids, pts, ex = ids[order], pts[order], ex[order]
    _, first, counts = np.unique(ids, return_index=True, return_counts=True)
    ref = np.repeat(first, counts)  # every sample against the first one of its vertex
    dist = np.linalg.norm(pts - pts[ref], axis=1)
    return dev, float(dist.max(initial=0.0)), float(dist[ex & ex[ref]].max(initial=0.0)), int((counts == 1).sum())


def subd_to_surfaces(vertices, faces, creases=None, levels: int = 2, fit_depth: int = 2,
                     name: str = "subd", rule: str = "standard") -> list:
    """Bicubic :class:`NurbsSurface` patches of a Catmull–Clark net (see :func:`subd_patches`).

    >>> len(subd_to_surfaces(*_cube(), levels=1))
    24
    """
    return subd_patches(vertices, faces, creases, levels, fit_depth, name, measure=False, rule=rule).surfaces


# --------------------------------------------------------------------------------------------------
# Rhino SubD objects (rhino3dm)

def _rhino_items(it):
    """Items of a rhino3dm SubD component iterator (its ``Next`` never returns None: count instead)."""
    n = it.Count
    return [it.First() if k == 0 else it.Next() for k in range(n)]


def subd_net_from_rhino(subd) -> tuple:
    """``(vertices, faces, creases)`` of a rhino3dm ``SubD``; ValueError for what is not supported.

    >>> import rhino3dm
    >>> subd_net_from_rhino(rhino3dm.SubD())[0].shape
    (0, 3)
    """
    V = _rhino_items(subd.Vertices)
    index = {v.Id: i for i, v in enumerate(V)}
    pts = np.array([[v.ControlNetPoint.X, v.ControlNetPoint.Y, v.ControlNetPoint.Z] for v in V]).reshape(-1, 3)
    E = _rhino_items(subd.Edges)
    for kind, items, ok in (("vertex", V, ("Smooth", "Crease")), ("edge", E, ("Smooth", "SmoothX", "Crease"))):
        for x in items:
            tag, sharp = str(x.Tag).rsplit(".", 1)[-1], x.VertexSharpness if kind == "vertex" else x.IsSharp
            if tag not in ok or sharp:
                raise ValueError(f"SubD {kind} {x.Id} is {'semi-sharp' if sharp else 'tagged ' + tag}; only "
                                 f"{', '.join(ok)} {kind}s without sharpness are supported.")
    faces = [[index[f.Vertex(i).Id] for i in range(f.VertexCount)] for f in _rhino_items(subd.Faces)]
    creases = [(index[e.VertexId(0)], index[e.VertexId(1)]) for e in E if str(e.Tag).endswith("Crease")]
    return pts, faces, creases


def subd_object_surfaces(subd, name: str, levels: int = 2, fit_depth: int = 2) -> list:
    """Bicubic patches of a rhino3dm ``SubD`` (named ``"<name> exact|approx <k>"``); ValueError if unsupported.

    >>> import rhino3dm
    >>> subd_object_surfaces(rhino3dm.SubD(), "empty")
    Traceback (most recent call last):
    ValueError: every face needs at least 3 vertices (and there must be faces).
    """
    pts, faces, creases = subd_net_from_rhino(subd)
    return subd_to_surfaces(pts, faces, creases, levels, fit_depth, name, rule="rhino")


def read_subd_objects(objects, levels: int = 2, fit_depth: int = 2) -> tuple:
    """``(surfaces, names, skipped)`` of the SubD objects of a ``File3dm.Objects`` table.

    ``skipped`` maps object names to the reason (unsupported tags, sharpness).

    >>> import rhino3dm
    >>> read_subd_objects(rhino3dm.File3dm().Objects)
    ([], [], {})
    """
    import rhino3dm

    surfaces, names, skipped = [], [], {}
    for obj in (o for o in objects if isinstance(o.Geometry, rhino3dm.SubD)):
        name = obj.Attributes.Name or str(obj.Attributes.Id)
        try:
            s = subd_object_surfaces(obj.Geometry, name, levels, fit_depth)
        except ValueError as err:
            skipped[name] = str(err)
            continue
        surfaces, names = surfaces + s, names + [x.name for x in s]
    return surfaces, names, skipped


# --------------------------------------------------------------------------------------------------
# small nets for examples and tests

def _cube():
    """The unit cube's control net: 8 vertices of valence 3, 6 quads (outward)."""
    V = [[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)]
    return V, [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]


def _torus(nu: int = 6, nv: int = 8, R: float = 3.0, r: float = 1.0):
    """A torus-like all-quad net, every vertex of valence 4."""
    A, B = np.meshgrid(2 * np.pi * np.arange(nu) / nu, 2 * np.pi * np.arange(nv) / nv, indexing="ij")
    V = np.stack([(R + r * np.cos(B)) * np.cos(A), (R + r * np.cos(B)) * np.sin(A), r * np.sin(B)], axis=-1)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij"))
    F = np.stack([i * nv + j, (i + 1) % nu * nv + j, (i + 1) % nu * nv + (j + 1) % nv, i * nv + (j + 1) % nv], 1)
    return V.reshape(-1, 3), F.tolist()

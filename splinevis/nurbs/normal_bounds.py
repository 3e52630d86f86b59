r"""Proven bounds of the angle between the normal a tessellated NURBS model shades with and the surface's exact
normal: the per-cell derivative bounds shared by the uniform tessellation's renderer
(:func:`splinevis.nurbs.renderers.normal_bounds`, whose docstring derives the cone, first-order and second-order
bounds and the seams) and the levels of detail of the walkthrough (:func:`lod_normal_bounds`, stored as
``LodModel.normal_bounds`` by :func:`splinevis.nurbs.lod.levels.build_lod`) [Kumar1997, sec. 3, 4].

Cells (:func:`_cells`). Every Bezier patch is cut into ``r x r`` cells of its local domain ``[0, 1]^2``; on each,
the Bernstein net of the sub-patch gives bounds of the surface's first and second derivatives and of the unit
normal's, ``N = (|n_u|, |n_v|, |n_uu|, |n_uv|, |n_vv|)`` (inf where the cell's pseudo-Gauss net has no cone or
touches zero: a pole, a fold), valid at every point of the cell (module docstring of
:mod:`splinevis.nurbs.renderers`).

The levels of detail (:func:`lod_normal_bounds`). A level's triangles are made per patch (the adaptive
tessellation of :mod:`splinevis.nurbs.lod.adaptive`: any triangle of the patch's local domain, not a grid), and
each vertex carries an exact unit normal of ONE patch (``LodModel.normals``: a vertex interior to a patch its
own; a vertex on an edge chain that of the edge's first side; a corner that of the first patch of its cluster of
corners; where ``S_u x S_v`` vanishes, the normal ``1e-6`` of the domain inside: *nudged*). For a triangle ``T``
of patch ``P`` with the bounding box ``du x dv`` of its domain triangle, ``N`` the maxima over the cells the box
meets, a point ``p`` of ``T`` and the shading normal ``m`` (the normalized barycentric combination of the stored
normals ``n_i``):

* **seams**: ``sigma_i`` bounds the angle between ``n_i`` and ``P``'s own normal at the vertex: 0 for a vertex whose
  normal is ``P``'s; on side ``k`` of ``P`` shared with the edge's first side ``Q``, the angle ``phi`` between the two
  sides' one-sided normals along the edge, from the Bernstein coefficients ``a(t), b(t)`` of the side rows of their
  pseudo-Gauss nets (aligned when one side runs against the other): ``a x b = 0`` and ``a . b >= 0`` means the same
  normals, else ``sin phi <= max |(a x b)_l| / (min a_l . alpha  min b_l . beta)``
  (:func:`_seam_angle`; inf when a minimum is not positive: a crease); at a corner, the shortest path of such
  ``phi`` from the cluster's first patch to ``P`` through the edges that meet there (the triangle inequality of
  angles; inf when none joins them), and the ``phi`` of both sides; inf for a nudged vertex or one on a collapsed
  side (a pole). ``sigma = max_i sigma_i``.
* **first order**: the angle between ``n(p)`` and ``P``'s normal at a vertex is at most the length of the path of
  ``n`` along the segment between them (in ``T``), ``rho = N_u du + N_v dv``; each ``n_i`` is within
  ``rho + sigma`` of ``n(p)``, and so is ``m`` while that is below 90 degrees (the cap is convex).
* **second order**: ``|sum l_i n_P(p_i) - n(p)| <= e = (du^2 N_uu + 2 du dv N_uv + dv^2 N_vv) / 8`` (eq. (4) of
  :mod:`splinevis.nurbs.lod.bounds`, which holds for any triangle with its bounding box, applied to the vector
  function ``n``), and ``|n_i - n_P(p_i)| <= sigma_i`` (a chord is shorter than its arc): ``m`` is within
  ``arcsin(e + sigma)`` of ``n(p)`` while ``e + sigma < 1``.
* **cone** (where the other two exceed 0.1 radians or fail, largest first, at most :data:`LOD_CONE_BUDGET`
  triangles): the normal cone ``(alpha, theta)`` of ``P``'s sub-patch on ``T``'s box holds every ``n(p)`` (poles
  too: limits in the closed cone); the angles ``beta_i`` between the *stored* ``n_i`` and ``alpha`` are measured,
  so ``m`` is within ``theta + max beta_i`` of ``n(p)`` while ``max beta_i < 90`` degrees. No seam argument is
  needed: this covers poles, nudged normals and corners.

The smallest of these holds; a bound of 90 degrees or more is reported as inf (it bounds nothing useful: a
crease). **Fans of the assembly** (:func:`splinevis.nurbs.lod.levels.assemble`) split a triangle whose side
``a b`` lies on a border edge at the finer chain's points ``x_j``, all on the same side of ``P`` between ``a`` and
``b``: each piece lies in the old domain triangle, so its box, extents and cells are within the old ones, and the
``x_j`` carry the edge's first side's normal, within ``phi`` of ``P``'s as ``a`` and ``b`` are (``sigma`` already
holds it; for the cone, ``beta <= phi + theta``). A fan on an edge with a nudged chain vertex, or whose side is not
on a side of ``P``, is inf. **Not bounded** (inf): levels simplified across patches (``simplified > 0``: the
triangles are no longer per patch) and super-surfaces with a patch clipped by trim curves (the clipped
triangles and stitched vertices are not followed here). Float64 rounding (the nets' ~1e-15 relative, the
parameters ``1 - t`` of reversed sides) is far below the float32 term ``8 u`` a renderer adds.
"""

from __future__ import annotations

import math

import numpy as np

from .model import NurbsModel
from .surface import NurbsSurface

__all__ = ["CELL_BUDGET", "LOD_CELL_BUDGET", "LOD_CONE_BUDGET", "lod_normal_bounds"]


EPS = np.finfo(float).eps
#: Most cells a model is cut into for the uniform tessellation's bounds (each patch ``r x r``, ``2 <= r <= 16``).
CELL_BUDGET = 65_536

_CHUNK = 4096  # boxes per block of subdivision (bounded memory for degree 7)


def _model(model) -> NurbsModel:
    return NurbsModel([model], source=model.name) if isinstance(model, NurbsSurface) else model


def _widen(bs) -> np.ndarray:
    """``(P, 2)``: the rounding of ``at_fraction``'s ``a + t (b - a)`` (and of its clamp) in the parent's parameters,
    in each patch's local ones (the cells are widened by it)."""
    rect = bs.rect
    du = 4 * EPS * (np.abs(rect[:, 0]) + np.abs(rect[:, 1])) / (rect[:, 1] - rect[:, 0]) + 4 * EPS
    dv = 4 * EPS * (np.abs(rect[:, 2]) + np.abs(rect[:, 3])) / (rect[:, 3] - rect[:, 2]) + 4 * EPS
    return np.column_stack([du, dv])


def _bezier(model, cache):
    from .lod.bezier import bezier_set

    if "nurbs_bezier" not in cache:
        bs = bezier_set(_model(model))
        cache["nurbs_bezier"] = (bs, _widen(bs))
    return cache["nurbs_bezier"]


def _grid_boxes(n: int, widen: np.ndarray) -> np.ndarray:
    """``(N, n, n, 4)`` boxes ``(u0, u1, v0, v1)`` of the ``n x n`` grid of ``[0, 1]^2``, widened by ``widen (N, 2)``
    and clipped to ``[0, 1]``."""
    a, b = np.arange(n) / n, (np.arange(n) + 1.0) / n
    u0 = np.clip(a[None, :] - widen[:, :1], 0.0, 1.0)
    u1 = np.clip(b[None, :] + widen[:, :1], 0.0, 1.0)
    v0 = np.clip(a[None, :] - widen[:, 1:], 0.0, 1.0)
    v1 = np.clip(b[None, :] + widen[:, 1:], 0.0, 1.0)
    N = widen.shape[0]
    box = np.empty((N, n, n, 4))
    box[..., 0], box[..., 1] = u0[:, :, None], u1[:, :, None]
    box[..., 2], box[..., 3] = v0[:, None, :], v1[:, None, :]
    return box


def _sub_nets(C: np.ndarray, box: np.ndarray):
    """Yield ``(rows, Q)``: the Bernstein nets ``Q (B, m + 1, n + 1, 4)`` of the patches ``C (N, ...)`` on
    ``box (N, n, n, 4)``, flattened (patch-major), in blocks of at most ``_CHUNK``."""
    from .lod.bounds import subdivide

    N, g = box.shape[0], box.shape[1] * box.shape[2]
    item = np.repeat(np.arange(N), g)
    flat = box.reshape(-1, 4)
    for a in range(0, flat.shape[0], _CHUNK):
        rows = slice(a, min(a + _CHUNK, flat.shape[0]))
        yield rows, subdivide(C[item[rows]], flat[rows])


def _diff_norm(Q: np.ndarray, axis: int, order: int) -> np.ndarray:
    """``max |Delta^order Q|`` along ``axis`` (1: s, 2: t) per net ``(B, ., ., c)`` (0 if the degree is lower)."""
    if Q.shape[axis] <= order:
        return np.zeros(Q.shape[0])
    D = np.diff(Q, n=order, axis=axis)
    return np.linalg.norm(D, axis=-1).reshape(Q.shape[0], -1).max(axis=1)


def _cell_derivatives(Q: np.ndarray, size: np.ndarray, mag: np.ndarray) -> dict:
    """Bounds over each cell of ``|F_u|, |F_v|`` (``f``, (B, 2)) and ``|F_uu|, |F_uv|, |F_vv|`` (``M``, (B, 3)) in the
    patch's local parameters, the hull box ``lo, hi`` of the cell's control points, from its nets ``Q`` and the cell
    sizes ``size (B, 2)`` and the magnitudes ``mag (B, 2)`` (largest ``|w P|`` and ``w``) of their patches' nets
    (derivation: :func:`splinevis.nurbs.renderers.chord_bounds`); also the nets shifted to the cells' centres."""
    m, n = Q.shape[1] - 1, Q.shape[2] - 1
    B = Q.shape[0]
    w = Q[..., 3]
    P = Q[..., :3] / w[..., None]
    Pf = P.reshape(B, -1, 3)
    lo, hi = Pf.min(axis=1), Pf.max(axis=1)
    c = 0.5 * (lo + hi)
    R = np.linalg.norm(Pf - c[:, None, :], axis=-1).max(axis=1)
    A = Q[..., :3] - c[:, None, None, :] * w[..., None]
    # rounding (worst case, [Higham2002, sec. 3.1]): the subdivided coefficients are convex combinations of the
    # patch's, off by (m + n + 4) eps times the patch's largest; forming A adds |c| times the weight's error
    eW = (m + n + 4) * EPS * mag[:, 1]
    eQ = 2.0 * (m + n + 4) * EPS * mag[:, 0] + 2.0 * np.linalg.norm(c, axis=1) * eW
    wmin = w.reshape(B, -1).min(axis=1) - eW
    R = R + 2.0 * eQ / wmin
    W = w[..., None]
    a1 = m * (_diff_norm(A, 1, 1) + 2 * eQ)
    a2 = n * (_diff_norm(A, 2, 1) + 2 * eQ)
    b1 = m * (_diff_norm(W, 1, 1) + 2 * eW)
    b2 = n * (_diff_norm(W, 2, 1) + 2 * eW)
    mixed = lambda X: np.linalg.norm(np.diff(np.diff(X, axis=1), axis=2), axis=-1).reshape(B, -1).max(axis=1)  # noqa: E731
    a11 = m * (m - 1) * (_diff_norm(A, 1, 2) + 4 * eQ)
    a22 = n * (n - 1) * (_diff_norm(A, 2, 2) + 4 * eQ)
    a12 = m * n * (mixed(A) + 4 * eQ)
    b11 = m * (m - 1) * (_diff_norm(W, 1, 2) + 4 * eW)
    b22 = n * (n - 1) * (_diff_norm(W, 2, 2) + 4 * eW)
    b12 = m * n * (mixed(W) + 4 * eW)
    f1, f2 = (a1 + b1 * R) / wmin, (a2 + b2 * R) / wmin
    M1 = (a11 + b11 * R + 2.0 * b1 * f1) / wmin
    M2 = (a12 + b12 * R + b1 * f2 + b2 * f1) / wmin
    M3 = (a22 + b22 * R + 2.0 * b2 * f2) / wmin
    hs, ht = size[:, 0], size[:, 1]
    slack = 1.0 + 1e-12  # the arithmetic of the lines above: a few roundings, relative
    M = np.column_stack([M1 / (hs * hs), M2 / (hs * ht), M3 / (ht * ht)]) * slack
    return {"M": M, "f": np.column_stack([f1 / hs, f2 / ht]) * slack, "lo": lo, "hi": hi,
            "shifted": np.concatenate([A, W], axis=-1)}


def _cell_normals(Q: np.ndarray, size: np.ndarray):
    """``(B, 5)`` bounds of ``|n_u|, |n_v|, |n_uu|, |n_uv|, |n_vv|`` over each cell (patch-local parameters; inf
    where the cell's pseudo-Gauss net has no cone or touches zero), derivation:
    :func:`splinevis.nurbs.renderers.normal_bounds`; the net's four side rows ``(B, 4, d + 1, 3)`` (s = 0, s = 1,
    t = 0, t = 1: the one-sided normals along the cell's sides)."""
    from .lod.gauss import normal_cone, pseudo_gauss_net

    G = pseudo_gauss_net(Q, rational=True)  # one degree for every net of a group (the seams compare them)
    B, a, b = G.shape[0], G.shape[1] - 1, G.shape[2] - 1
    axis, half = normal_cone(G.reshape(B, -1, 3))
    g = np.einsum("bklc,bc->bkl", G, axis).reshape(B, -1).min(axis=1)
    g1, g2 = a * _diff_norm(G, 1, 1), b * _diff_norm(G, 2, 1)
    mixed = np.linalg.norm(np.diff(np.diff(G, axis=1), axis=2), axis=-1).reshape(B, -1).max(axis=1)
    g11, g12, g22 = a * (a - 1) * _diff_norm(G, 1, 2), a * b * mixed, b * (b - 1) * _diff_norm(G, 2, 2)
    ok = (half < 0.5 * math.pi) & (g > 0)
    hs, ht = size[:, 0], size[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        nu, nv = g1 / g, g2 / g
        out = np.column_stack([nu / hs, nv / ht, (2 * g11 + 3 * g1 * nu) / g / (hs * hs),
                               (2 * g12 + 3 * g1 * nv) / g / (hs * ht), (2 * g22 + 3 * g2 * nv) / g / (ht * ht)])
    return np.where(ok[:, None], out, np.inf), (G[:, 0], G[:, -1], G[:, :, 0], G[:, :, -1])


def _square(Q: np.ndarray) -> np.ndarray:
    """The nets ``Q (B, m + 1, n + 1, 4)`` degree-raised to ``max(m, n)`` in both directions (the same surface
    [Farin2002, ch. 5]), so that the side rows of every net of a group have one length."""
    for axis in (1, 2):
        while Q.shape[axis] < max(Q.shape[1], Q.shape[2]):
            m = Q.shape[axis] - 1
            a = (np.arange(m + 2) / (m + 1)).reshape((1, -1, 1, 1) if axis == 1 else (1, 1, -1, 1))
            lo = np.concatenate([np.zeros_like(np.take(Q, [0], axis=axis)), Q], axis=axis)
            hi = np.concatenate([Q, np.zeros_like(np.take(Q, [0], axis=axis))], axis=axis)
            Q = a * lo + (1.0 - a) * hi
    return Q


def _product(a: np.ndarray, b: np.ndarray, op) -> np.ndarray:
    """Bernstein coefficients ``(S, 2d + 1, c)`` of ``op(a(t), b(t))`` for curves ``a, b (S, d + 1, 3)`` (``op``:
    the cross or the dot product, ``c`` components), by the product rule of Bernstein forms [Farin2002, ch. 5]."""
    from math import comb

    d = a.shape[1] - 1
    out = None
    for i in range(d + 1):
        for j in range(d + 1):
            term = (comb(d, i) * comb(d, j) / comb(2 * d, i + j)) * op(a[:, i], b[:, j])
            if out is None:
                out = np.zeros((a.shape[0], 2 * d + 1, term.shape[-1]))
            out[:, i + j] += term
    return out


def _seam_angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Bounds ``(S,)`` of the angle between the one-sided normals ``a(t)``, ``b(t)`` (pseudo-Gauss side curves
    ``(S, d + 1, 3)`` of two patches along their common side), derivation:
    :func:`splinevis.nurbs.renderers.normal_bounds`."""
    from .lod.gauss import normal_cone

    dot = lambda x, y: np.einsum("...c,...c->...", x, y)[..., None]  # noqa: E731
    c = np.linalg.norm(_product(a, b, np.cross), axis=-1).max(axis=-1)
    ab = _product(a, b, dot)[..., 0].min(axis=-1)
    size = np.linalg.norm(a, axis=-1).max(axis=-1) * np.linalg.norm(b, axis=-1).max(axis=-1)
    tol = 1e-12 * size
    parallel = (c <= tol) & (ab >= -tol)  # a x b = 0 and a . b >= 0 up to rounding: the same normals (G1)
    amin = np.einsum("skc,sc->sk", a, normal_cone(a)[0]).min(axis=-1)
    bmin = np.einsum("skc,sc->sk", b, normal_cone(b)[0]).min(axis=-1)
    ok = (amin > 0) & (bmin > 0) & (ab > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        angle = np.arcsin(np.minimum(1.0, c / (amin * bmin)))
    return np.where(parallel, 0.0, np.where(ok, angle, np.inf))


def _seams(bs, ids, sides, r) -> np.ndarray:
    """``(len(ids),)`` twice the largest seam angle of each patch's surface (0 for a single patch)."""
    out = np.zeros(len(ids))
    pos = {int(i): k for k, i in enumerate(ids)}
    for parent in np.unique(bs.parent[ids]):
        mine = np.flatnonzero(bs.parent == parent)
        rect = bs.rect[mine]
        nu, nv = np.unique(rect[:, 0]).size, np.unique(rect[:, 2]).size
        grid = np.array([pos[int(i)] for i in mine]).reshape(nu, nv)  # u-major (bezier_set)
        phi = [np.zeros(0)]
        if nu > 1:  # s = 1 of patch (I, J) against s = 0 of (I + 1, J)
            phi.append(_seam_angle(sides[1][grid[:-1]].reshape((-1,) + sides[1].shape[2:]),
                                   sides[0][grid[1:]].reshape((-1,) + sides[0].shape[2:])))
        if nv > 1:
            phi.append(_seam_angle(sides[3][grid[:, :-1]].reshape((-1,) + sides[3].shape[2:]),
                                   sides[2][grid[:, 1:]].reshape((-1,) + sides[2].shape[2:])))
        out[grid.ravel()] = 2.0 * max(float(p.max(initial=0.0)) for p in phi)
    return out


def _cells(model, cache, budget: int = CELL_BUDGET) -> dict:
    """The per-cell bounds of the model's patches (module docstring of :mod:`splinevis.nurbs.renderers`), at most
    ``budget`` cells (``r x r`` per patch, ``2 <= r <= 16``), computed once per model and budget."""
    key = "nurbs_cells" if budget == CELL_BUDGET else ("nurbs_cells", int(budget))
    if key in cache:
        return cache[key]
    bs, widen = _bezier(model, cache)
    P = len(bs)
    r = int(max(2, min(16, math.isqrt(max(int(budget) // max(P, 1), 4)))))
    out = {"r": r, "M": np.empty((P, r * r, 3)), "f": np.empty((P, r * r, 2)), "lo": np.empty((P, r * r, 3)),
           "hi": np.empty((P, r * r, 3)), "N": np.empty((P, r * r, 5)), "eval": np.empty(P), "seam": np.empty(P)}
    for g in bs.groups:
        (m, n), C, ids = g.degree, g.control, g.ids
        box = _grid_boxes(r, widen[ids])
        size = np.stack([(box[..., 1] - box[..., 0]).ravel(), (box[..., 3] - box[..., 2]).ravel()], axis=1)
        flat = {key: np.empty((len(ids) * r * r,) + out[key].shape[2:]) for key in ("M", "f", "lo", "hi", "N")}
        sides = [np.empty((len(ids), r, 3 * max(m, n) - 1, 3)) for _ in range(4)]  # the cells along each side
        cell = np.arange(len(ids) * r * r)
        mag = np.column_stack([np.linalg.norm(C[..., :3], axis=-1).reshape(len(ids), -1).max(axis=1),
                               C[..., 3].reshape(len(ids), -1).max(axis=1)])
        for rows, Q in _sub_nets(C, box):
            d = _cell_derivatives(Q, size[rows], mag[cell[rows] // (r * r)])
            for key in ("M", "f", "lo", "hi"):
                flat[key][rows] = d[key]
            flat["N"][rows], rows4 = _cell_normals(_square(d["shifted"]), size[rows])
            pa, a, b = cell[rows] // (r * r), cell[rows] // r % r, cell[rows] % r
            for side, (sel, at) in enumerate(((a == 0, b), (a == r - 1, b), (b == 0, a), (b == r - 1, a))):
                sides[side][pa[sel], at[sel]] = rows4[side][sel]
        for key in flat:
            out[key][ids] = flat[key].reshape(len(ids), r * r, -1)
        out["seam"][ids] = _seams(bs, ids, sides, r)
        # float64 evaluation of a vertex by the model (de Boor, then a division by w) [Higham2002, sec. 3.1]
        w = C[..., 3].reshape(len(ids), -1)
        size_p = np.linalg.norm(C[..., :3] / C[..., 3:], axis=-1).reshape(len(ids), -1).max(axis=1)
        out["eval"][ids] = 8.0 * (m + 1) * (n + 1) * EPS * size_p * w.max(axis=1) / w.min(axis=1)
    for key in ("M", "f", "lo", "hi", "N"):
        out[key] = out[key].reshape(P, r, r, -1)
    cache[key] = out
    return out


#: Most cells of a level-of-detail model's bounds (measured: the teapot's four levels bounded in 0.34 s with 2,048
#: cells, 0.71 s with 8,192 for bounds 1 % tighter; the torus' level 0 6.4 degrees against 5.8).
LOD_CELL_BUDGET = 2_048
#: Most triangles of a level-of-detail model whose normal cones are computed directly (about 20 us each).
LOD_CONE_BUDGET = 16_384
_CONE_FROM = 0.1  # radians: cones for the triangles whose first- and second-order bounds exceed this
# the corners (numbered (0, 0), (1, 0), (1, 1), (0, 1)) at the start and end of side k in its increasing
# parameter (as splinevis.nurbs.lod.levels)
_SIDE_ENDS = ((0, 1), (1, 2), (3, 2), (0, 3))


def _box_tables(N: np.ndarray):
    """Sparse tables of the maxima of ``N (P, r, r, c)`` over ``2^a x 2^b`` blocks of cells (clamped at the end)."""
    r = N.shape[1]
    A = int(math.floor(math.log2(r))) + 1
    rows = [N]
    for a in range(1, A):
        prev, h = rows[-1], 1 << (a - 1)
        rows.append(np.maximum(prev, prev[:, np.minimum(np.arange(r) + h, r - 1)]))
    out = {}
    for a, X in enumerate(rows):
        col = X
        for b in range(A):
            if b:
                h = 1 << (b - 1)
                col = np.maximum(col, col[:, :, np.minimum(np.arange(r) + h, r - 1)])
            out[a, b] = col
    return out


def _box_max(tables, r, patch, box) -> np.ndarray:
    """``(T, c)``: the maxima of the cells' bounds over the cells each box ``(u0, u1, v0, v1)`` of ``patch`` meets
    (a closed cell per ``[j / r, (j + 1) / r]``, boundaries taken on both sides)."""
    lo = np.clip(np.floor(box[:, 0::2] * r - 1e-9), 0, r - 1).astype(np.int64)
    hi = np.clip(np.ceil(box[:, 1::2] * r + 1e-9) - 1, 0, r - 1).astype(np.int64)
    hi = np.maximum(hi, lo)
    lg = np.floor(np.log2(hi - lo + 1)).astype(np.int64)
    out = np.empty((patch.size, tables[0, 0].shape[-1]))
    for (a, b), X in tables.items():
        sel = np.flatnonzero((lg[:, 0] == a) & (lg[:, 1] == b))
        if not sel.size:
            continue
        p, i0, j0 = patch[sel], lo[sel, 0], lo[sel, 1]
        i1, j1 = hi[sel, 0] - (1 << a) + 1, hi[sel, 1] - (1 << b) + 1
        out[sel] = np.maximum(np.maximum(X[p, i0, j0], X[p, i1, j0]), np.maximum(X[p, i0, j1], X[p, i1, j1]))
    return out


def _centred(C: np.ndarray, bbox: np.ndarray) -> np.ndarray:
    """The nets ``C`` moved to their boxes' centres (``G`` is translation invariant: no cancellation)."""
    centre = 0.5 * (bbox[:, 0::2] + bbox[:, 1::2])
    return np.concatenate([C[..., :3] - centre[:, None, None, :] * C[..., 3:], C[..., 3:]], axis=-1)


def _edge_seams(bs, edges):
    """``phi (P, 4)``: per patch side, the bound of the angle between the normal its edge's vertices carry (the
    first side's) and the side's own (0 on the first side and open edges, inf where none holds); and the pairs
    ``(first flat side, other flat side, phi)``."""
    from .lod.gauss import pseudo_gauss_net

    P = len(bs)
    rows = [None] * (4 * P)
    for g in bs.groups:
        G = pseudo_gauss_net(_centred(g.control, bs.bbox[g.ids]), rational=True)  # one degree along a side
        for k, R in enumerate((G[:, :, 0], G[:, -1, :], G[:, :, -1], G[:, 0, :])):
            for n, i in enumerate(g.ids):
                rows[4 * int(i) + k] = R[n]
    first = np.repeat(edges.edge_side, np.diff(edges.offsets))
    pairs = np.column_stack([first, edges.members])
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    flip = edges.side_reversed.ravel()
    phi = np.zeros(4 * P)
    angle = np.empty(len(pairs))
    by_len: dict = {}
    for n, (f, m) in enumerate(pairs):
        by_len.setdefault(rows[f].shape[0], []).append(n)
    for group in by_len.values():
        a = np.stack([rows[pairs[n, 0]][::-1] if flip[pairs[n, 0]] else rows[pairs[n, 0]] for n in group])
        b = np.stack([rows[pairs[n, 1]][::-1] if flip[pairs[n, 1]] else rows[pairs[n, 1]] for n in group])
        angle[group] = _seam_angle(a, b)
    np.maximum.at(phi, pairs[:, 1], angle)
    phi = phi.reshape(P, 4)
    phi[edges.side_edge < 0] = np.inf  # a collapsed side: its vertices are the pole's one vertex
    return phi, pairs, angle


def _corner_paths(edges, label, pairs, angle) -> np.ndarray:
    """``psi (P, 4)``: per patch corner, the shortest path of seam angles from the corner of its cluster whose
    normal the shared vertex carries (the cluster's first) through the edges meeting there; inf if none."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    P = label.shape[0]
    flip = edges.side_reversed.ravel()
    ends = np.array(_SIDE_ENDS)
    src, dst, w = [], [], []
    for end in (0, 1):  # the edge's start and end: the first side runs as the edge does
        f, m = pairs[:, 0], pairs[:, 1]
        a = 4 * (f // 4) + ends[f % 4, end]
        b = 4 * (m // 4) + ends[m % 4, np.where(flip[m], 1 - end, end)]
        ok = np.isfinite(angle) & (label.ravel()[a] == label.ravel()[b])
        src.append(a[ok]), dst.append(b[ok]), w.append(angle[ok])
    src, dst, w = np.concatenate(src), np.concatenate(dst), np.concatenate(w) + 1e-15  # explicit weight > 0
    lo, hi = np.minimum(src, dst), np.maximum(src, dst)
    order = np.lexsort((w, hi, lo))  # one link per pair of corners, its smallest angle
    lo, hi, w = lo[order], hi[order], w[order]
    keep = np.ones(lo.size, dtype=bool)
    keep[1:] = (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])
    graph = coo_matrix((w[keep], (lo[keep], hi[keep])), shape=(4 * P, 4 * P)).tocsr()
    rep = np.unique(label.ravel(), return_index=True)[1]
    if graph.nnz == 0:
        dist = np.full(4 * P, np.inf)
        dist[rep] = 0.0
    else:
        dist = dijkstra(graph, directed=False, indices=rep, min_only=True)
    return dist.reshape(P, 4)


def _vertex_seams(uv, patch, phi, psi) -> np.ndarray:
    """``(T, 3)`` the seam bound ``sigma_i`` of each vertex of each triangle (module docstring)."""
    on = (uv[..., 1] == 0.0, uv[..., 0] == 1.0, uv[..., 1] == 1.0, uv[..., 0] == 0.0)
    sig = np.zeros(uv.shape[:2])
    for k in range(4):
        sig = np.where(on[k], np.maximum(sig, phi[patch, k][:, None]), sig)
    for c, (k1, k2) in enumerate(((0, 3), (0, 1), (1, 2), (2, 3))):
        sig = np.where(on[k1] & on[k2], np.maximum(sig, psi[patch, c][:, None]), sig)
    return sig


def _fan_sides(uv, patch, tri, fans, edges, nudged_edge):
    """Per fan row: the side of the patch the fanned side ``a b`` lies on (-1 when it is not one side of the
    patch along that edge, or the edge has a nudged chain vertex: no bound)."""
    t = fans[:, 0]
    pa = (tri[t] == fans[:, 2:3]).argmax(axis=1)
    pb = (tri[t] == fans[:, 3:4]).argmax(axis=1)
    ua, ub = uv[t, pa], uv[t, pb]
    side = np.full(len(fans), -1)
    for k, (axis, value) in enumerate(((1, 0.0), (0, 1.0), (1, 1.0), (0, 0.0))):
        on = (ua[:, axis] == value) & (ub[:, axis] == value) & (edges.side_edge[patch[t], k] == fans[:, 1])
        side = np.where(on & (side < 0), k, side)
    return np.where(nudged_edge[fans[:, 1]], -1, side)


def _cones(bs, patch, box) -> tuple:
    """Axis and half-angle of the normal cone of each patch's sub-patch on ``box (T, 4)``."""
    from .lod.bounds import subdivide
    from .lod.gauss import normal_cone, pseudo_gauss_net

    axis, half = np.zeros((patch.size, 3)), np.full(patch.size, np.pi)
    for gi, g in enumerate(bs.groups):
        sel = np.flatnonzero(bs.group[patch] == gi)
        # polynomial patches (all weights equal): the subdivided weights are equal up to rounding
        rational = bool((g.control[..., 3] != g.control[0, 0, 0, 3]).any())
        for a in range(0, sel.size, _CHUNK):
            rows = sel[a:a + _CHUNK]
            C = _centred(g.control[bs.row[patch[rows]]], bs.bbox[patch[rows]])
            Q = subdivide(C, box[rows])
            if not rational:  # the exact sub-net's weights are the constant (subdivide rounds them)
                Q[..., 3] = g.control[0, 0, 0, 3]
            G = pseudo_gauss_net(Q, rational=rational)
            axis[rows], half[rows] = normal_cone(G.reshape(G.shape[0], -1, 3))
    return axis, half


def lod_normal_bounds(bs, edges, corner_label, edge_ids, normals, nudged, records, shape, cache=None,
                      cell_budget: int = LOD_CELL_BUDGET, cone_budget: int = LOD_CONE_BUDGET) -> np.ndarray:
    r"""Proven bounds ``(S, L)`` (radians) of the angle between the normal a level of detail's triangles shade with
    and the exact normal at the same parameter, per super-surface and level (module docstring); inf where none
    holds and where ``records`` gives nothing. The float32 rounding of the normals is not included.

    ``bs, edges``: the Bezier patches and their edges; ``corner_label (P, 4)``: the cluster of each patch corner;
    ``edge_ids``: per edge the global ids of its finest chain; ``normals (V, 3)``, ``nudged (V,)``: the stored
    vertex normals and where they were taken inside the patch; ``records``: ``(s, l, triangles (T, 3) global ids,
    patch (T,), uv (T, 3, 2) local parameters of the vertices in that patch, fan rows (F, 5))`` per super-surface
    and level to bound (:func:`splinevis.nurbs.lod.levels.build_lod` makes them).

    >>> from splinevis.nurbs.exact import torus
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod = build_lod(torus(), 0.01, levels=3, progress=False)  # calls this function
    >>> np.degrees(lod.normal_bounds.max(axis=0)).round(1).tolist()  # each level's largest, finest first
    [7.4, 27.4, 50.8]
    """
    cache = {} if cache is None else cache
    if "nurbs_bezier" not in cache:
        cache["nurbs_bezier"] = (bs, _widen(bs))
    cells = _cells(None, cache, cell_budget)
    r, tables = cells["r"], _box_tables(cells["N"])
    phi, pairs, angle = _edge_seams(bs, edges)
    psi = np.maximum(_corner_paths(edges, corner_label, pairs, angle), 0.0)
    nudged_edge = np.array([bool(nudged[ids[1:-1]].any()) for ids in edge_ids], dtype=bool)
    out = np.full(shape, np.inf)
    if not records:
        return out
    n_tri = np.array([len(rec[2]) for rec in records])
    start = np.concatenate([[0], np.cumsum(n_tri)])
    tri = np.concatenate([rec[2] for rec in records]).astype(np.int64)
    patch = np.concatenate([rec[3] for rec in records]).astype(np.int64)
    uv = np.concatenate([rec[4] for rec in records]).reshape(-1, 3, 2)
    fans = np.concatenate([np.asarray(rec[5], dtype=np.int64).reshape(-1, 5) + [start[n], 0, 0, 0, 0]
                           for n, rec in enumerate(records)])
    box = np.column_stack([uv[..., 0].min(axis=1), uv[..., 0].max(axis=1), uv[..., 1].min(axis=1),
                           uv[..., 1].max(axis=1)])
    du, dv = box[:, 1] - box[:, 0], box[:, 3] - box[:, 2]
    N = _box_max(tables, r, patch, box)
    sig = _vertex_seams(uv, patch, phi, psi)
    sig[nudged[tri]] = np.inf
    sigma = sig.max(axis=1)
    fan_side = _fan_sides(uv, patch, tri, fans, edges, nudged_edge)
    np.maximum.at(sigma, fans[:, 0], np.where(fan_side >= 0, 0.0, np.inf))
    with np.errstate(invalid="ignore", over="ignore"):
        rho = N[:, 0] * du + N[:, 1] * dv + sigma
        e = (du * du * N[:, 2] + 2.0 * du * dv * N[:, 3] + dv * dv * N[:, 4]) / 8.0 + sigma
        first = np.where(rho < 0.5 * np.pi, rho, np.inf)
        second = np.where(e < 1.0, np.arcsin(np.minimum(e, 1.0)), np.inf)
    bound = np.minimum(first, second)
    # cones where the others fail or are large, largest first, while they can lower a level's largest bound
    which = np.repeat(np.arange(len(records)), n_tri)
    cand = np.flatnonzero(~(bound <= _CONE_FROM))
    cand = cand[np.argsort(-bound[cand], kind="stable")]
    settled = np.zeros(len(records))  # the largest final bound of each record so far
    rest = np.ones(tri.shape[0], dtype=bool)
    rest[cand] = False
    np.maximum.at(settled, which[rest], bound[rest])
    done, block = 0, 512
    while cand.size and done < cone_budget:
        cand = cand[~(bound[cand] <= settled[which[cand]])]  # those at or below cannot raise the maximum
        todo, cand = cand[:min(block, int(cone_budget) - done)], cand[min(block, int(cone_budget) - done):]
        done, block = done + todo.size, 2 * block
        bound[todo] = np.minimum(bound[todo], _cone_bounds(bs, patch, box, tri, normals, fans, fan_side, phi,
                                                           todo))
        np.maximum.at(settled, which[todo], bound[todo])
    np.maximum.at(settled, which[cand], bound[cand])  # beyond the budget: the first- and second-order bounds
    bound = np.where(bound < 0.5 * np.pi, bound, np.inf)
    got = np.zeros(len(records))
    np.maximum.at(got, which, bound)
    s_l = np.array([(rec[0], rec[1]) for rec in records])
    out[s_l[:, 0], s_l[:, 1]] = got  # a level without triangles: 0
    return out


def _cone_bounds(bs, patch, box, tri, normals, fans, fan_side, phi, todo) -> np.ndarray:
    """The cone bounds of the triangles ``todo`` (module docstring)."""
    axis, half = _cones(bs, patch[todo], box[todo])
    n = normals[tri[todo]]
    cosb = np.einsum("tkc,tc->tk", n, axis)
    sinb = np.linalg.norm(np.cross(n, axis[:, None, :]), axis=-1)
    beta = np.arctan2(sinb, cosb).max(axis=1)
    # fan pieces' chain vertices: within phi of the patch's normal there, which the cone holds
    pos = np.full(tri.shape[0], -1)
    pos[todo] = np.arange(todo.size)
    rows = np.flatnonzero(pos[fans[:, 0]] >= 0)
    k = fan_side[rows]
    fan_beta = np.where(k >= 0, phi[patch[fans[rows, 0]], np.maximum(k, 0)], np.inf) + half[pos[fans[rows, 0]]]
    np.maximum.at(beta, pos[fans[rows, 0]], fan_beta)
    return np.where((half < 0.5 * np.pi) & (beta < 0.5 * np.pi), half + beta, np.inf)

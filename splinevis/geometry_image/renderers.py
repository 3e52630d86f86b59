"""The geometry image's renderers for the choice by accuracy (``Plotter.add_geometry_image(...,
max_error_px=..., max_normal_error_deg=...)``, :mod:`splinevis.choice`), declared on its program as
:data:`RENDERERS`.

One renderer, ``subdivision``: the program itself at the integer level ``L`` of :data:`LEVELS` (the limit
points of ``L`` subdivision steps on the grid triangulation of :func:`.subdivision.grid_faces`, shaded with
the limit normals at its vertices), ranked by its triangle count ``2 (2^L N)^2``. It is declared ``exact``:
the family has no renderer closer to the spline than its finest level, and every level's error is proven,
so when nothing meets the request the choice draws the level with the smallest proven error under the
triangle cap (a program without an exact renderer would get its own, the default level 3, error unknown).

**Positions** (:func:`error_px`, proven). The surface is the uniform bicubic B-spline ``P(s, t)`` of the
padded control image [Losasso2003, sec. 3]; on a cell ``[c, c + 1] x [r, r + 1]`` (image units) its second
derivatives are B-splines whose coefficients are differences of the 4 x 4 controls: ``P_ss`` linear x cubic
in the second differences along rows, ``P_st`` quadratic x quadratic in the mixed differences, ``P_tt`` cubic x
linear, all with convex weights, so ``M1, M2, M3`` (the largest differences' norms) bound them on the cell.
Subdivision's limit points are ``P`` at the dyadic parameters ``2^-L (c, r)`` exactly (the masks are the
B-spline's [Losasso2003, sec. 5]; at the cut vertices too: the same masks, no special rule for positions),
and each triangle (legs ``h = 2^-L`` along ``s`` and ``t``) lies in one cell, on which ``P`` is one bicubic
polynomial. The distance between the triangle and ``P`` at the same parameter is at most
``min((1/8) h^2 (M1 + 2 M2 + M3), (1/4) h^2 Lambda)`` (:func:`splinevis.nurbs.lod.bounds.kumar_bound`, eq. (4),
and :func:`~splinevis.nurbs.lod.bounds.waldron_bound`, eq. (3), with ``R^2 = h^2 / 2`` and ``Lambda`` the
largest eigenvalue of ``[[M1, M2], [M2, M3]]``). The passes' own rounding is added (bounded, not measured):
the GPU subdivides ``G - centre`` in float32 (:func:`.program.surface_arrays`); every pass is a sum with
nonnegative weights summing to 1, so an input error passes through unamplified and each pass adds at most
``gamma_c (X + e)`` per component (``X`` the largest centred coordinate, ``gamma_c = c u / (1 - c u)``, worst
summation order: ``c = 3`` for the split, 15 for the average, 10 for the limit mask with its rounded 1/36),
after one rounding of the upload; the float64 twin's own (the same recursion with ``u = 2^-53`` and the
uncentred coordinates) and the float64 addition of the centre are added too, so the bound holds for either
backend. VTK's float32 vertices add :func:`splinevis.gl.renderers.float32_margin`. The world bound ``e`` of a
cell becomes pixels over the cell's box (the controls' bounding box, which holds the cell's surface by the
convex hull property) grown by ``e`` (so that mesh points of boxes just outside the frustum count)
(:meth:`splinevis.gl.screen_error.View.box_pixels`), plus :data:`splinevis.gl.screen_error.SNAP_PX`.

**Normals** (:func:`normal_error_deg`, proven; inf where no bound exists). The mesh is shaded with a
normalized convex combination of its vertices' normals (perspective-correct interpolation keeps the weights
convex). With ``G = P_s x P_t`` the pseudo-normal, a bicubic cell is a bicubic Bezier patch and ``G`` a degree
(5, 5) Bezier patch (:func:`splinevis.nurbs.lod.gauss.pseudo_gauss_net`) whose coefficients lie in a cone of
half-angle ``theta`` (:func:`~splinevis.nurbs.lod.gauss.normal_cone`) [Kumar1997, sec. 3]. Both the normal at
a point of a triangle and its vertices' normals are in that cone, and the cone is convex (``theta < 90`` deg),
so the shading normal is within ``2 theta`` of the exact one. Second bound, first order in ``h``: along a
segment ``|d unit(G)| <= |dG| / |G|``, so a vertex normal is within ``h (max|G_s| + max|G_t|) / min|G|`` of
the normal at any point of its triangle (``max|G_s| <= 5 max|Delta_s G_ij|``; ``min|G| >= min G_ij . a`` for
the cone's axis ``a``), and all vertex normals lie in the spherical cap of that radius around it, which is
convex. The smaller of the two bounds is taken per cell. Where neither is finite, and in the cells at the
four cut vertices, where ``G = 0`` (``P_s = P_t = 0``, [Losasso2003, eq. 1]), the cones are taken per
level-``L`` sub-square (the cell's Bezier net subdivided, :func:`splinevis.nurbs.lod.bounds.subdivide`; at
most :data:`SUBSQUARE_BUDGET` of them, coarser sub-squares beyond that). At a cut vertex the normal is the
limit ``unit(P_ss x P_st + P_st x P_tt)`` of the C1 surface the centroid constraint defines
[Losasso2003, eq. 2, appendix]; there ``G`` and its first derivatives vanish, so the Bezier coefficients of
``G`` at that corner and its two neighbours on the sub-square's edges are zero for the constrained surface
and are set to 0 (in float64 the stored image meets the constraint to rounding: within ~1e-8 cells of a
cut vertex the float64 spline's own normal can turn any way; the bound is the constrained surface's, whose
normal at the cut vertex is the one both the GPU and the twin shade with). A sub-square whose coefficients
fit in no cone (a fold: the normal flips) has no bound: inf.

The GPU's float32 vertex normals add, per vertex, ``arcsin(|dv| / |v|) + u`` with ``v = T_s x T_t`` at level
``L`` (``|T| <= 2^-L max|P_s|`` from the first differences, ``|v| >= 4^-L min|G|``, ``|dv| <= |T_s| dT + dT
|T_t| + dT^2 + sqrt(3) gamma_2 (|T_s| + dT)(|T_t| + dT)``, ``dT = sqrt(3) (e_g + gamma_7 (X + e_g))`` from
the tangent masks on the level's control image, whose error ``e_g`` is the position recursion's): per cell
from ``min|G|``; in the sub-square cells per vertex, ``|P_s|``, ``|P_t|``, ``|G|`` evaluated in float64
(:meth:`.model.GeometryImage.evaluate`); at the cut vertices the float64 normal rounded to float32 (the
uniform): ``2 u``. The fragment shader's interpolation and normalization add ``8 u``. The bound looks at
the cells whose box is in the view frustum only (all cells when ``view`` is None).

Negative levels (subsampled level 0) are not offered: an image of ``n = 2^m + 1`` already has
``2 (n - 1)^2`` triangles at level 0.
"""

from __future__ import annotations

import math

import numpy as np

from ..gl.renderers import Renderer, float32_margin, mesh_cost
from ..gl.screen_error import SNAP_PX

__all__ = ["LEVELS", "SUBSQUARE_BUDGET", "position_bounds", "error_px", "normal_error_deg", "triangles", "measure",
           "RENDERERS", "add_by_accuracy"]

#: Subdivision levels tried, in order of cost (the program takes levels up to 8; the triangle cap decides).
LEVELS = (0, 1, 2, 3, 4, 5, 6, 7, 8)

#: Most sub-squares whose normal cones are computed per call of :func:`normal_error_deg` (module docstring).
SUBSQUARE_BUDGET = 1 << 14

U32, U64 = 2.0 ** -24, 2.0 ** -53
_SQRT3 = math.sqrt(3.0)
_TO_BEZIER = np.array([[1, 4, 1, 0], [0, 4, 2, 0], [0, 2, 4, 0], [0, 1, 4, 1]], dtype=np.float64) / 6.0
_CHUNK = 4096


def _gamma(c, u):
    return c * u / (1.0 - c * u)


def _control_error(levels: int, X: float, u: float, upload: bool) -> float:
    """Componentwise bound on the rounding error of the level's control image (module docstring)."""
    e = u * X if upload else 0.0
    for _ in range(levels):
        e = e + _gamma(3, u) * (X + e)
        e = e + _gamma(15, u) * (X + e)
    return e


def _cells(image, cache):
    """Per-cell data, ``(N * N, ...)`` row-major (cell ``(r, c)`` at ``r N + c``): controls ``(4 t, 4 s, 3)``,
    box, second-derivative bounds ``M`` and first-derivative bounds ``(|P_s|, |P_t|)``."""
    if "cells" in cache:
        return cache["cells"]
    from .image import pad

    Gp = pad(image.control, 1)
    N = image.n - 1
    W = np.lib.stride_tricks.sliding_window_view(Gp, (4, 4), axis=(0, 1))  # (N + 2 - 3, ., 3, 4, 4)
    C = np.ascontiguousarray(np.moveaxis(W[:N, :N], 2, -1)).reshape(N * N, 4, 4, 3)  # [cell, t, s, xyz]
    norm = lambda d: np.sqrt(np.einsum("k...i,k...i->k...", d, d)).reshape(len(d), -1).max(axis=1)  # noqa: E731
    d2s = C[:, :, 2:] - 2.0 * C[:, :, 1:-1] + C[:, :, :-2]
    d2t = C[:, 2:] - 2.0 * C[:, 1:-1] + C[:, :-2]
    dst = C[:, 1:, 1:] - C[:, 1:, :-1] - C[:, :-1, 1:] + C[:, :-1, :-1]
    ds, dt = C[:, :, 1:] - C[:, :, :-1], C[:, 1:] - C[:, :-1]
    M = np.stack([norm(d2s), norm(dst), norm(d2t)], axis=1) * (1.0 + 8 * U64)  # + the differences' rounding
    first = np.stack([norm(ds), norm(dt)], axis=1) * (1.0 + 4 * U64)
    G = np.asarray(image.control, dtype=np.float64).reshape(-1, 3)
    centre = 0.5 * (G.min(axis=0) + G.max(axis=0))
    X = float(np.abs(G - centre).max())  # the GPU's centred coordinates (program._at)
    cache["cells"] = {"C": C, "lo": C.min(axis=(1, 2)), "hi": C.max(axis=(1, 2)), "M": M, "first": first,
                      "X": X, "X64": float(np.abs(G).max()), "centre": float(np.abs(centre).max()), "N": N}
    return cache["cells"]


def _rounding(cells, L):
    """``(e_p, e_g)``: world bound on a limit point's rounding (GPU and twin, module docstring) and the GPU's
    componentwise bound on the level's control image."""
    X, X64 = cells["X"], cells["X64"]
    eg = _control_error(L, X, U32, True)
    eg64 = _control_error(L, X64, U64, False)
    ep = eg + _gamma(10, U32) * (X + eg) + U64 * (cells["centre"] + X)
    ep64 = eg64 + _gamma(10, U64) * (X64 + eg64)
    return _SQRT3 * max(ep, ep64), eg


def position_bounds(image, level: int, cache: dict | None = None) -> np.ndarray:
    """World bounds ``(N * N,)`` per cell (row-major) of the distance between the level-``level`` mesh and the
    limit surface at the same parameter, the passes' rounding included (module docstring).

    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.model import GeometryImage
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
    >>> [f"{position_bounds(gi, L).max():.2e}" for L in (0, 1, 2, 3)]  # the chord term falls as 4^-L
    ['2.38e-01', '5.95e-02', '1.49e-02', '3.73e-03']
    """
    from ..nurbs.lod.bounds import _lambda_max

    cache = {} if cache is None else cache
    cells = _cells(image, cache)
    h = 2.0 ** -int(level)
    M = cells["M"]
    chord = h * h * np.minimum(0.125 * (M[:, 0] + 2.0 * M[:, 1] + M[:, 2]), 0.25 * _lambda_max(M))
    return chord * (1.0 + 4 * U64) + _rounding(cells, int(level))[0]


def error_px(image, view, level, cache):
    """(pixels, True): the proven screen-space error of the level-``level`` mesh for ``view`` (module
    docstring), plus the sub-pixel snapping.

    >>> from splinevis.gl.screen_error import View
    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.model import GeometryImage
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(17)), constrain=True)
    >>> v = View((0.0, -4.0, 2.0), (0, 0, 0), (0, 0, 1), 30.0, width=320, height=240)
    >>> [round(error_px(gi, v, L, {})[0], 3) for L in (0, 1, 2, 3)]  # about 4^-L
    [20.26, 4.255, 1.024, 0.258]
    """
    cells = _cells(image, cache)
    e = position_bounds(image, level, cache)
    lo, hi = cells["lo"] - e[:, None], cells["hi"] + e[:, None]
    e = e + float32_margin(lo, hi)
    return float(view.box_pixels(lo, hi, e).max()) + SNAP_PX, True


def _cut_cells(N):
    """Cells touching the four cut vertices and, per cell, the local corner ``(a, b)`` (``s``, ``t`` in {0, 1})
    the cut vertex is at: ``[(cell index, a, b), ...]``."""
    h = N // 2
    out = []
    for r, c in ((0, h), (N, h), (h, 0), (h, N)):  # image.cut_vertices order (row, column)
        for rr in (r - 1, r):
            for cc in (c - 1, c):
                if 0 <= rr < N and 0 <= cc < N:
                    out.append((rr * N + cc, c - cc, r - rr))
    return out


def _bezier(C):
    """Bicubic Bezier nets ``(K, 4 s, 4 t, 4)`` (weight 1 last) of cells' B-spline controls ``(K, 4 t, 4 s, 3)``."""
    B = np.einsum("ia,jb,kbac->kijc", _TO_BEZIER, _TO_BEZIER, C)
    return np.concatenate([B, np.ones(B.shape[:-1] + (1,))], axis=-1)


def _gauss(nets, corners=None):
    """Pseudo-normal nets ``(K, 6, 6, 3)`` of Bezier nets; ``corners`` (``(K, 2)`` of 0/1, -1 for none): the
    corner at a cut vertex, whose coefficient and its two edge neighbours are set to 0 (module docstring)."""
    from ..nurbs.lod.gauss import pseudo_gauss_net

    Gn = pseudo_gauss_net(nets, rational=False)
    if corners is not None:
        for k in np.flatnonzero(corners[:, 0] >= 0):
            i, j = (5 * corners[k]).tolist()
            di, dj = (1 if i == 0 else -1), (1 if j == 0 else -1)
            Gn[k, i, j] = Gn[k, i + di, j] = Gn[k, i, j + dj] = 0.0
    return Gn


def _cones(Gn):
    """Half-angles, ``min G . axis`` (0 without a cone) and ``max|G_s| + max|G_t|`` of pseudo-normal nets."""
    from ..nurbs.lod.gauss import normal_cone

    V = Gn.reshape(len(Gn), -1, 3)
    axis, half = normal_cone(V)
    half = np.asarray(half, dtype=np.float64).reshape(-1)
    low = np.einsum("kji,ki->kj", V, axis).min(axis=1) * (1.0 - 16 * U64)
    low = np.where(half < 0.5 * math.pi, np.maximum(low, 0.0), 0.0)
    nrm = lambda d: np.sqrt(np.einsum("k...i,k...i->k...", d, d)).reshape(len(d), -1).max(axis=1)  # noqa: E731
    slope = 5.0 * (nrm(Gn[:, 1:] - Gn[:, :-1]) + nrm(Gn[:, :, 1:] - Gn[:, :, :-1])) * (1.0 + 8 * U64)
    return half, low, slope


def _cell_cones(image, cache):
    if "cones" not in cache:
        cells = _cells(image, cache)
        C, N = cells["C"], cells["N"]
        corners = -np.ones((len(C), 2), dtype=int)
        for k, a, b in _cut_cells(N):
            corners[k] = (a, b)
        parts = [_cones(_gauss(_bezier(C[i:i + _CHUNK]), corners[i:i + _CHUNK])) for i in range(0, len(C), _CHUNK)]
        cache["cones"] = tuple(np.concatenate(p) for p in zip(*parts))
    return cache["cones"]


def _float32_normal(Ts, Tt, v, eg, X):
    """Angle bound of the GPU's float32 vertex normals for tangent sizes ``Ts, Tt`` and ``|v| >= v`` at the
    level (module docstring)."""
    dT = _SQRT3 * (eg + _gamma(7, U32) * (X + eg))
    dv = Ts * dT + dT * Tt + dT * dT + _SQRT3 * _gamma(2, U32) * (Ts + dT) * (Tt + dT)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(v > 0, dv / np.maximum(v, 1e-300), np.inf)
    return np.where(ratio < 1.0, np.arcsin(np.minimum(ratio, 1.0)), np.inf) + U32


def _subsquares(cells, ks, j, corners):
    """Per cell of ``ks``: the largest over its ``4^j`` sub-squares of the smaller of ``2 theta`` (their cones)
    and the first-order bound ``(max|G_u| + max|G_v|) / min|G|`` in the sub-square's own parameters (its
    triangles span it); ``corners`` as in :func:`_gauss`."""
    from ..nurbs.lod.bounds import subdivide

    m = 1 << j
    a, b = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
    a, b = a.ravel(), b.ravel()
    box = np.stack([a, a + 1, b, b + 1], axis=1) / m  # (m * m, 4): (s0, s1, t0, t1) local
    nets = _bezier(cells["C"][ks])
    owner = np.repeat(np.arange(len(ks)), m * m)
    which = np.tile(np.arange(m * m), len(ks))
    cor = -np.ones((len(owner), 2), dtype=int)
    ca, cb = corners[owner, 0], corners[owner, 1]
    at = (ca >= 0) & (a[which] == ca * (m - 1)) & (b[which] == cb * (m - 1))
    cor[at] = corners[owner[at]]
    worst = np.zeros(len(ks))
    for lo in range(0, len(owner), _CHUNK):
        sl = slice(lo, lo + _CHUNK)
        half, low, slope = _cones(_gauss(subdivide(nets[owner[sl]], box[which[sl]]), cor[sl]))
        with np.errstate(divide="ignore", invalid="ignore"):
            lip = np.where(low > 0, slope / np.maximum(low, 1e-300), np.inf)
        angle = np.minimum(np.where(half < 0.5 * math.pi, 2.0 * half, np.inf), lip)
        np.maximum.at(worst, owner[sl], angle)
    return worst


def _vertex_normal_errors(image, cells, ks, L, eg):
    """Largest float32 normal error bound over the level-``L`` vertices of each cell ``ks``, from float64
    evaluations of ``|P_s|, |P_t|, |P_s x P_t|`` (module docstring); the cut vertices: ``2 u``."""
    N = cells["N"]
    m = 1 << L
    f = np.linspace(0.0, 1.0, m + 1)
    fs, ft = np.meshgrid(f, f, indexing="xy")
    cut = {(float(s), float(t)) for s, t in image.cut_vertices}
    out = np.empty(len(ks))
    for i, k in enumerate(ks):
        r, c = divmod(int(k), N)
        st = np.stack([c + fs, r + ft], axis=-1).reshape(-1, 2)
        _, Ps, Pt = image.evaluate(st, derivatives=1, cells=np.broadcast_to([c, r], st.shape))
        ns, nt = np.linalg.norm(Ps, axis=1), np.linalg.norm(Pt, axis=1)
        v = np.linalg.norm(np.cross(Ps, Pt), axis=1)
        slack = 64 * U64 * cells["X64"]  # the float64 evaluation's rounding, generously
        d = _float32_normal((ns + slack) / m, (nt + slack) / m, np.maximum(v - slack * (ns + nt + slack), 0.0) / (m * m),
                            eg, cells["X"])
        at_cut = np.array([(float(p), float(q)) in cut for p, q in st])
        d[at_cut] = 2 * U32
        out[i] = d.max()
    return out


def normal_error_deg(image, view, level, cache):
    """(degrees, proven): the largest angle between the normal the level-``level`` mesh shades with and the
    surface's normal at the same parameter, over the cells in ``view`` (module docstring); ``(inf, False)``
    where some visible cell has no bound (a fold).

    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.model import GeometryImage
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(17)), constrain=True)
    >>> [round(normal_error_deg(gi, None, L, {})[0], 2) for L in (0, 2, 4)]  # first order; float32 near cut vertices
    [26.79, 6.89, 4.1]
    """
    L = int(level)
    cells = _cells(image, cache)
    half, low, slope = _cell_cones(image, cache)
    h = 2.0 ** -L
    with np.errstate(divide="ignore", invalid="ignore"):
        lipschitz = np.where(low > 0, h * slope / np.maximum(low, 1e-300), np.inf)
    exact = np.minimum(np.where(half < 0.5 * math.pi, 2.0 * half, np.inf), lipschitz)
    eg = _rounding(cells, L)[1]
    first = cells["first"]
    rounding = _float32_normal(h * first[:, 0], h * first[:, 1], h * h * low, eg, cells["X"])
    bound = exact + rounding
    visible = np.ones(len(bound), bool) if view is None else view.box_pixels(cells["lo"], cells["hi"], 1.0) > 0
    cut = {k: (a, b) for k, a, b in _cut_cells(cells["N"])}
    forced = visible & (~(bound < 0.5 * math.pi) | np.isin(np.arange(len(bound)), list(cut)))
    # refine the cells that must be (cut vertices, no bound) and then the worst ones, within the budget
    spare = max((SUBSQUARE_BUDGET >> (2 * L)) - int(forced.sum()), 0)
    rest = np.flatnonzero(visible & ~forced)
    hard = np.concatenate([np.flatnonzero(forced), rest[np.argsort(-bound[rest], kind="stable")[:spare]]])
    if len(hard):
        j = L
        while j > 0 and len(hard) << (2 * j) > SUBSQUARE_BUDGET:
            j -= 1
        corners = np.array([cut.get(int(k), (-1, -1)) for k in hard]).reshape(-1, 2)
        sub = _subsquares(cells, hard, j, corners)
        need = ~(rounding[hard] < 0.5 * math.pi) | np.isin(hard, list(cut))  # no per-cell rounding bound
        vertex = rounding[hard].copy()
        if need.any():
            vertex[need] = (_vertex_normal_errors(image, cells, hard[need], L, eg)
                            if int(need.sum()) << (2 * L) <= SUBSQUARE_BUDGET else np.inf)
        bound[hard] = np.minimum(bound[hard], sub + vertex)
    worst = float(bound[visible].max()) if visible.any() else 0.0
    if not worst < 0.5 * math.pi:
        return math.inf, False
    return math.degrees(worst + 8 * U32), True


def triangles(image, level, cache) -> int:
    """Triangles of the level-``level`` mesh: ``2 (2^level (n - 1))^2``.

    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.model import GeometryImage
    >>> triangles(GeometryImage(octahedral_to_sphere(image_uv(17)), constrain=True), 2, {})
    8192
    """
    return 2 * ((image.n - 1) << int(level)) ** 2


def measure(image, view, level, cache, samples: int = 20_000, seed: int = 0):
    """(pixels, degrees) measured on the level-``level`` mesh (the float64 twin's limit points and normals)
    against the limit surface at ``samples`` random points of random triangles: the drawn point against the
    surface point at the same parameter (their projections' distance in ``view``), and the normalized
    interpolated vertex normal against the surface's normal there.

    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.model import GeometryImage
    >>> from splinevis.gl.screen_error import View
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
    >>> v = View((3, -4, 2), (0, 0, 0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 20))
    >>> px, deg = measure(gi, v, 1, {})
    >>> bool(0 < px <= error_px(gi, v, 1, {})[0]), bool(0 < deg <= normal_error_deg(gi, v, 1, {})[0])
    (True, True)
    """
    from .subdivision import subdivide

    rng = np.random.default_rng(seed)
    N, m = image.n - 1, 1 << int(level)
    M = N * m + 1
    sub = subdivide(image.control, int(level))
    p, nrm = sub.p.reshape(-1, 3), sub.n.reshape(-1, 3)
    a, b = rng.integers(0, N * m, samples), rng.integers(0, N * m, samples)  # sub-square column (s), row (t)
    v00 = b * M + a
    upper = rng.random(samples) < 0.5  # grid_faces: (00, 01, 11) and (00, 11, 10), 01 = next column
    v = np.where(upper[:, None], np.stack([v00, v00 + M + 1, v00 + M], 1), np.stack([v00, v00 + 1, v00 + M + 1], 1))
    lam = rng.dirichlet((1.0, 1.0, 1.0), samples)
    st = np.einsum("kj,kjd->kd", lam, np.stack([v % M, v // M], axis=-1) / m)
    cells = np.stack([np.minimum(a // m, N - 1), np.minimum(b // m, N - 1)], 1)  # the triangle's own piece
    drawn = np.einsum("kj,kjd->kd", lam, p[v])
    shade = np.einsum("kj,kjd->kd", lam, nrm[v])
    shade /= np.linalg.norm(shade, axis=1, keepdims=True)
    exact = image.normals(st)
    px = view.pixel_distance(drawn, image.evaluate(st, cells=cells))
    deg = np.degrees(np.arctan2(np.linalg.norm(np.cross(shade, exact), axis=1), np.einsum("kd,kd->k", shade, exact)))
    return (float(np.nanmax(px)) if np.isfinite(px).any() else 0.0), float(deg.max())


def _build(plotter, image, style, level, cache, spline_options, add_options):
    """The program at ``level``; ``add_options`` may carry the program's ``backend``."""
    extra = dict(add_options or {})
    unknown = sorted(set(extra) - {"backend"})
    if unknown:
        raise TypeError(f"options {unknown} cannot go with a choice by accuracy; the geometry image takes backend.")
    options = {k: v for k, v in spline_options.items() if k != "program_options"}
    options["program"] = "geometry_image"
    return plotter.add_spline(image, style, program_options={"level": int(level), **extra}, **options)


def add_by_accuracy(plotter, image, style, options, max_error_px, max_normal_error_deg, displacement=None,
                    backend="gpu"):
    """What ``Plotter.add_geometry_image(..., max_error_px=..., max_normal_error_deg=...)`` does: choose the
    level of ``image`` for the plotter's camera (:func:`splinevis.choice.add_model_by_accuracy`) and draw it
    with ``backend``; ``options`` are ``add_spline``'s keywords (``name``, effects). A displacement map belongs
    to one level and moves the surface off the spline: it cannot go with a request (ValueError).

    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.model import GeometryImage
    >>> from splinevis.plotting import Plotter
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(17)), constrain=True)
    >>> pl = Plotter(off_screen=True, window_size=(64, 48))
    >>> actor = add_by_accuracy(pl, gi, None, {"lights": 1}, 1.0, None)
    >>> actor.choice.renderer, actor.choice.meets, actor.choice.level
    ('subdivision', True, 1)
    >>> pl.close()
    """
    from ..choice import _SPLINE_KEYS, add_model_by_accuracy
    from ..plotting_options import _style_from

    if displacement is not None:
        raise ValueError("a displacement map belongs to one level and moves the surface off the spline: give "
                         "level=..., not max_error_px / max_normal_error_deg, with displacement.")
    options = dict(options)
    spline_options = {k: options.pop(k) for k in _SPLINE_KEYS if k in options}
    return add_model_by_accuracy(plotter, image, _style_from(style, options), max_error_px,
                                 add_options={"backend": backend}, max_normal_error_deg=max_normal_error_deg,
                                 **spline_options)


#: The geometry image's renderers (module docstring), declared on :data:`splinevis.geometry_image.program.PROGRAM`.
RENDERERS = (
    Renderer("subdivision", 0, LEVELS, error_px, _build, triangles, exact=True, normal_error_deg=normal_error_deg,
             measure=measure, cost=mesh_cost(triangles)),
)

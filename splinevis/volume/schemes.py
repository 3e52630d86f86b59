"""Quadratic super spline of volume data on the type-6 partition [Roessl2004; Nuernberger2005] (used on
the GPU in [Kalbe2008, sec. 4-5]), and the interface shared with
the cubic C1 scheme (:mod:`splinevis.volume.cubic`) in the format the GPU program reads: ``STENCIL``,
:func:`pad_volume`, :func:`tet_weights`, :func:`spline_coefficients`, :func:`cube_coefficients`,
:func:`evaluate`, :func:`evaluate_volume`. See docs/volume-schemes.md. The stencil and the padding are
:mod:`splinevis.volume.stencil`, the domain-point tables and inner C1 conditions of both degrees
:mod:`splinevis.volume.domain`.

Conventions
-----------
* ``volume[k, j, i]`` (shape ``(nz, ny, nx)``) is the data value ``f`` at the grid point with
  *index-space* coordinates ``(x, y, z) = (i, j, k)`` (spacing 1). Points are always given as
  ``(x, y, z)``.
* Every data point is the centre of one cube ``Q_kji = [i - 1/2, i + 1/2] x [j - 1/2, j + 1/2] x
  [k - 1/2, k + 1/2]``; the spline is defined on the union ``[-1/2, nx - 1/2] x [-1/2, ny - 1/2] x
  [-1/2, nz - 1/2]`` of these ``nz * ny * nx`` cubes. Each cube carries 24 quadratic BB patches (the
  tetrahedra of :mod:`splinevis.volume.partition`, local coordinates ``p - (i - 1/2, j - 1/2, k - 1/2)``)
  with 10 coefficients each, in :func:`splinevis.bb.simplex.multi_indices` ``(2, 3)`` order w.r.t. the
  vertices ``[vQ, wF, u, u']``.
* The scheme needs the 27 data values around a cube; at the boundary the volume is padded by one layer
  of linear extrapolation (``f[-1] = 2 f[0] - f[1]``), which keeps linear data linear.

Determining set and the remaining coefficients
----------------------------------------------
The 20 domain points on the cube's edges get data averages: a cube vertex (surrounded by 8 grid points)
gets the mean of those 8 values, an edge midpoint the mean of the 4 grid values around the edge. Both are
exact for linear ``f``.  The other 45 coefficients are fixed linear combinations of the cube's 27-point
data stencil, derived by :func:`derive_weights` (linear algebra, float64, then snapped to the exact
multiples of 1/16 they turn out to be; the package reads them as exact fractions from
:mod:`splinevis.volume._scheme_weights`, written by ``tools/gen_scheme_weights.py`` from this derivation):

1. the 30 coefficients on the cube's boundary faces (``wF`` and ``(wF + u)/2``) from the C1 conditions
   of the face restriction on the criss-cross split of the face; the solution is unique and depends only
   on the face's 8 edge coefficients, so neighbouring cubes agree on their common face (C0 everywhere):
   ``c((wF+u)/2)`` = mean of the two edge midpoints at u, ``c(wF)`` = mean of the 4 edge midpoints;
2. the 15 inner coefficients (``vQ``, ``(vQ + wF)/2``, ``(vQ + u)/2``) as data weights subject to, exactly,
   C1 across all 6 cube faces (as an identity in the data of both neighbouring cubes), reproduction of
   linear functions, and, greedily in row order, as many C1 conditions across the inner faces of the split
   as stay consistent (84 of 108); least squares over the remaining 24 conditions.
   The C1 quadratic splines on one type-6 cube form a space of dimension 16 < 20, so the edge data cannot
   in general be extended C1 inside the cube: the 12 faces ``[vQ, u, u']`` between different pyramids are
   crossed C0 only (the normal-derivative jump is linear on the face and vanishes at vQ).
"""

from __future__ import annotations

import functools
import itertools

import numpy as np

from .._validation import as_float64_array
from ..bb import simplex as bb
from . import cubic as _cubic
from .domain import domain_index, domain_table, inner_face_rows
# _inner_faces, _check_volume and _pad are re-exported: other modules and the tests read them from here
from .partition import NUM_TETS, _bary_mats, _inner_faces as _inner_faces, _locate, _tets
from .stencil import (
    _BIG_ID,
    _S27,
    STENCIL,
    _apply_point_weights,
    _check_volume as _check_volume,
    _lift,
    _pad as _pad,
    _stored_weights,
    pad_volume,
)

__all__ = ["domain_points", "edge_points", "inner_face_conditions", "derive_weights",
           "quadratic_super_spline", "evaluate", "NUM_DOMAIN_POINTS", "STENCIL", "SCHEMES", "pad_volume",
           "tet_weights", "spline_coefficients", "cube_coefficients", "evaluate_volume"]

#: Distinct quadratic domain points of one type-6 cube.
NUM_DOMAIN_POINTS = 65


def _domain():
    """``(points (65, 3), tet_map (24, 10), keys)`` of the quadratic domain points (read-only tables)."""
    return domain_table(2)


def domain_points():
    """``(points (65, 3), tet_map (24, 10))``: the distinct domain points (local coordinates) and, for
    every tetrahedron and BB coefficient, the index of its domain point.

    >>> points, tet_map = domain_points()
    >>> points.shape, tet_map.shape, points[tet_map[0, 0]]  # coefficient (2, 0, 0, 0) sits at vQ
    ((65, 3), (24, 10), array([0.5, 0.5, 0.5]))
    """
    pts, tmap, _ = _domain()
    return pts.copy(), tmap.copy()


def edge_points() -> np.ndarray:
    """Indices (into :func:`domain_points`) of the 20 determining points on the cube's edges, in
    increasing order.

    >>> points = domain_points()[0][edge_points()]
    >>> len(points), int(((points == 0) | (points == 1)).sum(axis=1).min())  # 8 vertices, 12 edge midpoints
    (20, 2)
    """
    pts = _domain()[0]
    on = ((pts == 0) | (pts == 1)).sum(axis=1) >= 2
    return np.flatnonzero(on)


def _face_points():
    pts = _domain()[0]
    on = ((pts == 0) | (pts == 1)).sum(axis=1) == 1
    return np.flatnonzero(on)


def _idx(x):
    """Index of the quadratic domain point ``x`` (local coordinates)."""
    return domain_index(2, x)


def inner_face_conditions():
    """C1 conditions across the 36 inner faces of the split: ``(A (108, 65), pairs)`` with ``A @ c = 0``
    for the 65 domain-point coefficients ``c`` of a spline that is C1 inside the cube; row ``3 m + r``
    belongs to the face shared by tetrahedra ``pairs[m]``.

    >>> A, pairs = inner_face_conditions()
    >>> A.shape, len(pairs), pairs[0]
    ((108, 65), 36, (0, 1))
    """
    A, pairs = inner_face_rows(2)
    return A.copy(), list(pairs)


def _face_conditions():
    """2-D C1 conditions of the face restrictions (criss-cross split of each cube face), as rows over the
    65 coefficients: across the face diagonal [wF, u'] of the triangles [wF, u, u'] and [wF, u', u'']
    (u'' = 2 wF - u): c((u''+b)/2) = 2 c((wF+b)/2) - c((u+b)/2) for b in {wF, u'}."""
    v = _tets()
    rows = []
    for f in range(6):
        wf = v[4 * f, 1]
        corners = [v[4 * f + k, 2] for k in range(4)]
        for k in range(4):
            u, up, upp = corners[k], corners[(k + 1) % 4], corners[(k + 2) % 4]
            for b in (wf, up):
                r = np.zeros(NUM_DOMAIN_POINTS)
                r[_idx((upp + b) / 2)] += 1.0
                r[_idx((wf + b) / 2)] -= 2.0
                r[_idx((u + b) / 2)] += 1.0
                rows.append(r)
    return np.array(rows)


def _solve_block(A, known, unknown, name):
    """W with x_unknown = W @ x_known minimizing |A x|; refuse rank deficiency."""
    Au, Ak = A[:, unknown], A[:, known]
    rank = np.linalg.matrix_rank(Au)
    if rank < len(unknown):
        raise RuntimeError(f"{name}: the smoothness conditions do not determine the {len(unknown)} coefficients "
                           f"(rank {rank}).")
    W, *_ = np.linalg.lstsq(Au, -Ak, rcond=None)
    return W


def _edge_data_weights():
    """(20, 27) data weights of the edge coefficients (cube centred at the data point 0)."""
    pts = _domain()[0][edge_points()]
    E = np.zeros((len(pts), 27))
    sid = {tuple(int(v) for v in o): n for n, o in enumerate(STENCIL)}
    for m, p in enumerate(pts):
        g = p - 0.5
        rng = [[0] if gg == 0 else [int(np.floor(gg)), int(np.ceil(gg))] for gg in g]
        w = 1.0 / np.prod([len(r) for r in rng])
        for o in itertools.product(*rng):
            E[m, sid[o]] += w
    return E


def _snap(w):
    """The derived weights are multiples of 1/16: remove the solvers' rounding noise (only if tiny)."""
    s = np.round(w * 2.0**10) / 2.0**10 + 0.0  # no negative zeros
    return s if np.abs(s - w).max() < 1e-9 else w


@functools.lru_cache(maxsize=None)
def _weights():
    """Derivation (see the module docstring and docs/volume-schemes.md). Returns (W (65, 27), diagnostics)."""
    n = NUM_DOMAIN_POINTS
    pts = _domain()[0]
    edge, face = edge_points(), _face_points()
    inner = np.setdiff1d(np.arange(n), np.concatenate([edge, face]))
    known = np.concatenate([edge, face])
    # 1. face coefficients from the criss-cross C1 conditions of each face (unique, consistent)
    F = _face_conditions()
    Wf = _solve_block(F, edge, face, "face coefficients")
    face_res = float(np.abs(F[:, face] @ Wf + F[:, edge]).max())
    if face_res > 1e-13:
        raise RuntimeError(f"face C1 conditions are inconsistent (residual {face_res:.3g}).")
    E = _edge_data_weights()
    K = np.zeros((n, 27))
    K[edge] = E
    K[face] = _snap(Wf @ E)
    # 2. inner coefficients: unknown data weights X (15, 27), vector x = X.ravel()
    ni = len(inner)
    nx = ni * 27
    iid = {int(k): m for m, k in enumerate(inner)}

    def inner_rows(p, shift):  # (125, nx): weights of inner coefficient p of the cube at `shift`
        M = np.zeros((125, nx))
        for j, o in enumerate(STENCIL):
            M[_BIG_ID[tuple(int(v) for v in o + shift)], iid[p] * 27 + j] = 1.0
        return M

    v = _tets()
    vq = np.full(3, 0.5)
    hard, hard_rhs = [], []
    # (a) C1 across the 6 cube faces: c(wF) and c((wF+u)/2) are the means of the two coefficients on
    #     either side (neighbour centre 2 wF - vQ), an identity in the data of both cubes' stencils
    for f in range(6):
        a, s = divmod(f, 2)
        d = np.zeros(3, dtype=np.int64)
        d[a] = 2 * s - 1
        wf = v[4 * f, 1]
        for target in [wf] + [v[4 * f + k, 2] for k in range(4)]:
            fp = _idx((wf + target) / 2)
            hard.append(inner_rows(_idx((vq + target) / 2), np.zeros(3, dtype=np.int64))
                        + inner_rows(_idx((vq + target - d) / 2), d))
            hard_rhs.append(2 * _lift(K[fp], np.zeros(3, dtype=np.int64)))
    # (b) reproduction of linear functions
    for m, p in enumerate(inner):
        for mono in range(4):
            r = np.zeros((1, nx))
            r[0, m * 27:(m + 1) * 27] = 1.0 if mono == 0 else STENCIL[:, mono - 1]
            hard.append(r)
            hard_rhs.append(np.array([1.0 if mono == 0 else pts[p][mono - 1] - 0.5]))
    # (c) inner C1 conditions, as identities in the data
    A, pairs = inner_face_conditions()
    soft, soft_rhs = [], []
    for r in range(A.shape[0]):
        M = np.zeros((125, nx))
        for m, p in enumerate(inner):
            if A[r, p] != 0:
                M[_S27, m * 27:(m + 1) * 27] += A[r, p] * np.eye(27)
        soft.append(M)
        soft_rhs.append(-_lift(A[r, known] @ K[known], np.zeros(3, dtype=np.int64)))
    H, h = np.vstack(hard), np.concatenate(hard_rhs)
    keep = np.abs(H).sum(axis=1) + np.abs(h) > 0
    H, h = H[keep], h[keep]
    x0, *_ = np.linalg.lstsq(H, h, rcond=None)
    if np.abs(H @ x0 - h).max() > 1e-12:
        raise RuntimeError("cube-face C1 + linear reproduction is inconsistent: refusing.")
    _, sv, vt = np.linalg.svd(H)
    N = vt[int(np.sum(sv > 1e-10 * sv[0])):].T  # solutions: x0 + N y
    # greedily impose inner C1 conditions (in row order) that stay consistent with the imposed ones
    added = []
    for r in range(A.shape[0]):
        R, b = soft[r], soft_rhs[r]
        RN = R @ N
        # the rank cut of every decision is 1e-10 (as for N): lstsq's default (eps * max(shape)) inverted a
        # roundoff-sized singular value on AVX-512 OpenBLAS kernels and judged 16 consistent conditions inconsistent
        y, *_ = np.linalg.lstsq(RN, b - R @ x0, rcond=1e-10)
        if np.abs(RN @ y + R @ x0 - b).max() < 1e-10:
            x0 = x0 + N @ y
            _, sv, vt = np.linalg.svd(RN)
            rk = int(np.sum(sv > 1e-10 * max(sv[0], 1.0))) if sv.size else 0
            N = N @ vt[rk:].T
            added.append(r)
    rest = [r for r in range(A.shape[0]) if r not in added]
    x = x0
    if rest and N.shape[1]:  # least squares over the conditions that cannot hold ("averaging")
        O = np.vstack([soft[r] for r in rest])
        o = np.concatenate([soft_rhs[r] for r in rest])
        y, *_ = np.linalg.lstsq(O @ N, o - O @ x0, rcond=None)
        x = x0 + N @ y
    x = _snap(x)
    Hall = np.vstack([np.vstack(hard)] + [soft[r] for r in added])
    hall = np.concatenate([np.concatenate(hard_rhs)] + [soft_rhs[r] for r in added])
    W = K.copy()
    W[inner] = x.reshape(ni, 27)
    res = np.array([np.abs(soft[r] @ x - soft_rhs[r]).max() for r in range(A.shape[0])])
    exact = res < 1e-10
    W.setflags(write=False)
    return W, exact, pairs, face_res, float(np.abs(Hall @ x - hall).max())


def derive_weights() -> dict:
    """The coefficient map of the scheme and its diagnostics.

    Returns
    -------
    dict with
        ``"W"``: (65, 27) data weights: coefficient at domain point m = ``W[m] @ data[STENCIL offsets]``;
        ``"exact_conditions"``: (108,) bool, which rows of :func:`inner_face_conditions` hold for all data;
        ``"exact_faces"``: list of the tetrahedron pairs whose common face is crossed C1 for all data;
        ``"face_residual"``: residual of the face (criss-cross) C1 solve;
        ``"hard_residual"``: residual of the exactly imposed conditions (cube-face C1, linear
        reproduction, the inner C1 conditions flagged exact).

    Examples
    --------
    >>> d = derive_weights()
    >>> d["W"].shape, len(d["exact_faces"]), bool(d["hard_residual"] < 1e-12)  # C1 across 24 of 36 faces
    ((65, 27), 24, True)
    """
    W, exact, pairs, face_res, hard_res = _weights()
    ex_faces = [pairs[m] for m in range(len(pairs)) if exact[3 * m:3 * m + 3].all()]
    return {"W": W.copy(), "exact_conditions": exact.copy(), "exact_faces": ex_faces, "face_residual": face_res,
            "hard_residual": hard_res}


# ----------------------------------------------------------------------------------------------------
# generic interface for both schemes (the format the GPU program reads)
# ----------------------------------------------------------------------------------------------------

#: Names of the spline schemes of this package: degree 2 (65 domain points per cube, C0/C1 as documented
#: above) and degree 3 (:mod:`splinevis.volume.cubic`, C1 everywhere).
SCHEMES = ("quadratic", "cubic")
_NCOEF = {"quadratic": 10, "cubic": 20}
_DEGREE_OF_M = {10: 2, 20: 3}


def _check_scheme(scheme):
    if not isinstance(scheme, str) or scheme not in SCHEMES:
        raise ValueError(f"scheme {scheme!r} is not known; choose one of: 'quadratic' (quadratic super spline, 10 "
                         f"coefficients per tetrahedron) or 'cubic' (cubic C1 spline, 20 coefficients).")
    return scheme


def _point_weights(scheme):
    """(number of domain points, 27) weights and the (24, m) tetrahedron map of a scheme."""
    if scheme == "quadratic":
        return _stored_weights("quadratic"), _domain()[1]
    return _stored_weights("cubic"), _cubic._domain()[1]


@functools.lru_cache(maxsize=None)
def _tet_weights(scheme):
    W, tmap = _point_weights(scheme)
    out = W[tmap]
    out.setflags(write=False)
    return out


def tet_weights(scheme: str) -> np.ndarray:
    """Data weights of every BB coefficient, the format of the GPU program.

    Parameters
    ----------
    scheme : {"quadratic", "cubic"}

    Returns
    -------
    (24, m, 27) float64 ndarray, m = 10 (quadratic) or 20 (cubic)
        Coefficient ``q`` (``multi_indices(m == 10 and 2 or 3, 3)`` order w.r.t. ``[vQ, wF, u, u']``) of
        tetrahedron ``t`` of the cube whose data point is ``(i, j, k)`` equals
        ``sum_s W[t, q, s] * padded[(i, j, k) + STENCIL[s]]`` with ``padded`` the volume padded by
        :func:`pad_volume` (index ``(x, y, z)`` reads ``padded[z + 1, y + 1, x + 1]``). The weights are
        multiples of 1/16 (quadratic, exact in float64) resp. 1/192 (cubic, rounded to float64),
        nonnegative, and sum to 1 per coefficient.

    Examples
    --------
    >>> W = tet_weights("quadratic")
    >>> W.shape, bool((16 * W == np.round(16 * W)).all()), float(W.sum(axis=-1).min()), float(W.min())
    ((24, 10, 27), True, 1.0, 0.0)
    """
    return _tet_weights(_check_scheme(scheme)).copy()


def spline_coefficients(volume, scheme: str) -> np.ndarray:
    """BB coefficients of every cube, vectorized.

    Parameters
    ----------
    volume : (nz, ny, nx) array_like, finite, every axis >= 2
        ``volume[k, j, i]`` = f at index-space point (x, y, z) = (i, j, k).
    scheme : {"quadratic", "cubic"}

    Returns
    -------
    (nz, ny, nx, 24, m) float64 ndarray, m = 10 or 20
        Needs ``nz * ny * nx * 24 * m * 8`` bytes (2.6 GB for a cubic 256^3 volume): for big volumes use
        :func:`cube_coefficients` on the cubes you need.

    Examples
    --------
    >>> spline_coefficients(np.zeros((4, 5, 6)), "cubic").shape
    (4, 5, 6, 24, 20)
    """
    scheme = _check_scheme(scheme)
    vol = _check_volume(volume)
    W, tmap = _point_weights(scheme)
    return _apply_point_weights(vol, W, tmap)


def _check_cubes(cubes, shape):
    c = np.asarray(cubes)
    if c.ndim != 2 or c.shape[1] != 3 or not (np.issubdtype(c.dtype, np.integer) or c.size == 0):
        raise ValueError(f"cubes must be an (n, 3) integer array of cube indices (i, j, k); got shape {c.shape}, "
                         f"dtype {c.dtype}.")
    c = c.astype(np.int64)
    nz, ny, nx = shape
    bad = (c < 0) | (c >= np.array([nx, ny, nz]))
    if bad.any():
        r = int(np.argwhere(bad.any(axis=1))[0, 0])
        raise ValueError(f"cubes[{r}] = {c[r].tolist()} is outside the volume: (i, j, k) needs 0 <= i < nx={nx}, "
                         f"0 <= j < ny={ny}, 0 <= k < nz={nz}.")
    return c


def cube_coefficients(volume, cubes, scheme: str) -> np.ndarray:
    """BB coefficients of selected cubes only (for volumes whose full coefficient array does not fit).

    Parameters
    ----------
    volume : (nz, ny, nx) array_like
    cubes : (n, 3) int array_like
        Cube indices ``(i, j, k)`` (= the data point at the cube's centre).
    scheme : {"quadratic", "cubic"}

    Returns
    -------
    (n, 24, m) float64 ndarray, equal to ``spline_coefficients(volume, scheme)[k, j, i]`` row by row (up to
    the rounding of a different summation order).

    Examples
    --------
    >>> volume = np.random.default_rng(0).random((4, 4, 4))
    >>> c = cube_coefficients(volume, [[1, 2, 0]], "quadratic")
    >>> c.shape, float(np.abs(c[0] - spline_coefficients(volume, "quadratic")[0, 2, 1]).max()) < 1e-15
    ((1, 24, 10), True)
    """
    scheme = _check_scheme(scheme)
    vol = _check_volume(volume)
    c = _check_cubes(cubes, vol.shape)
    return _cube_coefficients(_pad(vol), c, scheme)


def _cube_coefficients(padded, c, scheme):
    W = _tet_weights(scheme)
    idx = c[:, None, :] + STENCIL[None, :, :] + 1  # (n, 27, 3) as (x, y, z) into padded
    data = padded[idx[..., 2], idx[..., 1], idx[..., 0]]  # (n, 27)
    return np.einsum("ns,tqs->ntq", data, W)


def _check_coef(coef):
    c = as_float64_array(coef, "coef")
    if c.ndim != 5 or c.shape[3] != NUM_TETS or c.shape[4] not in _DEGREE_OF_M:
        raise ValueError(f"coef must have shape (nz, ny, nx, 24, 10) (quadratic) or (nz, ny, nx, 24, 20) (cubic), "
                         f"as returned by spline_coefficients; got {c.shape}.")
    return c


def _check_points(p, shape, tol):
    nz, ny, nx = shape
    hi = np.array([nx, ny, nz], dtype=np.float64) - 0.5
    out = (p < -0.5 - tol) | (p > hi + tol)
    if out.any():
        idx = tuple(int(v) for v in np.argwhere(out.any(axis=-1))[0]) if p.ndim > 1 else ()
        raise ValueError(f"points must lie in the spline domain [-1/2, n - 1/2] per axis (x: nx={nx}, y: ny={ny}, "
                         f"z: nz={nz}); the point at index {idx} is {p[idx].tolist()}.")
    cell = np.clip(np.floor(p + 0.5), 0, hi - 0.5).astype(np.int64)
    local = np.clip(p - (cell - 0.5), 0.0, 1.0)
    return cell, local


def _eval_patch(cc, t, lam, gradient):
    """Value (and gradient w.r.t. the local = index-space coordinates) of patches cc (..., m) of
    tetrahedra t at barycentric lam."""
    n = _DEGREE_OF_M[cc.shape[-1]]
    val = bb._decasteljau(cc, n, 3, lam)
    if not gradient:
        return val
    g = bb.gradient(cc, d=3)  # (..., 4, m'): d p / d lam_i as degree n-1 coefficients
    dlam = bb._decasteljau(g, n - 1, 3, lam[..., None, :])  # (..., 4)
    grad = np.einsum("...i,...ij->...j", dlam, _bary_mats()[t][..., :3])
    return val, grad


def evaluate(coef, points, *, gradient: bool = False, tol: float = 1e-9):
    """Evaluate a quadratic or cubic spline (and optionally its gradient) at index-space points.

    Parameters
    ----------
    coef : (nz, ny, nx, 24, m) array_like, m = 10 (degree 2) or 20 (degree 3)
        From :func:`spline_coefficients` (or :func:`quadratic_super_spline`).
    points : (..., 3) array_like
        Points ``(x, y, z)`` in ``[-1/2, nx - 1/2] x [-1/2, ny - 1/2] x [-1/2, nz - 1/2]`` (up to tol).
    gradient : bool
        Also return the gradient ``(..., 3)`` (d/dx, d/dy, d/dz) of the patch containing the point.

    Returns
    -------
    values (...), or (values, gradients (..., 3)).

    Examples
    --------
    >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
    >>> coef = spline_coefficients(x + 2 * y + 3 * z, "quadratic")
    >>> evaluate(coef, [[1.25, 2.0, 0.5]], gradient=True)  # linear data are reproduced
    (array([6.75]), array([[1., 2., 3.]]))
    """
    c = _check_coef(coef)
    p = as_float64_array(points, "points", shape_tail=(3,))
    cell, local = _check_points(p, c.shape[:3], tol)
    t, lam = _locate(local)
    cc = c[cell[..., 2], cell[..., 1], cell[..., 0], t]  # (..., m)
    return _eval_patch(cc, t, lam, gradient)


def evaluate_volume(volume, points, scheme: str, *, gradient: bool = False, tol: float = 1e-9,
                    prefilter: str = "none", padding: str = "linear"):
    """Evaluate the spline of ``volume`` at ``points`` building only the cubes that contain them
    (memory O(points) beyond the padded data); same result as ``evaluate(spline_coefficients(volume, scheme),
    points)``. ``prefilter`` and ``padding`` as for :class:`splinevis.volume.VolumeSpline`
    (:func:`splinevis.volume.prefilter.padded_data`).

    Examples
    --------
    >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
    >>> evaluate_volume(x ** 2, [[1.3, 1.0, 1.0]], "cubic").round(12)  # x^2 + 1/4: the schemes' constant shift
    array([1.94])
    """
    scheme = _check_scheme(scheme)
    vol = _check_volume(volume)
    p = as_float64_array(points, "points", shape_tail=(3,))
    cell, local = _check_points(p, vol.shape, tol)
    flat = cell.reshape(-1, 3)
    uniq, inv = np.unique(flat, axis=0, return_inverse=True)
    from .prefilter import _padded

    coefs = _cube_coefficients(_padded(vol, scheme, prefilter, padding), uniq, scheme)  # (u, 24, m)
    t, lam = _locate(local)
    cc = coefs[inv.reshape(cell.shape[:-1]), t]
    return _eval_patch(cc, t, lam, gradient)


def quadratic_super_spline(volume) -> np.ndarray:
    """BB coefficients of the quadratic super spline of ``volume``: ``spline_coefficients(volume,
    "quadratic")``.

    Parameters
    ----------
    volume : (nz, ny, nx) array_like, finite, every axis >= 2
        ``volume[k, j, i]`` = f at index-space point (x, y, z) = (i, j, k).

    Returns
    -------
    (nz, ny, nx, 24, 10) float64 ndarray
        Cube ``[k, j, i]`` is centred at the data point (i, j, k); patch t is tetrahedron t of
        :func:`splinevis.volume.partition.type6_tetrahedra`, coefficients in ``multi_indices(2, 3)`` order.

    Examples
    --------
    >>> c = quadratic_super_spline(np.full((3, 3, 3), 7.0))
    >>> c.shape, float(c.min()), float(c.max())  # constants are reproduced
    ((3, 3, 3, 24, 10), 7.0, 7.0)
    """
    return spline_coefficients(volume, "quadratic")

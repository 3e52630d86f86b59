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
data stencil, derived by :func:`derive_weights` (exact rational linear algebra, :mod:`splinevis._exact`; they turn out
to be multiples of 1/16; the package reads them as exact fractions from
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


@functools.lru_cache(maxsize=None)
def _weights():
    """Derivation (see the module docstring and docs/volume-schemes.md), in exact rational arithmetic
    (:mod:`splinevis._exact`): every decision of the greedy step 2 is an exact consistency test, so the result
    does not depend on the machine's BLAS (decided in float64 it did: one OpenBLAS SkylakeX thread imposed 56
    conditions instead of 84). Returns (W (65, 27) float64, exact conditions, pairs, face residual, hard residual);
    the residuals are exact, hence 0.0."""
    from .._exact import flint_module, lstsq_full_rank, nullspace, qmat, solve_any

    flint = flint_module()
    Q = flint.fmpq_mat
    n = NUM_DOMAIN_POINTS
    pts = _domain()[0]
    edge, face = edge_points(), _face_points()
    inner = np.setdiff1d(np.arange(n), np.concatenate([edge, face]))
    known = np.concatenate([edge, face])
    # 1. face coefficients from the criss-cross C1 conditions of each face (unique, consistent)
    F = _face_conditions()
    Fu, Fk = qmat(F[:, face], what="face condition"), qmat(F[:, edge], what="face condition")
    if Fu.rank() < len(face):
        raise RuntimeError(f"face coefficients: the smoothness conditions do not determine the {len(face)} "
                           f"coefficients (rank {Fu.rank()}).")
    Wf = lstsq_full_rank(Fu, -Fk)
    if Fu * Wf + Fk != Q(Fk.nrows(), Fk.ncols()):
        raise RuntimeError("face C1 conditions are inconsistent.")
    Eq = qmat(_edge_data_weights(), what="edge data weight")
    rows = {int(p): r for p, r in zip(edge, Eq.table())}
    rows.update({int(p): r for p, r in zip(face, (Wf * Eq).table())})
    zero27 = [flint.fmpq(0)] * 27
    K = [rows.get(m, zero27) for m in range(n)]  # exact data weights of the known points (inner: zero)
    # 2. inner coefficients: unknown data weights X (15, 27), vector x = X.ravel()
    ni = len(inner)
    nx = ni * 27
    iid = {int(k): m for m, k in enumerate(inner)}

    def inner_rows(p, shift):  # (125, nx): weights of inner coefficient p of the cube at `shift`
        M = np.zeros((125, nx))
        for j, o in enumerate(STENCIL):
            M[_BIG_ID[tuple(int(v) for v in o + shift)], iid[p] * 27 + j] = 1.0
        return M

    def lifted(w27, factor=1):  # exact _lift(w, 0): weights on the 125 offsets -2..2
        out = [flint.fmpq(0)] * 125
        for j, b in enumerate(_S27):
            out[int(b)] = factor * w27[j]
        return out

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
            hard_rhs += lifted(K[fp], 2)
    # (b) reproduction of linear functions
    for m, p in enumerate(inner):
        for mono in range(4):
            r = np.zeros((1, nx))
            r[0, m * 27:(m + 1) * 27] = 1.0 if mono == 0 else STENCIL[:, mono - 1]
            hard.append(r)
            hard_rhs.append(flint.fmpq(1) if mono == 0 else flint.fmpq(int(round(4 * (pts[p][mono - 1] - 0.5))), 4))
    H = np.vstack(hard)
    keep = [i for i in range(H.shape[0]) if np.abs(H[i]).sum() > 0 or hard_rhs[i] != 0]
    Hq = qmat(H[keep], what="cube-face or reproduction condition")
    hq = Q(len(keep), 1, [hard_rhs[i] for i in keep])
    x0 = solve_any(Hq, hq)
    if x0 is None:
        raise RuntimeError("cube-face C1 + linear reproduction is inconsistent: refusing.")
    N = nullspace(Hq)  # solutions: x0 + N y
    # (c) inner C1 conditions, as identities in the data: condition r says sum_p A[r, p] c_p = 0; its 27 data
    #     rows (the other 98 of the 125 offsets are 0 = 0): sum_m A[r, inner_m] X[m] = -sum_known A[r, k] K[k]
    A, pairs = inner_face_conditions()
    Aq = [[flint.fmpq(q.numerator, q.denominator) for q in row]
          for row in np.array(_fractions(A), dtype=object).reshape(A.shape)]

    def condition(r, basis, point):  # (R basis, rhs - R point) of condition r, 27 rows each
        cols = basis.ncols()
        btab, ptab = basis.table(), point.table()
        RB, rhs = [], []
        for j in range(27):
            row = [flint.fmpq(0)] * cols
            acc = -sum((Aq[r][k] * K[k][j] for k in known if Aq[r][k] != 0), flint.fmpq(0))
            for m, p in enumerate(inner):
                a = Aq[r][p]
                if a != 0:
                    brow = btab[m * 27 + j]
                    row = [x + a * y for x, y in zip(row, brow)]
                    acc -= a * ptab[m * 27 + j][0]
            RB.append(row)
            rhs.append(acc)
        return Q(27, cols, [x for row in RB for x in row]), Q(27, 1, rhs)

    # greedily impose inner C1 conditions (in row order) that stay consistent with the imposed ones
    added = []
    for r in range(A.shape[0]):
        RN, b = condition(r, N, x0)
        y = solve_any(RN, b) if N.ncols() else (Q(0, 1) if b == Q(27, 1) else None)
        if y is not None:
            if N.ncols():
                x0 = x0 + N * y
                N = N * nullspace(RN)
            added.append(r)
    rest = [r for r in range(A.shape[0]) if r not in added]
    x, Z = x0, N
    if rest and N.ncols():  # least squares over the conditions that cannot hold ("averaging")
        parts = [condition(r, N, x0) for r in rest]
        ON = Q(27 * len(rest), N.ncols(), [v for RN, _ in parts for row in RN.table() for v in row])
        o = Q(27 * len(rest), 1, [row[0] for _, b in parts for row in b.table()])
        y = solve_any(ON.transpose() * ON, ON.transpose() * o)
        x = x0 + N * y
        Z = N * nullspace(ON)
    if Z.ncols():  # the least-norm one among the solutions (what float64 lstsq and SVD null spaces gave)
        x = x - Z * (Z.transpose() * Z).solve(Z.transpose() * x)
    if Hq * x != hq:
        raise RuntimeError("the derived inner weights break the imposed conditions.")
    exact = np.array([condition(r, Q(nx, 0), x)[1] == Q(27, 1) for r in range(A.shape[0])])
    if not exact[added].all():
        raise RuntimeError("an imposed inner C1 condition does not hold for the derived weights.")
    W = np.array([[float(q) for q in row] for row in K], dtype=np.float64)
    W[inner] = np.array([float(q) for q in x.entries()]).reshape(ni, 27)
    W.setflags(write=False)
    return W, exact, pairs, 0.0, 0.0


def _fractions(a):
    from .._exact import rationals

    return rationals(a, what="inner C1 condition")


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

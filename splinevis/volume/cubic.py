"""Cubic C1 quasi-interpolating splines of volume data on the type-6 partition ([SorokinaZeilfelder2007],
"S31"; used on the GPU in [Kalbe2008, sec. 4, Fig. 4] (determining set D3 and its masks) and
[Kalbe2008, Fig. 7] (repeated averaging)). The published masks were not available: they are derived below
and checked by tests/test_volume_cubic.py. See docs/volume-schemes.md.

Conventions are those of :mod:`splinevis.volume.schemes` (data point = cube centre, 27-point
``STENCIL``, linear-extrapolation padding); each tetrahedron carries 20 BB coefficients in
:func:`splinevis.bb.simplex.multi_indices` ``(3, 3)`` order w.r.t. ``[vQ, wF, u, u']``; a cube has 175
distinct cubic domain points.

Derivation (:func:`derive_weights`, float64 linear algebra, < 1 s, cached)
--------------------------------------------------------------------------
The package does not run it: it reads the result, exact multiples of 1/192, from
:mod:`splinevis.volume._scheme_weights` (written by ``tools/gen_scheme_weights.py`` from this derivation and
checked against it by tests/test_scheme_weights.py).

1. Determining set D3 (56 points per cube, [Kalbe2008, sec. 5, Fig. 4]): the 8 cube vertices, the 24
   points at 1/3 and 2/3 of the 12 cube edges, and the 24 centroids of the boundary triangles
   ``[wF, u, u']``.
2. The 216 C1 conditions across the 36 inner faces of the split determine the other 119 coefficients
   uniquely from the 56 (rank 119), but the C1 cubic splines on one cube form a space of dimension
   52 < 56: the determining values must satisfy 4 consistency conditions (:func:`derive_weights` returns
   them as ``"consistency"``).
3. The masks of D3 (data weights of the 56 determining coefficients) are unknowns subject to: symmetry
   under the 48 symmetries of the cube; agreement of every shared point between all cubes containing it
   (an identity in the data); support in the data within max-norm distance 1 of the point; reproduction
   of linear functions; the 4 consistency conditions as identities in the data. This system has exactly
   one solution, and it consists of the fractions visible in [Kalbe2008, Fig. 4] (vertex: 1/8 of the 8
   surrounding values; edge point: 5/24 for the 4 values around the edge, 1/24 for the 4 beyond the
   near vertex; triangle centroid: 13/48, 7/48, 1/32, 1/96).
4. All 175 coefficients are then ``M @ K`` (``M`` from step 2), snapped to the multiples of 1/192 they
   turn out to be. Verified, not imposed: C1 across the 6 cube faces as an identity in the data of both
   neighbouring cubes; the weights are nonnegative.

The spline reproduces the trilinear polynomials (span of 1, x, y, z, xy, yz, zx, xyz) exactly and the
squares ``x^2`` up to the constant ``1/4`` (index space, spacing 1), so the gradients of all quadratics
are exact: approximation order 2 for values and gradients [Kalbe2008, sec. 4 and 6].
"""

from __future__ import annotations

import functools
import itertools

import numpy as np

from ..bb import simplex as bb
from .domain import domain_index, domain_table, inner_face_rows
from .partition import NUM_TETS, _inner_faces as _inner_faces, _tets  # _inner_faces re-exported for the tests
from .stencil import STENCIL, _apply_point_weights, _check_volume, _lift, _stored_weights

__all__ = ["NUM_DOMAIN_POINTS", "domain_points", "determining_set", "inner_face_conditions", "derive_weights",
           "cubic_c1_spline"]

#: Distinct cubic domain points of one type-6 cube.
NUM_DOMAIN_POINTS = 175
_SCALE = 6  # domain points of degree 3 on the partition are multiples of 1/6 (local coordinates)
_DENOM = 192  # the derived weights are multiples of 1/192


def _domain():
    """``(points (175, 3), tet_map (24, 20), keys)`` of the cubic domain points (read-only tables)."""
    return domain_table(3)


def _idx(x):
    """Index of the cubic domain point ``x`` (local coordinates)."""
    return domain_index(3, x)


def domain_points():
    """``(points (175, 3), tet_map (24, 20))``: the distinct cubic domain points of one cube (local
    coordinates) and, for every tetrahedron and BB coefficient, the index of its domain point.

    >>> points, tet_map = domain_points()
    >>> points.shape, tet_map.shape, bool((6 * points == np.round(6 * points)).all())  # multiples of 1/6
    ((175, 3), (24, 20), True)
    """
    pts, tmap, _ = _domain()
    return pts.copy(), tmap.copy()


@functools.lru_cache(maxsize=None)
def _determining():
    pts = _domain()[0]
    nb = ((pts == 0) | (pts == 1)).sum(axis=1)
    edge = np.flatnonzero(nb >= 2)  # 8 vertices + 24 edge points
    g = np.abs(pts - 0.5)
    # on one cube face (nb == 1): the triangle centroid has in-face offsets {1/3, 0} from the face centre,
    # the points on the diagonals [wF, u] have equal in-face offsets
    cent = [m for m in np.flatnonzero(nb == 1) if abs(np.sort(g[m])[0] - np.sort(g[m])[1]) > 1e-9]
    return np.sort(np.concatenate([edge, np.array(cent, dtype=np.int64)]))


def determining_set() -> np.ndarray:
    """Indices (into :func:`domain_points`) of the 56 points of the determining set D3 [Kalbe2008, Fig. 4]:
    cube vertices, edge points, centroids of the 24 boundary triangles; increasing order.

    >>> points = domain_points()[0][determining_set()]
    >>> on_faces = ((points == 0) | (points == 1)).sum(axis=1)  # 3: vertex, 2: edge point, 1: centroid
    >>> len(points), [int((on_faces == k).sum()) for k in (3, 2, 1)]
    (56, [8, 24, 24])
    """
    return _determining().copy()


def inner_face_conditions():
    """C1 conditions across the 36 inner faces: ``(A (216, 175), pairs)``, ``A @ c = 0`` for the
    coefficients ``c`` of a spline that is C1 inside the cube; rows ``6 m .. 6 m + 5`` belong to the face
    shared by tetrahedra ``pairs[m]``.

    >>> A, pairs = inner_face_conditions()
    >>> A.shape, len(pairs)
    ((216, 175), 36)
    """
    A, pairs = inner_face_rows(3)
    return A.copy(), list(pairs)


def _point_group():
    """The 48 symmetries of the cube about its centre, as (permutation, signs): g(x)_r = signs[r] x[perm[r]]."""
    return [(perm, signs) for perm in itertools.permutations(range(3)) for signs in itertools.product((1, -1), repeat=3)]


def _act(g, x):
    perm, signs = g
    return (signs[0] * x[perm[0]], signs[1] * x[perm[1]], signs[2] * x[perm[2]])


def _mask_classes(det):
    """Union-find of the mask entries (determining point m, stencil offset j) that must be equal:
    cube symmetries and the identification of a shared point with the same point of each neighbouring
    cube (offsets shift by the cube offset d). Entries that a cube sharing the point cannot see, or that
    lie farther than max-norm 1 from the point, are forced to zero. Returns (class id (56, 27), count)
    with -1 for forced zeros."""
    pts = _domain()[0]
    rel = {tuple(int(v) for v in np.round(_SCALE * (pts[d] - 0.5))): m for m, d in enumerate(det)}
    stencil = [tuple(int(v) for v in o) for o in STENCIL]
    sid = {o: j for j, o in enumerate(stencil)}
    n = len(det) * 27
    parent = list(range(n))
    zero = [False] * n
    group = _point_group()
    offsets = [d for d in itertools.product((-1, 0, 1), repeat=3) if any(d)]

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def union(a, b):
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[rb] = ra
            zero[ra] = zero[ra] or zero[rb]

    half = _SCALE // 2
    for r6, m in rel.items():
        for j, o in enumerate(stencil):
            a = m * 27 + j
            if max(abs(_SCALE * o[i] - r6[i]) for i in range(3)) > _SCALE:  # support: max-norm distance <= 1
                zero[find(a)] = True
            for g in group:
                union(a, rel[_act(g, r6)] * 27 + sid[_act(g, o)])
            for d in offsets:
                q = tuple(r6[i] - _SCALE * d[i] for i in range(3))
                if max(abs(v) for v in q) > half:
                    continue  # the cube at offset d does not contain the point
                o2 = tuple(o[i] - d[i] for i in range(3))  # the same data point seen from that cube
                if o2 in sid:
                    union(a, rel[q] * 27 + sid[o2])
                else:
                    zero[find(a)] = True
    roots: dict = {}
    cls = np.full(n, -1, dtype=np.int64)
    for a in range(n):
        r = find(a)
        if not zero[r]:
            cls[a] = roots.setdefault(r, len(roots))
    return cls.reshape(len(det), 27), len(roots)


#: Polynomials the masks must reproduce exactly (index space, cube centred at the data point 0): the
#: trilinear space.
_REPRODUCED = (("1", lambda p: np.ones(len(p))), ("x", lambda p: p[:, 0]), ("y", lambda p: p[:, 1]),
               ("z", lambda p: p[:, 2]), ("xy", lambda p: p[:, 0] * p[:, 1]), ("yz", lambda p: p[:, 1] * p[:, 2]),
               ("zx", lambda p: p[:, 2] * p[:, 0]), ("xyz", lambda p: p[:, 0] * p[:, 1] * p[:, 2]))
#: ... and up to one common unknown constant (so their gradients exactly): the squares. Linear
#: reproduction alone leaves one free mask parameter (the split of the triangle-centroid mask between the
#: data in the face's plane and the layers beside it); exact reproduction of the squares is impossible.
_SQUARES = (("x^2", lambda p: p[:, 0] ** 2), ("y^2", lambda p: p[:, 1] ** 2), ("z^2", lambda p: p[:, 2] ** 2))


def _poly_coefficients(f):
    """(175,) BB coefficients of a polynomial f of degree <= 3 (index-space points (n, 3) -> (n,)) on the
    cube centred at the data point 0: interpolation at the 20 domain points of every tetrahedron."""
    pts, tmap, _ = _domain()
    mi = bb._multi_indices(3, 3)
    B = bb.bernstein_basis(3, 3, mi / 3.0)  # (20, 20): B[r, q] = B_q(xi_r)
    out = np.zeros(NUM_DOMAIN_POINTS)
    v = _tets()
    for t in range(NUM_TETS):
        out[tmap[t]] = np.linalg.solve(B, f((mi / 3.0) @ v[t] - 0.5))
    return out


@functools.lru_cache(maxsize=None)
def _weights():
    A, pairs = inner_face_rows(3)
    det = _determining()
    rest = np.setdiff1d(np.arange(NUM_DOMAIN_POINTS), det)
    Au, Ak = A[:, rest], A[:, det]
    rank = np.linalg.matrix_rank(Au)
    if rank != len(rest):
        raise RuntimeError(f"cubic derivation: the inner C1 conditions determine only {rank} of the {len(rest)} "
                           f"coefficients outside the determining set.")
    X = np.linalg.lstsq(Au, -Ak, rcond=None)[0]
    M = np.zeros((NUM_DOMAIN_POINTS, len(det)))
    M[det] = np.eye(len(det))
    M[rest] = X
    # consistency: determining values admit a C1 extension iff P @ vals = 0 (P = residual projector)
    R = Ak + Au @ X
    U, s, _ = np.linalg.svd(R, full_matrices=False)
    ncons = int((s > 1e-10 * s[0]).sum())
    C = U[:, :ncons].T @ R  # (ncons, 56)
    # masks: unknown class values; equations: linear reproduction, consistency as data identities
    cls, ncls = _mask_classes(det)
    nvar = ncls + 1  # the class values and the constant s with Q(x^2) = x^2 + s
    rows, rhs = [], []
    for group, f in [(0, f) for _, f in _REPRODUCED] + [(1, f) for _, f in _SQUARES]:
        targ = _poly_coefficients(f)[det]
        vals = f(STENCIL.astype(np.float64))
        for m in range(len(det)):
            r = np.zeros(nvar)
            np.add.at(r, cls[m][cls[m] >= 0], vals[cls[m] >= 0])
            r[ncls] = -group
            rows.append(r)
            rhs.append(targ[m])
    for c in C:
        for j in range(27):
            r = np.zeros(nvar)
            for m in range(len(det)):
                if cls[m, j] >= 0:
                    r[cls[m, j]] += c[m]
            rows.append(r)
            rhs.append(0.0)
    E, e = np.array(rows), np.array(rhs)
    mask_rank = int(np.linalg.matrix_rank(E))
    if mask_rank != nvar:
        raise RuntimeError(f"cubic derivation: the mask conditions leave {nvar - mask_rank} free parameters.")
    y = np.linalg.lstsq(E, e, rcond=None)[0]
    mask_res = float(np.abs(E @ y - e).max())
    if mask_res > 1e-12:
        raise RuntimeError(f"cubic derivation: the mask conditions are inconsistent (residual {mask_res:.3g}).")
    # exact reproduction of the squares (s = 0) is impossible: residual of that system, for the record
    E0 = E[:, :ncls]
    y0 = np.linalg.lstsq(E0, e, rcond=None)[0]
    quad_res = float(np.abs(E0 @ y0 - e).max())
    shift = float(y[ncls])
    K = np.where(cls >= 0, y[np.maximum(cls, 0)], 0.0)
    W = M @ K
    Ws = np.round(W * _DENOM) / _DENOM
    if np.abs(Ws - W).max() > 1e-9:
        raise RuntimeError("cubic derivation: the weights are not multiples of 1/192 (snapping refused).")
    W = Ws + 0.0  # no negative zeros
    inner_res = float(np.abs(A @ W).max())
    cube_res = _cube_face_residual(W)
    W.setflags(write=False)
    return W, ncons, ncls, inner_res, cube_res, pairs, shift, quad_res, M, K


def _cube_face_residual(W):
    """Largest violation of the C1 conditions across the 6 cube faces, as identities in the data of both
    neighbouring cubes (weights on the 5x5x5 offsets): for T = [vQ, wF, u, u'] and the neighbour's
    T' = [vQ', wF, u, u'] with vQ' = 2 wF - vQ: c_T'(vQ', b) = 2 c_T(wF, b) - c_T(vQ, b)."""
    v = _tets()
    vq = np.full(3, 0.5)
    worst = 0.0
    for t in range(NUM_TETS):
        a, s = divmod(t // 4, 2)
        shift = np.zeros(3, dtype=np.int64)
        shift[a] = 1 if s else -1
        wf, u, up = v[t, 1], v[t, 2], v[t, 3]
        vq2 = 2 * wf - vq
        sh = [wf, u, up]
        for i1, i2 in itertools.combinations_with_replacement(range(3), 2):
            b = sh[i1] + sh[i2]
            lhs = _lift(W[_idx((vq2 + b) / 3 - shift)], shift)
            rhs = 2 * _lift(W[_idx((wf + b) / 3)], 0 * shift) - _lift(W[_idx((vq + b) / 3)], 0 * shift)
            worst = max(worst, float(np.abs(lhs - rhs).max()))
    return worst


def determining_map():
    """The determining-set encoding of the scheme [Kalbe2008, sec. 5.1]: ``(M (24, 20, 56), K (56, 27))`` with
    the 56 determining coefficients of a cube ``d = K @ data27`` (its masks, Fig. 4) and every tetrahedron's
    coefficients ``M[t] @ d`` (the inner C1 conditions solved for the other 119 points: "repeated averaging",
    Fig. 7). ``M[t] @ K`` equals :func:`splinevis.volume.schemes.tet_weights` ("cubic")[t] up to rounding."""
    _, _, _, _, _, _, _, _, M, K = _weights()
    _, tmap = domain_points()
    return M[tmap].copy(), K.copy()


def derive_weights() -> dict:
    """The coefficient map of the cubic C1 scheme and its diagnostics.

    Returns
    -------
    dict with
        ``"W"``: (175, 27) data weights, coefficient at domain point m = ``W[m] @ data[STENCIL offsets]``;
        ``"determining_set"``: the 56 indices of D3;
        ``"consistency_conditions"``: number of conditions the 56 determining values must satisfy for a C1
        extension into the cube (4: the C1 cubic splines on a cube have dimension 52);
        ``"mask_parameters"``: number of free symmetric mask values before the conditions (all fixed);
        ``"inner_residual"``: max |A @ W| over the 216 inner C1 conditions (0: C1 across all 36 faces);
        ``"cube_face_residual"``: C1 residual across the cube faces, as identities in the data (0);
        ``"exact_faces"``: the 36 tetrahedron pairs, all crossed C1;
        ``"square_shift"``: the constant s with spline(x^2) = x^2 + s (1/4, index space);
        ``"quadratic_reproduction_residual"``: residual of the mask system with s = 0 (> 0: exact
        reproduction of quadratics is impossible with these masks).

    Examples
    --------
    >>> d = derive_weights()
    >>> d["W"].shape, d["consistency_conditions"], round(d["square_shift"], 12), len(d["exact_faces"])
    ((175, 27), 4, 0.25, 36)
    """
    W, ncons, ncls, inner_res, cube_res, pairs, shift, quad_res, _, _ = _weights()
    return {"W": W.copy(), "determining_set": _determining().copy(), "consistency_conditions": ncons,
            "mask_parameters": ncls, "inner_residual": inner_res, "cube_face_residual": cube_res,
            "exact_faces": list(pairs) if inner_res < 1e-12 else [], "square_shift": shift,
            "quadratic_reproduction_residual": quad_res}


def cubic_c1_spline(volume) -> np.ndarray:
    """BB coefficients of the cubic C1 quasi-interpolant of ``volume``:
    ``spline_coefficients(volume, "cubic")``, shape ``(nz, ny, nx, 24, 20)``.

    >>> c = cubic_c1_spline(np.full((3, 3, 3), 2.0))
    >>> c.shape, bool(np.allclose(c, 2.0))
    ((3, 3, 3, 24, 20), True)
    """
    return _apply_point_weights(_check_volume(volume), _stored_weights("cubic"), _domain()[1])

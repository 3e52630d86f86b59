"""Quartic spline terrains on the type-1 triangulation, built from a uniform grid of heights.

Every scheme here sets the 15 quartic Bernstein-Bezier (BB) coefficients of each triangle directly as a
fixed linear combination of nearby heights (a *quasi-interpolant*, eq. (4) of the terrain paper,
``/work/shared/papers/000_7d449fa3247defe5.txt``, section IV). Schemes:

==========  =====================  ==========  ===========  =============================================
scheme      spline cell            smoothness  reproduces   data stencil per cell (offsets from its corner)
==========  =====================  ==========  ===========  =============================================
linear      1x1 data cells         C0          degree 1     2x2 (the cell's corners), degree-elevated
C0          4x4 data cells         C0          degree 4     5x5 (interpolates at all 15 domain points)
C1          1x1 data cells         C1          degree 3     22 points inside [-2, 3]^2 (derived, see docs)
C2          1x1 data cells         C2          degree 1     4x4, [-1, 2]^2 (quartic box spline, data as
                                                            coefficients: smoothing)
C2-cubic    1x1 data cells         C2          degree 3     30 points of [-2, 3]^2 (box spline with the
                                                            prefilter 3/2 z - 1/12 * 6 neighbours)
==========  =====================  ==========  ===========  =============================================

Conventions
-----------
* Heights ``z`` have shape ``(ny, nx)``; ``z[j, i]`` is the height at index point ``(x, y) = (i, j)``.
  Everything is in *index units* (a data cell is the unit square); physical spacing is applied outside.
* Cell ``(i, j)`` of the spline is ``[i, i+1] x [j, j+1]`` times the cell size (4 for ``C0``, else 1) and
  holds two triangles, with vertices (relative to the cell's lower-left corner, in cell units)
  ``T0 = [(0,0), (1,0), (1,1)]`` (lower) and ``T1 = [(0,0), (1,1), (0,1)]`` (upper).
* ``coef[j, i, t, :]`` are the quartic BB coefficients of triangle ``Tt`` of cell ``(i, j)`` in
  :func:`splinevis.bb.simplex.multi_indices` ``(4, 2)`` order relative to that vertex order. ``coef`` has
  shape ``(ny - 1, nx - 1, 2, 15)``, or ``((ny - 1) / 4, (nx - 1) / 4, 2, 15)`` for ``C0``.
* Boundary: schemes whose stencil reaches outside the grid (C1, C2, C2-cubic) pad the heights by cubic
  extrapolation, ``f[-1] = 4 f[0] - 6 f[1] + 4 f[2] - f[3]`` (repeated outward; first along x, then
  along y over the padded rows). The rule is exact for cubics in each variable, so padding keeps the
  schemes' polynomial reproduction up to the boundary. It needs 4 heights along each axis.

Engine
------
Every scheme is linear in ``z`` and translation invariant, so one engine serves all of them: a rectangular
window of the (padded) grid around each cell, flattened to ``S`` values, times a weight matrix ``W`` of
shape ``(S, 30)`` (15 coefficients of T0, then 15 of T1), done as a matrix product over sliding windows
(:func:`numpy.lib.stride_tricks.sliding_window_view`) in chunks of rows.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from math import factorial

import numpy as np

from .._validation import as_float64_array, check_choice
from ..bb import simplex as _bb

__all__ = [
    "SCHEMES",
    "TerrainInfo",
    "terrain_coefficients",
    "resample_for_c0",
    "evaluate",
    "gradient",
    "scheme_stencil",
]

#: Names accepted by :func:`terrain_coefficients`.
SCHEMES = ("linear", "C0", "C1", "C2", "C2-cubic")

_DEG = 4
_MI = _bb.multi_indices(_DEG, 2)                      # (15, 3), lexicographic descending
_IDX = {tuple(int(v) for v in a): q for q, a in enumerate(_MI)}
#: Triangle vertices in cell units, relative to the cell's lower-left corner.
_TRI = (np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)]), np.array([(0.0, 0.0), (1.0, 1.0), (0.0, 1.0)]))
# d(lambda_k)/dx and d(lambda_k)/dy on T0 (lam = (1-x, x-y, y)) and T1 (lam = (1-y, x, y-x)).
_DLAM = (np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]]), np.array([[0.0, 1.0, -1.0], [-1.0, 0.0, 1.0]]))

_SMOOTHNESS = {"linear": 0, "C0": 0, "C1": 1, "C2": 2, "C2-cubic": 2}
_REPRODUCES = {"linear": 1, "C0": 4, "C1": 3, "C2": 1, "C2-cubic": 3}
_MIN_SIZE = {"linear": 2, "C0": 5, "C1": 4, "C2": 4, "C2-cubic": 4}


@dataclass(frozen=True)
class TerrainInfo:
    """What :func:`terrain_coefficients` built.

    Attributes
    ----------
    scheme : str
        One of :data:`SCHEMES`.
    cell_size : int
        Side of a spline cell in index units (data cells): 1, or 4 for ``C0``.
    degree : int
        Polynomial degree of the pieces (always 4).
    smoothness : int
        r of C^r: 0, 1 or 2.
    reproduces : int
        Highest total degree of polynomials the scheme reproduces exactly.
    cells : tuple of int
        ``(ncy, ncx)``, the first two axes of ``coef``.
    data_shape : tuple of int
        ``(ny, nx)`` of the heights.
    """

    scheme: str
    cell_size: int
    degree: int
    smoothness: int
    reproduces: int
    cells: tuple
    data_shape: tuple


@dataclass(frozen=True)
class _Stencil:
    x0: int      # window's first data offset (x) relative to the cell corner (in data indices)
    y0: int
    kw: int      # window width/height in data points
    kh: int
    step: int    # data points per cell (4 for C0)
    W: np.ndarray  # (kh * kw, 30); row a * kw + b <-> offset (x0 + b, y0 + a)

    def pads(self):
        """(left, right, bottom, top) padding the window needs beyond the grid."""
        lo_x, lo_y = max(0, -self.x0), max(0, -self.y0)
        hi_x = max(0, self.x0 + self.kw - 1 - self.step)
        hi_y = max(0, self.y0 + self.kh - 1 - self.step)
        return lo_x, hi_x, lo_y, hi_y


# ----------------------------------------------------------------------------------------------------
# BB helpers (exact tables, no validation)
# ----------------------------------------------------------------------------------------------------

def _bern(alpha, lam):
    return factorial(_DEG) / np.prod([factorial(int(a)) for a in alpha]) * np.prod(np.asarray(lam, float) ** alpha)


@functools.lru_cache(maxsize=None)
def _collocation_inverse():
    """Inverse of the 15x15 matrix B[p, q] = B^4_q(domain point p): BB coefficients = Binv @ values."""
    B = np.array([[_bern(a, b / _DEG) for a in _MI] for b in _MI])
    Binv = np.linalg.inv(B)
    Binv.setflags(write=False)
    return Binv


def _domain_points(t):
    """(15, 2) domain points of triangle Tt in cell units."""
    return _MI @ _TRI[t] / _DEG


def _monomial_bb(a, b, t):
    """Quartic BB coefficients of x^a y^b (a + b <= 4) on triangle Tt of the cell at the origin."""
    p = _domain_points(t)
    return _collocation_inverse() @ (p[:, 0] ** a * p[:, 1] ** b)


def _edge_conditions(r):
    """C^0..C^r conditions between the triangles of neighbouring cells, as identities between coefficients.

    Returns a list of relations; each relation is a list of ``(cell_shift, t, q, weight)`` with
    ``sum weight * coef[cell + cell_shift, t, q] == 0`` required for every cell. The three pairs (T0, T1)
    of the same cell (diagonal edge), T0 of a cell and T1 of the cell below (horizontal edge), T0 and T1
    of the cell to the right (vertical edge) cover every interior edge. For triangles A, B sharing an edge,
    with B's opposite vertex e having barycentric coordinates lam w.r.t. A, the C^rho condition is
    ``c^B_beta = sum_{|g| = rho} B^rho_g(lam) c^A_{alpha0 + g}`` for every beta with beta_e = rho, where
    alpha0 carries beta's exponents on the shared vertices (Farin, ch. 18; Lai & Schumaker, Thm. 2.28).
    """
    rels = []
    pairs = [((0, 0), 0, (0, 0), 1), ((0, 0), 0, (0, -1), 1), ((0, 0), 0, (1, 0), 1)]
    for dA, tA, dB, tB in pairs:
        VA = _TRI[tA] + dA
        VB = _TRI[tB] + dB
        match = {k: m for k in range(3) for m in range(3) if np.array_equal(VA[k], VB[m])}
        eB = next(m for m in range(3) if m not in match.values())
        M = np.vstack([VA.T, np.ones(3)])
        lam = np.linalg.solve(M, np.append(VB[eB], 1.0))
        lam = np.round(lam * 8) / 8  # exact: the type-1 triangulation gives integer coordinates
        for rho in range(r + 1):
            for beta in _MI:
                if beta[eB] != rho:
                    continue
                alpha0 = np.zeros(3, dtype=np.int64)
                for k, m in match.items():
                    alpha0[k] = beta[m]
                terms = [(dB, tB, _IDX[tuple(int(v) for v in beta)], -1.0)]
                for g in _bb.multi_indices(rho, 2):
                    w = factorial(rho) / np.prod([factorial(int(v)) for v in g]) * np.prod(lam ** g)
                    if w != 0.0:
                        terms.append((dA, tA, _IDX[tuple(int(v) for v in alpha0 + g)], float(w)))
                rels.append(terms)
    return rels


# ----------------------------------------------------------------------------------------------------
# the schemes' weight matrices
# ----------------------------------------------------------------------------------------------------

def _offsets(x0, y0, kw, kh):
    return [(x0 + b, y0 + a) for a in range(kh) for b in range(kw)]


@functools.lru_cache(maxsize=None)
def _linear():
    offs = _offsets(0, 0, 2, 2)
    W = np.zeros((4, 30))
    for t in range(2):
        for k, v in enumerate(_TRI[t].astype(int)):
            s = offs.index((int(v[0]), int(v[1])))
            W[s, t * 15:(t + 1) * 15] += _MI[:, k] / _DEG
    return _Stencil(0, 0, 2, 2, 1, W)


@functools.lru_cache(maxsize=None)
def _c0():
    offs = _offsets(0, 0, 5, 5)
    Binv = _collocation_inverse()
    W = np.zeros((25, 30))
    for t in range(2):
        pts = (_MI @ _TRI[t]).astype(int)  # domain points in data units (cell side 4 = degree)
        for p, (px, py) in enumerate(pts):
            W[offs.index((int(px), int(py))), t * 15:(t + 1) * 15] += Binv[:, p]
    return _Stencil(0, 0, 5, 5, 4, W)


# 24 x the BB coefficients on T0 of the translates M(. - j) of the quartic box spline with directions
# (1,0), (0,1), (1,1) each twice (from the notes; verified by tests: partition of unity, C2, M(0) = 1/2).
_BOX_T0 = {
    (-1, -1): (2, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
    (-1, 0): (2, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
    (0, -1): (2, 3, 1, 4, 1, 0, 3, 1, 0, 0, 2, 1, 0, 0, 0),
    (0, 0): (12, 12, 12, 8, 10, 8, 4, 6, 6, 4, 2, 3, 4, 3, 2),
    (0, 1): (2, 1, 3, 0, 1, 4, 0, 0, 1, 3, 0, 0, 0, 1, 2),
    (1, -1): (0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 0),
    (1, 0): (2, 4, 3, 8, 6, 4, 12, 10, 6, 3, 12, 12, 8, 4, 2),
    (1, 1): (2, 3, 4, 4, 6, 8, 3, 6, 10, 12, 2, 4, 8, 12, 12),
    (1, 2): (0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2),
    (2, 0): (0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 1, 0, 0, 0),
    (2, 1): (0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 3, 4, 3, 2),
    (2, 2): (0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2),
}


def _box_weights():
    """{offset j: (30,) weights} of M(. - j) on T0 and T1 of the cell at the origin."""
    swap_q = [_IDX[(int(a[0]), int(a[2]), int(a[1]))] for a in _MI]  # T1 (a,b,c) <- T0 (a,c,b)
    out = {}
    for (jx, jy), row in _BOX_T0.items():
        out.setdefault((jx, jy), np.zeros(30))[:15] += np.array(row, float) / 24.0
        # T1 is the mirror image of T0 under x <-> y (with vertices 1, 2 exchanged):
        # coefficient (a,b,c) of M(. - j) on T1 = coefficient (a,c,b) of M(. - swap(j)) on T0.
        out.setdefault((jy, jx), np.zeros(30))[15:] += np.array(row, float)[swap_q] / 24.0
    return out


@functools.lru_cache(maxsize=None)
def _c2():
    offs = _offsets(-1, -1, 4, 4)
    W = np.zeros((16, 30))
    for j, w in _box_weights().items():
        W[offs.index(j)] += w
    return _Stencil(-1, -1, 4, 4, 1, W)


#: The cubic-exact prefilter of C2-cubic: c_j = 3/2 z_j - 1/12 (sum of z at the 6 mesh neighbours).
_PREFILTER = {(0, 0): 1.5, **{n: -1.0 / 12.0 for n in [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1)]}}


@functools.lru_cache(maxsize=None)
def _c2_cubic():
    offs = _offsets(-2, -2, 6, 6)
    W = np.zeros((36, 30))
    for j, w in _box_weights().items():
        for n, p in _PREFILTER.items():
            W[offs.index((j[0] + n[0], j[1] + n[1]))] += p * w
    return _Stencil(-2, -2, 6, 6, 1, W)


#: Data offsets of the C1 scheme (22 points; symmetric under x <-> y and under (x, y) -> (1-x, 1-y)):
#: the 4x4 block [-1, 2]^2 without its corners (-1, 2), (2, -1), plus two points beyond each side.
C1_STENCIL = tuple(sorted(
    [(x, y) for x in range(-1, 3) for y in range(-1, 3) if (x, y) not in ((-1, 2), (2, -1))]
    + [(-2, 0), (-2, 1), (3, 0), (3, 1), (0, -2), (1, -2), (0, 3), (1, 3)], key=lambda o: (o[1], o[0])))


def c1_system(offsets=C1_STENCIL, *, smoothness=1, reproduce=3):
    """The linear system whose solution is the C1 scheme's weights (see ``docs/terrain-schemes.md``).

    Unknowns ``w[s, tq]`` (``s`` over ``offsets``, ``tq = 15 t + q`` over the 30 coefficients of a cell),
    flattened as ``s * 30 + tq``. Rows: (i) for every C^0..C^smoothness edge condition of
    :func:`_edge_conditions` and every data offset ``o``, the weight of ``z(cell + o)`` in the condition
    must vanish (the condition holds for all data; a neighbour cell's weights are the stencil shifted by
    the cell offset); (ii) for every monomial ``x^a y^b`` with ``a + b <= reproduce`` and every coefficient,
    the weights applied to the monomial's samples give its BB coefficient (its blossom at the domain
    point). Returns ``(A, rhs, n_smooth_rows)``.
    """
    oi = {o: k for k, o in enumerate(offsets)}
    S = len(offsets)
    rows, rhs = [], []
    for terms in _edge_conditions(smoothness):
        outs = sorted({(o[0] + d[0], o[1] + d[1]) for d, _, _, _ in terms for o in offsets})
        for u in outs:
            row = {}
            for d, t, q, w in terms:
                s = oi.get((u[0] - d[0], u[1] - d[1]))
                if s is not None:
                    key = s * 30 + t * 15 + q
                    row[key] = row.get(key, 0.0) + w
            row = {k: v for k, v in row.items() if v != 0.0}
            if row:
                rows.append(row)
                rhs.append(0.0)
    n_smooth = len(rows)
    off = np.array(offsets, float)
    for a in range(reproduce + 1):
        for b in range(reproduce + 1 - a):
            samples = off[:, 0] ** a * off[:, 1] ** b
            for t in range(2):
                bb = _monomial_bb(a, b, t)
                for q in range(15):
                    rows.append({s * 30 + t * 15 + q: samples[s] for s in range(S) if samples[s] != 0.0})
                    rhs.append(bb[q])
    A = np.zeros((len(rows), S * 30))
    for k, row in enumerate(rows):
        for c, v in row.items():
            A[k, c] = v
    return A, np.array(rhs), n_smooth


@functools.lru_cache(maxsize=None)
def _c1_solution():
    """Least-norm weights of the C1 system (unique, hence symmetric) and the system's diagnostics."""
    A, rhs, n_smooth = c1_system()
    x, _, rank, _ = np.linalg.lstsq(A, rhs, rcond=None)
    resid = A @ x - rhs
    W = x.reshape(len(C1_STENCIL), 30)
    diag = {"rows": A.shape[0], "unknowns": A.shape[1], "rank": int(rank),
            "smoothness_residual": float(np.abs(resid[:n_smooth]).max()),
            "exactness_residual": float(np.abs(resid[n_smooth:]).max())}
    if max(diag["smoothness_residual"], diag["exactness_residual"]) > 1e-12:  # pragma: no cover
        raise RuntimeError(f"C1 weight system is inconsistent: {diag}")
    W.setflags(write=False)
    return W, diag


@functools.lru_cache(maxsize=None)
def _c1():
    Wc, _ = _c1_solution()
    offs = _offsets(-2, -2, 6, 6)
    W = np.zeros((36, 30))
    for s, o in enumerate(C1_STENCIL):
        W[offs.index(o)] = Wc[s]
    return _Stencil(-2, -2, 6, 6, 1, W)


_BUILDERS = {"linear": _linear, "C0": _c0, "C1": _c1, "C2": _c2, "C2-cubic": _c2_cubic}


def scheme_stencil(scheme):
    """The scheme's data stencil and weights: ``(offsets, W)``.

    ``offsets`` is a list of ``(dx, dy)`` data offsets from a cell's lower-left corner (in data indices;
    for ``C0`` the corner is at ``4 * (i, j)``), ``W`` has shape ``(len(offsets), 30)``: coefficient ``q`` of
    triangle ``t`` of the cell is ``sum_s W[s, 15 t + q] * z(corner + offsets[s])``. Only offsets with a
    nonzero weight are listed.
    """
    check_choice(scheme, "scheme", SCHEMES)
    st = _BUILDERS[scheme]()
    offs = _offsets(st.x0, st.y0, st.kw, st.kh)
    keep = [s for s in range(len(offs)) if np.any(st.W[s] != 0.0)]
    return [offs[s] for s in keep], st.W[keep].copy()


# ----------------------------------------------------------------------------------------------------
# input checks, padding, engine
# ----------------------------------------------------------------------------------------------------

def _check_heights(z, scheme):
    check_choice(scheme, "scheme", SCHEMES)
    z = as_float64_array(z, "z (heights)", finite=False)
    if z.ndim != 2:
        raise ValueError(f"z (heights) must be a 2-D array of shape (ny, nx) with z[j, i] at index point (i, j); "
                         f"got {z.ndim}-D shape {z.shape}.")
    bad = ~np.isfinite(z)
    if bad.any():
        r, c = (int(v) for v in np.argwhere(bad)[0])
        raise ValueError(f"z (heights) must be finite; found {int(bad.sum())} non-finite value(s), the first, "
                         f"{float(z[r, c])!r}, at row {r}, column {c} (z[{r}, {c}], index point x={c}, y={r}).")
    ny, nx = z.shape
    m = _MIN_SIZE[scheme]
    if ny < m or nx < m:
        raise ValueError(f"scheme {scheme} needs at least {m}x{m} heights, got {ny}x{nx} (rows x columns).")
    if scheme == "C0" and ((nx - 1) % 4 or (ny - 1) % 4):
        raise ValueError(
            f"scheme C0 interpolates at the 15 domain points of each triangle, spaced 1/4 of a cell side, so it "
            f"groups 4x4 data cells into one spline cell and needs (ny - 1) and (nx - 1) divisible by 4 (sizes "
            f"4k + 1); got {ny}x{nx}. Resample with resample_for_c0(z), which returns heights of size "
            f"{_next_c0(ny)}x{_next_c0(nx)} and the scale factors.")
    return z


def _next_c0(n):
    return 4 * -(-(n - 1) // 4) + 1


def _pad_cubic(z, lo_x, hi_x, lo_y, hi_y):
    """Pad by cubic extrapolation f[-1] = 4 f[0] - 6 f[1] + 4 f[2] - f[3] (x first, then y)."""
    ny, nx = z.shape
    out = np.empty((ny + lo_y + hi_y, nx + lo_x + hi_x))
    out[lo_y:lo_y + ny, lo_x:lo_x + nx] = z
    rows = slice(lo_y, lo_y + ny)
    for k in range(lo_x - 1, -1, -1):
        c = out[rows, k + 1:k + 5]
        out[rows, k] = 4 * c[:, 0] - 6 * c[:, 1] + 4 * c[:, 2] - c[:, 3]
    for k in range(lo_x + nx, lo_x + nx + hi_x):
        c = out[rows, k - 4:k]
        out[rows, k] = 4 * c[:, 3] - 6 * c[:, 2] + 4 * c[:, 1] - c[:, 0]
    for k in range(lo_y - 1, -1, -1):
        c = out[k + 1:k + 5]
        out[k] = 4 * c[0] - 6 * c[1] + 4 * c[2] - c[3]
    for k in range(lo_y + ny, lo_y + ny + hi_y):
        c = out[k - 4:k]
        out[k] = 4 * c[3] - 6 * c[2] + 4 * c[1] - c[0]
    return out


_CHUNK_CELLS = 1 << 13   # cells per gather (np.take) of the stencil values
# OpenBLAS runs a GEMM on one thread when M * N * K <= 65536 * 4; larger skinny products (K = S <= 30,
# N = 30) got *slower* with its threads on a loaded 2-core machine. So the products are kept below that
# size and the two cores are used by two Python threads working on alternate row chunks instead.
_GEMM_SINGLE = 65536 * 4
_THREADS = 2


def _apply(z, st: _Stencil):
    """coef[j, i] = W^T (heights at the cell's stencil points), for all cells, in chunks of rows."""
    lo_x, hi_x, lo_y, hi_y = st.pads()
    zp = _pad_cubic(z, lo_x, hi_x, lo_y, hi_y) if (lo_x or hi_x or lo_y or hi_y) else np.ascontiguousarray(z)
    ny, nx = z.shape
    ncx, ncy = (nx - 1) // st.step, (ny - 1) // st.step
    # Only the stencil points with a nonzero weight are gathered: a sliding window of the padded grid,
    # read through flat indices: cell (i, j)'s corner is (step i + lo_x, step j + lo_y) in the padded grid,
    # its window starts at corner + (x0, y0) (never negative: lo_x >= -x0, lo_y >= -y0).
    keep = np.flatnonzero(np.any(st.W != 0.0, axis=1))
    offs = np.array(_offsets(st.x0, st.y0, st.kw, st.kh))[keep] - (st.x0, st.y0)  # >= 0: window-relative
    W = np.ascontiguousarray(st.W[keep])
    S = len(keep)
    wp = zp.shape[1]
    zflat = zp.reshape(-1)
    rows = max(1, min(ncy, _CHUNK_CELLS // max(ncx, 1)))
    jj, ii = np.meshgrid(np.arange(rows), np.arange(ncx), indexing="ij")
    rel = ((st.step * jj * wp + st.step * ii).reshape(-1, 1) + (offs[:, 1] * wp + offs[:, 0])[None, :])
    out = np.empty((ncy, ncx, 2, 15))
    flat = out.reshape(ncy * ncx, 30)
    sub = max(16, _GEMM_SINGLE // (30 * S))

    def work(r0):
        r1 = min(ncy, r0 + rows)
        m = (r1 - r0) * ncx
        base = (st.step * r0 + lo_y + st.y0) * wp + lo_x + st.x0  # window start of cell (0, r0)
        blk = np.take(zflat[base:], rel[:m])
        dst = flat[r0 * ncx:r1 * ncx]
        for k in range(0, m, sub):
            np.matmul(blk[k:k + sub], W, out=dst[k:k + sub])

    starts = range(0, ncy, rows)
    if ncy * ncx >= 4 * _CHUNK_CELLS and _THREADS > 1:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(_THREADS) as ex:
            list(ex.map(work, starts))
    else:
        for r0 in starts:
            work(r0)
    return out


def terrain_coefficients(z, scheme="C1"):
    """Quartic BB coefficients of a terrain spline from a grid of heights.

    Parameters
    ----------
    z : (ny, nx) array_like
        Heights, ``z[j, i]`` at index point ``(i, j)``; finite real numbers.
    scheme : str
        One of :data:`SCHEMES`: ``"linear"`` (piecewise linear interpolant, degree-elevated), ``"C0"``
        (quartic interpolation at all domain points; needs sizes 4k + 1, see :func:`resample_for_c0`),
        ``"C1"`` (C1 quasi-interpolant exact on cubics), ``"C2"`` (the paper's quartic box spline with the
        data as coefficients; smooths, exact on linear functions), ``"C2-cubic"`` (the same spline with
        cubic-exact coefficients).

    Returns
    -------
    coef : (ncy, ncx, 2, 15) float64 ndarray
        ``coef[j, i, t]``: coefficients of triangle ``Tt`` of cell ``(i, j)`` (module docstring).
        ``ncx = nx - 1``, ``ncy = ny - 1``; for ``C0`` ``(nx - 1) / 4`` and ``(ny - 1) / 4``.
    info : TerrainInfo

    Raises
    ------
    ValueError
        Unknown scheme (the message lists :data:`SCHEMES`), ``z`` not 2-D, a non-finite height (the
        message names its row and column), a grid below the scheme's minimum size (2x2 for linear, 4x4
        for C1, C2, C2-cubic, 5x5 for C0) or, for C0, sizes that are not 4k + 1.
    TypeError
        ``z`` is not numeric.

    Examples
    --------
    >>> import numpy as np
    >>> coef, info = terrain_coefficients(np.zeros((5, 9)), "C0")
    >>> coef.shape, info.cell_size, info.smoothness
    ((1, 2, 2, 15), 4, 0)
    """
    z = _check_heights(z, scheme)
    st = _BUILDERS[scheme]()
    coef = _apply(z, st)
    info = TerrainInfo(scheme=scheme, cell_size=st.step, degree=_DEG, smoothness=_SMOOTHNESS[scheme],
                       reproduces=_REPRODUCES[scheme], cells=coef.shape[:2], data_shape=z.shape)
    return coef, info


_RESAMPLE_PAD = 24


def resample_for_c0(z):
    """Resample heights to the next sizes ``4k + 1`` that scheme ``C0`` accepts.

    The new grid spans the same rectangle: new point ``(i', j')`` sits at old index coordinates
    ``(i' * sx, j' * sy)`` with ``sx = (nx - 1) / (nx' - 1)`` (likewise ``sy``). Values come from cubic
    B-spline interpolation (:func:`scipy.ndimage.map_coordinates`, ``order=3``) of the heights padded by
    24 points of cubic extrapolation on every side (the padding of :func:`terrain_coefficients`), so the
    spline prefilter's boundary condition sits far outside (its influence decays like 0.268^24 ~ 2e-14)
    and cubic polynomials are reproduced up to rounding. Sizes that are already valid are returned
    unchanged (a copy, scale ``(1.0, 1.0)``).

    Parameters
    ----------
    z : (ny, nx) array_like
        Heights, at least 4x4, finite.

    Returns
    -------
    z_new : (ny', nx') float64 ndarray
        ``ny' = 4 ceil((ny - 1) / 4) + 1``, likewise ``nx'``.
    scale : tuple of float
        ``(sx, sy)``: old index units per new index unit. Multiply new index coordinates (and the physical
        grid spacing) by it.
    """
    z = as_float64_array(z, "z (heights)", finite=False)
    if z.ndim != 2:
        raise ValueError(f"z (heights) must be a 2-D array of shape (ny, nx); got {z.ndim}-D shape {z.shape}.")
    bad = ~np.isfinite(z)
    if bad.any():
        r, c = (int(v) for v in np.argwhere(bad)[0])
        raise ValueError(f"z (heights) must be finite; the first non-finite value, {float(z[r, c])!r}, is at "
                         f"row {r}, column {c}.")
    ny, nx = z.shape
    if ny < 4 or nx < 4:
        raise ValueError(f"resample_for_c0 needs at least 4x4 heights (for its cubic padding), got {ny}x{nx}.")
    nyn, nxn = _next_c0(ny), _next_c0(nx)
    if (nyn, nxn) == (ny, nx):
        return z.copy(), (1.0, 1.0)
    from scipy.ndimage import map_coordinates

    P = _RESAMPLE_PAD
    zp = _pad_cubic(z, P, P, P, P)
    sx, sy = (nx - 1) / (nxn - 1), (ny - 1) / (nyn - 1)
    jj, ii = np.meshgrid(np.arange(nyn) * sy + P, np.arange(nxn) * sx + P, indexing="ij")
    out = map_coordinates(zp, [jj, ii], order=3, mode="nearest")
    return out, (sx, sy)


# ----------------------------------------------------------------------------------------------------
# evaluation
# ----------------------------------------------------------------------------------------------------

def _locate(coef, info, x, y):
    coef = as_float64_array(coef, "coef", ndim=4, shape_tail=(2, 15))
    if not isinstance(info, TerrainInfo):
        raise TypeError(f"info must be the TerrainInfo returned by terrain_coefficients, got {type(info).__name__}.")
    ncy, ncx = coef.shape[:2]
    x = as_float64_array(x, "x")
    y = as_float64_array(y, "y")
    x, y = np.broadcast_arrays(x, y)
    h = float(info.cell_size)
    u, v = x / h, y / h
    outside = (u < 0) | (u > ncx) | (v < 0) | (v > ncy)
    if outside.any():
        k = tuple(int(i) for i in np.argwhere(outside)[0]) if outside.ndim else ()
        raise ValueError(f"point (x, y) = ({float(x[k])!r}, {float(y[k])!r}) at index {k} lies outside the "
                         f"terrain's domain [0, {ncx * h:g}] x [0, {ncy * h:g}] (index units).")
    i = np.minimum(np.floor(u).astype(np.int64), ncx - 1)
    j = np.minimum(np.floor(v).astype(np.int64), ncy - 1)
    fx, fy = u - i, v - j
    upper = fy > fx
    t = upper.astype(np.int64)
    lam = np.where(upper[..., None],
                   np.stack([1.0 - fy, fx, fy - fx], axis=-1),
                   np.stack([1.0 - fx, fx - fy, fy], axis=-1))
    return coef[j, i, t], lam, t, h


def evaluate(coef, info, x, y):
    """Spline values at points ``(x, y)`` in index coordinates (arrays broadcast).

    The point's cell is ``floor(x / cell_size)`` (the last cell includes the far boundary), its triangle is
    T1 when ``y > x`` inside the cell, else T0; the value comes from de Casteljau's algorithm
    (:func:`splinevis.bb.simplex.de_casteljau`). Points outside ``[0, ncx * cell] x [0, ncy * cell]`` raise
    ValueError.
    """
    c, lam, _, _ = _locate(coef, info, x, y)
    return _bb.de_casteljau(c, lam, d=2)


def gradient(coef, info, x, y):
    """``(ds/dx, ds/dy)`` in index units at points ``(x, y)``, stacked on the last axis.

    On an edge the triangle chosen by :func:`evaluate` is used (a one-sided derivative for C0 splines).
    """
    c, lam, t, h = _locate(coef, info, x, y)
    g = _bb.gradient(c, d=2)                       # (..., 3, 10): n * c[a + e_k]
    part = _bb.de_casteljau(g, lam[..., None, :], d=2)  # (..., 3): dp/dlam_k
    dl = np.stack(_DLAM)[t]                        # (..., 2, 3)
    return np.einsum("...ck,...k->...c", dl, part) / h

"""Quartic spline terrains on the type-1 triangulation, built from a uniform grid of heights.

Every scheme here sets the 15 quartic Bernstein-Bezier (BB) coefficients of each triangle directly as a
fixed linear combination of nearby heights (a *quasi-interpolant*, [Reis2008, sec. IV, eq. (4)]).
Schemes:

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
C2-interp   1x1 data cells         C2          degree 3     global: the C2 stencil on heights prefiltered
                                                            so the spline interpolates the samples
                                                            (:mod:`splinevis.terrain.interpolating`)
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


Modules
-------
This module defines the schemes and the public interface. The stencil engine that applies a scheme's
weights to all cells, with the cubic padding, is :mod:`splinevis.terrain.engine`; the quartic BB tables of
a cell and the smoothness conditions between cells are :mod:`splinevis.terrain.cell`; the derivation of
the C1 weights is :mod:`splinevis.terrain.c1_scheme`; the box-spline C2 schemes are
:mod:`splinevis.terrain.box_spline`, and the prefilter (a sparse solve) of the interpolating one,
``C2-interp``, is :mod:`splinevis.terrain.interpolating`.

References
----------
.. [Reis2008] Reis et al. 2008, quartic terrain splines.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .._validation import as_float64_array, check_choice
from ..bb import simplex as _bb
from .box_spline import _c2, _c2_cubic
# C1_STENCIL, c1_system, _c1_solution and _pad_cubic are re-exported: the package and the tests read them here
from .c1_scheme import C1_STENCIL as C1_STENCIL, _c1, _c1_solution as _c1_solution, c1_system as c1_system
from .cell import _DEG, _DLAM, _MI, _TRI, _collocation_inverse
from .engine import _apply, _check_height_grid, _offsets, _pad_cubic as _pad_cubic, _Stencil

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
SCHEMES = ("linear", "C0", "C1", "C2", "C2-cubic", "C2-interp")

#: The schemes whose coefficients are a fixed local stencil of the heights (what :func:`scheme_stencil` and the
#: out-of-core tiles need); ``C2-interp`` is global (a solve over the whole grid).
STENCIL_SCHEMES = ("linear", "C0", "C1", "C2", "C2-cubic")

_SMOOTHNESS = {"linear": 0, "C0": 0, "C1": 1, "C2": 2, "C2-cubic": 2, "C2-interp": 2}
_REPRODUCES = {"linear": 1, "C0": 4, "C1": 3, "C2": 1, "C2-cubic": 3, "C2-interp": 3}
_MIN_SIZE = {"linear": 2, "C0": 5, "C1": 4, "C2": 4, "C2-cubic": 4, "C2-interp": 4}


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

    Examples
    --------
    >>> terrain_coefficients(np.zeros((6, 6)), "C1")[1]
    TerrainInfo(scheme='C1', cell_size=1, degree=4, smoothness=1, reproduces=3, cells=(5, 5), data_shape=(6, 6))
    """

    scheme: str
    cell_size: int
    degree: int
    smoothness: int
    reproduces: int
    cells: tuple
    data_shape: tuple


# ----------------------------------------------------------------------------------------------------
# the schemes' weight matrices
# ----------------------------------------------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def _linear():
    """The linear scheme: the interpolant at the cell corners, degree-elevated to quartic."""
    offs = _offsets(0, 0, 2, 2)
    W = np.zeros((4, 30))
    for t in range(2):
        for k, v in enumerate(_TRI[t].astype(int)):
            s = offs.index((int(v[0]), int(v[1])))
            W[s, t * 15:(t + 1) * 15] += _MI[:, k] / _DEG
    return _Stencil(0, 0, 2, 2, 1, W)


@functools.lru_cache(maxsize=None)
def _c0():
    """The C0 scheme: quartic interpolation at the 15 domain points of each triangle of a 4x4 cell."""
    offs = _offsets(0, 0, 5, 5)
    Binv = _collocation_inverse()
    W = np.zeros((25, 30))
    for t in range(2):
        pts = (_MI @ _TRI[t]).astype(int)  # domain points in data units (cell side 4 = degree)
        for p, (px, py) in enumerate(pts):
            W[offs.index((int(px), int(py))), t * 15:(t + 1) * 15] += Binv[:, p]
    return _Stencil(0, 0, 5, 5, 4, W)


_BUILDERS = {"linear": _linear, "C0": _c0, "C1": _c1, "C2": _c2, "C2-cubic": _c2_cubic}


def scheme_stencil(scheme):
    """The scheme's data stencil and weights: ``(offsets, W)``.

    ``offsets`` is a list of ``(dx, dy)`` data offsets from a cell's lower-left corner (in data indices;
    for ``C0`` the corner is at ``4 * (i, j)``), ``W`` has shape ``(len(offsets), 30)``: coefficient ``q`` of
    triangle ``t`` of the cell is ``sum_s W[s, 15 t + q] * z(corner + offsets[s])``. Only offsets with a
    nonzero weight are listed.

    Examples
    --------
    >>> offsets, W = scheme_stencil("linear")
    >>> offsets, W.shape
    ([(0, 0), (1, 0), (0, 1), (1, 1)], (4, 30))
    >>> W.sum(axis=0).round(12).min(), W.sum(axis=0).round(12).max()  # every coefficient: weights sum to 1
    (np.float64(1.0), np.float64(1.0))
    """
    check_choice(scheme, "scheme", SCHEMES)
    if scheme not in STENCIL_SCHEMES:
        raise ValueError(f"scheme {scheme} has no local stencil: its coefficients are the C2 stencil "
                         f"(scheme_stencil('C2')) applied to heights prefiltered by a solve over the whole grid "
                         f"(splinevis.terrain.interpolating.prefilter_heights).")
    st = _BUILDERS[scheme]()
    offs = _offsets(st.x0, st.y0, st.kw, st.kh)
    keep = [s for s in range(len(offs)) if np.any(st.W[s] != 0.0)]
    return [offs[s] for s in keep], st.W[keep].copy()


# ----------------------------------------------------------------------------------------------------
# input checks, coefficients, resampling
# ----------------------------------------------------------------------------------------------------

def _check_heights(z, scheme):
    """``z`` as a finite 2-D float64 grid of at least the scheme's minimum size (sizes 4k + 1 for C0)."""
    check_choice(scheme, "scheme", SCHEMES)
    z = _check_height_grid(z)
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
    """The smallest size ``4k + 1 >= n``."""
    return 4 * -(-(n - 1) // 4) + 1


def terrain_coefficients(z, scheme="C1"):
    """Quartic BB coefficients of a terrain spline from a grid of heights.

    Parameters
    ----------
    z : (ny, nx) array_like
        Heights, ``z[j, i]`` at index point ``(i, j)``; finite real numbers.
    scheme : str
        One of :data:`SCHEMES`: ``"linear"`` (piecewise linear interpolant, degree-elevated), ``"C0"``
        (quartic interpolation at all domain points; needs sizes 4k + 1, see :func:`resample_for_c0`),
        ``"C1"`` (C1 quasi-interpolant exact on cubics), ``"C2"`` (the quartic box spline of [Reis2008, sec. IV] with the
        data as coefficients; smooths, exact on linear functions), ``"C2-cubic"`` (the same spline with
        cubic-exact coefficients), ``"C2-interp"`` (the same spline interpolating the heights: the C2 stencil
        on prefiltered heights, :func:`splinevis.terrain.interpolating.prefilter_heights`).

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
        for C1, C2, C2-cubic, C2-interp, 5x5 for C0) or, for C0, sizes that are not 4k + 1.
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
    if scheme == "C2-interp":
        from .interpolating import prefilter_heights

        st = _c2()
        coef = _apply(prefilter_heights(z), st)
    else:
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

    Examples
    --------
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> z, scale = resample_for_c0(x ** 3 + y)  # 6 x 6 -> 9 x 9
    >>> z.shape, scale
    ((9, 9), (0.625, 0.625))
    >>> round(float(z[8, 8]), 9), round(float(z[4, 4]), 9)  # cubics reproduced: x = y = 5 and 2.5
    (130.0, 18.125)
    """
    z = _check_height_grid(z)
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

    Examples
    --------
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> coef, info = terrain_coefficients(x ** 3 - x * y, "C1")  # cubics are reproduced
    >>> round(float(evaluate(coef, info, 2.5, 1.5)), 9)
    11.875
    >>> evaluate(coef, info, 6.0, 1.0)
    Traceback (most recent call last):
    ValueError: point (x, y) = (6.0, 1.0) at index () lies outside the terrain's domain [0, 5] x [0, 5] (index units).
    """
    c, lam, _, _ = _locate(coef, info, x, y)
    return _bb.de_casteljau(c, lam, d=2)


def gradient(coef, info, x, y):
    """``(ds/dx, ds/dy)`` in index units at points ``(x, y)``, stacked on the last axis.

    On an edge the triangle chosen by :func:`evaluate` is used (a one-sided derivative for C0 splines).

    Examples
    --------
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> coef, info = terrain_coefficients(x ** 3 - x * y, "C1")
    >>> gradient(coef, info, 2.5, 1.5).round(9)  # (3 x^2 - y, -x)
    array([17.25, -2.5 ])
    """
    c, lam, t, h = _locate(coef, info, x, y)
    g = _bb.gradient(c, d=2)                       # (..., 3, 10): n * c[a + e_k]
    part = _bb.de_casteljau(g, lam[..., None, :], d=2)  # (..., 3): dp/dlam_k
    dl = np.stack(_DLAM)[t]                        # (..., 2, 3)
    return np.einsum("...ck,...k->...c", dl, part) / h

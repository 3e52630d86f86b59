"""Interpolation on height grids (scipy): filling gaps, resampling non-uniform grids onto uniform ones.

Used by :func:`splinevis.io.read_heights` for ``fill=`` and ``resample=``:

* ``fill="nearest"``: the value of the nearest valid sample in world distance (anisotropic spacing
  counts), from ``scipy.ndimage.distance_transform_edt``.
* ``fill="linear"``: linear interpolation on a Delaunay triangulation (``scipy.interpolate.griddata``)
  of the valid samples within two cells of a gap; points outside their convex hull take the nearest
  value. A plane is reproduced exactly (to rounding).
* ``resample``: ``scipy.interpolate.RegularGridInterpolator`` (linear or cubic) onto a uniform grid over
  the same extent whose spacing is the extent divided into ``ceil(extent / smallest_step)`` equal
  steps, i.e. at most the smallest input step.

Coordinates are local: ``(x - x[0], y - y[0])``, so that large (UTM) origins do not cost precision.
"""

from __future__ import annotations

import math

import numpy as np

from ._common import fill_nearest

__all__ = ["fill_gaps", "resample_uniform"]


def fill_gaps(h: np.ndarray, miss: np.ndarray, local: tuple, method: str) -> np.ndarray:
    """Fill the missing heights.

    Parameters
    ----------
    h : (ny, nx) ndarray of float64
        Heights, rows south to north.
    miss : (ny, nx) ndarray of bool
        True at the gaps; at least one sample is valid.
    local : ((nx,), (ny,)) ndarrays
        Increasing local x and y coordinates of the columns and rows.
    method : {"nearest", "linear"}

    Returns
    -------
    (ny, nx) ndarray of float64

    Examples
    --------
    >>> h = np.array([[0.0, 1.0, 2.0], [1.0, np.nan, 3.0], [2.0, 3.0, 4.0]])  # the plane x + y, one gap
    >>> axes = (np.arange(3.0), np.arange(3.0))
    >>> fill_gaps(h, np.isnan(h), axes, "linear")[1, 1], fill_gaps(h, np.isnan(h), axes, "nearest")[1, 1]
    (np.float64(2.0), np.float64(1.0))
    """
    from scipy import interpolate, ndimage

    (xl, yl) = local
    if method == "nearest":
        # sampling = (row step, col step): nearest in world distance on anisotropic grids
        dy = float(np.min(np.diff(yl)))
        dx = float(np.min(np.diff(xl)))
        return fill_nearest(h, miss, (dy, dx))
    # linear: triangulate the valid samples near the gaps only (cost scales with the gaps, not the grid)
    near = ndimage.binary_dilation(miss, iterations=2) & ~miss
    XX, YY = np.meshgrid(xl, yl)
    src = np.column_stack([XX[near], YY[near]])
    dst = np.column_stack([XX[miss], YY[miss]])
    out = h.copy()
    vals = np.full(dst.shape[0], np.nan)
    if src.shape[0] >= 3:
        try:
            vals = interpolate.griddata(src, h[near], dst, method="linear")
        except Exception:  # collinear support (e.g. one row of valid samples): fall back to nearest
            pass
    outside = ~np.isfinite(vals)
    if outside.any():
        vals[outside] = interpolate.griddata(np.column_stack([XX[~miss], YY[~miss]]), h[~miss],
                                             dst[outside], method="nearest")
    out[miss] = vals
    return out


def resample_uniform(h: np.ndarray, local: tuple, method: str) -> tuple:
    """Resample heights on non-uniform coordinates onto a uniform grid over the same extent.

    Parameters
    ----------
    h : (ny, nx) ndarray of float64
        Heights without gaps, rows south to north.
    local : ((nx,), (ny,)) ndarrays
        Increasing local x and y coordinates, starting at 0.
    method : {"linear", "cubic"}

    Returns
    -------
    heights : ndarray of float64
        On the new grid, which starts at the same corner.
    spacing : (dx, dy) floats

    Examples
    --------
    Columns at x = 0, 1, 3 become columns at the smallest step, x = 0, 1, 2, 3:

    >>> h = np.array([[0.0, 1.0, 3.0], [0.0, 1.0, 3.0]])  # the height is x
    >>> resample_uniform(h, (np.array([0.0, 1.0, 3.0]), np.array([0.0, 1.0])), "linear")
    (array([[0., 1., 2., 3.],
           [0., 1., 2., 3.]]), (1.0, 1.0))
    """
    from scipy.interpolate import RegularGridInterpolator

    xl, yl = local
    new = []
    for c in (xl, yl):
        n = int(math.ceil(c[-1] / float(np.min(np.diff(c))) - 1e-9)) + 1
        new.append(np.linspace(0.0, c[-1], n))
    interp = RegularGridInterpolator((yl, xl), h, method=method)
    YY, XX = np.meshgrid(new[1], new[0], indexing="ij")
    out = interp(np.column_stack([YY.ravel(), XX.ravel()])).reshape(YY.shape)
    spacing = (float(xl[-1] / (new[0].size - 1)), float(yl[-1] / (new[1].size - 1)))
    return out, spacing

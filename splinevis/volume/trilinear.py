"""The trilinear interpolant of volume data: the baseline of the spline schemes (what VTK's ray caster and
most GPU volume renderers use; [Kalbe2008, sec. 1, Fig. 8]: "continuous, piecewise cubics obtained from
successive univariate linear interpolation").

Conventions as in :mod:`splinevis.volume.schemes`: ``volume[k, j, i]`` is the value at the index-space
point ``(x, y, z) = (i, j, k)``. Unlike the splines (one cube per data point, domain ``[-1/2, n - 1/2]``)
the trilinear interpolant lives on the cells *between* data points, domain ``[0, nx - 1] x [0, ny - 1] x
[0, nz - 1]``; it interpolates the data, is C0, and its gradient jumps across every cell face.
"""

from __future__ import annotations

import numpy as np

from .._validation import as_float64_array
from .schemes import _check_volume

__all__ = ["trilinear_interpolate"]


def trilinear_interpolate(volume, points, *, gradient: bool = False, tol: float = 1e-9):
    """Value (and gradient) of the trilinear interpolant of ``volume`` at index-space points.

    Parameters
    ----------
    volume : (nz, ny, nx) array_like, finite, every axis >= 2
    points : (..., 3) array_like
        ``(x, y, z)`` in ``[0, nx - 1] x [0, ny - 1] x [0, nz - 1]`` (up to ``tol``).
    gradient : bool
        Also return ``(d/dx, d/dy, d/dz)`` of the cell's trilinear polynomial. A point on a cell face
        belongs to the cell above it (``floor``), except on the last face of each axis.

    Returns
    -------
    values (...), or (values, gradients (..., 3)).

    Examples
    --------
    >>> import numpy as np
    >>> v = np.arange(8.0).reshape(2, 2, 2)          # f = x + 2 y + 4 z
    >>> float(trilinear_interpolate(v, [0.5, 0.5, 0.5]))
    3.5
    """
    vol = _check_volume(volume, "trilinear interpolation")
    p = as_float64_array(points, "points", shape_tail=(3,))
    nz, ny, nx = vol.shape
    hi = np.array([nx, ny, nz], dtype=np.float64) - 1.0
    out = (p < -tol) | (p > hi + tol)
    if out.any():
        idx = tuple(int(v) for v in np.argwhere(out.any(axis=-1))[0]) if p.ndim > 1 else ()
        raise ValueError(f"points must lie in the trilinear domain [0, n - 1] per axis (x: nx={nx}, y: ny={ny}, "
                         f"z: nz={nz}); the point at index {idx} is {p[idx].tolist()}.")
    cell = np.clip(np.floor(p), 0, hi - 1).astype(np.int64)
    u = np.clip(p - cell, 0.0, 1.0)
    i, j, k = cell[..., 0], cell[..., 1], cell[..., 2]
    c = {(a, b, d): vol[k + d, j + b, i + a] for a in (0, 1) for b in (0, 1) for d in (0, 1)}
    x, y, z = u[..., 0], u[..., 1], u[..., 2]
    # successive linear interpolation along x, then y, then z
    c00 = c[0, 0, 0] + x * (c[1, 0, 0] - c[0, 0, 0])
    c10 = c[0, 1, 0] + x * (c[1, 1, 0] - c[0, 1, 0])
    c01 = c[0, 0, 1] + x * (c[1, 0, 1] - c[0, 0, 1])
    c11 = c[0, 1, 1] + x * (c[1, 1, 1] - c[0, 1, 1])
    c0 = c00 + y * (c10 - c00)
    c1 = c01 + y * (c11 - c01)
    val = c0 + z * (c1 - c0)
    if not gradient:
        return val
    dz = c1 - c0
    dy = (c10 - c00) + z * ((c11 - c01) - (c10 - c00))
    dx00 = c[1, 0, 0] - c[0, 0, 0]
    dx10 = c[1, 1, 0] - c[0, 1, 0]
    dx01 = c[1, 0, 1] - c[0, 0, 1]
    dx11 = c[1, 1, 1] - c[0, 1, 1]
    dx0 = dx00 + y * (dx10 - dx00)
    dx1 = dx01 + y * (dx11 - dx01)
    dx = dx0 + z * (dx1 - dx0)
    return val, np.stack([dx, dy, dz], axis=-1)

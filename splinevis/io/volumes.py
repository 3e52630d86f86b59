"""Volume data on uniform, axis-aligned grids (issue 4): the result type every volume reader returns.

``VolumeGrid.values[k, j, i]`` is the sample at the world point
``origin + (i * dx, j * dy, k * dz)``; index-space coordinates are ``(x, y, z) = (i, j, k)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import as_float64_array

__all__ = ["VolumeGrid"]


def _check_triple(value, name: str, *, positive: bool = False) -> tuple:
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be three numbers (x, y, z), got the string {value!r}.")
    try:
        t = tuple(float(v) for v in value)
    except TypeError:
        raise TypeError(f"{name} must be three numbers (x, y, z), got {type(value).__name__}.") from None
    if len(t) != 3:
        raise ValueError(f"{name} must have 3 entries (x, y, z), got {len(t)}: {value!r}.")
    if not all(np.isfinite(t)):
        raise ValueError(f"{name} must be finite, got {t}.")
    if positive and min(t) <= 0:
        raise ValueError(f"{name} must be > 0 on every axis, got {t}.")
    return t


@dataclass(frozen=True, eq=False)
class VolumeGrid:
    """Samples of a scalar field on a uniform, axis-aligned grid.

    Parameters
    ----------
    values : (nz, ny, nx) ndarray
        ``values[k, j, i]`` is the sample at ``origin + (i*dx, j*dy, k*dz)``. Stored as a read-only
        float64 copy; every value finite.
    spacing : (dx, dy, dz) floats > 0
        May differ per axis (anisotropic).
    origin : (x0, y0, z0) floats
        World position of ``values[0, 0, 0]``, kept in float64.
    source : str
        Where the data came from (a file path, ``"numpy array"``, ``"pyvista.ImageData"``, ...).
    scalars : str or None
        Name of the array read, if the source names it.
    dtype : str
        The data type of the source samples before conversion (``"uint8"``, ``"int16"``, ...).
    """

    values: np.ndarray
    spacing: tuple = (1.0, 1.0, 1.0)
    origin: tuple = (0.0, 0.0, 0.0)
    source: str = "numpy array"
    scalars: str | None = None
    dtype: str = "float64"

    def __post_init__(self):
        v = as_float64_array(self.values, "values", ndim=3)
        v = np.array(v, dtype=np.float64, copy=True)
        v.flags.writeable = False
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "spacing", _check_triple(self.spacing, "spacing", positive=True))
        object.__setattr__(self, "origin", _check_triple(self.origin, "origin"))
        if not isinstance(self.source, str):
            raise TypeError(f"source must be a str, got {type(self.source).__name__}.")

    @property
    def shape(self) -> tuple:
        """``(nz, ny, nx)``."""
        return self.values.shape

    @property
    def bounds(self) -> tuple:
        """``(xmin, xmax, ymin, ymax, zmin, zmax)`` of the sample positions (pyvista order)."""
        (nz, ny, nx), (dx, dy, dz), (x0, y0, z0) = self.shape, self.spacing, self.origin
        return (x0, x0 + (nx - 1) * dx, y0, y0 + (ny - 1) * dy, z0, z0 + (nz - 1) * dz)

    @property
    def value_range(self) -> tuple:
        """``(min, max)`` of the samples."""
        return (float(self.values.min()), float(self.values.max()))

    def to_index(self, points) -> np.ndarray:
        """World points ``(..., 3)`` to index-space coordinates ``(x, y, z) = (i, j, k)`` (float64)."""
        p = np.asarray(points, dtype=np.float64)
        return (p - np.asarray(self.origin)) / np.asarray(self.spacing)

    def to_world(self, index_points) -> np.ndarray:
        """Index-space coordinates ``(..., 3)`` to world points (float64)."""
        q = np.asarray(index_points, dtype=np.float64)
        return np.asarray(self.origin) + q * np.asarray(self.spacing)

    def to_pyvista(self):
        """A ``pyvista.ImageData`` with the samples as point data ``"values"`` (x fastest, VTK order)."""
        import pyvista as pv

        img = pv.ImageData(dimensions=self.shape[::-1], spacing=self.spacing, origin=self.origin)
        img.point_data["values"] = np.ascontiguousarray(self.values).ravel(order="C")
        return img

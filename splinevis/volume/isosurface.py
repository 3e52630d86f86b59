"""Isosurface: the isosurface ``s = isovalue`` of a :class:`~splinevis.volume.model.VolumeSpline`, the model the
isosurface program draws. Plain numpy: what depends on the isovalue (the relevant cubes) is computed on first
use and recomputed when the isovalue changes."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .model import Relevant, VolumeSpline

__all__ = ["Isosurface", "value_reference"]


@dataclass
class Isosurface:
    """The isosurface ``s = isovalue`` of a :class:`VolumeSpline`, what :meth:`splinevis.Plotter.add_spline`
    draws. ``relevant`` is computed on first use (and is all that changes with the isovalue).

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> surface = Isosurface(VolumeSpline(sphere_grid(12)), 0.7)  # |x| on [-1, 1]^3: a sphere
    >>> surface.isovalue, len(surface.relevant.cubes)
    (0.7, 272)
    """

    spline: VolumeSpline
    isovalue: float
    _relevant: Relevant | None = field(default=None, repr=False)

    def __post_init__(self):
        if not isinstance(self.spline, VolumeSpline):
            raise TypeError(f"spline must be a VolumeSpline, got {type(self.spline).__name__}.")
        self.isovalue = float(self.isovalue)
        if not np.isfinite(self.isovalue):
            raise ValueError(f"isovalue must be finite, got {self.isovalue!r}.")

    @property
    def relevant(self) -> Relevant:
        """The cubes and tetrahedra of the current isovalue (recomputed after a change).

        >>> from splinevis.volume.hard_cases import sphere_grid
        >>> surface = Isosurface(VolumeSpline(sphere_grid(12)), 0.7)
        >>> surface.isovalue = 0.4
        >>> surface.relevant.isovalue, len(surface.relevant.cubes)  # a smaller sphere
        (0.4, 80)
        """
        if self._relevant is None or self._relevant.isovalue != self.isovalue:
            self._relevant = self.spline.relevant(self.isovalue)
        return self._relevant

    @property
    def extent(self):
        """``(xmin, xmax, ymin, ymax)`` of the spline's domain: what a draped texture spans
        (``Style.texture_extent`` is relative to it).

        >>> surface = Isosurface(VolumeSpline(np.zeros((4, 4, 4)), spacing=(0.5, 1.0, 1.0), order="zyx"), 0.0)
        >>> surface.extent
        (-0.25, 1.75, -0.5, 3.5)
        """
        b = self.spline.bounds
        return (b[0], b[1], b[2], b[3])

    @property
    def bounds(self) -> tuple:
        """``(xmin, xmax, ymin, ymax, zmin, zmax)`` of the spline's domain (lattice frame; what a camera is
        fitted to, as a PyVista dataset's bounds).

        >>> Isosurface(VolumeSpline(np.zeros((4, 4, 4)), spacing=(0.5, 1.0, 1.0), order="zyx"), 0.0).bounds
        (-0.25, 1.75, -0.5, 3.5, -0.5, 3.5)
        """
        return tuple(self.spline.bounds)


def value_reference(spline: VolumeSpline) -> float:
    """The value subtracted from the data before float32 upload (mid-range; isovalue independent).

    Examples
    --------
    >>> value_reference(VolumeSpline(np.arange(27.0).reshape(3, 3, 3) + 1000.0, order="zyx"))
    1013.0
    """
    lo, hi = spline.value_range
    return 0.5 * (lo + hi)

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
    draws. ``relevant`` is computed on first use (and is all that changes with the isovalue)."""

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
        if self._relevant is None or self._relevant.isovalue != self.isovalue:
            self._relevant = self.spline.relevant(self.isovalue)
        return self._relevant

    @property
    def extent(self):  # texture coordinates span the volume's x/y (Style.texture_extent)
        b = self.spline.bounds
        return (b[0], b[1], b[2], b[3])


def value_reference(spline: VolumeSpline) -> float:
    """The value subtracted from the data before float32 upload (mid-range; isovalue independent)."""
    lo, hi = spline.value_range
    return 0.5 * (lo + hi)

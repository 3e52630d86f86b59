"""Terrain splines: quartic Bernstein-Bezier patches on the type-1 triangulation of a height grid
(schemes linear, C0, C1, C2, C2-cubic and C2-interp; see :mod:`.schemes` and ``docs/terrain-schemes.md``)."""

from .schemes import (
    C1_STENCIL as C1_STENCIL,
    SCHEMES as SCHEMES,
    TerrainInfo as TerrainInfo,
    c1_system as c1_system,
    evaluate as evaluate,
    gradient as gradient,
    resample_for_c0 as resample_for_c0,
    scheme_stencil as scheme_stencil,
    terrain_coefficients as terrain_coefficients,
)
from .prefilter import smooth_heights as smooth_heights

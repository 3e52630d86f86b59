"""The terrain's renderers for the choice by accuracy (``Plotter.add_terrain(..., max_error_px=...)``,
:mod:`splinevis.choice`), declared on its program as :data:`RENDERERS`.

* ``mesh``: the spline sampled ``k x k`` per cell (:mod:`splinevis.terrain.sampled_mesh`), **proven**:
  vertical chord <= M h^2 / 4 per cell (h = 1/k, M the Hessian bound from the BB second differences), plus
  the float32 rounding of the vertices (:func:`splinevis.gl.renderers.float32_margin`), turned into pixels
  over each cell's box (:meth:`splinevis.gl.screen_error.View.box_pixels`); rank 0.
* ``mesh_guided``: the program with ``proxy="mesh"`` (:mod:`splinevis.terrain.mesh_proxy`), the same picture
  as the box ray cast (the same hard cases agree with the float64 twin), the ray cast's error. It was 2.5-4x
  cheaper than the box ray cast; since the box ray cast walks its cells in rounds (4x faster,
  docs/results/profile/) it is the slower of the two (222 against 163 ms on the profile scene): rank 15, above
  the box ray cast, so it is drawn only where the box ray cast is excluded.
* ``raycast``: the program itself (box proxy), rank 10.

Ranks are the measured costs of :mod:`splinevis.choice` (docs/results/terrain/pareto.md).
"""

from __future__ import annotations

from ..gl.renderers import MESH_LEVELS, Renderer, add_mesh_actor, float32_margin, mesh_refuses
from ..gl.screen_error import SNAP_PX

__all__ = ["mesh_error_px", "RENDERERS"]


def _boxes_and_hessian(terrain, cache):
    from . import sampled_mesh as sm

    if "boxes" not in cache:
        lo, hi = sm.cell_boxes(terrain)
        cache["boxes"] = (lo.reshape(-1, 3), hi.reshape(-1, 3))
        cache["hessian"] = sm.chord_bounds(terrain, 1).reshape(-1) * 4.0  # M: the k = 1 chord bound is M / 4
    return cache["boxes"], cache["hessian"]


def mesh_error_px(terrain, view, k, cache):
    """(pixels, True): the proven screen-space error of the ``k x k`` sampled mesh for ``view`` (module
    docstring), plus the sub-pixel snapping.

    >>> import numpy as np
    >>> from splinevis.gl.screen_error import View
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:17, 0:17] / 16.0
    >>> t = TerrainSpline.from_heights(0.3 * np.sin(4 * x) * np.cos(3 * y), "C1", spacing=(1 / 16, 1 / 16))
    >>> v = View((0.5, -1.5, 1.5), (0.5, 0.5, 0.0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 5))
    >>> [round(mesh_error_px(t, v, k, {})[0], 3) for k in (1, 2, 4)]  # the chord term falls as 1 / k^2
    [1.299, 0.327, 0.086]
    """
    (lo, hi), M = _boxes_and_hessian(terrain, cache)
    err = M / (4.0 * k * k) + float32_margin(lo, hi)  # chord_bounds(terrain, k) without recomputing M
    return float(view.box_pixels(lo, hi, err).max()) + SNAP_PX, True


def _mesh_triangles(terrain, k, cache):
    from .sampled_mesh import mesh_triangles

    return mesh_triangles(terrain, k)


def _mesh_build(plotter, terrain, style, k, cache, spline_options, add_options):
    from .sampled_mesh import sampled_mesh

    return add_mesh_actor(plotter, sampled_mesh(terrain, k), style, spline_options)


#: The terrain's renderers (module docstring), declared on :data:`splinevis.terrain.program.PROGRAM`.
RENDERERS = (
    Renderer("mesh", 0, MESH_LEVELS, mesh_error_px, _mesh_build, _mesh_triangles, mesh_refuses),
    Renderer("mesh_guided", 15, exact=True, program_options={"proxy": "mesh", "mesh_samples": 1}),
    Renderer("raycast", 10, exact=True),
)

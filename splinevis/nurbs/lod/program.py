"""The NURBS level-of-detail program (kind ``mesh``): the CPU tessellates the model into levels of detail with
proven deviation bounds and draws one crack-free mesh of them [Kumar1997, sec. 4].

``build`` has no camera (a ``mesh`` program makes its dataset once, :mod:`splinevis.gl.contract`), so it
picks the one level that meets ``pixel_error`` for *every* camera that has the whole model in view: such a
camera (vertical field of view ``FOV_Y``, a viewport of ``VIEWPORT_HEIGHT`` pixels) is at least
``R / sin(FOV_Y / 2)`` from the centre of the model's bounding sphere (radius ``R``), hence at least
``d = R / sin(FOV_Y / 2) - R`` from every point of the model, where a deviation ``tol`` covers at most
``tol * VIEWPORT_HEIGHT / (2 d tan(FOV_Y / 2))`` pixels (:mod:`.select`). View-dependent levels, culling and
the threaded pipeline are :class:`.pipeline.Walkthrough`.
"""

from __future__ import annotations

import math

import numpy as np

from ...gl.contract import HardCase, SplineProgram
from ..model import NurbsModel
from ..surface import NurbsSurface
from ..program import model_from

__all__ = ["lod_mesh", "static_level", "PROGRAM", "FOV_Y", "VIEWPORT_HEIGHT"]

#: The view ``build`` answers for (module docstring): pyvista's default 30 degree field of view ...
FOV_Y = math.radians(30.0)
#: ... on a full-HD viewport.
VIEWPORT_HEIGHT = 1080


def static_level(tolerance, radius: float, pixel_error=1.0) -> int:
    """The coarsest level whose bound ``tolerance[l]`` covers at most ``pixel_error`` pixels from every camera
    that has a model of bounding radius ``radius`` wholly in view (module docstring); 0 when none does or
    ``pixel_error`` is None.

    Examples
    --------
    A unit ball is at least 2.864 from such a camera; at 1080 pixels one pixel there is 0.00142 units:

    >>> [static_level([0.001, 0.004, 0.016], 1.0, pixel_error=e) for e in (1.0, 4.0, 12.0, None)]
    [0, 1, 2, 0]
    """
    tol = np.asarray(tolerance, dtype=np.float64).reshape(-1)
    if pixel_error is None:
        return 0
    d = float(radius) / math.sin(0.5 * FOV_Y) - float(radius)
    limit = float(pixel_error) * d * 2.0 * math.tan(0.5 * FOV_Y) / VIEWPORT_HEIGHT
    return max(int(np.searchsorted(tol, limit, side="right")) - 1, 0)


def lod_mesh(model, delta=None, pixel_error=1.0, levels: int = 4, progress: bool = False):
    """A PyVista PolyData of ``model`` at the level :func:`static_level` picks from a
    :func:`.levels.build_lod` with ``delta`` (default: 1e-3 of the model's diagonal) and ``levels``; its
    field data ``lod_level`` and ``lod_bound`` say which level and what bound was drawn.

    Examples
    --------
    >>> from splinevis.nurbs.exact import torus
    >>> mesh = lod_mesh(torus(), delta=0.05, levels=2, pixel_error=40.0)  # 40 pixels: 0.2 units
    >>> mesh.n_cells > 0, mesh.field_data["lod_level"].tolist(), mesh.field_data["lod_bound"].tolist()
    (True, [1], [0.2])
    """
    import pyvista as pv

    from .levels import assemble, build_lod

    model = model_from(model)
    lo, hi = np.asarray(model.bounds()[0::2], float), np.asarray(model.bounds()[1::2], float)
    diagonal = float(np.linalg.norm(hi - lo))
    if delta is None:
        delta = 1e-3 * diagonal
    if pixel_error is not None and not float(pixel_error) > 0:
        raise ValueError(f"pixel_error must be a positive number of pixels or None, got {pixel_error!r}.")
    lod = build_lod(model, float(delta), levels=int(levels), progress=progress)
    level = static_level(lod.tolerance, 0.5 * diagonal, pixel_error)
    points, triangles, info = assemble(lod, np.full(len(lod.supers.members), level, dtype=np.int64))
    mesh = pv.PolyData(np.asarray(points, dtype=np.float64),
                       faces=pv.CellArray.from_regular_cells(np.asarray(triangles, dtype=np.int64)))
    mesh.point_data.active_normals = lod.normals  # the surface's exact normals, not averaged from triangles
    mesh.field_data["lod_level"] = np.array([level])
    mesh.field_data["lod_bound"] = np.array([float(lod.tolerance[level])])
    return mesh


def _build(model, style, *, newton_iterations, delta=None, pixel_error=1.0, levels=4):
    return lod_mesh(model, delta=delta, pixel_error=pixel_error, levels=levels)


def _hard_cases():
    from ..exact import cylinder, sphere, torus

    return [HardCase("sphere-poles", lambda: NurbsModel([sphere()]), [(2.0, -2.0, 3.5), (0, 0, 0), (0, 1, 0)],
                     program_options={"delta": 0.01}),
            HardCase("torus-close", lambda: NurbsModel([torus()]), [(1.2, -1.2, 0.6), (0, 0, 0), (0, 0, 1)],
                     program_options={"delta": 0.005, "pixel_error": 0.5}),
            HardCase("cylinder-far", lambda: NurbsModel([cylinder()]), [(40.0, -50.0, 30.0), (0, 0, 0), (0, 0, 1)],
                     program_options={"pixel_error": 4.0, "levels": 5})]


PROGRAM = SplineProgram(
    name="nurbs_lod", kind="mesh", model_type=NurbsModel, build=_build, hard_cases=_hard_cases, model_from=model_from,
    converts=(NurbsSurface,),
    options=("delta", "pixel_error", "levels"),
    description="NURBS levels of detail with proven deviation bounds, one crack-free mesh [Kumar1997]")

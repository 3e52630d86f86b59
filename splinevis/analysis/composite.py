"""Does a ray-cast surface composite correctly with ordinary meshes? GPU against float64, per pixel.

The scene (built by the caller, e.g. the showcase's patch and a sphere cutting through it) holds one spline,
drawn unlit red (:data:`UNLIT`), and ordinary meshes, drawn here unlit blue. The GPU image says per pixel
which surface is in front. The reference says the same from the spline's float64 ray-cast depth (its
program's twin) and the meshes' own rasterized depth (an ordinary mesh's depth is whatever the rasterizer
makes of it, read back from a render of the meshes alone).
"""

from __future__ import annotations

import numpy as np

from ..gl.camera import pixel_rays, window_depth

__all__ = ["front_surface_agreement", "reference_depth", "UNLIT"]

#: The spline's style in a compositing check: unlit pure red.
UNLIT = dict(lights=0, color=(1.0, 0.0, 0.0))

BACKGROUND, PATCH, SPHERE = 0, 1, 2


def _classify(rgb: np.ndarray) -> np.ndarray:
    r, g, b = (rgb[..., k].astype(int) for k in range(3))
    out = np.full(rgb.shape[:2], BACKGROUND, dtype=np.int8)
    out[(r > 200) & (g < 60) & (b < 60)] = PATCH
    out[(b > 200) & (r < 60) & (g < 60)] = SPHERE
    return out


def reference_depth(model, matrix, width, height, *, method="reference"):
    """(H, W) float64 window depth of the model by its program's float64 twin (NaN where the ray misses).

    Examples
    --------
    With the identity as camera matrix, world coordinates are normalized device coordinates: the rays of a
    2 x 2 window run along +z through x, y = +-0.5, and the window depth of a point is (z + 1) / 2.

    >>> import numpy as np
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> ramp = QuarticTrianglePatch.from_function(lambda x, y: 0.5 * x, [[-3, -3], [3, -3], [0, 3]])
    >>> reference_depth(ramp, np.eye(4), 2, 2).round(12)  # z = -0.25 and 0.25
    array([[0.375, 0.625],
           [0.375, 0.625]])
    """
    from .agreement import reference_hits

    o, d = pixel_rays(matrix, width, height)
    hits = reference_hits(model, o, d, method=method)
    return window_depth(matrix, o + hits.t[..., None] * d)


def front_surface_agreement(pl, model) -> dict:
    """Render the scene of Plotter ``pl`` (one spline of ``model`` styled :data:`UNLIT`, and meshes) and compare
    the front surface per pixel with the float64 reference; closes ``pl``.

    Returns a dict with ``gpu_front``, ``reference_front`` (H, W int arrays: 0 background, 1 patch,
    2 sphere), ``disagree`` (bool), ``compared`` (pixels where either says a surface is present),
    ``disagree_count``, ``agreement`` (fraction) and ``both_ways`` (pixels where the sphere is in front
    of a patch point and where the patch is in front of a sphere point, per the reference).

    Examples
    --------
    >>> import pyvista as pv
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> from splinevis.plotting import Plotter
    >>> patch = QuarticTrianglePatch.demo()
    >>> pl = Plotter(off_screen=True, window_size=(64, 48))
    >>> _ = pl.add_spline(patch, **UNLIT)
    >>> _ = pl.add_mesh(pv.Sphere(radius=0.3, center=(0.05, -0.15, 0.22)))  # cuts through the patch
    >>> pl.camera_position = [(2.5, -3.3, 2.4), (0.05, -0.1, 0.05), (0, 0, 1)]
    >>> r = front_surface_agreement(pl, patch)
    >>> r["disagree_count"], min(r["both_ways"]) > 0  # each in front of the other somewhere
    (0, True)
    """
    w, h = pl.window_size
    for actor in pl.renderer.actors.values():
        if actor.GetMapper().GetClassName() != "vtkOpenGLPolyDataMapper":
            actor.GetProperty().SetColor(0.0, 0.0, 1.0)
            actor.GetProperty().LightingOff()
    rgb = pl.screenshot()
    matrix = pl.camera_matrix()
    # The sphere alone, same camera and clipping range: its rasterized depth.
    spline = pl._spline_actors[0]
    spline.actor.VisibilityOff()
    pl.render()
    sphere_depth = pl.depth_buffer()
    pl.close()

    patch_depth = reference_depth(model, matrix, w, h)
    sphere_present = sphere_depth < 1.0
    ref = np.full((h, w), BACKGROUND, dtype=np.int8)
    patch_present = np.isfinite(patch_depth) & (patch_depth >= 0) & (patch_depth <= 1)
    ref[sphere_present] = SPHERE
    patch_front = patch_present & (~sphere_present | (patch_depth < sphere_depth))
    ref[patch_front] = PATCH
    gpu = _classify(rgb)
    compared = (gpu != BACKGROUND) | (ref != BACKGROUND)
    disagree = compared & (gpu != ref)
    n = int(compared.sum())
    both = patch_present & sphere_present
    return {
        "gpu_front": gpu,
        "reference_front": ref,
        "disagree": disagree,
        "compared": n,
        "disagree_count": int(disagree.sum()),
        "agreement": 1.0 - disagree.sum() / max(n, 1),
        "both_ways": (int((both & (sphere_depth < patch_depth)).sum()), int((both & (patch_depth < sphere_depth)).sum())),
    }

"""Does the ray-cast surface composite correctly with ordinary meshes? GPU against float64, per pixel.

The scene is the showcase one: the analytic patch, unlit red, and a sphere mesh, unlit blue, cutting
through it. The GPU image says per pixel which surface is in front. The reference says the same from
the patch's float64 ray-cast depth and the sphere's own rasterized depth (the sphere is an ordinary
mesh: its depth is whatever the rasterizer makes of it, read back from a render of the sphere alone).
"""

from __future__ import annotations

import numpy as np

from .rays import pixel_rays, window_depth

__all__ = ["front_surface_agreement", "patch_depth_agreement"]

BACKGROUND, PATCH, SPHERE = 0, 1, 2


def _classify(rgb: np.ndarray) -> np.ndarray:
    r, g, b = (rgb[..., k].astype(int) for k in range(3))
    out = np.full(rgb.shape[:2], BACKGROUND, dtype=np.int8)
    out[(r > 200) & (g < 60) & (b < 60)] = PATCH
    out[(b > 200) & (r < 60) & (g < 60)] = SPHERE
    return out


def reference_patch_depth(patch, matrix, width, height, *, method="reference"):
    """(H, W) float64 window depth of the patch (NaN where the ray misses)."""
    o, d = pixel_rays(matrix, width, height)
    hits = patch.raycast(o, d, 0.0, method=method)
    return window_depth(matrix, o + hits.t[..., None] * d)


def front_surface_agreement(window_size=(640, 480)) -> dict:
    """Render the composite scene and compare the front surface per pixel with the float64 reference.

    Returns a dict with ``gpu_front``, ``reference_front`` (H, W int arrays: 0 background, 1 patch,
    2 sphere), ``disagree`` (bool), ``compared`` (pixels where either says a surface is present),
    ``disagree_count``, ``agreement`` (fraction) and ``both_ways`` (pixels where the sphere is in front
    of a patch point and where the patch is in front of a sphere point, per the reference).
    """
    from ..studies.demo import composite_scene

    w, h = window_size
    unlit = dict(lights=0, color=(1.0, 0.0, 0.0))
    pl, patch, _ = composite_scene(window_size, style=unlit)
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

    patch_depth = reference_patch_depth(patch, matrix, w, h)
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


def patch_depth_agreement(window_size=(640, 480), camera=None, newton_iterations=8) -> dict:
    """Render the showcase patch alone; compare hit/miss and window depth with the float64 reference
    (:func:`splinevis.analysis.agreement.depth_agreement` at the showcase camera)."""
    from ..analytic import QuarticTrianglePatch
    from ..studies.demo import CAMERA
    from .agreement import depth_agreement

    return depth_agreement(QuarticTrianglePatch.demo(), camera if camera is not None else CAMERA, window_size,
                           newton_iterations=newton_iterations)

"""GPU against float64, per pixel: hits, misses and window depths of any spline model.

The model is rendered alone (unlit, no effects: depth does not depend on shading), the depth buffer is
read back, and every pixel's ray is cast in float64 by the model's reference ray caster with the same
camera matrix. Depth differences are judged against a derived per-pixel bound
(:func:`splinevis.analysis.bounds.ray_depth_error_bound` or ``isosurface_depth_error_bound``) plus the depth
change over the rasterizer's sub-pixel snapping (:func:`subpixel_depth_slack`; found on a one-voxel sheet whose
isosurface lies on cube faces: the shader's rays were those of points up to 2^-8 px off the pixel centre).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from .bounds import isosurface_depth_error_bound, ray_depth_error_bound
from .rays import pixel_rays, window_depth

__all__ = ["depth_agreement", "reference_hits"]


def reference_hits(model, origins, directions, *, method="reference"):
    """Float64 ray cast of a supported model (analytic patch, terrain or isosurface)."""
    from types import SimpleNamespace

    from ..analytic import QuarticTrianglePatch
    from ..terrain.model import TerrainSpline
    from ..terrain.raycast import raycast_terrain
    from ..volume.program import Isosurface
    from ..volume.raycast import raycast_isosurface

    if isinstance(model, Isosurface):
        shape = np.shape(origins)[:-1]
        t, normal = raycast_isosurface(model, np.reshape(origins, (-1, 3)), np.reshape(directions, (-1, 3)),
                                       method=method)
        return SimpleNamespace(t=t.reshape(shape), normal=normal.reshape(shape + (3,)))

    if isinstance(model, QuarticTrianglePatch):
        return model.raycast(origins, directions, 0.0, method=method)
    if isinstance(model, TerrainSpline):
        return raycast_terrain(model, origins, directions, 0.0, method=method)
    raise TypeError(f"no float64 ray caster for {type(model).__name__}")


def _bound(model, matrix, o, d, t):
    from ..analytic import QuarticTrianglePatch
    from ..volume.program import Isosurface, value_reference

    if isinstance(model, Isosurface):
        sp = model.spline
        off = sp.origin
        lo, hi = sp.value_range
        ref = value_reference(sp)
        scale = max(abs(hi - ref), abs(lo - ref), abs(model.isovalue - ref))
        b = np.array(sp.bounds).reshape(3, 2) - off[:, None]
        return isosurface_depth_error_bound(lambda q: sp.evaluate(q + off, gradient=True), scale, sp.spacing,
                                            _shift(matrix, off), o - off, d, t, float(np.abs(b).max()), sp.degree)

    p = o + t[..., None] * d
    # The shader's rays start on the far side of the proxy (lib/raycast.glsl), so the coordinates it
    # rounds are bounded by the proxy's extent in the frame the program works in.
    if isinstance(model, QuarticTrianglePatch):
        extent = np.abs(model.vertices).max(axis=0)
        return ray_depth_error_bound(lambda q: model.gradient(q), float(np.abs(model.coefficients).max()), matrix,
                                     o, d, t, np.broadcast_to(extent, p[..., :2].shape),
                                     proxy_size=float(np.ptp(model.vertices, axis=0).max() + np.ptp(model.zrange)))
    # terrain: the shader works in the model frame (world - offset) and in index coordinates
    off = model.offset
    o_mc = o - off
    x0, x1, y0, y1 = model.extent
    coord = np.broadcast_to(np.array([x1 - x0, y1 - y0]), p[..., :2].shape)  # index coordinates, physical units
    return ray_depth_error_bound(lambda q: model.gradient(q[..., 0] + off[0], q[..., 1] + off[1]),
                                 float(np.abs(model.coefficients).max()), _shift(matrix, off),
                                 o_mc, d, t, coord, proxy_size=float(max(x1 - x0, y1 - y0, np.ptp(model.zrange))))


def _shift(matrix, off):
    """Camera matrix acting on model-frame points (world = model + off)."""
    T = np.eye(4)
    T[:3, 3] = off
    return np.asarray(matrix) @ T


#: Sub-pixel precision of the rasterizer: vertices are snapped to 2^-8 of a pixel (llvmpipe's fixed-point
#: setup, FIXED_ORDER = 8; the same order as GPUs' 8 sub-pixel bits).
SUBPIXEL = 2.0 ** -8


def subpixel_depth_slack(ref_depth: np.ndarray) -> np.ndarray:
    """Depth change over a sub-pixel offset of the ray: ``SUBPIXEL * (|d depth/dx| + |d depth/dy|)`` per pixel.

    The shader's ray passes through the fragment's interpolated position on the proxy, and the proxy's
    vertices were snapped to SUBPIXEL before interpolation: the ray is that of a point up to SUBPIXEL
    (per axis) away from the pixel centre. The slope is the larger one-sided difference of the float64
    reference depth to a neighbour that also hits (0 where none does).
    """
    r = np.asarray(ref_depth, dtype=np.float64)
    ok = np.isfinite(r) & (r >= 0) & (r <= 1)
    slope = np.zeros_like(r)
    for axis in (0, 1):
        for shift in (1, -1):
            nb = np.roll(r, shift, axis=axis)
            nok = np.roll(ok, shift, axis=axis)
            edge = np.zeros_like(ok)
            if axis == 0:
                edge[0 if shift == 1 else -1, :] = True
            else:
                edge[:, 0 if shift == 1 else -1] = True
            diff = np.where(ok & nok & ~edge, np.abs(r - nb), 0.0)
            slope_axis = diff if shift == 1 else np.maximum(prev, diff)
            prev = slope_axis
        slope += slope_axis
    return SUBPIXEL * slope


def depth_agreement(model, camera_position, window_size=(400, 300), *, newton_iterations=8, plotter_hook=None) -> dict:
    """Render ``model`` alone from ``camera_position`` and compare with the float64 reference.

    Returns a dict: ``pixels``, ``hit_disagree`` (pixels where exactly one side hits), ``leaks``
    (GPU misses at pixels whose reference hits and whose 8 neighbours all hit: cracks), ``both``,
    ``depth_error`` and ``depth_bound`` (over pixels where both hit), ``gpu_depth``,
    ``reference_depth``, ``matrix``.
    """
    from ..plotting import Plotter

    w, h = window_size
    pl = Plotter(off_screen=True, window_size=window_size)
    pl.add_spline(model, lights=0, color=(1.0, 0.0, 0.0), newton_iterations=newton_iterations)
    pl.camera_position = camera_position
    pl.reset_camera_clipping_range()
    if plotter_hook is not None:
        plotter_hook(pl)
    pl.screenshot()
    gpu = pl.depth_buffer()
    matrix = pl.camera_matrix()
    pl.close()
    o, d = pixel_rays(matrix, w, h)
    hits = reference_hits(model, o, d)
    ref = window_depth(matrix, o + hits.t[..., None] * d)
    ref_hit = np.isfinite(ref) & (ref >= 0) & (ref <= 1)
    gpu_hit = gpu < 1.0
    both = gpu_hit & ref_hit
    interior = ndimage.binary_erosion(ref_hit, structure=np.ones((3, 3)), border_value=0)
    bound = _bound(model, matrix, o[both], d[both], hits.t[both]) + subpixel_depth_slack(ref)[both]
    return {
        "pixels": w * h,
        "hit_disagree": int((gpu_hit != ref_hit).sum()),
        "leaks": int((interior & ~gpu_hit).sum()),
        "both": int(both.sum()),
        "depth_error": np.abs(gpu - ref)[both],
        "depth_bound": bound,
        "gpu_depth": gpu,
        "reference_depth": ref,
        "matrix": matrix,
    }

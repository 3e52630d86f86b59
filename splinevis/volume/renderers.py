"""The isosurface's renderers for the choice by accuracy (``Plotter.add_isosurface(..., max_error_px=...)``,
:mod:`splinevis.choice`), declared on its program as :data:`RENDERERS`.

* ``mesh``: flying edges of the spline's values at ``k`` samples per cube
  (:mod:`splinevis.volume.sampled_mesh`). The value error on the mesh is proven,
  |s - iso| <= M (e^2/8 + D^2/2) (edge interpolation plus the triangle's chord; e the largest fine spacing, D
  the fine cell's diagonal, M the Hessian bound per relevant cube); it is turned into a distance with an
  **estimated** lower bound of |grad s| (the smallest at the ``k = 1`` mesh's vertices), plus the float32
  rounding of the vertices, and into pixels over each relevant cube's box. Rank 0; rotated lattices are
  refused (the mesh is built in the lattice frame). Its normals are the spline's gradient directions at
  the vertices, interpolated: within ``(M / g)(D + delta)`` radians of the exact normal at the surface point a
  mesh point stands for (:func:`mesh_normal_error_deg`), an **estimate** since ``g`` is.
* ``raycast``: the program itself, rank 10.

Ranks are the measured costs of :mod:`splinevis.choice` (docs/results/volume/volume.md).
"""

from __future__ import annotations

import numpy as np

from ..gl.renderers import MESH_LEVELS, Renderer, add_mesh_actor, float32_margin, mesh_cost, mesh_refuses, raycast_cost
from ..gl.screen_error import SNAP_PX

__all__ = ["RAYCAST_NS_PER_PIXEL", "mesh_error_px", "mesh_normal_error_deg", "mesh_measure", "RENDERERS"]


def _mesh1(surface, cache):
    """The k = 1 mesh (its triangle count scales the others'; its vertices give the gradient estimate)."""
    from .sampled_mesh import sampled_mesh

    if ("mesh", 1) not in cache:
        cache["mesh", 1] = sampled_mesh(surface.spline, surface.isovalue, 1, surface.relevant)
    return cache["mesh", 1]


def _bounds(surface, cache):
    from . import sampled_mesh as sm

    if "hessian" not in cache:
        spline = surface.spline
        cubes = surface.relevant.cubes
        h = np.asarray(spline.spacing, dtype=np.float64)
        lo = np.asarray(spline.origin, dtype=np.float64) - 0.5 * h + cubes * h
        cache["boxes"] = (lo, lo + h)
        cache["hessian"] = sm.hessian_bounds(spline, cubes) if len(cubes) else np.zeros(0)
        cache["gradient"] = sm.gradient_floor(spline, _mesh1(surface, cache))
    return cache


def mesh_error_px(surface, view, k, cache):
    """(pixels, False): the estimated screen-space error of the mesh at ``k`` samples per cube for ``view``
    (module docstring), plus the sub-pixel snapping.

    >>> import numpy as np
    >>> from splinevis.gl.screen_error import View
    >>> from splinevis.volume.isosurface import Isosurface
    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[-1:1:20j, -1:1:20j, -1:1:20j]
    >>> s = VolumeSpline(np.sqrt(x**2 + y**2 + z**2), spacing=(2 / 19,) * 3, origin=(-1, -1, -1))
    >>> v = View((3, -4, 2), (0, 0, 0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 20))
    >>> cache = {}
    >>> [round(mesh_error_px(Isosurface(s, 0.7), v, k, cache)[0], 3) for k in (1, 2, 4)]
    [4.213, 1.037, 0.262]
    """
    c = _bounds(surface, cache)
    lo, hi = c["boxes"]
    if len(lo) == 0:
        return SNAP_PX, False
    from .sampled_mesh import value_error_factor

    delta = c["hessian"] * value_error_factor(surface.spline.spacing, k)
    g = c["gradient"]
    err = (delta / g if g > 0 else np.full(len(delta), np.inf)) + float32_margin(lo, hi)
    return float(view.box_pixels(lo, hi, err).max()) + SNAP_PX, False


def mesh_normal_error_deg(surface, view, k, cache):
    """(degrees, False): the largest angle between the normal the mesh at ``k`` samples per cube shades with
    and the spline's normal ``n = grad s / |grad s|`` at the surface point a mesh point stands for.

    Derivation. ``dn = (I - n n^T) H dp / |grad s|``, so ``|dn| <= (M / g) |dp|`` on a cube (``M`` its Hessian
    bound, ``g`` a lower bound of ``|grad s|``). A mesh point ``p`` of a fine cell stands for a surface point
    ``q`` within ``delta`` (the distance bound of :func:`mesh_error_px`), and the triangle's vertices ``v_i``
    are in the same fine cell, so ``|q - v_i| <= D + delta`` (``D`` the fine cell's diagonal): every vertex
    normal is within ``(M / g)(D + delta)`` of ``n(q)`` (vertices on the mesh are within ``delta`` of the
    surface; the gradient direction there is what they carry), and so is their normalized convex combination,
    the shading normal (a spherical cap of radius below 90 degrees is convex). ``g`` is the smallest
    ``|grad s|`` at the ``k = 1`` mesh's vertices, an estimate: hence not proven.

    >>> import numpy as np
    >>> from splinevis.volume.isosurface import Isosurface
    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[-1:1:20j, -1:1:20j, -1:1:20j]
    >>> s = VolumeSpline(np.sqrt(x**2 + y**2 + z**2), spacing=(2 / 19,) * 3, origin=(-1, -1, -1))
    >>> cache = {}
    >>> [round(mesh_normal_error_deg(Isosurface(s, 0.7), None, k, cache)[0], 1) for k in (1, 4, 16)]
    [29.4, 6.3, 1.5]
    """
    c = _bounds(surface, cache)
    if len(c["hessian"]) == 0:
        return 0.0, False
    from .sampled_mesh import value_error_factor

    delta = c["hessian"] * value_error_factor(surface.spline.spacing, k)
    g = c["gradient"]
    if not g > 0:
        return float("inf"), False
    diagonal = float(np.linalg.norm(np.asarray(surface.spline.spacing, dtype=np.float64))) / k  # D
    radians = float((c["hessian"] / g * (diagonal + delta / g)).max())
    return float(np.degrees(min(radians, np.pi))), False


def mesh_measure(surface, view, k, cache, samples: int = 20_000, seed: int = 0):
    """(pixels, degrees) measured on the mesh at ``k`` samples per cube against the float64 spline: at
    ``samples`` random points of its triangles (a random triangle each, random barycentric weights), the
    drawn point against the surface point it stands for (Newton steps along the gradient onto the
    isosurface), their projections' distance in ``view``, and the normalized interpolated vertex normal
    against the spline's normal there.

    >>> import numpy as np
    >>> from splinevis.gl.screen_error import View
    >>> from splinevis.volume.isosurface import Isosurface
    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[-1:1:20j, -1:1:20j, -1:1:20j]
    >>> s = VolumeSpline(np.sqrt(x**2 + y**2 + z**2), spacing=(2 / 19,) * 3, origin=(-1, -1, -1))
    >>> v = View((3, -4, 2), (0, 0, 0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 20))
    >>> surface, cache = Isosurface(s, 0.7), {}
    >>> px, deg = mesh_measure(surface, v, 2, cache)
    >>> bool(0 < px <= mesh_error_px(surface, v, 2, cache)[0]), bool(0 < deg <= mesh_normal_error_deg(surface, v, 2, cache)[0])
    (True, True)
    """
    from .sampled_mesh import sampled_mesh

    mesh = cache.get(("mesh", k))
    if mesh is None:
        mesh = cache["mesh", k] = sampled_mesh(surface.spline, surface.isovalue, k, surface.relevant)
    if mesh.n_cells == 0:
        return 0.0, 0.0
    rng = np.random.default_rng(seed)
    tri = mesh.faces.reshape(-1, 4)[:, 1:][rng.integers(0, mesh.n_cells, samples)]
    w = rng.dirichlet([1.0, 1.0, 1.0], samples)
    drawn = np.einsum("tk,tkc->tc", w, np.asarray(mesh.points, dtype=np.float64)[tri])
    n = np.einsum("tk,tkc->tc", w, np.asarray(mesh.point_data["Normals"], dtype=np.float64)[tri])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    iso, spline = surface.isovalue, surface.spline
    q = drawn.copy()
    for _ in range(8):  # Newton along the gradient: quadratic convergence from within a fine cell
        val, g = spline.evaluate(q, gradient=True)
        q -= ((val - iso) / np.maximum(np.einsum("ij,ij->i", g, g), 1e-300))[:, None] * g
    _, g = spline.evaluate(q, gradient=True)
    exact = g / np.linalg.norm(g, axis=1, keepdims=True)
    px = view.pixel_distance(drawn, q)
    deg = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", n, exact), -1.0, 1.0)))
    return (float(np.nanmax(px)) if np.isfinite(px).any() else 0.0), float(deg.max())


def _mesh_triangles(surface, k, cache):
    from .sampled_mesh import MAX_FINE_POINTS, fine_points

    if fine_points(surface.spline, k) > MAX_FINE_POINTS:
        raise ValueError(f"{fine_points(surface.spline, k):,} fine samples (more than {MAX_FINE_POINTS:,})")
    return int(_mesh1(surface, cache).n_cells) * k * k  # surface area / fine cell area ~ k^2


def _mesh_build(plotter, surface, style, k, cache, spline_options, add_options):
    from .sampled_mesh import sampled_mesh

    mesh = cache.get(("mesh", k))
    if mesh is None:
        mesh = sampled_mesh(surface.spline, surface.isovalue, k, surface.relevant)
    return add_mesh_actor(plotter, mesh, style, spline_options)


def _mesh_refuses(surface, style):
    if not np.allclose(np.asarray(surface.spline.grid.direction, dtype=np.float64), np.eye(3)):
        return "rotated lattices are drawn by the ray cast only"
    return mesh_refuses(surface, style)


#: The isosurface ray cast's frame time per pixel of the volume's screen rectangle, ns (Marschner-Lobb 41^3,
#: quadratic, 800 x 600, pyvista's default view: 123.8 ms for 285,100 pixels, benchmarks/bench_choice.py).
RAYCAST_NS_PER_PIXEL = 434.0


#: The isosurface's renderers (module docstring), declared on :data:`splinevis.volume.program.PROGRAM`.
RENDERERS = (
    Renderer("mesh", 0, MESH_LEVELS[:8], mesh_error_px, _mesh_build, _mesh_triangles, _mesh_refuses,
             normal_error_deg=mesh_normal_error_deg, measure=mesh_measure, cost=mesh_cost(_mesh_triangles)),
    Renderer("raycast", 10, exact=True, cost=raycast_cost(RAYCAST_NS_PER_PIXEL)),
)

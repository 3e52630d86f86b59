"""The toy sphere's renderers, declared on its program as a plugin would (``SplineProgram.renderers``): a
tessellated sphere with a proven error bound, and the exact ray cast. No package file knows them.

The mesh is VTK's UV sphere of ``n`` x ``n`` divisions: its vertices lie on the sphere, its faces are the
planar quads between two circles of latitude (split into two triangles) and the triangle fans at the poles,
so it is the convex hull of its vertices and every ray from the centre meets it once. A triangle with all
three vertices on the sphere lies in a plane at distance sqrt(r^2 - rho^2) from the centre (rho its
circumradius: the plane cuts the sphere in the triangle's circumcircle), so each of its points p has
sqrt(r^2 - rho^2) <= |p| <= r. The point of the sphere it stands for (on the same ray from the centre) is
r - |p| away: at most the sagitta r - sqrt(r^2 - rho^2) = rho^2 / (r + sqrt(r^2 - rho^2)), attained at the
circumcentre when it lies in the triangle or its quad partner (the two share the circle). Plus the float32
rounding of the vertices and of their transform (``float32_margin``). In pixels: over the sphere's box.
"""

from __future__ import annotations

import numpy as np

from splinevis.gl.renderers import Renderer, add_mesh_actor, float32_margin, mesh_refuses
from splinevis.gl.screen_error import SNAP_PX

#: Divisions in longitude and latitude tried, in order of cost.
LEVELS = (8, 16, 32, 64, 128, 256)


def sphere_mesh(model, n, cache=None):
    import pyvista as pv

    cache = {} if cache is None else cache
    if ("toy mesh", n) not in cache:
        cache["toy mesh", n] = pv.Sphere(radius=model.radius, center=model.center, theta_resolution=n,
                                         phi_resolution=n)
    return cache["toy mesh", n]


def sagitta_bounds(model, mesh):
    """Per triangle, r - sqrt(r^2 - rho^2) (module docstring), float64 from the stored vertices."""
    tri = np.asarray(mesh.points, dtype=np.float64)[mesh.faces.reshape(-1, 4)[:, 1:]]
    a = np.linalg.norm(tri[:, 1] - tri[:, 2], axis=1)
    b = np.linalg.norm(tri[:, 2] - tri[:, 0], axis=1)
    c = np.linalg.norm(tri[:, 0] - tri[:, 1], axis=1)
    area2 = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)  # twice the area
    rho = a * b * c / (2.0 * area2)
    r = model.radius
    return rho * rho / (r + np.sqrt(np.maximum(r * r - rho * rho, 0.0)))


def world_error(model, n, cache=None):
    """The proven distance between the mesh of ``n`` divisions and the sphere (module docstring)."""
    lo, hi = model.center - model.radius, model.center + model.radius
    return float(sagitta_bounds(model, sphere_mesh(model, n, cache)).max()) + float32_margin(lo, hi)


def mesh_error_px(model, view, n, cache):
    lo, hi = model.center - model.radius, model.center + model.radius
    return float(view.box_pixels(lo, hi, world_error(model, n, cache)).max()) + SNAP_PX, True


def mesh_triangles(model, n, cache):
    return int(sphere_mesh(model, n, cache).n_cells)


def mesh_build(plotter, model, style, n, cache, spline_options, add_options):
    return add_mesh_actor(plotter, sphere_mesh(model, n, cache), style, spline_options)


#: A mesh first (rank 0, proven), the exact ray cast of the program itself (rank 10) when no mesh meets the request.
RENDERERS = (
    Renderer("mesh", 0, LEVELS, mesh_error_px, mesh_build, mesh_triangles, mesh_refuses),
    Renderer("raycast", 10, exact=True),
)

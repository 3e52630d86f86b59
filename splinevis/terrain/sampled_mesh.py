"""A terrain spline drawn as an ordinary triangle mesh: the spline sampled ``k x k`` per cell, with a proven
bound of the vertical distance between the mesh and the spline (what :mod:`splinevis.choice` turns into
pixels to decide between this mesh and the exact ray cast).

**The mesh.** Vertex ``(a, b)`` of the global sample grid sits at index coordinates ``(a / k, b / k)`` and
carries the exact height ``s(a / k, b / k)`` and the exact normal (from the spline's gradient). Every
sub-square is split along the direction of its cell's own diagonal (u = v), so every sub-triangle lies in
one BB triangle (T0 or T1) of one cell: a right isosceles triangle with legs ``h = 1 / k`` (index units).

**The chord bound** is the one the mesh-guided proxy lifts its mesh by (proof in
:mod:`splinevis.terrain.mesh_proxy`): on a sub-triangle with Hessian spectral norm at most M (index units),
the linear interpolant of the vertices is within **M h^2 / 4** of the spline (Taylor with barycentric
weights; the circumradius of the right isosceles sub-triangle is h / sqrt(2)), and M is bounded per cell
from the BB coefficients of the second derivatives (convex hull, Gershgorin:
:func:`~splinevis.terrain.mesh_proxy.second_derivative_bounds`). The bound is per cell, in height units
(heights are world z), and is attained by a paraboloid (tests/test_choice.py).
"""

from __future__ import annotations

import numpy as np

from .mesh_proxy import second_derivative_bounds

__all__ = ["chord_bounds", "cell_boxes", "sampled_mesh", "mesh_triangles"]


def chord_bounds(terrain, k: int) -> np.ndarray:
    """(ncy, ncx) bound of |spline - mesh| (vertical, height units) over each cell for ``k x k`` samples per
    cell: M h^2 / 4 with h = 1 / k.

    Examples
    --------
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> round(float(chord_bounds(TerrainSpline.from_heights(x * x, "C1"), 2).max()), 9)  # 2 (1/2)^2 / 4
    0.125
    """
    k = _check_k(k)
    return second_derivative_bounds(terrain.coefficients) / (4.0 * k * k)


def cell_boxes(terrain) -> tuple:
    """``(lo, hi)``, each (ncy, ncx, 3): world bounding boxes of the cells (heights from the coefficients'
    convex hull).

    >>> from splinevis.terrain.model import TerrainSpline
    >>> lo, hi = cell_boxes(TerrainSpline.from_heights(np.arange(6.0).reshape(2, 3), "linear"))
    >>> lo[0, 1].tolist(), hi[0, 1].tolist()
    ([1.0, 0.0, 1.0], [2.0, 1.0, 5.0])
    """
    ncy, ncx = terrain.shape
    sx, sy = terrain.cell_spacing
    c = terrain.coefficients.reshape(ncy, ncx, 30)
    x = terrain.origin[0] + sx * np.arange(ncx)
    y = terrain.origin[1] + sy * np.arange(ncy)
    X, Y = np.meshgrid(x, y)
    lo = np.stack([X, Y, terrain.z_ref + c.min(axis=-1)], axis=-1)
    hi = np.stack([X + sx, Y + sy, terrain.z_ref + c.max(axis=-1)], axis=-1)
    return lo, hi


def mesh_triangles(terrain, k: int) -> int:
    """Number of triangles of the ``k x k`` sampled mesh: 2 k^2 per cell.

    >>> from splinevis.terrain.model import TerrainSpline
    >>> mesh_triangles(TerrainSpline.from_heights(np.zeros((5, 5)), "C1"), 3)
    288
    """
    ncy, ncx = terrain.shape
    return 2 * _check_k(k) ** 2 * ncx * ncy


def sampled_mesh(terrain, k: int):
    """The ``k x k`` sampled mesh (pyvista PolyData, world coordinates, exact point normals ``"Normals"``).

    Examples
    --------
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:4, 0:5].astype(float)
    >>> t = TerrainSpline.from_heights(np.sin(x) + y, "C1")
    >>> mesh = sampled_mesh(t, 2)
    >>> mesh.n_points, mesh.n_cells == mesh_triangles(t, 2)
    (63, True)
    >>> bool(np.allclose(mesh.points[:, 2], t.evaluate(mesh.points[:, 0], mesh.points[:, 1])))
    True
    """
    import pyvista as pv

    k = _check_k(k)
    ncy, ncx = terrain.shape
    nu, nv = k * ncx + 1, k * ncy + 1
    U, V = np.meshgrid(np.arange(nu) / k, np.arange(nv) / k)  # (nv, nu)
    z = terrain.z_ref + terrain.height_at_index(U, V)
    sx, sy = terrain.cell_spacing
    x = terrain.origin[0] + U * sx
    y = terrain.origin[1] + V * sy
    points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    idx = np.arange(nu * nv).reshape(nv, nu)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    # (a, b, c) and (a, c, d): split along u = v, the cells' own diagonal; counter-clockwise seen from +z
    tris = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    faces = np.column_stack([np.full(len(tris), 3), tris]).ravel()
    mesh = pv.PolyData(points, faces)
    g = terrain.gradient(points[:, 0], points[:, 1])
    n = np.column_stack([-g[:, 0], -g[:, 1], np.ones(len(points))])
    mesh.point_data["Normals"] = n / np.linalg.norm(n, axis=1, keepdims=True)
    mesh.point_data.active_normals_name = "Normals"
    return mesh


def _check_k(k) -> int:
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise ValueError(f"samples per cell k must be a positive integer, got {k!r}.")
    return int(k)

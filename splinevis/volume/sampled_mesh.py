"""An isosurface of a volume spline drawn as an ordinary triangle mesh: marching cubes (VTK's flying edges) of the
spline's own values sampled ``k`` times per cube and axis, with an estimate of the mesh's distance to the
spline's isosurface (what :mod:`splinevis.choice` turns into pixels).

**Sampling.** The fine grid has spacing ``spacing / k`` over the spline's domain (cube faces), so every fine
cell lies in one cube. The spline is evaluated exactly (float64) at the fine points of the *relevant* cubes
(:meth:`~splinevis.volume.model.VolumeSpline.relevant`: all others hold no point of the isosurface); the other
fine points only need the right side of the isovalue, which is that of their cube's centre value (the spline
is continuous and does not reach the isovalue on a closed non-relevant cube, so neighbouring non-relevant
cubes agree on their common faces). Every fine edge the surface crosses lies in a relevant cube, so the
marching-cubes vertices come from exact spline values only.

**The estimate.** Let M bound the spectral norm of the spline's Hessian on a relevant cube (from the BB
coefficients: D_a D_b s has BB coefficients n (n - 1) Delta_a Delta_b c, convex hull property per
tetrahedron, Gershgorin over the three world axes: :func:`hessian_bounds`). A marching-cubes vertex is the
zero of the linear interpolant along a fine edge of length e: there, |s - iso| <= M e^2 / 8 (linear
interpolation error). On a triangle (diameter at most the fine cell's diagonal D), s differs from the
linear interpolant of its vertex values by at most M D^2 / 2 (Taylor with the barycentric weights), so
on the mesh **|s - iso| <= M (e_max^2 / 8 + D^2 / 2) = delta** -- this much is proven. Turning the value
error into a distance needs a lower bound g of |grad s| near the surface: a point where |s - iso| <= delta
lies within delta / g of the isosurface if |grad s| >= g on that ball (follow the gradient). We take g as
the smallest |grad s| over the vertices of the ``k = 1`` mesh (:func:`gradient_floor`): an **estimate**, not
a bound (|grad s| may dip lower between the vertices; a critical point on the surface makes the distance
unbounded, and the estimate infinite if it is hit). The distance is one-sided (mesh to surface).
"""

from __future__ import annotations

import numpy as np

from ..bb import simplex as _bb
from . import schemes as _schemes
from .partition import NUM_TETS, _bary_mats

__all__ = ["hessian_bounds", "value_error_factor", "distance_estimates", "gradient_floor", "sample_spline", "sampled_mesh",
           "fine_points", "MAX_FINE_POINTS"]

#: Largest fine grid (points) :func:`sample_spline` builds.
MAX_FINE_POINTS = 2 ** 24


def hessian_bounds(spline, cubes, *, chunk: int = 8192) -> np.ndarray:
    """(n,) bound of the spectral norm of the spline's Hessian (world units) on each cube ``(i, j, k)``:
    per tetrahedron, |s_ab| <= max |BB coefficient of D_a D_b s| over the world axes a, b, then Gershgorin
    (largest row sum); the largest over the cube's 24 tetrahedra.

    Examples
    --------
    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[0:5, 0:5, 0:5] * 0.5
    >>> s = VolumeSpline(x * x + 3 * y * z, "cubic", order="zyx", spacing=(0.5,) * 3)  # Hessian [[2,0,0],[0,0,3],[0,3,0]]
    >>> hessian_bounds(s, [[2, 2, 2]]).round(9)  # Gershgorin: max(2, 3, 3)
    array([3.])
    """
    cubes = np.asarray(cubes, dtype=np.int64).reshape(-1, 3)
    G = _bary_mats()[:, :, :3] / np.asarray(spline.spacing, dtype=np.float64)  # (24, 4, 3) d lam / d world
    out = np.zeros(len(cubes))
    for s in range(0, len(cubes), chunk):
        coef = spline.cube_coefficients(cubes[s:s + chunk])  # (n, 24, m)
        for t in range(NUM_TETS):
            first = [_bb.derivative(coef[:, t], G[t, :, a], d=3) for a in range(3)]
            H = np.zeros((len(coef), 3, 3))
            for a in range(3):
                for b in range(a, 3):
                    H[:, a, b] = H[:, b, a] = np.abs(_bb.derivative(first[a], G[t, :, b], d=3)).max(axis=-1)
            out[s:s + chunk] = np.maximum(out[s:s + chunk], H.sum(axis=2).max(axis=1))
    return out


def value_error_factor(spacing, k: int) -> float:
    """``e_max^2 / 8 + D^2 / 2`` of the fine cells at ``k`` samples per cube (``e_max`` their longest side, ``D``
    their diagonal): times a cube's Hessian bound ``M``, the proven value error ``delta`` on the mesh (edge
    interpolation plus the triangle's chord, module docstring).

    >>> value_error_factor((1.0, 1.0, 1.0), 2)  # 1/32 + 3/8
    0.40625
    """
    h = np.asarray(spacing, dtype=np.float64) / int(k)
    return float(h.max() ** 2 / 8.0 + (h ** 2).sum() / 2.0)


def distance_estimates(spline, cubes, k: int, gradient_min: float) -> np.ndarray:
    """(n,) estimated distance (world) from the ``k``-sampled mesh to the isosurface in each cube: delta / g
    with delta = M (e_max^2 / 8 + D^2 / 2) (proven value error on the mesh) and g = ``gradient_min`` (module
    docstring); infinite where g is 0.

    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[0:5, 0:5, 0:5].astype(float)
    >>> s = VolumeSpline(x * x, "quadratic", order="zyx")  # s_xx = 2; fine cells of side 1/2: delta = 2 (1/32 + 3/8)
    >>> distance_estimates(s, [[2, 2, 2]], 2, 4.0).round(9)  # at |grad s| >= 4
    array([0.203125])
    """
    delta = hessian_bounds(spline, cubes) * value_error_factor(spline.spacing, k)
    with np.errstate(divide="ignore"):
        return delta / gradient_min if gradient_min > 0 else np.full(len(delta), np.inf)


def gradient_floor(spline, mesh) -> float:
    """Smallest |grad s| over the mesh's vertices (the estimate g of :func:`distance_estimates`); inf for an
    empty mesh.

    >>> from splinevis.volume.model import VolumeSpline
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> s = VolumeSpline(sphere_grid(12))  # |x| on a coarse grid: gradient near 1 away from the centre
    >>> round(gradient_floor(s, sampled_mesh(s, 0.7, 1)), 2)
    0.98
    """
    if mesh.n_points == 0:
        return float("inf")
    _, grad = spline.evaluate(np.asarray(mesh.points, dtype=np.float64), gradient=True)
    return float(np.linalg.norm(grad, axis=1).min())


def fine_points(spline, k: int) -> int:
    """Number of fine grid points of :func:`sample_spline` at ``k`` samples per cube and axis.

    >>> from splinevis.volume.model import VolumeSpline
    >>> fine_points(VolumeSpline(np.zeros((3, 4, 5)), order="zyx"), 2)
    693
    """
    return int(np.prod([n * int(k) + 1 for n in spline.shape]))


def sample_spline(spline, isovalue: float, k: int, relevant=None):
    """A :class:`~splinevis.io.VolumeGrid` of the spline's values on the fine grid (``k`` per cube and axis):
    exact in the relevant cubes, elsewhere ``isovalue`` plus or minus the data's span (module docstring).

    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[0:6, 0:6, 0:6].astype(float)
    >>> g = sample_spline(VolumeSpline(x, "quadratic", order="zyx"), 2.25, 2)  # linear data are reproduced
    >>> g.shape, g.spacing, g.values[0, 0, 4:8].tolist()  # x = 1.5, 2, 2.5 (cube 2, exact); x = 3: filled
    ((13, 13, 13), (0.5, 0.5, 0.5), [1.5, 2.0, 2.5, 7.25])
    """
    from ..io.volumes import VolumeGrid

    k = int(k)
    if k < 1:
        raise ValueError(f"samples per cube k must be a positive integer, got {k!r}.")
    if fine_points(spline, k) > MAX_FINE_POINTS:
        raise ValueError(f"{k} samples per cube make {fine_points(spline, k)} points (more than {MAX_FINE_POINTS}).")
    rel = spline.relevant(isovalue) if relevant is None else relevant
    nz, ny, nx = spline.shape
    h = np.asarray(spline.spacing, dtype=np.float64)
    lo = np.asarray(spline.origin, dtype=np.float64) - 0.5 * h
    # side of each cube from its centre value (coefficient 0 of tetrahedron 0 is the centre)
    w = spline.weights[0, 0]
    P = spline.padded
    centre = np.zeros((nz, ny, nx))
    for s, (ox, oy, oz) in enumerate(_schemes.STENCIL):
        centre += w[s] * P[1 + oz: 1 + oz + nz, 1 + oy: 1 + oy + ny, 1 + ox: 1 + ox + nx]
    vmin, vmax = spline.value_range
    span = max(vmax - vmin, 1.0)
    fill = np.where(centre > isovalue, isovalue + span, isovalue - span)
    iz, iy, ix = (np.minimum(np.arange(n * k + 1) // k, n - 1) for n in (nz, ny, nx))
    values = fill[np.ix_(iz, iy, ix)]
    if len(rel.cubes):
        off = np.stack(np.meshgrid(*(np.arange(k + 1),) * 3, indexing="ij"), axis=-1).reshape(-1, 3)
        idx = (rel.cubes[:, None, :] * k + off[None]).reshape(-1, 3)  # (x, y, z) fine indices
        flat = np.unique(np.ravel_multi_index((idx[:, 2], idx[:, 1], idx[:, 0]), values.shape))
        fz, fy, fx = np.unravel_index(flat, values.shape)
        pts = lo + np.column_stack([fx, fy, fz]) * (h / k)
        pts = np.clip(pts, lo, lo + np.array([nx, ny, nz]) * h)  # rounding at the far faces
        values.reshape(-1)[flat] = spline.evaluate(pts)
    return VolumeGrid(values, spacing=tuple(h / k), origin=tuple(lo), source=f"spline sampled {k}x per cube")


def sampled_mesh(spline, isovalue: float, k: int, relevant=None):
    """Marching cubes (flying edges, :func:`splinevis.volume.baselines.marching_cubes_mesh`) of
    :func:`sample_spline`: pyvista PolyData in world coordinates with the spline's exact unit normals (towards
    increasing values) at the vertices.

    >>> from splinevis.volume.model import VolumeSpline
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> s = VolumeSpline(sphere_grid(12))
    >>> meshes = [sampled_mesh(s, 0.7, k) for k in (1, 2, 4)]
    >>> [m.n_cells for m in meshes]
    [536, 2120, 8600]
    >>> [round(float(abs(s.evaluate(m.points) - 0.7).max()), 4) for m in meshes]  # vertex values: O(1 / k^2)
    [0.0034, 0.0012, 0.0003]
    """
    from .baselines import marching_cubes_mesh

    mesh = marching_cubes_mesh(sample_spline(spline, isovalue, k, relevant), isovalue, method="flying_edges")
    if mesh.n_points:  # the exact normals (the library's come from differences of the filled samples too)
        _, grad = spline.evaluate(np.asarray(mesh.points, dtype=np.float64), gradient=True)
        norm = np.linalg.norm(grad, axis=1, keepdims=True)
        mesh.point_data["Normals"] = np.where(norm > 0, grad / np.where(norm > 0, norm, 1.0), mesh.point_data["Normals"])
        mesh.point_data.active_normals_name = "Normals"
    return mesh

"""The terrain's renderers for the choice by accuracy (``Plotter.add_terrain(..., max_error_px=...)``,
:mod:`splinevis.choice`), declared on its program as :data:`RENDERERS`.

* ``mesh``: the spline sampled ``k x k`` per cell (:mod:`splinevis.terrain.sampled_mesh`), **proven**:
  vertical chord <= M h^2 / 4 per cell (h = 1/k, M the Hessian bound from the BB second differences), plus
  the float32 rounding of the vertices (:func:`splinevis.gl.renderers.float32_margin`), turned into pixels
  over each cell's box (:meth:`splinevis.gl.screen_error.View.box_pixels`); rank 0. Its normals are the
  spline's at the vertices, interpolated: **proven** within the smaller of a first-order (``||H|| l``) and a
  second-order (third derivatives, ``l^2``) bound of the spline's normal at the same ``(x, y)``
  (:func:`mesh_normal_error_deg`; C1 schemes).
* ``mesh_guided``: the program with ``proxy="mesh"`` (:mod:`splinevis.terrain.mesh_proxy`), the same picture
  as the box ray cast (the same hard cases agree with the float64 twin), the ray cast's error. It was 2.5-4x
  cheaper than the box ray cast; since the box ray cast walks its cells in rounds (4x faster,
  docs/results/profile/) it is the slower of the two (222 against 163 ms on the profile scene): rank 15, above
  the box ray cast, so it is drawn only where the box ray cast is excluded.
* ``raycast``: the program itself (box proxy), rank 10.

Ranks are the measured costs of :mod:`splinevis.choice` (docs/results/terrain/pareto.md).
"""

from __future__ import annotations

import numpy as np

from ..gl.renderers import MESH_LEVELS, Renderer, add_mesh_actor, float32_margin, mesh_cost, mesh_refuses, raycast_cost
from ..gl.screen_error import SNAP_PX

__all__ = ["RAYCAST_NS_PER_PIXEL", "mesh_error_px", "third_derivative_bounds", "mesh_normal_error_deg", "mesh_measure", "RENDERERS"]


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


def third_derivative_bounds(coefficients) -> np.ndarray:
    """(ncy, ncx) bound of every third partial derivative's magnitude (index coordinates u, v; heights as
    stored) over each cell: ``D_a D_b D_c f`` of a quartic piece is linear with BB coefficients
    ``24 (Delta_a Delta_b Delta_c c)`` (third differences along the barycentric directions of u and v), so
    by the convex hull property its largest coefficient magnitude bounds it; the largest over the four
    partials and the cell's two triangles.

    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> t = TerrainSpline.from_heights(x ** 3 / 6.0, "C1")   # f = u^3 / 6 (C1 reproduces cubics): f_uuu = 1
    >>> bool(np.allclose(third_derivative_bounds(t.coefficients), 1.0))
    True
    """
    from ..bb import simplex
    from .model import _DLAM_DU, _DLAM_DV

    c = np.asarray(coefficients, dtype=np.float64)
    out = np.zeros(c.shape[:-2])
    for dirs in ((_DLAM_DU,) * 3, (_DLAM_DU, _DLAM_DU, _DLAM_DV), (_DLAM_DU, _DLAM_DV, _DLAM_DV), (_DLAM_DV,) * 3):
        for tri in (0, 1):
            d = c[..., tri, :]
            for a in dirs:
                d = simplex.derivative(d, a[tri], d=2)
            out = np.maximum(out, np.abs(d).max(axis=-1))
    return out


def mesh_normal_error_deg(terrain, view, k, cache):
    """(degrees, True): the largest angle between the normal the ``k x k`` sampled mesh shades with and the
    spline's normal at the same ``(x, y)``, over all cells; (inf, False) for schemes that are not C1 (the
    normal jumps across cell edges, so a vertex has no single normal).

    Derivation. On a sub-triangle (inside one polynomial piece) the normal of the graph ``z = f(x, y)`` is
    ``n = phi / |phi|``, ``phi = (-f_x, -f_y, 1)``, ``|phi| >= 1``; world bounds: ``|phi'| <= M`` (the Hessian's
    spectral norm, ``M_index / min(s)^2``) and ``|phi''| <= 2 sqrt(2) T`` (``T`` the largest third partial,
    :func:`third_derivative_bounds` over ``min(s)^3``; ``|D_d^2 f_x| <= (|d_x| + |d_y|)^2 T <= 2 T``) along any
    unit direction, ``s`` the cell spacing. Two bounds, the smaller is used:

    * first order: ``|n'| <= |phi'| / |phi| <= M``, so every vertex normal ``n_i`` is within ``M l`` radians of
      ``n(p)`` (``l = sqrt(s_x^2 + s_y^2) / k``, the sub-triangles' longest side);
    * second order: ``|n''| <= 2 |phi''| + 6 |phi'|^2 =: K`` (differentiating ``phi / |phi|`` twice), and
      Taylor's formula at ``p`` with ``sum lam_i (p_i - p) = 0`` gives ``|n(p) - sum lam_i n_i| <= K R^2 / 2``
      (``R^2 = l^2 / 4`` the right sub-triangle's circumradius squared, ``sum lam_i |p_i - p|^2 <= R^2``), and a
      vector within ``e < 1`` of the unit ``n(p)`` is within ``asin(e)`` of its direction.

    The rasterizer shades with a normalized convex combination of the ``n_i``: in the first case it lies in the
    spherical cap of that radius around ``n(p)`` (convex below 90 degrees), in the second its direction is the
    combination's. Float32 rounding of the unit normals adds ``8 u`` radians.

    >>> import numpy as np
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:17, 0:17] / 16.0
    >>> t = TerrainSpline.from_heights(0.3 * np.sin(4 * x) * np.cos(3 * y), "C1", spacing=(1 / 16, 1 / 16))
    >>> [round(mesh_normal_error_deg(t, None, k, {})[0], 3) for k in (1, 4, 16)]  # second order once k is large
    [24.879, 1.507, 0.094]
    """
    from ..gl.error_bounds import U32
    from .mesh_proxy import C1_SCHEMES

    if terrain.scheme not in C1_SCHEMES:
        return float("inf"), False
    _, M = _boxes_and_hessian(terrain, cache)
    if "third" not in cache:
        cache["third"] = third_derivative_bounds(terrain.coefficients).reshape(-1)
    sx, sy = (float(v) for v in terrain.cell_spacing)
    hw = M / min(sx, sy) ** 2  # per cell
    tw = cache["third"] / min(sx, sy) ** 3
    l = np.hypot(sx, sy) / k
    first = hw * l
    e = (2.0 * 2.0 * np.sqrt(2.0) * tw + 6.0 * hw * hw) * l * l / 8.0
    second = np.where(e < 1.0, np.arcsin(np.minimum(e, 1.0)), np.inf)
    radians = float(np.minimum(first, second).max()) + 8.0 * U32
    return float(np.degrees(min(radians, np.pi))), True


def mesh_measure(terrain, view, k, cache, samples: int = 20_000, seed: int = 0):
    """(pixels, degrees) measured on the ``k x k`` sampled mesh against the float64 spline at ``samples``
    random ``(x, y)``: the mesh point drawn there against the spline point ``(x, y, s(x, y))`` it stands for
    (their projections' distance in ``view``, :meth:`~splinevis.gl.screen_error.View.pixel_distance`; points
    outside the view skipped), and the normalized interpolated vertex normal against the spline's normal.

    >>> import numpy as np
    >>> from splinevis.gl.screen_error import View
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:17, 0:17] / 16.0
    >>> t = TerrainSpline.from_heights(0.3 * np.sin(4 * x) * np.cos(3 * y), "C1", spacing=(1 / 16, 1 / 16))
    >>> v = View((0.5, -1.5, 1.5), (0.5, 0.5, 0.0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 5))
    >>> px, deg = mesh_measure(t, v, 2, {})
    >>> bool(px <= mesh_error_px(t, v, 2, {})[0]), bool(deg <= mesh_normal_error_deg(t, v, 2, {})[0])
    (True, True)
    """
    rng = np.random.default_rng(seed)
    x0, x1, y0, y1 = terrain.extent
    x, y = rng.uniform(x0, x1, samples), rng.uniform(y0, y1, samples)
    u, v = terrain.to_index(x, y)
    ncy, ncx = terrain.shape
    a = np.minimum(np.floor(u * k), k * ncx - 1)
    b = np.minimum(np.floor(v * k), k * ncy - 1)
    lu, lv = u * k - a, v * k - b
    upper = lv > lu  # the sub-square's triangles (00, 10, 11) and (00, 11, 01), split along u = v
    corners = [(a, b), (a + 1, b + 1), (np.where(upper, a, a + 1), np.where(upper, b + 1, b))]
    weights = [1.0 - np.maximum(lu, lv), np.minimum(lu, lv), np.abs(lu - lv)]
    sx, sy = (float(s) for s in terrain.cell_spacing)
    z = np.zeros(samples)
    n = np.zeros((samples, 3))
    for (ca, cb), w in zip(corners, weights):
        cu, cv = ca / k, cb / k
        xv, yv = terrain.origin[0] + cu * sx, terrain.origin[1] + cv * sy
        z += w * terrain.height_at_index(cu, cv)
        g = terrain.gradient(xv, yv)
        nv = np.column_stack([-g[:, 0], -g[:, 1], np.ones(samples)])
        n += w[:, None] * nv / np.linalg.norm(nv, axis=1, keepdims=True)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    g = terrain.gradient(x, y)
    exact = np.column_stack([-g[:, 0], -g[:, 1], np.ones(samples)])
    exact /= np.linalg.norm(exact, axis=1, keepdims=True)
    drawn = np.column_stack([x, y, terrain.z_ref + z])
    spline = np.column_stack([x, y, terrain.evaluate(x, y)])
    px = view.pixel_distance(drawn, spline)
    deg = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", n, exact), -1.0, 1.0)))
    return (float(np.nanmax(px)) if np.isfinite(px).any() else 0.0), float(deg.max())


def _mesh_triangles(terrain, k, cache):
    from .sampled_mesh import mesh_triangles

    return mesh_triangles(terrain, k)


def _mesh_build(plotter, terrain, style, k, cache, spline_options, add_options):
    from .sampled_mesh import sampled_mesh

    return add_mesh_actor(plotter, sampled_mesh(terrain, k), style, spline_options)


#: The box ray cast's frame time per pixel of the terrain's screen rectangle, ns (Franke 33 x 33 C1 at 800 x 600
#: in pyvista's default view: 34.9 ms for 274,600 pixels, benchmarks/bench_choice.py); the mesh-guided one
#: took 1.36 times the box's on the profile scene (docs/results/profile/).
RAYCAST_NS_PER_PIXEL = 127.0


#: The terrain's renderers (module docstring), declared on :data:`splinevis.terrain.program.PROGRAM`.
RENDERERS = (
    Renderer("mesh", 0, MESH_LEVELS, mesh_error_px, _mesh_build, _mesh_triangles, mesh_refuses,
             normal_error_deg=mesh_normal_error_deg, measure=mesh_measure, cost=mesh_cost(_mesh_triangles)),
    Renderer("mesh_guided", 15, exact=True, program_options={"proxy": "mesh", "mesh_samples": 1},
             cost=raycast_cost(1.36 * RAYCAST_NS_PER_PIXEL)),
    Renderer("raycast", 10, exact=True, cost=raycast_cost(RAYCAST_NS_PER_PIXEL)),
)

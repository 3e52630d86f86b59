"""Mesh-guided exact rendering of a terrain spline: the proxy is a lifted tessellation of the spline itself
instead of its bounding box (program option ``proxy="mesh"`` of :mod:`splinevis.terrain.program`).

What is built here (Python) and in ``glsl/lib/terrain/mesh_guided.glsl``:

* **The lifted mesh.** The spline is sampled on a grid of ``k x k`` sub-squares per cell (``mesh_samples``),
  each split along the cell's own diagonal direction (u = v), so every sub-triangle lies in one BB triangle
  (T0 or T1) of one cell. Vertex heights are ``s(vertex) + lift(vertex)``, where ``lift(vertex)`` is the
  largest cell lift (below) over the cells that touch the vertex: shared vertices get one height (the mesh
  is watertight when rasterized) and every sub-triangle of cell c is lifted by at least that cell's lift.
  Side walls go down from the border vertices to below the terrain's box, and a bottom face (a fan over the
  walls' bottom vertices: no T-junction) closes the region R = {(x, y) in the domain, z_bottom <= z <=
  mesh(x, y)}, outward oriented. Every vertex carries its cell (i, j) (flat attribute ``sv_mesh_cell``; -1 on
  the walls and the bottom, whose fragments locate their cell from their position).
* **The lift is a proof, not a guess.** On a sub-triangle T with vertices v_i and linear interpolant L of a
  C2 function f, for x in T with x = sum lam_i v_i, Taylor's theorem at x gives
  f(v_i) = f(x) + grad f(x).(v_i - x) + 1/2 (v_i - x)^T H(xi_i) (v_i - x); summing with weights lam_i
  (sum lam_i (v_i - x) = 0): L(x) - f(x) = 1/2 sum lam_i (v_i - x)^T H(xi_i) (v_i - x), so
  |f(x) - L(x)| <= M/2 sum lam_i |v_i - x|^2 <= M/2 R^2, with M a bound of the spectral norm of the Hessian
  over T and R the circumradius of T (sum lam_i |v_i - x|^2 = R^2 - |x - centre|^2). A sub-triangle is a
  right isosceles triangle with legs h = 1/k (index units), R^2 = h^2/2: the chord error is at most
  M h^2 / 4. M is bounded from the BB coefficients: D_a D_b f of a quartic is the quadratic with BB
  coefficients 12 (Delta_a Delta_b c) (second differences of the coefficients along the barycentric
  directions a, b of index u and v), so by the convex hull property |f_uu| <= A, |f_uv| <= B, |f_vv| <= C
  with A, B, C the largest magnitudes of those coefficients over the cell's two triangles, and by
  Gershgorin M <= max(A, C) + B. The cell's lift is M h^2 / 4 plus a float32 margin (1e-5 of the height
  span plus 1e-5 of the largest coordinate: the VBO holds float32 positions and the rasterizer
  interpolates them; the horizontal part of that error moves the point vertically by up to the slope times it,
  so the coordinate term is multiplied by 1 + |f_x| + |f_y|, bounded from the first differences). The bound
  is per cell, hence valid for every scheme (no continuity across cell edges is used).
* **The fragment** (glsl/lib/terrain/mesh_guided.glsl; float64 twin :mod:`splinevis.terrain.trace`). With the
  eye outside R (decided per frame on the CPU, conservatively: :meth:`LiftedMesh.eye_inside`), back faces are
  culled (``ProgramSpec.cull_per_frame``) and every ray that meets the surface enters R through a front face
  before it, at or after the fragment's own point (t = 0). From there the ray's height above the surface is
  traced to its first zero by steps that cannot pass it (the bound of g'' from the piece's second differences
  along the ray; derivation in :mod:`splinevis.terrain.trace`), stopping at piece borders, skipping blocks of
  the min/max hierarchy the ray passes wholly on its side. A ray that rises above the mesh after having been
  under it has left R: a miss here (the next front face along it starts its own trace). Where 32 steps
  (``mesh_steps``) do not converge (a ray crawling past a near-double root, a grazing silhouette), the
  fragment runs the full hierarchy walk from its point. Two things the rasterizer does had to be met: it
  extrapolates positions past a triangle's edges (vertices snapped to subpixels), on a cliff by far more than
  the lift, so a fragment may lie above the mesh (the exit test applies only once the ray was seen under the
  mesh) or under the surface (it backs up along the ray); and a ray running along a cell edge or a diagonal
  must read the piece ahead of it (its point is nudged along the ray by the walk's cell margin), or it steps
  by a rounding error at a time. With the eye (possibly) inside R the actor compiles another build
  (``ProgramSpec.defines_per_frame``): front faces culled, back faces run the full walk from the eye, as the box
  does; the default build does not carry that walk in every fragment (llvmpipe runs both sides of a branch).

What works, measured (llvmpipe, 2 cores):

* Agreement with the float64 twin: all 44 terrain hard cases (the 2048^2 fractal with a mesh over blocks of
  4 x 4 cells; the other 43 also with the cap lowered to 300 squares, blocks of up to 8 x 8 cells) pass
  :func:`splinevis.analysis.agreement.agreement_failures` exactly as the box program does, at
  ``mesh_samples`` 1 and 32 steps (``python -c`` over ``splinevis.programs.get("terrain").hard_cases()`` with
  ``program_options={"proxy": "mesh"}``; tests/test_terrain_mesh_proxy.py runs 7 of the hardest). The tracing's
  twin finds the reference's first root to 1e-8 on 3,000 rays per scheme over a crater and a cliff
  (tests/test_terrain_trace.py).
* Speed (benchmarks/bench_mesh_guided.py, full-screen C1 frame, 800 x 600): 2.5 to 4x faster than the box
  proxy in the same run, depending on the load; but 10 to 13x slower than a plain mesh of the same triangles
  (18 ms). The tracing itself costs a few loop iterations of one quartic evaluation; most of the rest is the
  fallback walk's code, which llvmpipe executes (masked) in every 8-pixel group even when no fragment needs it.

What does not, or is not built:

* A level of detail chosen from the screen-space size is not built: ``k`` is fixed per program, and grids over
  :data:`MAX_MESH_CELLS` cells get one square per block of B x B cells (:func:`mesh_block`), lifted by the
  block's bound (the smaller of the Hessian bound, for the C1 schemes, and the block's coefficient range), whatever
  the view.
* The near clipping plane is handled conservatively (:meth:`LiftedMesh.near_cuts`): a frame whose near plane may
  cut R where it is seen runs the eye-inside build, as slow as the box. The test assumes view angles up to 120
  degrees; it is not exercised by a hard case.
* Overdraw: every front face along a ray runs the trace (gl_FragDepth is written, so there is no early depth
  test).
* No debug builds (``debug`` is refused with ``proxy="mesh"``); no frustum culling of the mesh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..bb import simplex as _simplex
from .model import _DLAM_DU as _DU  # d(lambda)/du, d(lambda)/dv of T0 = (1 - u, u - v, v), T1 = (1 - v, u, v - u)
from .model import _DLAM_DV as _DV

__all__ = ["triangle_hessian_bounds", "trace_bounds", "mesh_block", "C1_SCHEMES", "second_derivative_bounds", "gradient_bounds", "cell_lifts", "lifted_mesh", "mesh_above", "LiftedMesh", "MAX_MESH_CELLS"]

#: Most squares of the mesh proxy: a grid with more cells gets one square per block of cells (:func:`mesh_block`).
MAX_MESH_CELLS = 512 * 512


def triangle_hessian_bounds(coefficients) -> np.ndarray:
    """(ncy, ncx, 2) bound M of the Hessian's spectral norm (index coordinates u, v; heights as stored) on each
    BB triangle T0, T1 of each cell: max(A, C) + B with A, B, C the largest |BB coefficient| of f_uu, f_uv, f_vv
    (12 times the second differences of the coefficients along the barycentric directions of u and v; convex
    hull property, Gershgorin). The mesh-guided tracing reads it per piece (module docstring).

    Examples
    --------
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> t = TerrainSpline.from_heights(x * y, "C1")   # f = u v: f_uu = f_vv = 0, f_uv = 1
    >>> bool(np.allclose(triangle_hessian_bounds(t.coefficients), 1.0))
    True
    """
    c = np.asarray(coefficients, dtype=np.float64)
    bounds = []
    for a, b in ((_DU, _DU), (_DU, _DV), (_DV, _DV)):
        per_tri = []
        for tri in (0, 1):
            d1 = _simplex.derivative(c[..., tri, :], a[tri], d=2)
            d2 = _simplex.derivative(d1, b[tri], d=2)
            per_tri.append(np.abs(d2).max(axis=-1))
        bounds.append(np.stack(per_tri, axis=-1))
    A, B, C = bounds
    return np.maximum(A, C) + B


def second_derivative_bounds(coefficients) -> np.ndarray:
    """(ncy, ncx) bound M of the Hessian's spectral norm over each cell: the larger of
    :func:`triangle_hessian_bounds` over T0 and T1.

    Examples
    --------
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> t = TerrainSpline.from_heights(x * x, "C1")   # f = u^2 (C1 reproduces cubics): f_uu = 2
    >>> m = second_derivative_bounds(t.coefficients)
    >>> bool(np.allclose(m, 2.0))
    True
    """
    return triangle_hessian_bounds(coefficients).max(axis=-1)


def cell_lifts(terrain, k: int) -> np.ndarray:
    """(ncy, ncx) lift of each cell for ``k x k`` sub-squares per cell: M h^2 / 4 with h = 1/k (module
    docstring), plus the float32 margin.

    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> t = TerrainSpline.from_heights(x * x, "C1")
    >>> lifts = cell_lifts(t, 2)  # the chord bound 2 (1/2)^2 / 4 = 0.125 and the float32 margin
    >>> bool((lifts >= 0.125).all() and (lifts < 0.13).all())
    True
    """
    c = terrain.coefficients
    h = 1.0 / k
    lift = second_derivative_bounds(c) * h * h / 4.0
    x0, x1, y0, y1 = terrain.extent
    span = float(c.max() - c.min())
    coord = max(0.5 * (x1 - x0), 0.5 * (y1 - y0), float(np.abs(c).max()))
    # the fragment's point (float32, interpolated) may sit off the mesh by ~1e-5 coord in any direction: on a
    # slope of gradient g that moves it vertically by g times as much (the linear scheme's cliff leaked without)
    sx, sy = terrain.cell_spacing
    return lift + 1e-5 * span + 1e-5 * coord * (1.0 + gradient_bounds(c, sx, sy))


#: Schemes whose spline is C1 across cell edges: a mesh square spanning several cells may use the Hessian bound
#: (Taylor's theorem with integral remainder needs f in C1 with piecewise bounded second derivatives).
C1_SCHEMES = ("C1", "C2", "C2-cubic", "C2-interp")


def mesh_block(terrain, k: int = 1) -> int:
    """Cells per side of a square of the mesh: 1 (``k x k`` sub-squares per cell) while the grid has at most
    :data:`MAX_MESH_CELLS` cells, else the smallest power of two B with ceil(ncx / B) ceil(ncy / B) squares
    within it (then ``k`` must be 1).

    >>> from splinevis.terrain.model import TerrainSpline
    >>> mesh_block(TerrainSpline.from_heights(np.zeros((9, 9)), "C1"))
    1
    """
    ncy, ncx = terrain.shape
    if ncx * ncy <= MAX_MESH_CELLS:
        return 1
    if k != 1:
        raise ValueError(f"mesh_samples={k} on a grid of {ncx}x{ncy} cells: more than {MAX_MESH_CELLS} cells are "
                         "drawn with one mesh square per block of cells; use mesh_samples=1.")
    B = 2
    while -(-ncx // B) * -(-ncy // B) > MAX_MESH_CELLS:
        B *= 2
    return B


def _block_reduce(a, B, op):
    """(ny, nx) -> (ceil(ny / B), ceil(nx / B)) by ``op`` (np.max or np.min) over B x B blocks (edge-padded)."""
    ny, nx = a.shape
    by, bx = -(-ny // B), -(-nx // B)
    a = np.pad(a, ((0, by * B - ny), (0, bx * B - nx)), mode="edge")
    return op(a.reshape(by, B, bx, B), axis=(1, 3))


def _groups(terrain, k: int):
    """The mesh's squares: corner lines ``gu`` (ngx + 1), ``gv`` (ngy + 1) in index units, sub-squares per square
    ``kk``, the block size B and per square the chord bound and the lift (chord bound plus float32 margins).

    B = 1: a square is a cell, every sub-triangle lies in one BB triangle: chord <= M h^2 / 4, h = 1 / k
    (:func:`cell_lifts`). B > 1: a square spans B x B cells; its two triangles are right triangles with legs
    hx, hy <= B, circumradius^2 (hx^2 + hy^2) / 4, so chord <= M (hx^2 + hy^2) / 8 with M the largest cell bound
    of the block, for the C1 schemes; for every scheme chord <= max - min of the block's coefficients (the
    interpolant and the spline both lie in that range); the smaller bound is used.
    """
    ncy, ncx = terrain.shape
    B = mesh_block(terrain, k)
    if B == 1:
        M = second_derivative_bounds(terrain.coefficients)
        return (np.arange(ncx + 1.0), np.arange(ncy + 1.0), k, 1, M / (4.0 * k * k), cell_lifts(terrain, k))
    c = terrain.coefficients
    gu = np.minimum(np.arange(-(-ncx // B) + 1) * B, ncx).astype(np.float64)
    gv = np.minimum(np.arange(-(-ncy // B) + 1) * B, ncy).astype(np.float64)
    hx, hy = np.diff(gu), np.diff(gv)
    chord = _block_reduce(c.max(axis=(2, 3)), B, np.max) - _block_reduce(c.min(axis=(2, 3)), B, np.min)
    if getattr(terrain, "scheme", None) in C1_SCHEMES:  # both bounds hold: the smaller
        M = _block_reduce(second_derivative_bounds(c), B, np.max)
        chord = np.minimum(chord, M * (hy[:, None] ** 2 + hx[None, :] ** 2) / 8.0)
    x0, x1, y0, y1 = terrain.extent
    span = float(c.max() - c.min())
    coord = max(0.5 * (x1 - x0), 0.5 * (y1 - y0), float(np.abs(c).max()))
    sx, sy = terrain.cell_spacing
    grad = _block_reduce(gradient_bounds(c, sx, sy), B, np.max)
    return gu, gv, 1, B, chord, chord + 1e-5 * span + 1e-5 * coord * (1.0 + grad)


def _cells_of(a, B, shape):
    """Per-square values (ngy, ngx) spread over the cells (ncy, ncx) of blocks of B x B cells."""
    return np.repeat(np.repeat(a, B, axis=0), B, axis=1)[: shape[0], : shape[1]]


def trace_bounds(terrain, k: int) -> np.ndarray:
    """(ncy, ncx, 2) per cell: the Hessian bound M of :func:`second_derivative_bounds` (the tracing's step) and a
    bound G of the lifted mesh's height above the spline on the cell (the tracing's exit: a ray higher than G
    above the spline has left the region under the mesh). On a sub-triangle the mesh is the linear interpolant
    of s + lift at its vertices, so mesh - s <= (chord error) + (largest vertex lift) <= M h^2 / 4 + the largest
    cell lift among the 3 x 3 cells around (a vertex's lift is the largest of the cells touching it); for a grid
    drawn with squares of B x B cells (:func:`mesh_block`), the same over squares (:func:`_groups`), spread over
    their cells.

    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:6, 0:6].astype(float)
    >>> b = trace_bounds(TerrainSpline.from_heights(x * x, "C1"), 2)
    >>> b.shape, bool(np.allclose(b[..., 0], 2.0)), bool((b[..., 1] >= 0.25).all())  # G >= chord + lift
    ((5, 5, 2), True, True)
    """
    M = second_derivative_bounds(terrain.coefficients)
    _, _, _, B, chord, lifts = _groups(terrain, k)
    pad = np.pad(lifts, 1, mode="edge")
    ny, nx = lifts.shape
    near = np.max([pad[dy: dy + ny, dx: dx + nx] for dy in range(3) for dx in range(3)], axis=0)
    return np.stack([M, _cells_of(chord + near, B, M.shape)], axis=-1)


def gradient_bounds(coefficients, sx: float = 1.0, sy: float = 1.0) -> np.ndarray:
    """(ncy, ncx) bound of |f_x| + |f_y| (model units; cell size sx x sy) over each cell: the largest
    |BB coefficient| of f_u and f_v (4 first differences) over T0 and T1, divided by the cell size.

    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:4, 0:4].astype(float)
    >>> bool(np.allclose(gradient_bounds(TerrainSpline.from_heights(3 * x - y, "C1").coefficients), 4.0))
    True
    """
    c = np.asarray(coefficients, dtype=np.float64)
    out = 0.0
    for dirs, size in ((_DU, sx), (_DV, sy)):
        out = out + np.maximum(*(np.abs(_simplex.derivative(c[..., tri, :], dirs[tri], d=2)).max(axis=-1)
                                 for tri in (0, 1))) / size
    return out


@dataclass
class LiftedMesh:
    """The lifted mesh in the model frame: ``points`` (N, 3), ``triangles`` (M, 3), ``cells`` (N, 2) float
    (cell i, j; -1 on the bottom face), ``top`` (ncy, ncx) highest lifted vertex of each cell (model z),
    ``bottom`` (model z of the bottom face), the model-frame extent (x0, x1, y0, y1), sub-squares per cell
    ``k``, and the squares' size ``block`` (cells) and corner lines ``gu``, ``gv`` (index units).

    >>> from splinevis.terrain.model import TerrainSpline
    >>> m = lifted_mesh(TerrainSpline.from_heights(np.zeros((4, 5)), "C1"), 1)
    >>> m.top.shape, m.k, bool(m.bottom < 0 < m.top.min())   # 3 x 4 cells, lifted above the plane z = 0
    ((3, 4), 1, True)
    """

    points: np.ndarray
    triangles: np.ndarray
    cells: np.ndarray
    top: np.ndarray
    bottom: float
    extent: tuple
    k: int
    block: int = 1
    gu: np.ndarray | None = None
    gv: np.ndarray | None = None

    def eye_inside(self, eye, reach: float = 0.0) -> bool:
        """Whether ``eye`` (model frame) may lie inside the region under the mesh, or within ``reach`` of it
        (conservative: within one cell (plus ``reach``) of the domain and below the highest lifted vertex of the
        3 x 3 cells around it, plus a margin and ``reach``).

        >>> from splinevis.terrain.model import TerrainSpline
        >>> m = lifted_mesh(TerrainSpline.from_heights(np.zeros((5, 5)), "C1"), 2)
        >>> m.eye_inside((0.0, 0.0, 0.5)), m.eye_inside((0.0, 0.0, 0.0)), m.eye_inside((0.0, 0.0, -0.5))
        (False, True, False)
        >>> m.eye_inside((0.0, 0.0, 0.5), reach=0.6)
        True
        """
        x0, x1, y0, y1 = self.extent
        ncy, ncx = self.top.shape
        sx, sy = (x1 - x0) / ncx, (y1 - y0) / ncy
        ex, ey, ez = (float(v) for v in eye)
        if not (x0 - sx - reach <= ex <= x1 + sx + reach and y0 - sy - reach <= ey <= y1 + sy + reach):
            return False
        ri, rj = int(np.ceil(reach / sx)) + 1, int(np.ceil(reach / sy)) + 1
        i = int(np.clip(np.floor((ex - x0) / sx), 0, ncx - 1))
        j = int(np.clip(np.floor((ey - y0) / sy), 0, ncy - 1))
        top = float(self.top[max(j - rj, 0): j + rj + 1, max(i - ri, 0): i + ri + 1].max())
        margin = 1e-4 * (abs(top) + abs(self.bottom) + 1.0) + reach
        return self.bottom - margin <= ez <= top + margin

    def near_cuts(self, eye, view, near: float) -> bool:
        """Whether the near clipping plane (at distance ``near`` along ``view`` from ``eye``) may cut the region
        under the mesh where the view sees it: some of the region's box lies closer than ``near`` and the eye
        is within reach of the near plane's rectangle (4 ``near``: conservative for view angles up to 120
        degrees) of the region. A clipped front face would hand its rays to a later face, past the surface
        between them; such frames use the full walk from the eye instead.

        >>> from splinevis.terrain.model import TerrainSpline
        >>> m = lifted_mesh(TerrainSpline.from_heights(np.zeros((5, 5)), "C1"), 1)
        >>> m.near_cuts((2.0, 2.0, 0.05), (0.0, 1.0, 0.0), 0.1), m.near_cuts((2.0, -9.0, 5.0), (0.0, 1.0, 0.0), 0.1)
        (True, False)
        """
        x0, x1, y0, y1 = self.extent
        corners = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (self.bottom, float(self.top.max()))])
        depth = (corners - np.asarray(eye, dtype=np.float64)) @ np.asarray(view, dtype=np.float64)
        return bool(depth.min() < near) and self.eye_inside(eye, reach=4.0 * near)


def lifted_mesh(terrain, k: int = 2) -> LiftedMesh:
    """The lifted tessellation of ``terrain`` with ``k x k`` sub-squares per cell, side walls and a bottom face,
    in the model frame (module docstring).

    Examples
    --------
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:4, 0:5].astype(float)
    >>> t = TerrainSpline.from_heights(np.sin(x) + y, "C1")
    >>> m = lifted_mesh(t, 2)
    >>> m.points.shape, m.triangles.shape   # 12 cells x 9 vertices + walls + bottom
    ((165, 3), (180, 3))
    >>> u = np.random.default_rng(0).uniform(0, 1, (2000, 2))  # the mesh lies above the surface
    >>> bool(mesh_above(t, m, u[:, 0] * 4, u[:, 1] * 3).min() > 0)
    True
    """
    if k < 1:
        raise ValueError(f"mesh_samples must be at least 1, got {k}.")
    ncy, ncx = terrain.shape
    off = terrain.offset
    x0, x1, y0, y1 = terrain.extent
    sx, sy = terrain.cell_spacing
    # the squares: cells with k x k sub-squares, or blocks of B x B cells on grids over MAX_MESH_CELLS
    gu, gv, kk, B, _, lifts = _groups(terrain, k)
    ngy, ngx = lifts.shape
    # global vertex lines (index coordinates), heights in the model frame (relative to z_ref)
    nu, nv = kk * ngx + 1, kk * ngy + 1
    ci = np.minimum(np.arange(nu) // kk, ngx - 1)  # the square of each vertex line
    cj = np.minimum(np.arange(nv) // kk, ngy - 1)
    a = gu[ci] + (gu[ci + 1] - gu[ci]) * (np.arange(nu) - ci * kk) / kk
    b = gv[cj] + (gv[cj + 1] - gv[cj]) * (np.arange(nv) - cj * kk) / kk
    U, V = np.meshgrid(a, b)  # (nv, nu)
    z = terrain.height_at_index(U, V)
    # vertex lift: the largest lift of the squares touching the vertex
    pad = np.pad(lifts, 1, mode="edge")
    touch = np.maximum(np.maximum(pad[:-1, :-1], pad[1:, :-1]), np.maximum(pad[:-1, 1:], pad[1:, 1:]))  # (ngy+1, ngx+1)
    vl = np.zeros((nv, nu))
    on_u = (np.arange(nu) % kk) == 0
    on_v = (np.arange(nv) % kk) == 0
    # inside a square: the square's lift; on a square's edge or corner: the max of the squares sharing it
    vl[:] = lifts[cj][:, ci]
    left = lifts[cj][:, np.maximum(ci - 1, 0)]
    below = lifts[np.maximum(cj - 1, 0)][:, ci]
    vl = np.where(on_u[None, :], np.maximum(vl, left), vl)
    vl = np.where(on_v[:, None], np.maximum(vl, below), vl)
    both = on_u[None, :] & on_v[:, None]
    jj, ii = np.nonzero(both)
    vl[jj, ii] = touch[jj // kk, ii // kk]
    zl = z + vl
    X = x0 - off[0] + U * sx
    Y = y0 - off[1] + V * sy
    # per-square vertex blocks (vertices duplicated per square so each carries its first cell's id)
    s = np.arange(kk + 1)
    cj_all, ci_all = np.meshgrid(np.arange(ngy), np.arange(ngx), indexing="ij")
    gb = cj_all[..., None, None] * kk + s[None, None, :, None]   # (ngy, ngx, kk+1, 1) global row
    ga = ci_all[..., None, None] * kk + s[None, None, None, :]   # (ngy, ngx, 1, kk+1) global column
    gb, ga = np.broadcast_arrays(gb, ga)
    pts_top = np.stack([X[gb, ga], Y[gb, ga], zl[gb, ga]], axis=-1).reshape(-1, 3)
    cell_top = np.stack([np.broadcast_to(ci_all[..., None, None] * B, gb.shape),
                         np.broadcast_to(cj_all[..., None, None] * B, gb.shape)], axis=-1).reshape(-1, 2).astype(np.float64)
    top = _cells_of(zl[gb, ga].reshape(ngy, ngx, -1).max(axis=-1), B, (ncy, ncx))
    # triangles per square: sub-square (p, q) with corners v00, v10, v11, v01 (local grid index q * (kk+1) + p);
    # split along u = v: (v00, v10, v11) and (v00, v11, v01), counter-clockwise seen from above
    p, q = np.meshgrid(np.arange(kk), np.arange(kk))
    v00 = (q * (kk + 1) + p).ravel()
    v10, v01, v11 = v00 + 1, v00 + (kk + 1), v00 + (kk + 2)
    local = np.concatenate([np.stack([v00, v10, v11], 1), np.stack([v00, v11, v01], 1)])
    base = (np.arange(ngy * ngx) * (kk + 1) ** 2)[:, None, None]
    tris_top = (base + local[None]).reshape(-1, 3)
    # walls and bottom
    zb = float(terrain.coefficients.min()) - 1e-6 * max(1.0, float(np.ptp(terrain.coefficients))) - float(lifts.max())
    ring = ([(a_, 0) for a_ in range(nu)] + [(nu - 1, b_) for b_ in range(1, nv)] +
            [(a_, nv - 1) for a_ in range(nu - 2, -1, -1)] + [(0, b_) for b_ in range(nv - 2, 0, -1)])
    ring = np.array(ring)  # counter-clockwise around the domain seen from above
    ra, rb = ring[:, 0], ring[:, 1]
    n0 = len(pts_top)
    wall_top = np.stack([X[rb, ra], Y[rb, ra], zl[rb, ra]], axis=-1)
    wall_bot = np.stack([X[rb, ra], Y[rb, ra], np.full(len(ring), zb)], axis=-1)
    nr = len(ring)
    idx = np.arange(nr)
    nxt = (idx + 1) % nr
    t_ = n0 + idx
    b_ = n0 + nr + idx
    # outward: for a counter-clockwise ring seen from above, (bottom_i, bottom_next, top_next), (bottom_i, top_next, top_i)
    tris_wall = np.concatenate([np.stack([b_, n0 + nr + nxt, n0 + nxt], 1), np.stack([b_, n0 + nxt, t_], 1)])
    # bottom: a fan from the centre over the walls' bottom vertices, facing down (the domain is convex); it shares
    # the walls' bottom edges, so the closed mesh has no T-junction (four corner triangles left a crack)
    nc = n0 + 2 * nr
    bottom = np.array([[0.5 * (x0 + x1) - off[0], 0.5 * (y0 + y1) - off[1], zb]])
    tris_bottom = np.stack([np.full(nr, nc), n0 + nr + nxt, n0 + nr + idx], 1)
    points = np.concatenate([pts_top, wall_top, wall_bot, bottom])
    # walls and bottom carry cell -1: their fragments locate their cell from their position (clamped)
    cells = np.concatenate([cell_top, np.full((2 * nr + 1, 2), -1.0)])
    triangles = np.concatenate([tris_top, tris_wall, tris_bottom]).astype(np.int64)
    return LiftedMesh(points, triangles, cells, top, zb, (x0 - off[0], x1 - off[0], y0 - off[1], y1 - off[1]), k,
                      B, gu, gv)


def mesh_above(terrain, mesh: LiftedMesh, u, v) -> np.ndarray:
    """Lifted mesh height minus spline height at index points (u, v) (model frame; positive: above), by
    locating the sub-triangle of the top mesh (for tests).

    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:4, 0:4].astype(float)
    >>> t = TerrainSpline.from_heights(x - y, "linear")   # a plane: the mesh lies above by its lift only
    >>> d = mesh_above(t, lifted_mesh(t, 1), [0.5, 1.5], [0.25, 2.5])
    >>> bool((d > 0).all() and (d < 1e-3).all())
    True
    """
    u = np.asarray(u, float)
    v = np.asarray(v, float)
    kk = mesh.k if mesh.block == 1 else 1
    gu, gv = mesh.gu, mesh.gv
    ngx, ngy = len(gu) - 1, len(gv) - 1
    blocks = mesh.points[: (kk + 1) ** 2 * ngx * ngy].reshape(ngy, ngx, kk + 1, kk + 1, 3)
    i = np.clip(np.searchsorted(gu, u, side="right") - 1, 0, ngx - 1)
    j = np.clip(np.searchsorted(gv, v, side="right") - 1, 0, ngy - 1)
    fu, fv = (u - gu[i]) / (gu[i + 1] - gu[i]) * kk, (v - gv[j]) / (gv[j + 1] - gv[j]) * kk
    p = np.clip(np.floor(fu).astype(np.int64), 0, kk - 1)
    q = np.clip(np.floor(fv).astype(np.int64), 0, kk - 1)
    s, t = fu - p, fv - q
    z00 = blocks[j, i, q, p, 2]
    z10 = blocks[j, i, q, p + 1, 2]
    z01 = blocks[j, i, q + 1, p, 2]
    z11 = blocks[j, i, q + 1, p + 1, 2]
    zl = np.where(t <= s, z00 + s * (z10 - z00) + t * (z11 - z10), z00 + t * (z01 - z00) + s * (z11 - z01))
    x0, _, y0, _ = terrain.extent
    sx, sy = terrain.cell_spacing
    f = terrain.evaluate(x0 + u * sx, y0 + v * sy) - terrain.z_ref
    return zl - f

"""Float64 ray casting of a TerrainSpline: the reference the terrain shader is tested against.

The reference walks every ray cell by cell through the grid (Amanatides-Woo 2-D DDA), vectorized over
rays: at each step every active ray sits in one cell on a parameter segment [ta, tb]. Where the ray's
height range over the segment overlaps the cell's coefficient range (convex hull property), both
triangles are tested: clip to the triangle, restrict the quartic to the segment by blossoming, take
the first root [Reis2008, sec. V]. The first hit along the ray wins.

This is deliberately a different traversal from the shader's min/max hierarchy, so a bug in one does
not hide in the other.
"""

from __future__ import annotations

import numpy as np

from .._validation import as_float64_array, check_choice
from ..bb.ray import graph_patch_first_hit
from ..gl.contract import RayHits
from .model import TerrainSpline, cell_barycentric

__all__ = ["raycast_terrain", "first_hit_in_cell"]

#: A batch of candidate segments is solved when it has this many rows or spans this many walk steps.
FLUSH_ROWS = 20_000
FLUSH_STEPS = 16


def first_hit_in_cell(coef_cell, lu0, lv0, z0, du, dv, dz, ta, tb, *, method="reference", iterations=8):
    """First t in [ta, tb] where the ray meets the cell's spline, else NaN. All arrays (N,); coef (N, 2, 15).

    The ray is given in cell-local coordinates: (lu0 + t du, lv0 + t dv) and height z0 + t dz.

    Examples
    --------
    A vertical ray from height 2 through cell point (0.25, 0.75) (triangle T1) onto the plane 0.5:

    >>> one = np.ones(1)
    >>> first_hit_in_cell(np.full((1, 2, 15), 0.5), 0.25 * one, 0.75 * one, 2.0 * one, 0 * one, 0 * one,
    ...                   -one, 0 * one, np.inf * one)
    array([1.5])
    """
    # Both triangles in one batch (rows 0..N-1: T0, rows N..2N-1: T1): graph_patch_first_hit works row by row, so
    # the hits are those of one call per triangle, at half the calls (a walk makes thousands of small ones).
    n = len(ta)
    tri = np.repeat([0, 1], n)
    lu0, lv0, z0, du, dv, dz, ta, tb = (np.tile(a, 2) for a in (lu0, lv0, z0, du, dv, dz, ta, tb))
    lam_o = cell_barycentric(lu0, lv0, tri)
    lam_d = cell_barycentric(du, dv, tri) - cell_barycentric(0.0, 0.0, tri)
    t = graph_patch_first_hit(np.concatenate([coef_cell[:, 0], coef_cell[:, 1]]), lam_o, lam_d, z0, dz, ta, tb,
                              method=method, iterations=iterations)
    t0, t1 = t[:n], t[n:]
    return np.where(np.isnan(t0) | (t1 < t0), t1, t0)  # the nearer hit; NaN only where both miss


class _Batch:
    """The candidate segments (ray, cell, ta, tb) of several walk steps, solved at once: the root finder's cost is
    numpy's per-call overhead on the few hundred rows one step has. A ray walks on after its candidates until the
    batch is solved (at most :data:`FLUSH_STEPS` steps or :data:`FLUSH_ROWS` rows), then stops at its first
    candidate with a root, in the walk's order: the hits are those of solving every step apart, bit for bit.
    :meth:`solve` writes ``t_hit`` and clears ``active`` of the rays that hit."""

    def __init__(self, terrain, U0, V0, Z0, dU, dV, dZ, t_hit, active, *, method, iterations):
        self.terrain, self.ray = terrain, (U0, V0, Z0, dU, dV, dZ)
        self.t_hit, self.active = t_hit, active
        self.options = {"method": method, "iterations": iterations}
        self.pending, self.rows, self.steps = [], 0, 0

    def add(self, rays, i, j, ta, tb):
        self.pending.append((rays, i, j, ta, tb))
        self.rows += len(rays)

    def due(self) -> bool:
        """One more walk step taken: is the batch to be solved now?"""
        self.steps += 1
        return bool(self.pending) and (self.rows >= FLUSH_ROWS or self.steps >= FLUSH_STEPS)

    def solve(self):
        if self.pending:
            rays, ii, jj, ta, tb = (np.concatenate(a) for a in zip(*self.pending))
            U0, V0, Z0, dU, dV, dZ = self.ray
            th = first_hit_in_cell(self.terrain.coefficients[jj, ii], U0[rays] - ii, V0[rays] - jj, Z0[rays],
                                   dU[rays], dV[rays], dZ[rays], ta, tb, **self.options)
            found = np.nonzero(np.isfinite(th))[0]
            first = found[np.unique(rays[found], return_index=True)[1]]  # each ray's earliest candidate with a root
            self.t_hit[rays[first]] = th[first]
            self.active[rays[first]] = False
        self.pending, self.rows, self.steps = [], 0, 0


def raycast_terrain(terrain: TerrainSpline, origins, directions, tmin=0.0, *, method: str = "reference",
                    iterations: int = 8, max_steps: int | None = None) -> RayHits:
    """Intersect rays (world coordinates, float64) with ``terrain``; the first hit of each ray.

    Parameters
    ----------
    terrain : TerrainSpline
    origins, directions : (…, 3) array_like
    tmin : float
        Smallest admissible ray parameter.
    method : {"reference", "bracketed", "paper"}
        Root finder on each candidate segment: the robust all-roots reference, or the shader's methods in
        float64: bracketed Newton on convex pieces, or Newton from four secure starting points
        [Reis2008, sec. V].

    Returns
    -------
    RayHits
        ``t`` (NaN on a miss), surface points and normals (unnormalized, (-s_x, -s_y, 1)).

    Examples
    --------
    >>> y, x = np.mgrid[0:5, 0:6].astype(float)
    >>> terrain = TerrainSpline.from_heights(x + 2 * y, "C1", spacing=(10.0, 10.0), origin=(100.0, 200.0))
    >>> hits = raycast_terrain(terrain, [[125.0, 215.0, 50.0], [0.0, 0.0, 50.0]], [0.0, 0.0, -1.0])
    >>> hits.t.round(9), hits.points[0].round(9)  # the second ray misses the domain
    (array([44.5,  nan]), array([125. , 215. ,   5.5]))
    >>> hits.normals[0].round(12)
    array([-0.1, -0.2,  1. ])
    """
    if not isinstance(terrain, TerrainSpline):
        raise TypeError(f"terrain must be a TerrainSpline, got {type(terrain).__name__}.")
    check_choice(method, "method", {"reference", "bracketed", "paper"})
    o = as_float64_array(origins, "origins", shape_tail=(3,))
    d = as_float64_array(directions, "directions", shape_tail=(3,))
    o, d = np.broadcast_arrays(o, d)
    shape = o.shape[:-1]
    o = o.reshape(-1, 3)
    d = d.reshape(-1, 3)
    n = len(o)
    ncy, ncx = terrain.shape
    sx, sy = terrain.cell_spacing
    # index space: U = (x - x0)/sx, V = (y - y0)/sy, Z = z - z_ref; t is shared.
    U0 = (o[:, 0] - terrain.origin[0]) / sx
    V0 = (o[:, 1] - terrain.origin[1]) / sy
    Z0 = o[:, 2] - terrain.z_ref
    dU, dV, dZ = d[:, 0] / sx, d[:, 1] / sy, d[:, 2]
    zlo, zhi = float(terrain.coefficients.min()), float(terrain.coefficients.max())
    zpad = 1e-12 * max(abs(zlo), abs(zhi), 1.0)
    zlo, zhi = zlo - zpad, zhi + zpad
    t0 = np.full(n, float(tmin))
    t1 = np.full(n, np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for p0, dp, lo, hi in ((U0, dU, 0.0, ncx), (V0, dV, 0.0, ncy), (Z0, dZ, zlo, zhi)):
            flat = np.abs(dp) < 1e-300
            ta, tb = (lo - p0) / dp, (hi - p0) / dp
            t0 = np.where(flat, np.where((p0 < lo) | (p0 > hi), np.inf, t0), np.maximum(t0, np.minimum(ta, tb)))
            t1 = np.where(flat, t1, np.minimum(t1, np.maximum(ta, tb)))
    active = t0 <= t1
    t_hit = np.full(n, np.nan)
    batch = _Batch(terrain, U0, V0, Z0, dU, dV, dZ, t_hit, active, method=method, iterations=iterations)
    cell_lo, cell_hi = terrain.hierarchy.levels[0]
    steps = max_steps if max_steps is not None else 2 * (ncx + ncy) + 4
    # The walking rays' state is kept compact (their rows only), so a step costs what its rays cost: rows of rays
    # that stopped are dropped once they are a quarter of the rows (they walk on until then, marked dead: they add
    # no candidate and their results are never read). Every ray does the same float operations as alone.
    rays = np.nonzero(active)[0]
    tm = t0[rays]
    u0, v0, z0, du, dv, dz, t_end = (a[rays] for a in (U0, V0, Z0, dU, dV, dZ, t1))
    ci = np.clip(np.floor(u0 + tm * du).astype(np.int64), 0, ncx - 1)
    cj = np.clip(np.floor(v0 + tm * dv).astype(np.int64), 0, ncy - 1)
    walking = np.ones(len(rays), dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        flat_u, flat_v = np.abs(du) < 1e-300, np.abs(dv) < 1e-300
        step_i, step_j = np.where(du > 0, 1, -1), np.where(dv > 0, 1, -1)
        for _ in range(steps):
            if not walking.any():
                break
            if 4 * int(np.count_nonzero(walking)) <= 3 * len(rays):  # compact
                rays, tm, u0, v0, z0, du, dv, dz, t_end, ci, cj, flat_u, flat_v, step_i, step_j = (
                    a[walking] for a in (rays, tm, u0, v0, z0, du, dv, dz, t_end, ci, cj, flat_u, flat_v, step_i,
                                         step_j))
                walking = np.ones(len(rays), dtype=bool)
            nbu = np.where(du > 0, ci + 1, ci).astype(np.float64)
            nbv = np.where(dv > 0, cj + 1, cj).astype(np.float64)
            txu = np.where(flat_u, np.inf, (nbu - u0) / du)
            txv = np.where(flat_v, np.inf, (nbv - v0) / dv)
            ta = tm
            tb = np.minimum(np.minimum(txu, txv), t_end)
            za, zb = z0 + ta * dz, z0 + tb * dz
            rlo, rhi = np.minimum(za, zb), np.maximum(za, zb)
            overlap = walking & (rhi >= cell_lo[cj, ci]) & (rlo <= cell_hi[cj, ci])
            if overlap.any():
                batch.add(rays[overlap], ci[overlap], cj[overlap], ta[overlap], tb[overlap])
            # advance every ray (a dead one's cell is kept inside the grid, where its lookups stay valid)
            go_u = txu <= txv
            tm = tb
            ci = ci + np.where(go_u, step_i, 0)
            cj = cj + np.where(go_u, 0, step_j)
            out = (ci < 0) | (ci >= ncx) | (cj < 0) | (cj >= ncy)
            walking &= ~((tb >= t_end) | out)
            ci, cj = np.where(out, 0, ci), np.where(out, 0, cj)
            if batch.due():
                batch.solve()  # rays that found their hit stop walking
                walking &= active[rays]
        batch.solve()
    t = t_hit.reshape(shape)
    pts = o.reshape(shape + (3,)) + t[..., None] * d.reshape(shape + (3,))
    normals = np.full(pts.shape, np.nan)
    hit = np.isfinite(t)
    if hit.any():
        g = terrain.gradient(pts[hit][:, 0], pts[hit][:, 1])
        normals[hit] = np.c_[-g, np.ones(len(g))]
    return RayHits(t, pts, normals)

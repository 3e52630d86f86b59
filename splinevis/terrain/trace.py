"""Float64 twin of the mesh-guided terrain program's root tracing (glsl/lib/terrain/mesh_guided.glsl).

A ray P(t) = P0 + t D (index coordinates u, v in cells, heights relative to the reference height) starts at a
point known not to be past its first root (on the GPU: a fragment of the lifted mesh, which lies above the
surface). Its height above the surface g(t) = z(t) - s(u(t), v(t)) is followed by steps that cannot pass a
zero: on the current BB triangle ("piece"), |g''| <= K with K = max |BB coefficients of D_w D_w s| (w the
barycentric direction of D.xy; the coefficients are second differences of the piece's coefficients, convex
hull property), so by Taylor's theorem

    sigma g(t + h) >= sigma g(t) + sigma g'(t) h - K h^2 / 2 > 0   for 0 <= h < h*,

sigma the sign of g at the start and h* the positive root of that quadratic, written
h* = 2 sigma g / (sqrt(g'^2 + 2 K sigma g) - sigma g') (no cancellation). Steps stop at the piece's border
(the cell's edges and its diagonal u = v), where the next piece's bound and derivative apply; the piece a ray on
a border is in is the one ahead along the ray. Near a simple root h* tends to the Newton step, so the
convergence is quadratic; near a double root (a ray grazing the surface) it is slow, and the program then hands
the fragment to the full hierarchy walk. ``exit_bound``: the lifted mesh's height above the spline is at most
G per cell (:func:`splinevis.terrain.mesh_proxy.trace_bounds`); a ray above the surface that was under the mesh
and then rises higher than G above the surface has left the region under the mesh (on the GPU a later
front face of the mesh starts a new trace). The GPU also skips blocks of the min/max hierarchy that the ray
passes wholly on its side; that changes no result (a block skipped holds no root) and is not repeated here.

Why our own code: no library traces a ray against a piecewise BB height field; this file states the method
the shader runs so that tests can check it in exact-ish arithmetic against the independent DDA reference
(:func:`splinevis.terrain.raycast.raycast_terrain`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..bb import simplex as _simplex
# _DU, _DV: barycentric directions of index u and v on T0 = (1 - u, u - v, v) and T1 = (1 - v, u, v - u)
from .model import _DLAM_DU as _DU, _DLAM_DV as _DV, TerrainSpline, cell_barycentric

__all__ = ["TraceResult", "trace_first_root"]


@dataclass
class TraceResult:
    """``t`` (NaN unless ``state`` is "hit"), ``state`` ("hit", "missed": left the box, the domain or the
    mesh's region; "capped": not converged in the allowed steps) and the ``steps`` taken per ray.

    >>> y, x = np.mgrid[0:5, 0:5].astype(float)
    >>> r = trace_first_root(TerrainSpline.from_heights(0 * x, "C1"), [[2.0, 2.0, 1.0]], [[0.0, 0.0, -1.0]])
    >>> r.t, r.state, r.steps   # a vertical ray onto a plane: the first step lands on it
    (array([1.]), array(['hit'], dtype='<U3'), array([2]))
    """

    t: np.ndarray
    state: np.ndarray
    steps: np.ndarray


def trace_first_root(terrain: TerrainSpline, origins, directions, *, max_steps: int = 32, exit_bound=None,
                     tol: float = 1e-12) -> TraceResult:
    """Trace rays (world coordinates; the origin must not be past the first root) to their first root.

    ``exit_bound``: None (no exit test) or the (ncy, ncx) bound G of the lifted mesh's height above the
    spline. ``tol``: a root is accepted where |g| <= tol times the heights' scale.

    Examples
    --------
    >>> y, x = np.mgrid[0:9, 0:9].astype(float)
    >>> t = TerrainSpline.from_heights(np.sin(x / 2) + np.cos(y / 3), "C1")
    >>> r = trace_first_root(t, [[1.0, 1.0, 5.0]], [[0.6, 0.48, -0.64]])
    >>> from splinevis.terrain.raycast import raycast_terrain
    >>> str(r.state[0]), bool(abs(r.t[0] - raycast_terrain(t, [[1.0, 1.0, 5.0]], [[0.6, 0.48, -0.64]]).t[0]) < 1e-9)
    ('hit', True)
    """
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    o, d = np.broadcast_arrays(o, d)
    n = len(o)
    ncy, ncx = terrain.shape
    sx, sy = terrain.cell_spacing
    P0 = np.column_stack([(o[:, 0] - terrain.origin[0]) / sx, (o[:, 1] - terrain.origin[1]) / sy, o[:, 2] - terrain.z_ref])
    D = np.column_stack([d[:, 0] / sx, d[:, 1] / sy, d[:, 2]])
    coef = terrain.coefficients
    scale = max(1.0, float(np.abs(coef).max()))
    # the terrain's box, padded in height as the program's (a root on a floor at the lowest coefficient lies on it)
    pad = 1e-6 * max(1.0, float(np.ptp(coef)))
    lo = np.array([0.0, 0.0, coef.min() - pad])
    hi = np.array([ncx, ncy, coef.max() + pad])
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (lo - P0) / D, (hi - P0) / D
        t_end = np.where(np.abs(D) < 1e-300, np.inf, np.maximum(ta, tb)).min(axis=1)
    t = np.zeros(n)
    sigma = np.zeros(n)
    inside = np.zeros(n, dtype=bool)
    state = np.full(n, "capped", dtype=object)
    steps = np.zeros(n, dtype=np.int64)
    active = np.ones(n, dtype=bool)
    dmax = np.maximum(np.abs(D[:, 0]), np.abs(D[:, 1]))
    for _ in range(max_steps):
        k = np.nonzero(active)[0]
        if not len(k):
            break
        steps[k] += 1
        tk, Dk, P0k = t[k], D[k], P0[k]
        P = P0k + tk[:, None] * Dk
        mg = np.maximum(2.0**-16, 1e-12 * (np.abs(P0k[:, :2]).max(axis=1) + np.abs(tk) * dmax[k]))
        ahead = P[:, :2] + mg[:, None] * np.sign(Dk[:, :2])
        i = np.clip(np.floor(ahead[:, 0]).astype(np.int64), 0, ncx - 1)
        j = np.clip(np.floor(ahead[:, 1]).astype(np.int64), 0, ncy - 1)
        lu, lv = P[:, 0] - i, P[:, 1] - j
        tri = (lv - lu + mg * np.sign(Dk[:, 1] - Dk[:, 0]) > 0).astype(np.int64)
        b = coef[j, i, tri]
        lam = cell_barycentric(lu, lv, tri)
        f = _simplex.de_casteljau(b, lam, d=2)
        du, dv = _DU[tri], _DV[tri]
        fu = _simplex.de_casteljau(_simplex.derivative(b, du, d=2), lam, d=2)
        fv = _simplex.de_casteljau(_simplex.derivative(b, dv, d=2), lam, d=2)
        g = P[:, 2] - f
        gp = Dk[:, 2] - (fu * Dk[:, 0] + fv * Dk[:, 1])
        w = Dk[:, :1] * du + Dk[:, 1:2] * dv
        K = np.abs(_simplex.derivative(_simplex.derivative(b, w, d=2), w, d=2)).max(axis=1)
        hit = np.abs(g) <= tol * scale
        sig = np.where(sigma[k] == 0, np.where(g > 0, 1.0, -1.0), sigma[k])
        hit |= sig * g < 0  # a sign change at a border (rounding of the next piece's value there)
        sigma[k] = sig
        if exit_bound is not None:
            G = exit_bound[j, i]
            inside[k] |= g <= G
            leave = ~hit & (sig > 0) & inside[k] & (g > G)
        else:
            leave = np.zeros(len(k), dtype=bool)
        state[k[hit]] = "hit"
        state[k[leave]] = "missed"
        go = ~hit & ~leave
        sg, sgp = sig * g, sig * gp
        with np.errstate(divide="ignore", invalid="ignore"):
            h = 2.0 * sg / np.maximum(np.sqrt(np.maximum(sgp * sgp + 2.0 * K * sg, 0.0)) - sgp, 1e-300)
            tx = np.where(np.abs(Dk[:, 0]) < 1e-300, np.inf, (np.where(Dk[:, 0] > 0, i + 1.0, i) - P0k[:, 0]) / Dk[:, 0])
            ty = np.where(np.abs(Dk[:, 1]) < 1e-300, np.inf, (np.where(Dk[:, 1] > 0, j + 1.0, j) - P0k[:, 1]) / Dk[:, 1])
            dw = Dk[:, 1] - Dk[:, 0]
            tdg = np.where(np.abs(dw) < 1e-300, np.inf, ((P0k[:, 0] - i) - (P0k[:, 1] - j)) / dw)
        border = np.minimum(tx, ty)
        border = np.where(tdg > tk, np.minimum(border, tdg), border)
        t_new = np.where(tk + h >= border, border, tk + h)
        q = P0k[:, :2] + t_new[:, None] * Dk[:, :2]
        out = go & ((t_new >= t_end[k]) | (q[:, 0] < 0) | (q[:, 1] < 0) | (q[:, 0] > ncx) | (q[:, 1] > ncy))
        state[k[out]] = "missed"
        t[k[go]] = t_new[go]
        active[k[~go | out]] = False
    t_hit = np.where(state == "hit", t, np.nan)
    return TraceResult(t_hit, state.astype(str), steps)

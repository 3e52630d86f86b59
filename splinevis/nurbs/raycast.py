"""The float64 twin of the NURBS fragment program (``glsl/programs/nurbs.glsl``) and its derived depth bound.

The GPU rasterizes a coarse tessellation whose vertices carry ``(u, v)`` and a patch id, and refines the
interpolated parameters by Newton on the pixel's ray written as two planes [Kanai2007, sec. 3.1]. Here:

* :func:`tessellate`: that tessellation (shared with ``program.py``), a shell of two layers pushed along the
  normal by a bound of the chord deviation, open edges pushed outward in the tangent plane;
* :func:`newton_on_rays`: the same clamped/wrapped Newton, vectorized, in float64;
* :func:`reference`: the robust ray cast: every crossing of the ray with a finer shell gives a start, Newton
  in float64 to convergence, the nearest converged root in the domain wins;
* :func:`depth_bound`: the derived bound on |GPU window depth - float64 window depth|.
"""

from __future__ import annotations

import numpy as np

from ..gl.contract import RayHits
from ..gl.error_bounds import U32, depth_error, model_frame_matrix
from .basis import at_fraction, into_domain
from .model import NurbsModel
from .poles import cross_pole, pole_tables
from .surface import NurbsSurface
from .tessellate import span_grid

__all__ = ["model_offset", "patch_facts", "tessellate", "newton_on_rays", "reference", "residual_tolerance",
           "depth_bound"]


def _as_model(model) -> NurbsModel:
    return NurbsModel([model]) if isinstance(model, NurbsSurface) else model


def model_offset(model) -> np.ndarray:
    """World position of the model frame's origin: the centre of the control points' box.

    >>> from splinevis.nurbs.exact import sphere
    >>> model_offset(NurbsModel([sphere(1.0, (1e6, 0, 0))])).tolist()
    [1000000.0, 0.0, 0.0]
    """
    b = np.asarray(_as_model(model).bounds()).reshape(3, 2)
    return 0.5 * (b[:, 0] + b[:, 1])


def _closed(s: NurbsSurface, axis: int) -> bool:
    (u0, u1), (v0, v1) = s.domain
    t = np.linspace(0.0, 1.0, 7)
    if axis == 0:
        a, b = s.evaluate(np.full(7, u0), at_fraction(v0, v1, t)), s.evaluate(np.full(7, u1), at_fraction(v0, v1, t))
    else:
        a, b = s.evaluate(at_fraction(u0, u1, t), np.full(7, v0)), s.evaluate(at_fraction(u0, u1, t), np.full(7, v1))
    scale = np.abs(s.control_points).max() + np.ptp(s.control_points.reshape(-1, 3), axis=0).max()
    return bool(np.abs(a - b).max() <= 1e-12 * scale)


def _poles(s: NurbsSurface) -> tuple:
    """Collapsed edges (u=lo, u=hi, v=lo, v=hi): edges whose control points coincide (a pole of a revolved
    surface)."""
    P = s.control_points
    scale = 1e-12 * (1 + np.abs(P).max())
    return tuple(bool(np.ptp(e, axis=0).max() <= scale) for e in (P[0], P[-1], P[:, 0], P[:, -1]))


def patch_facts(model) -> list:
    """Per patch: dict with ``closed`` (u, v), ``magnitude`` M = max |P - offset| * max w / min w (model frame)
    and ``knot_max`` = largest |knot|: what the float32 tolerances of the shader are built from; ``poles``: which
    edges (u=lo, u=hi, v=lo, v=hi) collapse to a point; ``pole_tables``: per edge, the antipode table of a pole
    without half-turn symmetry (:func:`splinevis.nurbs.poles.pole_tables`) or None.

    >>> from splinevis.nurbs.exact import sphere
    >>> f = patch_facts(NurbsModel([sphere()]))[0]
    >>> f["closed"], round(f["magnitude"], 6), f["knot_max"]
    ((True, False), 3.464102, 1.0)
    """
    m = _as_model(model)
    off = model_offset(m)
    out = []
    for s in m.surfaces:
        w = np.ones(s.shape) if s.weights is None else s.weights
        mag = float(np.linalg.norm(s.control_points - off, axis=-1).max() * w.max() / w.min())
        kmax = float(max(np.abs(s.knots[0]).max(), np.abs(s.knots[1]).max()))
        closed, poles = (_closed(s, 0), _closed(s, 1)), _poles(s)
        out.append({"closed": closed, "magnitude": mag, "knot_max": kmax, "poles": poles,
                    "pole_tables": pole_tables(s, closed, poles)})
    return out


def tessellate(model, subdivisions: int = 4, margin: float = 2.0, certified: bool = True):
    """The shell the GPU rasterizes: per patch, each non-empty knot span cut into ``subdivisions`` parts in u
    and v; every grid vertex carries its ``(u, v)`` and patch id.

    The chord deviation of each cell's two triangles is bounded by :func:`certified_deviation` (Bernstein
    coefficients of ``A - w L`` over the cell: an upper bound, not a sample); ``certified=False`` samples it
    instead (an 8 x 8 grid of the cell's parameters) times ``margin``. Two layers, at +dev and -dev along the unit
    normal, enclose the surface; vertices on an open patch edge also move by dev outward in the tangent plane
    (so the boundary curve's own chord deviation is covered).

    Returns ``points (N, 3)`` (model frame), ``triangles (M, 3)``, ``uv (N, 2)``, ``patch (N,)``.

    >>> from splinevis.nurbs.exact import saddle
    >>> pts, tris, uv, patch = tessellate(NurbsModel([saddle()]), 2)
    >>> pts.shape, tris.shape, sorted(set(patch.tolist()))
    ((18, 3), (16, 3), [0.0])
    """
    m = _as_model(model)
    off = model_offset(m)
    facts = patch_facts(m)
    P, T, UV, ID = [], [], [], []
    base = 0
    for k, s in enumerate(m.surfaces):
        us, vs = span_grid(s, subdivisions)
        dev = certified_deviation(s, us, vs) if certified else _chord_deviation(s, us, vs, margin)
        hu, hv = np.diff(us), np.diff(vs)
        floor = 64 * U32 * facts[k]["magnitude"]
        vdev = np.full((len(us), len(vs)), floor)
        for di in (0, 1):
            for dj in (0, 1):
                vdev[di: di + len(hu), dj: dj + len(hv)] = np.maximum(vdev[di: di + len(hu), dj: dj + len(hv)], dev + floor)
        gu, gv = np.meshgrid(us, vs, indexing="ij")
        uu, vv = gu.ravel(), gv.ravel()
        d1 = s.derivatives(uu, vv, 1)
        S = d1[:, 0, 0] - off
        n = s.normal(uu, vv)
        n = np.where(np.isfinite(n), n, 0.0)
        push = vdev.ravel()[:, None]
        side = np.zeros_like(S)
        closed_u, closed_v = facts[k]["closed"]
        for axis, closed, at in ((0, closed_u, uu), (1, closed_v, vv)):
            if closed:
                continue
            tang = d1[:, 1, 0] if axis == 0 else d1[:, 0, 1]
            size = np.linalg.norm(tang, axis=-1, keepdims=True)
            unit = np.divide(tang, size, out=np.zeros_like(tang), where=size > 0)
            lo, hi = s.domain[axis]
            for end, sign in ((lo, -1.0), (hi, 1.0)):
                on = at == end
                if np.ptp(S[on], axis=0).max() <= 1e-12 * (1 + np.abs(S).max()):
                    continue  # a collapsed edge (a pole): a point, not a boundary
                side += sign * np.where(on[:, None], unit, 0.0)
        nverts = len(uu)
        for sign in (1.0, -1.0):
            P.append(S + sign * push * n + push * side)
            UV.append(np.column_stack([uu, vv]))
            ID.append(np.full(nverts, float(k)))
            idx = base + np.arange(nverts).reshape(len(us), len(vs))
            a, b, c, e = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
            T.append(np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, e])]))
            base += nverts
    return np.concatenate(P), np.concatenate(T), np.concatenate(UV), np.concatenate(ID)


def _bernstein_collocation(n: int) -> np.ndarray:
    """Inverse of the (n+1) x (n+1) matrix of the degree-n Bernstein polynomials at the nodes k / n."""
    from math import comb

    x = np.arange(n + 1) / n
    M = np.array([[comb(n, j) * xi**j * (1 - xi) ** (n - j) for j in range(n + 1)] for xi in x])
    return np.linalg.inv(M)


def certified_deviation(s, us, vs) -> np.ndarray:
    """Per cell ``[us[i], us[i+1]] x [vs[j], vs[j+1]]``: an upper bound on the distance between the surface and
    the two triangles (diagonal from (u0, v0) to (u1, v1)) that interpolate its corners.

    On a cell (inside one knot span) the homogeneous surface ``(A, w)`` is a polynomial of bidegree (p, q); for
    a triangle's linear interpolant L, ``S - L = (A - w L) / w`` with ``A - w L`` of bidegree (p + 1, q + 1).
    Its Bernstein coefficients on the cell (from values at (p + 2) x (q + 2) nodes) bound it (convex hull:
    ``|A - w L| <= max |d_ij|``), and ``w >= min`` of w's coefficients at the same bidegree, positive for
    positive weights. So ``|S - L| <= max |d_ij| / min w_ij`` on the whole cell, a fortiori on the triangle;
    the collocation's rounding (condition ~1e3 for bidegree 8) is covered by a relative 1e-12 of the
    coordinates.

    >>> from splinevis.nurbs.exact import cylinder
    >>> s = cylinder(1.0)
    >>> us, vs = np.linspace(0, 1, 17), np.array([0.0, 1.0])
    >>> b = certified_deviation(s, us, vs)
    >>> bool((b >= _chord_deviation(s, us, vs, 1.0, k=32)).all()), round(float(b.max()), 4)
    (True, 0.0286)
    """
    (p, q) = s.degree
    gu, gv = _bernstein_collocation(p + 1), _bernstein_collocation(q + 1)
    fu, fv = np.arange(p + 2) / (p + 1), np.arange(q + 2) / (q + 1)
    nu, nv = len(us) - 1, len(vs) - 1
    uu = at_fraction(us[:-1, None], us[1:, None], fu[None, :])  # (nu, p+2), each node inside its cell
    vv = at_fraction(vs[:-1, None], vs[1:, None], fv[None, :])  # (nv, q+2)
    # keep each node inside its own cell's knot span (the right end of a span belongs to the next one)
    U, V = s.knots
    uu[:, -1] = np.nextafter(uu[:, -1], uu[:, 0])
    vv[:, -1] = np.nextafter(vv[:, -1], vv[:, 0])
    UU = np.broadcast_to(uu[:, None, :, None], (nu, nv, p + 2, q + 2)).ravel()
    VV = np.broadcast_to(vv[None, :, None, :], (nu, nv, p + 2, q + 2)).ravel()
    Aw = s._homogeneous_derivatives(UU, VV, 0)[:, 0, 0].reshape(nu, nv, p + 2, q + 2, 4)
    A, w = Aw[..., :3], Aw[..., 3]
    S = A / w[..., None]
    c00, c10, c01, c11 = S[:, :, 0, 0], S[:, :, -1, 0], S[:, :, 0, -1], S[:, :, -1, -1]
    a, b = fu[:, None, None], fv[None, :, None]  # node coordinates in the cell
    lower = c00[:, :, None, None] + a * (c10 - c00)[:, :, None, None] + b * (c11 - c10)[:, :, None, None]
    upper = c00[:, :, None, None] + a * (c11 - c01)[:, :, None, None] + b * (c01 - c00)[:, :, None, None]
    wc = np.einsum("ik,jl,xykl->xyij", gu, gv, w)  # Bernstein coefficients of w at bidegree (p+1, q+1)
    wmin = wc.min(axis=(2, 3))
    if (wmin <= 0).any():
        raise ValueError(f"{s.name or 'patch'}: a cell's weights are not all positive; cannot bound its chord.")
    bound = np.zeros((nu, nv))
    for L in (lower, upper):
        d = np.einsum("ik,jl,xyklc->xyijc", gu, gv, A - w[..., None] * L)
        bound = np.maximum(bound, np.linalg.norm(d, axis=-1).max(axis=(2, 3)) / wmin)
    size = np.abs(S).max(axis=(2, 3, 4))
    return bound + 1e-12 * size


def _chord_deviation(s, us, vs, margin, k=8):
    """Per cell: ``margin`` times the largest distance, over a k x k sample of the cell, between the surface and
    the two triangles (diagonal from (u0, v0) to (u1, v1)) that interpolate its corners."""
    f = np.arange(k + 1) / k
    uf = np.append((us[:-1, None] + f[:-1] * np.diff(us)[:, None]).ravel(), us[-1])
    vf = np.append((vs[:-1, None] + f[:-1] * np.diff(vs)[:, None]).ravel(), vs[-1])
    gu, gv = np.meshgrid(uf, vf, indexing="ij")
    S = s.evaluate(gu.ravel(), gv.ravel()).reshape(len(uf), len(vf), 3)
    nu, nv = len(us) - 1, len(vs) - 1
    cells = np.lib.stride_tricks.sliding_window_view(S, (k + 1, k + 1), axis=(0, 1))[::k, ::k]  # (nu, nv, 3, k+1, k+1)
    cells = np.moveaxis(cells, 2, -1)
    p00, p10, p01, p11 = cells[:, :, :1, :1], cells[:, :, -1:, :1], cells[:, :, :1, -1:], cells[:, :, -1:, -1:]
    a, b = f[:, None, None], f[None, :, None]
    lower = p00 + a * (p10 - p00) + b * (p11 - p10)  # a >= b: triangle (00, 10, 11)
    upper = p00 + a * (p11 - p01) + b * (p01 - p00)  # a < b: triangle (00, 11, 01)
    lin = np.where(a >= b, lower, upper)
    return margin * np.linalg.norm(cells - lin, axis=-1).reshape(nu, nv, -1).max(axis=-1)


#: Fraction of the way to an open edge a Newton step that would leave the domain goes (never onto the edge:
#: a collapsed edge, a pole, has S_u = 0 and would stop the iteration).
EDGE_STEP = 0.5


def _step(s, closed, poles, x, step, tables=(None,) * 4):
    """x - lambda step, lambda <= 1 the largest that goes at most EDGE_STEP of the way to an open edge; a step
    over a pole of a patch closed in the other parameter continues on the far side of the pole: on the meridian
    half a turn on where the pole has half-turn symmetry (no table), else on the antipodal meridian t' of the
    step's end t_e at rho times its distance beyond the pole (:func:`splinevis.nurbs.poles.cross_pole`)."""
    lam = np.ones(len(x))
    x, step = x.copy(), step.copy()
    for axis in (0, 1):
        if closed[axis]:
            continue
        lo, hi = s.domain[axis]
        new = x[:, axis] - step[:, axis]
        other = 1 - axis
        if closed[other]:  # across a pole of a patch closed the other way: over the pole, on the far side
            half = 0.5 * (s.domain[other][1] - s.domain[other][0])
            for end, edge in ((lo, 2 * axis), (hi, 2 * axis + 1)):
                over = ((new < lo) if end == lo else (new > hi)) & poles[edge]
                if tables[edge] is None:  # half-turn symmetry: exact as it stands
                    x[over, axis] = 2 * end - x[over, axis]
                    step[over, axis] *= -1
                    x[over, other] += half
                elif over.any():  # x' - step' = (t', end + rho (end - new)): t' = antipode of the step's end
                    tp, rho = cross_pole(s, edge, tables[edge], x[over, other] - step[over, other])
                    x[over, axis] = end + (end - x[over, axis]) * rho
                    step[over, axis] *= -rho
                    x[over, other] = tp + step[over, other]
            new = x[:, axis] - step[:, axis]
        with np.errstate(divide="ignore", invalid="ignore"):
            lam = np.where(new < lo, np.minimum(lam, EDGE_STEP * (x[:, axis] - lo) / (x[:, axis] - new)), lam)
            lam = np.where(new > hi, np.minimum(lam, EDGE_STEP * (hi - x[:, axis]) / (new - x[:, axis])), lam)
    return _into_domain(s, closed, x - lam[:, None] * step)


def _into_domain(s, closed, uv):
    (u0, u1), (v0, v1) = s.domain
    u, v = uv[:, 0].copy(), uv[:, 1].copy()
    if closed[0]:
        u = u0 + np.mod(u - u0, u1 - u0)
    if closed[1]:
        v = v0 + np.mod(v - v0, v1 - v0)
    return np.column_stack([into_domain(u, u0, u1), into_domain(v, v0, v1)])


def _planes(d):
    rd = d / np.linalg.norm(d, axis=-1, keepdims=True)
    ax = np.where((np.abs(rd[:, 0]) < 0.57735)[:, None], [1.0, 0, 0],
                  np.where((np.abs(rd[:, 1]) < 0.57735)[:, None], [0, 1.0, 0], [0, 0, 1.0]))
    n1 = np.cross(rd, ax)
    n1 /= np.linalg.norm(n1, axis=-1, keepdims=True)
    return rd, n1, np.cross(rd, n1)


def newton_on_rays(model, patch, uv, origins, directions, iterations: int, *, settle: bool = False):
    """The fragment program's Newton in float64: ``iterations`` steps on F(u, v) = (n1 . (S - o), n2 . (S - o))
    from ``uv``, kept in each patch's domain (wrapped across closed seams, clamped at open edges).

    ``settle=True`` (the float64 reference, not the shader's twin): a ray stops once a step moves neither
    parameter by more than 4 eps of its size (the iterate is a fixed point up to rounding; further steps
    only dither it by rounding), so converged rays do not pay for the remaining steps.

    ``origins`` are model-frame (world minus :func:`model_offset`). Returns ``uv (n, 2)``, the residual |F|
    ``(n,)`` and ``derivatives (n, 2, 2, 3)`` (S, S_u, S_v with S model frame) at the result.

    >>> from splinevis.nurbs.exact import sphere
    >>> m = NurbsModel([sphere()])
    >>> uv, res, d = newton_on_rays(m, np.zeros(1), np.array([[0.1, 0.45]]), np.array([[5.0, 0, 0.1]]),
    ...                             np.array([[-1.0, 0, 0]]), 8)
    >>> np.round(d[0, 0, 0], 12).tolist(), bool(res[0] < 1e-14)
    ([0.994987437107, 0.0, 0.1], True)
    """
    m = _as_model(model)
    off = model_offset(m)
    facts = patch_facts(m)
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    rd, n1, n2 = _planes(np.asarray(directions, dtype=np.float64).reshape(-1, 3))
    patch = np.asarray(patch).astype(int).ravel()
    uv = np.array(uv, dtype=np.float64).reshape(-1, 2)
    res = np.full(len(uv), np.inf)
    der = np.full((len(uv), 2, 2, 3), np.nan)
    for k, s in enumerate(m.surfaces):
        sel = np.flatnonzero(patch == k)
        if not sel.size:
            continue
        closed, poles, tables = facts[k]["closed"], facts[k]["poles"], facts[k]["pole_tables"]
        x = _into_domain(s, closed, uv[sel])
        a1, a2, oo = n1[sel], n2[sel], o[sel]
        live = np.arange(len(sel))  # rays still iterating (all of them unless settle)
        for _ in range(iterations):
            if not live.size:
                break
            xl, b1, b2 = x[live], a1[live], a2[live]
            d = s.derivatives(xl[:, 0], xl[:, 1], 1)
            e = d[:, 0, 0] - off - oo[live]
            F = np.stack([np.einsum("ij,ij->i", b1, e), np.einsum("ij,ij->i", b2, e)], axis=-1)
            j11, j12 = np.einsum("ij,ij->i", b1, d[:, 1, 0]), np.einsum("ij,ij->i", b1, d[:, 0, 1])
            j21, j22 = np.einsum("ij,ij->i", b2, d[:, 1, 0]), np.einsum("ij,ij->i", b2, d[:, 0, 1])
            det = j11 * j22 - j12 * j21
            ok = det != 0
            safe = np.where(ok, det, 1.0)
            step = np.stack([j22 * F[:, 0] - j12 * F[:, 1], -j21 * F[:, 0] + j11 * F[:, 1]], axis=-1) / safe[:, None]
            x[live] = np.where(ok[:, None], _step(s, closed, poles, xl, step, tables), xl)
            if settle:
                moved = np.abs(x[live] - xl) > 4 * np.finfo(np.float64).eps * np.maximum(np.abs(xl), 1.0)
                live = live[ok & moved.any(axis=1)]
        d = s.derivatives(x[:, 0], x[:, 1], 1)
        d[:, 0, 0] -= off
        e = d[:, 0, 0] - oo
        res[sel] = np.hypot(np.einsum("ij,ij->i", a1, e), np.einsum("ij,ij->i", a2, e))
        uv[sel], der[sel] = x, d[:, :2, :2]
    return uv, res, der


def _candidates(o, d, tri_pts):
    """(ray, triangle) pairs whose ray may cross the triangle: VTK's BSP tree (vtkModifiedBSPTree) finds the
    triangles each ray's segment through the shell's bounding box meets (with a tolerance of 1e-7 of the box),
    instead of testing every ray against every triangle."""
    import vtk
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray

    n = len(tri_pts)
    poly = vtk.vtkPolyData()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(tri_pts.reshape(-1, 3)), deep=True))
    cells = vtk.vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(np.arange(0, 3 * n + 1, 3, dtype=np.int64), deep=True),
                  numpy_to_vtkIdTypeArray(np.arange(3 * n, dtype=np.int64), deep=True))
    poly.SetPoints(pts)
    poly.SetPolys(cells)
    tree = vtk.vtkModifiedBSPTree()
    tree.SetDataSet(poly)
    tree.BuildLocator()
    lo, hi = tri_pts.reshape(-1, 3).min(axis=0), tri_pts.reshape(-1, 3).max(axis=0)
    size = float(np.linalg.norm(hi - lo)) or 1.0
    lo, hi = lo - 1e-6 * size, hi + 1e-6 * size
    with np.errstate(divide="ignore", invalid="ignore"):  # the segment of each line inside the box (slabs)
        ta, tb = (lo - o) / d, (hi - o) / d
        t0 = np.nanmax(np.where(d != 0, np.minimum(ta, tb), -np.inf), axis=1)
        t1 = np.nanmin(np.where(d != 0, np.maximum(ta, tb), np.inf), axis=1)
    inside = (d == 0) & ((o < lo) | (o > hi))
    use = (t0 <= t1) & ~inside.any(axis=1)
    p1, p2 = o + t0[:, None] * d, o + t1[:, None] * d
    hit_pts, ids = vtk.vtkPoints(), vtk.vtkIdList()
    rays, tris = [], []
    for r in np.flatnonzero(use):
        tree.IntersectWithLine(p1[r].tolist(), p2[r].tolist(), 1e-7 * size, hit_pts, ids)
        k = ids.GetNumberOfIds()
        if k:
            rays.append(np.full(k, r))
            tris.append([ids.GetId(i) for i in range(k)])
    if not rays:
        return np.zeros(0, int), np.zeros(0, int)
    return np.concatenate(rays), np.concatenate(tris).astype(int)


def _ray_triangles(o, d, tri_pts):
    """All crossings (ray index, triangle index, b1, b2) of rays with triangles (Moller-Trumbore on the
    candidate pairs of :func:`_candidates`)."""
    r, t = _candidates(o, d, tri_pts)
    A, B, C = tri_pts[t, 0], tri_pts[t, 1], tri_pts[t, 2]
    e1, e2 = B - A, C - A
    dd = d[r]
    pv = np.cross(dd, e2)
    det = np.einsum("ik,ik->i", pv, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        tv = o[r] - A
        b1 = np.einsum("ik,ik->i", tv, pv) * inv
        b2 = np.einsum("ik,ik->i", np.cross(tv, e1), dd) * inv
        tol = 1e-9
        ok = (det != 0) & (b1 >= -tol) & (b2 >= -tol) & (b1 + b2 <= 1 + tol)
    return r[ok], t[ok], b1[ok], b2[ok]


def _cast(model, origins, directions, tmin, iterations, subdivisions, gpu):
    m = _as_model(model)
    off = model_offset(m)
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3) - off
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    shells = [tessellate(m, sub) for sub in ((subdivisions,) if gpu else (4, subdivisions))]
    pts = np.concatenate([sh[0] for sh in shells])
    shift = np.cumsum([0] + [len(sh[0]) for sh in shells[:-1]])
    tris = np.concatenate([sh[1] + k for sh, k in zip(shells, shift)])
    uvs, ids = np.concatenate([sh[2] for sh in shells]), np.concatenate([sh[3] for sh in shells])
    r, ti, b1, b2 = _ray_triangles(o, d, pts[tris])
    uv0 = (1 - b1 - b2)[:, None] * uvs[tris[ti, 0]] + b1[:, None] * uvs[tris[ti, 1]] + b2[:, None] * uvs[tris[ti, 2]]
    pid = ids[tris[ti, 0]].astype(int)
    uv, res, der = newton_on_rays(m, pid, uv0, o[r], d[r], iterations, settle=not gpu)
    S = der[:, 0, 0]
    t = np.einsum("ij,ij->i", S - o[r], d[r]) / np.einsum("ij,ij->i", d[r], d[r])
    if gpu:
        facts = patch_facts(m)
        E = np.linalg.norm(pts, axis=-1).max()
        tol = np.zeros(len(pid))
        for k, s in enumerate(m.surfaces):
            sel = pid == k
            tol[sel] = residual_tolerance(s, facts[k], der[sel, 1, 0], der[sel, 0, 1], E)
    else:
        tol = 1e-9 * (np.abs(S).max(axis=-1, initial=0) + np.abs(o[r]).max(axis=-1) + 1.0)
    good = (res <= tol) & (t >= tmin)
    if any(tr is not None for tr in m.trims):  # trimmed away: not a hit; the next root along the ray may be
        from .trim import inside, trim_pieces

        pieces = trim_pieces(m.trims)
        for k in range(len(m.surfaces)):
            sel = np.flatnonzero(good & (pid == k))
            if sel.size and pieces.count[k]:
                good[sel] = inside(pieces, k, uv[sel, 0], uv[sel, 1])
    n = len(o)
    t_out, pid_out, uv_out = np.full(n, np.nan), np.full(n, -1), np.full((n, 2), np.nan)
    idx = np.flatnonzero(good)
    order = idx[np.lexsort((t[idx], r[idx]))]
    first = order[np.r_[True, r[order][1:] != r[order][:-1]]] if order.size else order
    t_out[r[first]], pid_out[r[first]], uv_out[r[first]] = t[first], pid[first], uv[first]
    return t_out, pid_out, uv_out


def reference(model, origins, directions, tmin=0.0, *, method="reference", iterations=None):
    """Float64 ray cast of a NURBS model (world rays of any leading shape): :class:`RayHits`.

    ``method="reference"``: every crossing of the ray with the GPU's shell (8 subdivisions per knot span, the
    default) and a coarser one (4) starts a
    float64 Newton of 40 steps; the nearest root with residual below 1e-9 of the coordinates' size wins.
    ``method="newton"``: the GPU's way: every crossing of the GPU's shell (a fragment each) starts
    ``iterations`` steps, the shader's residual test accepts, the nearest accepted wins (the depth test).

    >>> from splinevis.nurbs.exact import sphere
    >>> h = reference(NurbsModel([sphere()]), [[0.0, 0.0, 5.0], [3.0, 3.0, 5.0]], [[0.0, 0.1, -1.0], [0, 0, -1.0]])
    >>> np.round(h.t, 9).tolist()[0], bool(h.hit[1])
    (4.087346744, False)
    """
    m = _as_model(model)
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    shape = o.shape[:-1]
    if method == "reference":
        t, pid, uv = _cast(m, o, d, tmin, 40, 8, False)
    elif method == "newton":
        t, pid, uv = _cast(m, o, d, tmin, 12 if iterations is None else iterations, 8, True)
    else:
        raise ValueError(f"method must be 'reference' or 'newton', got {method!r}.")
    o2, d2 = o.reshape(-1, 3), d.reshape(-1, 3)
    points = o2 + t[:, None] * d2
    normals = np.full_like(points, np.nan)
    for k, s in enumerate(m.surfaces):
        sel = np.flatnonzero(pid == k)
        if sel.size:
            normals[sel] = s.normal(uv[sel, 0], uv[sel, 1])
    return RayHits(t.reshape(shape), points.reshape(shape + (3,)), normals.reshape(shape + (3,)))


def residual_tolerance(surface, facts, Su, Sv, ray_origin_size):
    """The shader's acceptance threshold on |F| (``glsl/programs/nurbs.glsl``), in model units.

    The float32 error of S: the basis functions (p levels of Cox-de Boor, a few roundings each) and the two
    tensor sums of (p+1)(q+1) terms with non-negative weights give |fl(A) - A| <= gamma_{c(p+q)} sum N_a N_b |Pw|
    (Higham-style, c ~ 3 with the quotient by w), and sum N_a N_b |Pw| / sum N_a N_b w <= M; knots rounded to
    float32 move the basis as a parameter change of u |U|max: eps_S = (6 (p+q) + 8) u M + u |U|max (|S_u| + |S_v|).
    The residual's own evaluation (S - ro and two dot products) adds 8 u (M + |ro|). Threshold: twice the sum.

    >>> from splinevis.nurbs.exact import saddle
    >>> s = saddle()
    >>> f = patch_facts(NurbsModel([s]))[0]
    >>> round(float(residual_tolerance(s, f, np.zeros(3), np.zeros(3), 1.0) / U32), 3)
    194.885
    """
    return 2.0 * (_eps_s(surface, facts, Su, Sv) + 8.0 * U32 * (facts["magnitude"] + ray_origin_size))


def _eps_s(surface, facts, Su, Sv):
    p, q = surface.degree
    size = np.linalg.norm(Su, axis=-1) + np.linalg.norm(Sv, axis=-1)
    return (6 * (p + q) + 8) * U32 * facts["magnitude"] + U32 * facts["knot_max"] * size


def depth_bound(model, matrix, origins, directions, t):
    """Per-pixel bound on |GPU window depth - float64 window depth| at hits ``origins + t directions``.

    Derivation (float32, u = 2^-24): the GPU accepts S(u, v) when the residual |F| (the distance of S from the
    ray, measured in the two planes) is below tol (:func:`residual_tolerance`); S itself is off by eps_S and the
    ray (origin on the shell, rounded to 4 u E for the shell's size E, direction normalized: 3 u per unit
    travelled) by eps_r = 8 u E. So S lies within delta = tol + eps_S + eps_r of the exact ray. Where the unit
    normal makes the angle with cosine c with the ray, a point of the surface at distance delta from the ray is
    within delta / c of the true hit along the ray (first order; near-tangential rays grow as the problem's
    condition), and within D = delta (1 + 1/c) + eps_S of the hit in space. Window depth changes at most
    |d depth / dt| / cos(theta) per unit of distance, theta the angle of the ray with the view axis (depth is a
    function of view z only): D / cos(theta) / |d| as the ray-parameter error in
    :func:`splinevis.gl.error_bounds.depth_error`, which adds the clip-space arithmetic and quantization.

    >>> from splinevis.nurbs.exact import sphere
    >>> m = NurbsModel([sphere()])
    >>> b = depth_bound(m, np.eye(4), np.array([[0.0, 0.0, -5.0]]), np.array([[0.0, 0.0, 1.0]]), np.array([4.0]))
    >>> bool(0 < b[0] < 1e-4)  # a few hundred u: a well-conditioned hit at the pole
    True
    """
    m = _as_model(model)
    off = model_offset(m)
    facts = patch_facts(m)
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    t = np.asarray(t, dtype=np.float64).ravel()
    _, pid, uv = _cast(m, o + (t - 1e-3 * np.abs(t) - 1e-9)[:, None] * d, d, 0.0, 40, 8, False)
    pts = tessellate(m)[0]
    E = float(np.linalg.norm(pts, axis=-1).max())
    rd = d / np.linalg.norm(d, axis=-1, keepdims=True)
    D = np.zeros(len(o))
    for k, s in enumerate(m.surfaces):
        sel = np.flatnonzero(pid == k)
        if not sel.size:
            continue
        der = s.derivatives(uv[sel, 0], uv[sel, 1], 1)
        n = s.normal(uv[sel, 0], uv[sel, 1])
        c = np.maximum(np.abs(np.einsum("ij,ij->i", n, rd[sel])), 1e-6)
        Su, Sv = der[:, 1, 0], der[:, 0, 1]
        eps_s = _eps_s(s, facts[k], Su, Sv)
        delta = residual_tolerance(s, facts[k], Su, Sv, E) + eps_s + 8 * U32 * E
        D[sel] = delta * (1 + 1 / c) + eps_s
    mm = model_frame_matrix(matrix, off)
    axis = np.asarray(matrix, dtype=np.float64)[3, :3]
    cos = np.abs(rd @ axis) / np.linalg.norm(axis) if np.linalg.norm(axis) > 0 else np.ones(len(o))
    dt = D / np.maximum(cos, 0.1) / np.linalg.norm(d, axis=-1)
    h = 1e-6 * np.maximum(1.0, np.abs(t))
    return depth_error(mm, o - off, d, t, h, dt)

"""The float64 twin of the NURBS fragment program (``glsl/programs/nurbs.glsl``) and its derived depth bound.

The GPU rasterizes a coarse tessellation whose vertices carry ``(u, v)`` and a patch id, and refines the
interpolated parameters by Newton on the pixel's ray written as two planes [Kanai2007, sec. 3.1]. Here:

* the tessellation itself (shared with ``program.py``) is :func:`splinevis.nurbs.shell.tessellate`;
* :func:`newton_on_rays`: the same clamped/wrapped Newton, vectorized, in float64;
* :func:`reference`: the robust ray cast: every crossing of the ray with a finer shell gives a start, Newton
  in float64 to convergence, the nearest converged root in the domain wins;
* :func:`depth_bound`: the derived bound on |GPU window depth - float64 window depth|.
"""

from __future__ import annotations

import numpy as np

from ..gl.contract import RayHits
from ..gl.error_bounds import U32, depth_error, model_frame_matrix
from .basis import into_domain
from .poles import cross_pole
from .shell import _as_model, model_offset, patch_facts, tessellate

__all__ = ["newton_on_rays", "reference", "residual_tolerance", "depth_bound"]


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
    >>> from splinevis.nurbs.model import NurbsModel
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
    # the GPU's own shell (adaptive) for its twin; the reference starts from the uniform 4 and 8 per span
    shells = [tessellate(m, sub, adaptive=gpu) for sub in ((subdivisions,) if gpu else (4, subdivisions))]
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
    >>> from splinevis.nurbs.model import NurbsModel
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
    # each hit's patch and (u, v): what depth_bound needs at the hits (RayHits.surface), so it need not cast again
    surface = {"patch": pid.reshape(shape), "uv": uv.reshape(shape + (2,))}
    return RayHits(t.reshape(shape), points.reshape(shape + (3,)), normals.reshape(shape + (3,)), surface)


def residual_tolerance(surface, facts, Su, Sv, ray_origin_size):
    """The shader's acceptance threshold on |F| (``glsl/programs/nurbs.glsl``), in model units.

    The float32 error of S: the basis functions (p levels of Cox-de Boor, a few roundings each) and the two
    tensor sums of (p+1)(q+1) terms with non-negative weights give |fl(A) - A| <= gamma_{c(p+q)} sum N_a N_b |Pw|
    (Higham-style, c ~ 3 with the quotient by w), and sum N_a N_b |Pw| / sum N_a N_b w <= M; knots rounded to
    float32 move the basis as a parameter change of u |U|max: eps_S = (6 (p+q) + 8) u M + u |U|max (|S_u| + |S_v|).
    The residual's own evaluation (S - ro and two dot products) adds 8 u (M + |ro|). Threshold: twice the sum.

    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.model import NurbsModel
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


def depth_bound(model, matrix, origins, directions, t, *, surface=None):
    """Per-pixel bound on |GPU window depth - float64 window depth| at hits ``origins + t directions``; ``surface``:
    the hits' ``patch`` and ``uv`` (:meth:`~splinevis.gl.contract.RayHits.surface_at` of the :func:`reference` cast
    that found them; without it, or where a patch is -1, each ray is cast again from just before its hit).

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
    >>> from splinevis.nurbs.model import NurbsModel
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
    # the patch and (u, v) of each hit: those of the reference cast that found it, else cast again from just
    # before the hit (the first root after that start is the hit)
    if surface is not None:
        pid = np.array(surface["patch"], dtype=np.int64).reshape(-1)
        uv = np.array(surface["uv"], dtype=np.float64).reshape(-1, 2)
        if len(pid) != len(o) or len(uv) != len(o):
            raise ValueError(f"surface has {len(pid)} patches and {len(uv)} (u, v) for {len(o)} rays: pass "
                             "RayHits.surface_at of the same rays as origins, directions and t.")
    else:
        pid, uv = np.full(len(o), -1, dtype=np.int64), np.full((len(o), 2), np.nan)
    again = np.flatnonzero(pid < 0)
    if again.size:
        oa, da, ta = o[again], d[again], t[again]
        _, pid[again], uv[again] = _cast(m, oa + (ta - 1e-3 * np.abs(ta) - 1e-9)[:, None] * da, da, 0.0, 40, 8, False)
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

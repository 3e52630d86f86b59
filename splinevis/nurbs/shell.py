"""The proxy shell the NURBS fragment program rasterizes, and the per-patch facts its tolerances come from.

The GPU draws a coarse tessellation of each patch whose vertices carry ``(u, v)`` and a patch id; the fragment
program refines the interpolated parameters by Newton on the pixel's ray [Kanai2007, sec. 3.1]. For every
root to be found from a start inside its cell, the shell must enclose the surface: two layers pushed along the
normal by a certified bound of the chord deviation (Bernstein coefficients of ``A - w L`` over each cell,
[Farin2002, sec. 5.5] convex-hull property), open edges pushed outward in the tangent plane. Straight spans
(planes, rulings) take one cell (:func:`shell_grid`). The ray cast itself is in ``raycast.py``.
"""

from __future__ import annotations

import weakref

import numpy as np

from ..gl.error_bounds import U32
from .basis import at_fraction
from .model import NurbsModel
from .poles import pole_tables
from .surface import NurbsSurface
from .tessellate import span_grid

__all__ = ["model_offset", "patch_facts", "span_turning", "span_affine", "shell_grid", "tessellate", "certified_deviation",
           "STRAIGHT"]


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
    return _closed_both(s)[axis]


def _closed_both(s: NurbsSurface) -> tuple:
    """Closed in u, closed in v: the opposite edges agree at 7 parameters to 1e-12 of the net's size (both
    directions' 28 points in one evaluation)."""
    (u0, u1), (v0, v1) = s.domain
    t = np.linspace(0.0, 1.0, 7)
    tv, tu = at_fraction(v0, v1, t), at_fraction(u0, u1, t)
    uu = np.concatenate([np.full(7, u0), np.full(7, u1), tu, tu])
    vv = np.concatenate([tv, tv, np.full(7, v0), np.full(7, v1)])
    x = s.evaluate(uu, vv).reshape(4, 7, 3)
    scale = np.abs(s.control_points).max() + np.ptp(s.control_points.reshape(-1, 3), axis=0).max()
    return bool(np.abs(x[0] - x[1]).max() <= 1e-12 * scale), bool(np.abs(x[2] - x[3]).max() <= 1e-12 * scale)


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
    cached = _FACTS.get(m)
    if cached is not None:  # a model is immutable: the program build asks three times (tables, shell, defines)
        return list(cached)
    off = model_offset(m)
    out = []
    for s in m.surfaces:
        w = np.ones(s.shape) if s.weights is None else s.weights
        mag = float(np.linalg.norm(s.control_points - off, axis=-1).max() * w.max() / w.min())
        kmax = float(max(np.abs(s.knots[0]).max(), np.abs(s.knots[1]).max()))
        closed, poles = _closed_both(s), _poles(s)
        out.append({"closed": closed, "magnitude": mag, "knot_max": kmax, "poles": poles,
                    "pole_tables": pole_tables(s, closed, poles)})
    _FACTS[m] = tuple(out)
    return out


_FACTS = weakref.WeakKeyDictionary()  # NurbsModel -> its patch facts (models are frozen; surfaces immutable)


def span_turning(s: NurbsSurface, axis: int) -> np.ndarray:
    """Per non-empty knot span along ``axis`` (0: u, 1: v): an upper bound (radians, at most pi) on the angle
    through which the isoparametric curves' tangents turn inside the span.

    On a span the tangent of a (rational, positive weights) isoparametric curve is a non-negative combination
    of the legs ``P[a+1] - P[a]`` of the span's control rows (for a Bezier curve ``C' = sum_{i<j} c_ij
    (P_j - P_i)`` with ``c_ij = w_i w_j (B_j' B_i - B_j B_i') / W^2 >= 0``; knot insertion makes the Bezier legs
    non-negative combinations of the de Boor legs; across the other direction's span the curve's legs are
    convex combinations of its columns' legs when the weights are a product, as in revolved and extruded
    surfaces). So all tangents lie in the cone of those legs; with ``m`` the sum of the legs' unit vectors the
    cone's angular diameter is at most ``2 max angle(e, m)`` (pi when ``m`` vanishes). A curve that turns back
    and forth (a bumpy high-degree span) stays inside a narrow cone: the total turning of each column's control
    polygon (the sum of the angles between consecutive legs, which bounds the curve's own) counts too, the
    larger of the two is returned. Zero legs (a pole's collapsed row) point nowhere and are left out; the
    bound per span is the largest over the other direction's spans.

    >>> from splinevis.nurbs.exact import cylinder
    >>> np.degrees(span_turning(cylinder(), 0)).round(6).tolist(), span_turning(cylinder(), 1).tolist()
    ([90.0, 90.0, 90.0, 90.0], [0.0])
    """
    P = np.moveaxis(s.control_points, axis, 0)  # rows along axis
    p, q = s.degree[axis], s.degree[1 - axis]
    U, V = s.knots[axis], s.knots[1 - axis]
    nu, nv = P.shape[:2]
    legs = P[1:] - P[:-1]  # (nu - 1, nv, 3)
    size = np.linalg.norm(legs, axis=-1)
    tiny = 1e-12 * (1.0 + np.abs(P).max())
    unit = np.divide(legs, size[..., None], out=np.zeros_like(legs), where=(size > tiny)[..., None])
    iu = np.flatnonzero(U[p:nu] < U[p + 1: nu + 1]) + p  # non-empty spans: U[i] < U[i+1], p <= i < nu
    iv = np.flatnonzero(V[q:nv] < V[q + 1: nv + 1]) + q
    rows = iu[:, None] - p + np.arange(p)  # legs a = i-p .. i-1 (between rows i-p .. i)
    cols = iv[:, None] - q + np.arange(q + 1)  # columns j-q .. j
    e = unit[rows[:, None, :, None], cols[None, :, None, :]]  # (spans, other spans, p, q + 1, 3)
    e = e.reshape(len(iu), len(iv), -1, 3)
    m = e.sum(axis=2)
    mn = np.linalg.norm(m, axis=-1)
    valid = np.linalg.norm(e, axis=-1) > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.einsum("ijkc,ijc->ijk", e, m) / mn[..., None]
    cos = np.where(valid, np.clip(cos, -1.0, 1.0), 1.0)
    angle = np.minimum(2.0 * np.arccos(cos.min(axis=2)), np.pi)
    angle = np.where((mn > 1e-9) | ~valid.any(axis=2), angle, np.pi)  # opposite legs cancel: a full turn
    # a curve that turns back and forth stays in a narrow cone: count its total turning too, the sum of the
    # angles between consecutive legs of each column (a Bezier curve turns at most as much as its polygon)
    turn = np.zeros(len(iu))
    if p >= 2:
        col = unit[rows]  # (spans, p, nv, 3)
        dots = np.clip(np.einsum("spvc,spvc->spv", col[:, 1:], col[:, :-1]), -1.0, 1.0)
        both = (np.linalg.norm(col[:, 1:], axis=-1) > 0) & (np.linalg.norm(col[:, :-1], axis=-1) > 0)
        turn = np.minimum(np.where(both, np.arccos(dots), 0.0).sum(axis=1).max(axis=1), np.pi)
    return np.maximum(angle.max(axis=1), turn)


def span_affine(s: NurbsSurface, axis: int) -> np.ndarray:
    """Per non-empty knot span along ``axis``: True where every isoparametric curve along ``axis`` is an affine
    function of the parameter there (a sufficient test: each column's control points of the span are
    ``A + B xi`` at their Greville abscissae ``xi``, to 1e-9 of the net's size, so the curve is ``A + B t`` by
    linear precision, ``sum_i N_i(t) xi_i = t``; and the weights are constant along ``axis``, so they cancel).

    >>> from splinevis.nurbs.exact import cylinder
    >>> span_affine(cylinder(), 1).tolist()  # the rulings: two control rows, a line at constant speed
    [True]
    """
    P = np.moveaxis(s.control_points, axis, 0)
    p, U = s.degree[axis], s.knots[axis]
    nu = P.shape[0]
    iu = np.flatnonzero(U[p:nu] < U[p + 1: nu + 1]) + p
    xi = np.array([U[i + 1: i + p + 1].mean() for i in range(nu)])  # Greville abscissae
    rows = iu[:, None] - p + np.arange(p + 1)
    X = xi[rows]
    dx = X - X.mean(axis=1, keepdims=True)
    Q = P[rows]  # (spans, p + 1, other, 3)
    dQ = Q - Q.mean(axis=1, keepdims=True)
    ss = (dx**2).sum(axis=1)
    B = np.einsum("sk,skvc->svc", dx, dQ) / np.where(ss > 0, ss, 1.0)[:, None, None]
    resid = np.abs(dQ - dx[:, :, None, None] * B[:, None]).max(axis=(1, 2, 3))
    ok = (resid <= 1e-9 * (1.0 + np.abs(P).max())) & (ss > 0)
    if s.weights is not None:
        W = np.moveaxis(s.weights, axis, 0)[rows]  # (spans, p + 1, other)
        ok &= np.ptp(W, axis=1).max(axis=1) <= 1e-12 * W.max()
    return ok


#: Turning (radians) up to which a knot span counts as straight in the adaptive shell (:func:`shell_grid`): the
#: precision of the bound's arccos near 1 (~1e-8) with room to spare.
STRAIGHT = 1e-6


def shell_grid(s: NurbsSurface, subdivisions: int) -> tuple:
    """Parameter lines ``(us, vs)`` of the GPU shell: each non-empty knot span cut into ``subdivisions`` parts
    as :func:`splinevis.nurbs.tessellate.span_grid` does, except where its curves are straight lines traced
    at constant speed (:func:`span_turning` at most STRAIGHT and :func:`span_affine`: planes, the rulings of
    cylinders, cones and extrusions as CAD systems write them): one cell there. There the cell's linear
    interpolation of the parameter is the exact parameter along that direction, and a ray cannot meet a line
    twice. A straight span traced at varying speed keeps its cells (a fuselage's rulings whose control points
    bunch up 7 : 1: one cell there started Newton so far off that stripes of pixels found no hit within the
    shader's steps). On llvmpipe every small triangle costs the
    fragment program of a whole 4 x 4 pixel block, so a plane drawn as 8 x 8 cells (256 triangles in two
    layers) costs far more than its 4 triangles. Curved spans keep all their cells: cutting a span that turns
    only 10 degrees into 2 instead of 8 cells already loses the nearer of two roots of grazing rays (a dark
    seam pixel on the cornetta part where the finer shell found the front hit).

    >>> from splinevis.nurbs.exact import cylinder
    >>> us, vs = shell_grid(cylinder(), 2)
    >>> us.tolist(), vs.tolist()
    ([0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0], [0.0, 1.0])
    """
    out = []
    for axis in (0, 1):
        knots, (lo, hi) = s.knots[axis], s.domain[axis]
        k = np.unique(knots[(knots >= lo) & (knots <= hi)])
        turn = span_turning(s, axis)
        n = np.where((turn <= STRAIGHT) & span_affine(s, axis), 1, subdivisions)
        out.append(np.concatenate([at_fraction(a, b, np.linspace(0.0, 1.0, c + 1)[:-1])
                                   for a, b, c in zip(k[:-1], k[1:], n)] + [[hi]]))
    return tuple(out)


def tessellate(model, subdivisions: int = 4, margin: float = 2.0, certified: bool = True, adaptive: bool = False):
    """The shell the GPU rasterizes: per patch, each non-empty knot span cut into ``subdivisions`` parts in u
    and v (``adaptive=True``: as many as the span's turn needs, at most ``subdivisions``: :func:`shell_grid`);
    every grid vertex carries its ``(u, v)`` and patch id.

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
        us, vs = shell_grid(s, subdivisions) if adaptive else span_grid(s, subdivisions)
        dev = certified_deviation(s, us, vs) if certified else _chord_deviation(s, us, vs, margin)
        hu, hv = np.diff(us), np.diff(vs)
        floor = 64 * U32 * facts[k]["magnitude"]
        vdev = np.full((len(us), len(vs)), floor)
        for di in (0, 1):
            for dj in (0, 1):
                vdev[di: di + len(hu), dj: dj + len(hv)] = np.maximum(vdev[di: di + len(hu), dj: dj + len(hv)], dev + floor)
        gu, gv = np.meshgrid(us, vs, indexing="ij")
        uu, vv = gu.ravel(), gv.ravel()
        d1 = s.derivatives(uu, vv, 2)  # S, S_u, S_v (the same bits as order 1) and what the normal needs
        S = d1[:, 0, 0] - off
        n = s._normal(uu, vv, d1)
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
    # Bernstein coefficients at bidegree (p+1, q+1): one contraction per direction (numpy's own loops, not BLAS;
    # a three-operand einsum would sum over both directions at once, (p+2)(q+2) times the work)
    wc = np.einsum("jl,xyil->xyij", gv, np.einsum("ik,xykl->xyil", gu, w))
    wmin = wc.min(axis=(2, 3))
    if (wmin <= 0).any():
        raise ValueError(f"{s.name or 'patch'}: a cell's weights are not all positive; cannot bound its chord.")
    bound = np.zeros((nu, nv))
    for L in (lower, upper):
        d = np.einsum("jl,xyilc->xyijc", gv, np.einsum("ik,xyklc->xyilc", gu, A - w[..., None] * L))
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

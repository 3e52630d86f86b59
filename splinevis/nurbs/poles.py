"""Where a Newton step over a pole goes on: the antipodal meridian of a collapsed edge.

A pole is an edge whose control points coincide, of a patch closed in the other parameter (a sphere's
v = v_lo with u around the axis). Below, the pole is at v = v_p (the u edges are the same with u and v
swapped); t is the parameter along the pole edge (u here).

Derivation. With clamped knots, at v = v_p only the pole row's basis function is non-zero, so
``A = w0(t) P_pole`` (``w0(t) = sum_i N_i(t) w_i0``) and only the pole row and its neighbour r (1 at v_lo, nv - 2 at
v_hi) have non-zero v-derivative, ``+-c`` (``c = q / (V[q+1] - V[q])``). The quotient rule gives

    S_v(t, v_p) = +-c C(t) / w0(t),    C(t) = sum_i N_i(t) w_ir (P_ir - P_pole),

so the meridian at t leaves the pole along the direction of ``C(t)`` (a curve in the pole's tangent plane; the
rows next to the pole), ``|S - P_pole| ~ |v - v_p| c |C(t)| / w0(t)``. Newton's linear model continues a meridian
through the pole: the point at ``v_e`` beyond the pole on meridian t is ``P_pole - |v_e - v_p| c C(t) / w0(t)``.
On the surface that point lies, to first order, on the meridian t' whose direction is opposite,
``C(t') || -C(t)``, at ``|v' - v_p| = rho |v_e - v_p|`` with ``rho = (|C(t)| / w0(t)) / (|C(t')| / w0(t'))``.
Measured as an angle about the pole normal n (the projections C_perp onto the plane normal to n), t' is the
root of

    phi(t') = angle from -C(t) to C(t') about n = atan2(((-C(t)) x C(t')) . n, -C_perp(t) . C_perp(t')),

which is increasing in t' (a simple pole's meridian direction turns once around n, monotonically: that is
what keeps the surface from folding over at the pole) with derivative
``omega(t') = ((C x C') . n) / |C_perp|^2``. For a surface with half-turn symmetry (a surface of revolution made
of equal arcs) t' = t + half the period and rho = 1: the old rule, kept exact (no table, no flag) where it holds.

The rule (:func:`cross_pole`; ``sv_nurbs_cross_pole`` in ``glsl/lib/nurbs/poles.glsl`` does the same in
float32): a per-pole table of ``d(t_k) = t'(t_k) - t_k`` at K + 1 even steps of the period (computed once on
the CPU by :func:`antipode`, to float64 precision) gives a start by linear interpolation; one Newton step on phi,
clamped to one table step, refines it (the start's error e becomes ~ e^2 |omega'| / (2 omega); the clamp keeps a
start near a kink of d, at a knot, from jumping); rho is taken at the start. Cost: two table floats and two
evaluations of C (the basis along the edge, two rows of control points), only when a step crosses a pole.
A table (65 floats per pole) rather than Newton from t + half: its start is within the interpolation error
however asymmetric the pole is, where Newton from t + half may leave the bracket of a strongly non-uniform
turn.
"""

from __future__ import annotations

import weakref

import numpy as np

from .basis import at_fraction, ders_basis_funs, find_span

__all__ = ["POLE_TABLE", "pole_curve", "pole_normal", "antipode", "pole_table", "pole_tables", "cross_pole"]

#: Table steps per pole (K): K + 1 values of t' - t at even steps of the period, after 3 floats of the normal.
POLE_TABLE = 64


def _edge_data(s, edge):
    """Along-edge degree, knots and domain; the pole row's and its neighbour's homogeneous control points."""
    axis, hi_end = divmod(edge, 2)
    Pw = s.homogeneous()
    if axis == 0:  # u = lo / hi edges: rows P[0] / P[-1], the neighbour P[1] / P[-2]; t is v
        pole, near = Pw[-1 if hi_end else 0], Pw[-2 if hi_end else 1]
    else:
        pole, near = Pw[:, -1 if hi_end else 0], Pw[:, -2 if hi_end else 1]
    along = 1 - axis
    return s.degree[along], np.asarray(s.knots[along], dtype=np.float64), s.domain[along], pole, near


def pole_curve(s, edge: int, t):
    """``C(t)``, ``C'(t)`` and ``w0(t)`` at parameters ``t`` along a collapsed edge (0: u=lo, 1: u=hi, 2: v=lo,
    3: v=hi): the direction curve of the meridians leaving the pole (module docstring), its derivative and the
    pole row's weight. ``C = sum_i N_i(t) (Pw_ir.xyz - Pw_ir.w P_pole)`` as in the shader.

    >>> from splinevis.nurbs.exact import sphere
    >>> C, dC, w0 = pole_curve(sphere(), 2, np.array([0.0, 0.25]))
    >>> C.round(12).tolist(), w0.tolist()  # the south pole's meridians leave along +x at u = 0, +y at u = 1/4
    ([[0.707106781187, 0.0, 0.0], [0.0, 0.707106781187, 0.0]], [1.0, 1.0])
    """
    deg, K, _, pole, near = _edge_data(s, edge)
    t = np.atleast_1d(np.asarray(t, dtype=np.float64))
    span = find_span(deg, K, t)
    N = ders_basis_funs(span, t, deg, 1, K)
    idx = span[:, None] - deg + np.arange(deg + 1)
    P0 = pole[0, :3] / pole[0, 3]
    Q = near[idx, :3] - near[idx, 3:] * P0
    C, dC = np.einsum("nj,njc->nc", N[:, 0], Q), np.einsum("nj,njc->nc", N[:, 1], Q)
    return C, dC, np.einsum("nj,nj->n", N[:, 0], pole[idx, 3])


def _grid(s, edge, m):
    lo, hi = _edge_data(s, edge)[2]
    return at_fraction(lo, hi, np.arange(m + 1) / m)


def pole_normal(s, edge: int, samples: int = 1024):
    """The pole's unit normal, oriented with the turn of the meridians (the vector area of the closed curve C:
    ``sum C(t_k) x C(t_k+1)``), or None where C does not turn around it once, monotonically (a pole that is
    not simple: a cone-like tip folding over, a vanishing row): no general continuation there.

    >>> from splinevis.nurbs.exact import sphere
    >>> pole_normal(sphere(), 2).round(12).tolist()  # the south pole: u turns counter-clockwise about +z
    [0.0, 0.0, 1.0]
    """
    g = _grid(s, edge, samples)
    C, dC, _ = pole_curve(s, edge, g)
    a = np.cross(C[:-1], C[1:]).sum(axis=0)
    if not np.linalg.norm(a) > 0:
        return None
    n = a / np.linalg.norm(a)
    Cp = C - np.outer(C @ n, n)
    turn = np.cross(Cp[:-1], Cp[1:]) @ n
    size = np.linalg.norm(Cp, axis=-1)
    total = np.arctan2(turn, np.einsum("ij,ij->i", Cp[:-1], Cp[1:])).sum()
    if size.min() <= 1e-9 * size.max() or (turn <= 0).any() or abs(total - 2 * np.pi) > 1e-6:
        return None
    return n


def _phi(C, Ct, n):
    """Angle from -C to Ct about n (arrays of vectors, broadcast)."""
    y = np.einsum("...c,...c->...", np.cross(-C, Ct), n)
    x = -(np.einsum("...c,...c->...", C, Ct) - np.einsum("...c,...c->...", C, n) * np.einsum("...c,...c->...", Ct, n))
    return np.arctan2(y, x)


def antipode(s, edge: int, t, n=None, samples: int = 1024):
    """The exact antipodal meridian t' of each meridian t at a pole: ``C(t') || -C(t)`` in the plane normal to
    the pole normal n (module docstring), in float64: the sign change of phi on ``samples`` even steps of the
    period brackets it (phi is increasing in t'; its other jump, from +pi to -pi at t' = t, is not a root),
    bisection to the last bit. Values in ``[lo, hi)``.

    >>> from splinevis.nurbs.exact import sphere
    >>> antipode(sphere(), 2, [0.0, 0.1, 0.8]).round(12).tolist()  # a sphere of equal arcs: half a turn on
    [0.5, 0.6, 0.3]
    """
    n = pole_normal(s, edge) if n is None else np.asarray(n, dtype=np.float64)
    t = np.atleast_1d(np.asarray(t, dtype=np.float64))
    lo, hi = _edge_data(s, edge)[2]
    g = _grid(s, edge, samples)
    C = pole_curve(s, edge, lo + np.mod(t - lo, hi - lo))[0]
    Cg = pole_curve(s, edge, g)[0]
    ph = _phi(C[:, None, :], Cg[None, :, :], n)  # (queries, grid)
    up = (ph[:, :-1] <= 0) & (ph[:, 1:] > 0) & (ph[:, 1:] - ph[:, :-1] < np.pi)
    j = np.argmax(up, axis=1)
    a, b = g[j], g[j + 1]
    for _ in range(64):
        mid = 0.5 * (a + b)
        neg = _phi(C, pole_curve(s, edge, mid)[0], n) <= 0
        a, b = np.where(neg, mid, a), np.where(neg, b, mid)
    out = 0.5 * (a + b)
    return np.where(out >= hi, lo, out)


def pole_table(s, edge: int):
    """The pole's table for the shader and the twin: ``[n_x, n_y, n_z, d_0, ..., d_K]`` with
    ``d_k = t'(t_k) - t_k`` (:func:`antipode`, ``t_k = lo + k (hi - lo) / K``, K = :data:`POLE_TABLE`, d unwrapped
    into ``(0, hi - lo)``), or None where the half turn is exact (``d = (hi - lo) / 2`` and ``rho = 1`` to 1e-12:
    the old rule, bit for bit) or the pole is not simple (:func:`pole_normal`: the half turn, as before).

    >>> from splinevis.nurbs.exact import sphere
    >>> pole_table(sphere(), 2) is None
    True
    """
    lo, hi = _edge_data(s, edge)[2]
    n = pole_normal(s, edge)
    if n is None:
        return None
    tk = _grid(s, edge, POLE_TABLE)
    d = np.mod(antipode(s, edge, tk, n) - tk, hi - lo)
    C, _, w0 = pole_curve(s, edge, tk)
    C2, _, w2 = pole_curve(s, edge, lo + np.mod(tk + 0.5 * (hi - lo) - lo, hi - lo))
    speed = lambda C, w: np.linalg.norm(C - np.outer(C @ n, n), axis=-1) / w  # noqa: E731
    if np.abs(d - 0.5 * (hi - lo)).max() <= 1e-12 * (hi - lo) and np.allclose(speed(C, w0), speed(C2, w2), 1e-12, 0):
        return None
    return np.concatenate([n, d])


def pole_tables(s, closed, poles) -> tuple:
    """Per edge (u=lo, u=hi, v=lo, v=hi): the :func:`pole_table` of a pole of a patch closed in the other
    parameter and open in its own, with clamped knots at that end (the pole row is the surface's edge), else None.

    >>> from splinevis.nurbs.exact import sphere
    >>> pole_tables(sphere(), (True, False), (False, False, True, True))
    (None, None, None, None)
    """
    key = (tuple(bool(c) for c in closed), tuple(bool(p) for p in poles))
    cached = _TABLES.get(s, {})
    if key not in cached:  # ~10 ms a pole, and patch_facts asks on every ray cast: once per (immutable) surface
        cached[key] = _pole_tables(s, closed, poles)
        _TABLES[s] = cached
    return cached[key]


_TABLES = weakref.WeakKeyDictionary()  # per surface (immutable): {(closed, poles): tables}


def _pole_tables(s, closed, poles) -> tuple:
    out = []
    for edge in range(4):
        axis, hi_end = divmod(edge, 2)
        deg, K = s.degree[axis], np.asarray(s.knots[axis])
        end = K[-deg - 1:] if hi_end else K[:deg + 1]
        ok = poles[edge] and closed[1 - axis] and not closed[axis] and np.ptp(end) == 0 and s.shape[axis] >= 2
        out.append(pole_table(s, edge) if ok else None)
    return tuple(out)


def cross_pole(s, edge: int, table, t_e):
    """The general continuation over a pole (module docstring): for meridians ``t_e`` (any real: wrapped into
    the period), ``(t', rho)``: the meridian on the far side and the ratio of the distances from the pole (far
    over near, per unit of the pole-normal parameter). Same steps as ``sv_nurbs_cross_pole`` (float32 there).

    >>> from splinevis.nurbs.exact import sphere
    >>> s = sphere()
    >>> table = np.concatenate([[0, 0, 1.0], np.full(POLE_TABLE + 1, 0.5)])  # the half turn, as a table
    >>> tp, rho = cross_pole(s, 2, table, np.array([0.1, 1.3]))
    >>> tp.round(12).tolist(), rho.round(12).tolist()
    ([0.6, 0.8], [1.0, 1.0])
    """
    lo, hi = _edge_data(s, edge)[2]
    span = hi - lo
    n, d = np.asarray(table[:3]), np.asarray(table[3:])
    t = lo + np.mod(np.asarray(t_e, dtype=np.float64) - lo, span)
    f = (t - lo) / span * POLE_TABLE
    k = np.minimum(np.floor(f), POLE_TABLE - 1).astype(int)
    f = f - k
    t0 = t + (d[k] + f * (d[k + 1] - d[k]))
    t0 = np.clip(lo + np.mod(t0 - lo, span), lo, hi)
    a, _, wa = pole_curve(s, edge, t)
    b, db, wb = pole_curve(s, edge, t0)
    bp = b - np.outer(b @ n, n)
    ap = a - np.outer(a @ n, n)
    bb = np.einsum("ij,ij->i", bp, bp)
    omega = np.cross(b, db) @ n
    h = span / POLE_TABLE
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(omega > 0, np.clip(_phi(a, b, n) * bb / omega, -h, h), 0.0)
        na, nb = np.sqrt(np.einsum("ij,ij->i", ap, ap)), np.sqrt(bb)
        rho = np.where(nb * wa > 0, na * wb / (nb * wa), 1.0)
    tp = t0 - delta
    return np.clip(lo + np.mod(tp - lo, span), lo, hi), rho

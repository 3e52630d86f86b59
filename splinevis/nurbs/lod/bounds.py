r"""Proven bounds of the distance between a (rational) Bezier patch and a triangle through three of its points,
and between a boundary curve and its chords [Kumar1997, sec. 4.1].

A patch of degree ``(m, n)`` is ``F = A / w`` on its local domain ``[0, 1]^2`` with homogeneous control points
``Pw[i, j] = (w_ij P_ij, w_ij)``; a triangle ``T`` of the domain with vertices ``p_1, p_2, p_3`` carries the
linear interpolant ``L`` of ``F`` at them (the flat triangle through ``F(p_k)``). Everything below is an
inequality about exact real numbers; the last step adds a float64 rounding term.

Derivative bounds of a polynomial (``second_derivative_bounds``)
------------------------------------------------------------------
The second derivatives of ``P(u, v) = sum B_i^m(u) B_j^n(v) P_ij`` are Bezier patches with coefficients
``m (m - 1) D2u P_ij``, ``m n DuDv P_ij``, ``n (n - 1) D2v P_ij`` (forward differences) [Farin2002, ch. 5];
a Bezier patch lies in the convex hull of its coefficients, so with ``|.|`` the Euclidean norm::

    (1)  M1 = m (m-1) max |D2u P_ij| >= max |P_uu|,  M2 = m n max |DuDv P_ij| >= max |P_uv|,
         M3 = n (n-1) max |D2v P_ij| >= max |P_vv|.

On a sub-rectangle ``[u0, u1] x [v0, v1]`` the net is first re-expressed there (:func:`subdivide`, the blossom
``Q_kl = b(u0^(m-k), u1^k; v0^(n-l), v1^l)``, de Casteljau's result) and (1) is applied in the local
parameters, then divided by ``(u1 - u0)^2``, ``(u1 - u0)(v1 - v0)``, ``(v1 - v0)^2``: tighter the smaller the box.

The triangle bound (``waldron_bound``, ``box_bound``)
------------------------------------------------------
Let ``G`` be smooth on ``T`` with ``G(p_k) = 0`` (G = F - L for a polynomial F). For ``p`` in ``T`` with
barycentric coordinates ``l_k`` and ``h_k = p_k - p``, Taylor's formula with integral remainder gives
``0 = G(p_k) = G(p) + DG(p) h_k + r_k``, ``|r_k| <= (1/2) sup_T |D^2_(h_k) G|`` (the segment lies in ``T``);
since ``sum l_k h_k = 0``::

    (2)  |G(p)| = |sum l_k r_k| <= (1/2) sum_k l_k sup_T |D^2_(h_k) G|.

With ``|D^2_h G| <= |h|^2 Lambda``, ``Lambda = lambda_max([[M1, M2], [M2, M3]])`` (since
``|D^2_d G| <= d1^2 M1 + 2 |d1 d2| M2 + d2^2 M3`` for ``|d| = 1``), and with ``c, R`` the centre and radius of
``T``'s smallest enclosing circle, ``sum l_k |p_k - p|^2 = sum l_k |p_k - c|^2 - |p - c|^2 <= R^2``::

    (3)  max_T |G| <= (1/2) R^2 Lambda        (sharp for linear interpolation on a simplex [Waldron1998]).

Keeping the coordinates apart instead, ``sum l_k (h_k)_1^2 = sum l_k (p_k)_1^2 - p_1^2`` is the variance of a
distribution on the three u-values, at most ``du^2 / 4`` (``du``: the u-extent of ``T``), likewise ``dv^2 / 4``,
and ``sum l_k |(h_k)_1 (h_k)_2| <= du dv / 4`` by Cauchy-Schwarz::

    (4)  max_T |G| <= (1/8) (du^2 M1 + 2 du dv M2 + dv^2 M3),

which for the axis-aligned right triangle with legs ``l1, l2`` (``du = l1``, ``dv = l2``) is the formula of
[Kumar1997, sec. 4.1] (after [Filip1986]); (4) holds for any triangle with its bounding box. On an axis-aligned
right triangle (4) <= (3) always (``R^2 = (l1^2 + l2^2) / 4`` and ``l^T M l <= |l|^2 Lambda``); on an acute or
rotated triangle with isotropic curvature (3) is smaller (equilateral: ``R^2 = s^2/3`` against ``7 s^2 / 16``).
We use the smaller of the two.

The rational case (``triangle_bounds``)
----------------------------------------
``F - L = (A - w L) / w`` and ``G = A - w L`` vanishes at the vertices (``A(p_k) = w(p_k) F(p_k)``); once ``L``
is fixed ``G`` is a polynomial of degree ``(m + 1, n + 1)`` with::

    (5)  D^2_d G = D^2_d A - (D^2_d w) L - 2 (D_d w)(D_d L)      (D^2 L = 0),

so (3), (4) apply to ``G`` with the ``M`` of ``G`` on ``T``'s bounding box, and::

    (6)  max_T |F - L| <= max_T |G| / min_T w,   min_T w >= min of w's Bernstein coefficients on the box > 0.

``method="net"`` bounds ``M`` of ``G`` by (1) applied to ``G``'s own Bernstein net on the box
(``A``, ``w`` degree-raised, ``w L`` by ``u B_i^m = (i+1)/(m+1) B_(i+1)^(m+1)``): the convex hull of the whole
expression (5), no triangle inequality between its terms. ``method="split"`` bounds (5) term by term,
``|G_uu| <= M1(A) + M1(w) max|L| + 2 W1 |L_u|`` etc. (``W1 >= |w_u|`` from first differences), the
textbook route; ``method="best"`` (default) takes the smaller of each ``M`` (each is proven).
``F - L`` is translation invariant, and ``G`` too (``A - c w - w (L - c) = A - w L``), so the coordinates are
shifted to the centroid of ``F(p_k)`` first: ``|L|`` stays the size of the triangle (``split``)
and the coefficients of ``G`` are formed without cancellation of large numbers (both). For a polynomial patch
(all weights equal) ``G = w (F - L)`` and the net of ``G`` is the degree-raised net of ``F - L``, whose
differences are convex combinations of those of ``F``: no worse than (1).

Curves (``curve_chord_bounds``)
--------------------------------
For a curve ``C`` and its chord over ``[t0, t1]`` (1-D: ``R = (t1 - t0) / 2``, both (3) and (4) read)::

    (7)  max |C - chord| <= (1/8) (t1 - t0)^2 max |C''|,  rational: <= (1/8) (p+1) p max |D2 g_k| / min w_k

with ``g_k`` the degree ``p + 1`` net of ``G = A - w chord`` on ``[t0, t1]`` (local parameter).

Rounding (a worst-case estimate, [Higham2002, sec. 3.1, 3.4]). The subdivided coefficients are convex
combinations of ``Pw``: off by ``(m + n + 4) eps max |Pw|``; shifting, degree raising and subtracting ``w L``
keep the coefficients of ``G`` within ``e_g = 4 (m + n + 4) eps max w (2 max |P| + |alpha| + |beta| + |gamma|)``
(``L = alpha + beta s + gamma t`` in the box's parameters); the second differences times their factors, summed
as in (4), multiply that by at most ``(m + n + 2)^2 / 2``. And ``L`` goes through the computed points ``F_k``,
not ``F(p_k)``: ``G(p_k) = w (F(p_k) - F_k)``, whose linear interpolant adds ``max w |F(p_k) - F_k|``, at most
``4 (m + 1)(n + 1) eps max |P| max w / min w`` times ``max w``. The bound adds both, divided by ``min w``
(and ``(p + 2)^2 / 2``, ``p + 1`` in place of ``(m + n + 2)^2 / 2``, ``(m + 1)(n + 1)`` for a curve). For
``max |P| = 1`` and degree 5 x 5 that is ~1e-12: far below any useful ``delta``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .bezier import bernstein

__all__ = ["subdivide", "second_derivative_bounds", "enclosing_radius", "waldron_bound", "kumar_bound",
           "box_bound", "triangle_bounds", "curve_chord_bounds", "patch_points", "curve_points", "side_net",
           "collapsed_point"]

EPS = np.finfo(float).eps


def _bernstein_table(m: int, t: np.ndarray) -> np.ndarray:
    """``(N, m + 1, m + 2)``: row ``d`` holds ``B_i^d(t)`` for ``i <= d`` and zeros after (one zero column
    more), by the recurrence of :func:`splinevis.nurbs.lod.bezier.bernstein` with the same roundings (the
    padded zeros add exactly: ``x + 0 = x``), so each row equals ``bernstein(d, t)`` bitwise."""
    s = 1.0 - t
    T = np.zeros((t.size, m + 1, m + 2))
    T[:, 0, 0] = 1.0
    for d in range(1, m + 1):
        np.multiply(s[:, None], T[:, d - 1, :d], out=T[:, d, :d])
        T[:, d, 1:d + 1] += t[:, None] * T[:, d - 1, :d]
    return T


@lru_cache(maxsize=None)
def _diagonal_index(m: int):
    """``(m + 1, m + 1)`` index ``i - j`` (``m + 1``, a zero column of :func:`_bernstein_table`, where ``i < j``)."""
    j, i = np.meshgrid(np.arange(m + 1), np.arange(m + 1), indexing="ij")
    return np.where(i >= j, i - j, m + 1)


def _subdivision_matrix(m: int, a, b) -> np.ndarray:
    """``S (N, m + 1, m + 1)`` with ``Q = S P`` the Bernstein coefficients on ``[a, b]`` of the degree-m
    polynomial with coefficients ``P`` on ``[0, 1]``: ``S_ki = sum_j B_j^(m-k)(a) B_(i-j)^k(b)`` (the blossom
    at ``a^(m-k) b^k``). Entries are non-negative and rows sum to 1 for ``0 <= a <= b <= 1``.

    The sum runs over ``j`` in increasing order from 0 (the terms outside ``0 <= i - j <= k``, ``j <= m - k``
    are exact zeros), the rounding of the textbook double loop.

    >>> _subdivision_matrix(2, [0.0], [0.5])[0].tolist()
    [[1.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.25, 0.5, 0.25]]
    """
    a, b = np.atleast_1d(np.asarray(a, dtype=np.float64)), np.atleast_1d(np.asarray(b, dtype=np.float64))
    N = a.size
    T = _bernstein_table(m, np.concatenate([a, b]))
    Ta, Tb = T[:N, ::-1, :m + 1], T[N:]  # Ta[:, k, j] = B_j^(m-k)(a), Tb[:, k, l] = B_l^k(b)
    Z = Ta[..., None] * Tb[:, :, _diagonal_index(m)]  # (N, k, j, i)
    S = Z[:, :, 0, :].copy()
    for j in range(1, m + 1):
        S += Z[:, :, j, :]
    return S


def subdivide(P, box) -> np.ndarray:
    """Bernstein coefficients of the Bezier patch ``P (..., m + 1, n + 1, k)`` on the sub-rectangles
    ``box (..., 4) = (u0, u1, v0, v1)`` of ``[0, 1]^2`` (leading axes broadcast): ``(..., m + 1, n + 1, k)``.

    >>> P = np.arange(3.0)[:, None, None] * np.ones((3, 2, 1))  # P(u, v) = 2 u
    >>> subdivide(P, [0.5, 1.0, 0.0, 1.0])[:, 0, 0].tolist()
    [1.0, 1.5, 2.0]
    """
    P = np.asarray(P, dtype=np.float64)
    box = np.asarray(box, dtype=np.float64)
    lead = np.broadcast_shapes(P.shape[:-3], box.shape[:-1])
    m, n = P.shape[-3] - 1, P.shape[-2] - 1
    bx = np.broadcast_to(box, lead + (4,)).reshape(-1, 4)
    Su = _subdivision_matrix(m, bx[:, 0], bx[:, 1])
    Sv = _subdivision_matrix(n, bx[:, 2], bx[:, 3])
    Pb = np.broadcast_to(P, lead + P.shape[-3:]).reshape((-1,) + P.shape[-3:])
    Q = np.einsum("Nki,Nlj,Nijc->Nklc", Su, Sv, Pb)
    return Q.reshape(lead + P.shape[-3:])


def _local_bounds(Q: np.ndarray) -> np.ndarray:
    """``(..., 3)``: eq. (1) in the net's own parameters."""
    m, n = Q.shape[-3] - 1, Q.shape[-2] - 1
    lead = Q.shape[:-3]
    out = np.zeros(lead + (3,))
    norm = lambda d: np.linalg.norm(d, axis=-1).reshape(lead + (-1,)).max(axis=-1)  # noqa: E731
    if m >= 2:
        out[..., 0] = m * (m - 1) * norm(Q[..., 2:, :, :] - 2 * Q[..., 1:-1, :, :] + Q[..., :-2, :, :])
    if m >= 1 and n >= 1:
        out[..., 1] = m * n * norm(Q[..., 1:, 1:, :] - Q[..., :-1, 1:, :] - Q[..., 1:, :-1, :] + Q[..., :-1, :-1, :])
    if n >= 2:
        out[..., 2] = n * (n - 1) * norm(Q[..., :, 2:, :] - 2 * Q[..., :, 1:-1, :] + Q[..., :, :-2, :])
    return out


def _to_domain(M: np.ndarray, box: np.ndarray) -> np.ndarray:
    du, dv = box[..., 1] - box[..., 0], box[..., 3] - box[..., 2]
    return M / np.stack([du * du, du * dv, dv * dv], axis=-1)


def second_derivative_bounds(P, box=None) -> np.ndarray:
    """``(..., 3)`` bounds ``M1 >= max |P_uu|``, ``M2 >= max |P_uv|``, ``M3 >= max |P_vv|`` of the polynomial
    Bezier patch ``P (..., m + 1, n + 1, k)`` (any k coordinates: a Cartesian net, or one homogeneous
    coordinate), eq. (1), over ``[0, 1]^2`` or the sub-rectangles ``box (..., 4)`` in the patch's parameters.

    >>> from splinevis.nurbs.exact import saddle  # z = x^2 - y^2, x = 2u - 1: z_uu = 8, z_vv = -8
    >>> P = saddle().control_points
    >>> second_derivative_bounds(P).tolist(), second_derivative_bounds(P, [0.0, 0.5, 0.0, 0.5]).tolist()
    ([8.0, 0.0, 8.0], [8.0, 0.0, 8.0])
    """
    P = np.asarray(P, dtype=np.float64)
    if box is None:
        return _local_bounds(P)
    box = np.asarray(box, dtype=np.float64)
    return _to_domain(_local_bounds(subdivide(P, box)), box)


def enclosing_radius(tri) -> np.ndarray:
    """Radius of the smallest circle containing each triangle ``tri (..., 3, 2)``: half the longest edge for a
    right or obtuse triangle, else the circumradius.

    >>> enclosing_radius([[[0, 0], [1, 0], [0, 1]], [[0, 0], [2, 0], [1, 3 ** 0.5]]]).round(6).tolist()
    [0.707107, 1.154701]
    """
    t = np.asarray(tri, dtype=np.float64)
    e = t[..., [1, 2, 0], :] - t[..., [2, 0, 1], :]  # edge k opposite vertex k
    l2 = np.einsum("...ki,...ki->...k", e, e)
    big = l2.max(axis=-1)
    area2 = np.abs(e[..., 0, 0] * e[..., 1, 1] - e[..., 0, 1] * e[..., 1, 0])  # 2 * area
    obtuse = 2.0 * big >= l2.sum(axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        circum = np.sqrt(l2.prod(axis=-1)) / (2.0 * area2)
    return np.where(obtuse, 0.5 * np.sqrt(big), circum)


def _lambda_max(M: np.ndarray) -> np.ndarray:
    a, b, c = M[..., 0], M[..., 1], M[..., 2]
    return 0.5 * (a + c) + np.hypot(0.5 * (a - c), b)


def waldron_bound(tri, M) -> np.ndarray:
    """Eq. (3): ``(1/2) R^2 lambda_max([[M1, M2], [M2, M3]])`` for triangles ``tri (..., 3, 2)`` and second
    derivative bounds ``M (..., 3)`` valid on them, in the same parameters [Waldron1998].

    >>> round(float(waldron_bound([[0, 0], [1, 0], [0, 1]], [2.0, 0.0, 0.0])), 12)  # z = u^2: (1/2)(1/2) 2
    0.5
    """
    M = np.asarray(M, dtype=np.float64)
    return 0.5 * enclosing_radius(tri) ** 2 * _lambda_max(M)


def kumar_bound(l1, l2, M) -> np.ndarray:
    """Eq. (4): ``(1/8)(l1^2 M1 + 2 l1 l2 M2 + l2^2 M3)``, the formula of [Kumar1997, sec. 4.1] for the right
    triangle with legs ``l1`` (along u) and ``l2`` (along v); valid for any triangle with ``l1, l2`` the extents
    of its bounding box (:func:`box_bound`).

    >>> float(kumar_bound(1.0, 1.0, [2.0, 0.0, 0.0]))  # z = u^2 on the unit right triangle: max 1/4 at u = 1/2
    0.25
    """
    M = np.asarray(M, dtype=np.float64)
    l1, l2 = np.asarray(l1, dtype=np.float64), np.asarray(l2, dtype=np.float64)
    return 0.125 * (l1 * l1 * M[..., 0] + 2.0 * l1 * l2 * M[..., 1] + l2 * l2 * M[..., 2])


def box_bound(tri, M) -> np.ndarray:
    """Eq. (4) for any triangles ``tri (..., 3, 2)``: :func:`kumar_bound` with the bounding-box extents.

    >>> float(box_bound([[0, 0], [2, 0], [1, 3 ** 0.5]], [1.0, 0.0, 1.0]))  # (1/8)(4 + 3)
    0.875
    """
    t = np.asarray(tri, dtype=np.float64)
    ext = t.max(axis=-2) - t.min(axis=-2)
    return kumar_bound(ext[..., 0], ext[..., 1], M)


@lru_cache(maxsize=None)
def _raise_weights(m: int, axis: int, ndim: int):
    shape = [1] * ndim
    shape[axis] = m + 2
    a = (np.arange(m + 2) / (m + 1)).reshape(shape)
    return a, 1.0 - a


def _shifted(Q: np.ndarray, axis: int, first: bool) -> np.ndarray:
    """``Q`` with one zero slice added along ``axis`` in front (``first``) or at the end (``np.pad``)."""
    shape = list(Q.shape)
    shape[axis] += 1
    out = np.zeros(shape)
    idx = [slice(None)] * Q.ndim
    idx[axis] = slice(1, None) if first else slice(0, -1)
    out[tuple(idx)] = Q
    return out


def _elevate(Q: np.ndarray, axis: int) -> np.ndarray:
    """Degree raising by one along ``axis`` (a non-negative axis of ``Q``)."""
    a, b = _raise_weights(Q.shape[axis] - 1, axis, Q.ndim)
    return a * _shifted(Q, axis, True) + b * _shifted(Q, axis, False)


def _times_param(Q: np.ndarray, axis: int) -> np.ndarray:
    """Coefficients of ``s * Q(s)`` one degree up along ``axis``: ``(s Q)_k = k / (m + 1) Q_(k - 1)``."""
    a = _raise_weights(Q.shape[axis] - 1, axis, Q.ndim)[0]
    return a * _shifted(Q, axis, True)


def _bernstein_eval(P: np.ndarray, t) -> np.ndarray:
    """``sum_i B_i(t) P_i`` for a curve net ``P (p + 1, k)``, in a fixed order (bitwise reproducible)."""
    B = bernstein(P.shape[0] - 1, t)
    out = B[:, 0, None] * P[0]
    for i in range(1, P.shape[0]):
        out = out + B[:, i, None] * P[i]
    return out


def curve_points(Pw_curve, t) -> np.ndarray:
    """Cartesian points of the rational Bezier curve ``Pw_curve (p + 1, k + 1)`` (weight last) at ``t``: ``(N, k)``.
    The ends are the end control points exactly, and equal inputs give bitwise equal points.

    >>> h = 2 ** -0.5
    >>> curve_points([[1, 0, 1], [h, h, h], [0, 1, 1]], [0.0, 0.5]).round(6).tolist()  # a quarter circle
    [[1.0, 0.0], [0.707107, 0.707107]]
    """
    A = _bernstein_eval(np.asarray(Pw_curve, dtype=np.float64), t)
    return A[:, :-1] / A[:, -1:]


def patch_points(Pw, uv) -> np.ndarray:
    """Cartesian points ``(K, 3)`` of the patch ``Pw (m + 1, n + 1, 4)`` at local parameters ``uv (K, 2)``.

    Points on a side (``v = 0``, ``u = 1``, ``v = 1``, ``u = 0``, exactly) are evaluated through that side's
    curve (:func:`curve_points`), so two patches with the same side curve give bitwise equal boundary points;
    on a collapsed side (all its control points equal: a pole) every point is that control point.

    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.operations import bezier_patches
    >>> Pw = bezier_patches(sphere())[0][0].homogeneous()  # v = 0 is the south pole
    >>> patch_points(Pw, [[0.3, 0.0], [0.5, 0.5]]).round(6).tolist()
    [[0.0, 0.0, -1.0], [0.5, 0.5, -0.707107]]
    """
    Pw = np.asarray(Pw, dtype=np.float64)
    uv = np.atleast_2d(np.asarray(uv, dtype=np.float64))
    u, v = uv[:, 0], uv[:, 1]
    Bu, Bv = bernstein(Pw.shape[0] - 1, u), bernstein(Pw.shape[1] - 1, v)
    A = np.einsum("ki,kj,ijc->kc", Bu, Bv, Pw)
    out = A[:, :3] / A[:, 3:]
    for side, (on, t) in enumerate(((v == 0, u), (u == 1, v), (v == 1, u), (u == 0, v))):
        if on.any():
            C = side_net(Pw, side)
            out[on] = pole if (pole := collapsed_point(C)) is not None else curve_points(C, t[on])
    return out


def _patch_points_many(Pws: np.ndarray, poles, item: np.ndarray, uv: np.ndarray, chunk: int = 1 << 15) -> np.ndarray:
    """:func:`patch_points` of many patches ``Pws (I, m + 1, n + 1, 4)`` of one degree at once: point ``k`` of
    patch ``item[k]`` at ``uv[k]``; ``poles`` per side ``(is_pole (I,), pole (I, 3))`` (:func:`collapsed_point`).
    Row by row the same operations in the same order as :func:`patch_points`: bitwise the same points."""
    u, v = uv[:, 0], uv[:, 1]
    m, n = Pws.shape[1] - 1, Pws.shape[2] - 1
    out = np.empty((uv.shape[0], 3))
    for a in range(0, uv.shape[0], chunk):
        b = min(a + chunk, uv.shape[0])
        A = np.einsum("ki,kj,kijc->kc", bernstein(m, u[a:b]), bernstein(n, v[a:b]), Pws[item[a:b]])
        out[a:b] = A[:, :3] / A[:, 3:]
    for side, (on, t) in enumerate(((v == 0, u), (u == 1, v), (v == 1, u), (u == 0, v))):
        rows = np.flatnonzero(on)
        if rows.size:
            it = item[rows]
            is_pole, pole = poles[side]
            res = np.empty((rows.size, 3))
            sel = is_pole[it]
            res[sel] = pole[it[sel]]
            cur = np.flatnonzero(~sel)
            if cur.size:
                C = (Pws[:, :, 0], Pws[:, -1, :], Pws[:, :, -1], Pws[:, 0, :])[side][it[cur]]  # (K, p + 1, 4)
                res[cur] = _curve_points_rows(C, t[rows[cur]])
            out[rows] = res
    return out


def collapsed_point(Pw_curve):
    """The point of a collapsed curve (all control points within ``16 eps`` of the largest coordinate of the
    first: a pole), else None.

    >>> collapsed_point([[0, 0, -0.5, 0.5], [0, 0, -1, 1]]).tolist(), collapsed_point([[0, 0, 1], [1, 0, 1]])
    ([0.0, 0.0, -1.0], None)
    """
    C = np.asarray(Pw_curve, dtype=np.float64)
    X = C[:, :-1] / C[:, -1:]
    tol = 16.0 * EPS * max(float(np.abs(X).max()), np.finfo(float).tiny)
    return X[0].copy() if np.abs(X - X[0]).max() <= tol else None


def side_net(Pw, side: int) -> np.ndarray:
    """Homogeneous control points of side ``side`` (0: ``v = 0``, 1: ``u = 1``, 2: ``v = 1``, 3: ``u = 0``),
    running in the increasing parameter (the numbering of :mod:`splinevis.nurbs.lod.adjacency`).

    >>> side_net(np.arange(16.0).reshape(2, 2, 4), 1)[:, 0].tolist()  # u = 1: Pw[1, :]
    [8.0, 12.0]
    """
    Pw = np.asarray(Pw)
    return (Pw[:, 0], Pw[-1, :], Pw[:, -1], Pw[0, :])[int(side)]


def triangle_bounds(Pw, tri, vertices=None, method: str = "best") -> np.ndarray:
    """Proven bounds ``(T,)`` of ``max_T |F - L|`` for triangles ``tri (T, 3, 2)`` of the local domain of the
    patch ``Pw`` (``(m + 1, n + 1, 4)``, or ``(T, m + 1, n + 1, 4)`` one per triangle): eqs. (3)-(6) on each
    triangle's bounding box, the smaller of (3) and (4), plus the rounding term. ``vertices (T, 3, 3)`` are the
    triangle's corners in space (default :func:`patch_points` of the domain corners). ``method`` is ``"net"``,
    ``"split"`` (module docstring) or ``"best"``: each of ``M1, M2, M3`` the smaller of the two. Raises
    ValueError where ``w`` is not positive on a box; a triangle without area gets ``inf``.

    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.operations import bezier_patches
    >>> Pw = bezier_patches(sphere())[1][0].homogeneous()
    >>> tri = np.array([[[0, 0], [1, 0], [0, 1]], [[0.4, 0.4], [0.5, 0.4], [0.4, 0.5]]])
    >>> triangle_bounds(Pw, tri).round(4).tolist()  # a whole half patch, a small triangle
    [3.019, 0.0112]
    """
    tri = np.asarray(tri, dtype=np.float64).reshape(-1, 3, 2)
    Pw = np.asarray(Pw, dtype=np.float64)
    T = tri.shape[0]
    m, n = Pw.shape[-3] - 1, Pw.shape[-2] - 1
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    box = np.column_stack([lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1]])
    Q = subdivide(Pw, box)  # (T, m+1, n+1, 4)
    if vertices is None:
        if Pw.ndim == 3:
            vertices = patch_points(Pw, tri.reshape(-1, 2)).reshape(T, 3, 3)
        else:  # one patch per triangle: the tensor-product sum (no side-curve route)
            Bu = bernstein(m, tri[..., 0].ravel()).reshape(T, 3, m + 1)
            Bv = bernstein(n, tri[..., 1].ravel()).reshape(T, 3, n + 1)
            Aw = np.einsum("tki,tkj,tijc->tkc", Bu, Bv, np.broadcast_to(Pw, (T,) + Pw.shape[-3:]))
            vertices = Aw[..., :3] / Aw[..., 3:]
    Fk = np.asarray(vertices, dtype=np.float64).reshape(T, 3, 3)
    c = Fk.mean(axis=1)
    A = Q[..., :3] - c[:, None, None, :] * Q[..., 3:]  # shifted homogeneous coordinates
    w = Q[..., 3]
    # L(s, t) = alpha + beta s + gamma t in the box's local parameters
    size = np.stack([box[:, 1] - box[:, 0], box[:, 3] - box[:, 2]], axis=-1)
    q = (tri - lo[:, None, :]) / size[:, None, :]
    E = np.stack([q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]], axis=-1)  # (T, 2, 2): columns are edge vectors
    D = np.stack([Fk[:, 1] - Fk[:, 0], Fk[:, 2] - Fk[:, 0]], axis=-1)  # (T, 3, 2)
    det = E[:, 0, 0] * E[:, 1, 1] - E[:, 0, 1] * E[:, 1, 0]
    flat = ~(np.abs(det) > 0)  # no area (or a zero box extent): no interpolant
    det = np.where(flat, 1.0, det)
    Einv = np.stack([np.stack([E[:, 1, 1], -E[:, 0, 1]], -1), np.stack([-E[:, 1, 0], E[:, 0, 0]], -1)], 1)
    J = D @ np.where(flat[:, None, None], np.eye(2), Einv / det[:, None, None])  # (T, 3, 2): beta, gamma
    beta, gamma = J[..., 0], J[..., 1]
    alpha = Fk[:, 0] - c - beta * q[:, 0, :1] - gamma * q[:, 0, 1:]
    we = _elevate(_elevate(w[..., None], 1), 2)
    wmin = we.min(axis=(1, 2, 3))
    if not (wmin > 0).all():
        k = int(np.flatnonzero(~(wmin > 0))[0])
        raise ValueError(f"the weights are not positive on triangle {k} (box {box[k].tolist()}): the lower bound of "
                         f"w there is {float(wmin[k])!r}; a patch with non-positive weights has no chord bound.")
    if method not in ("best", "net", "split"):
        raise ValueError(f"method must be 'best', 'net' or 'split', got {method!r}.")
    M = np.full((T, 3), np.inf)
    if method in ("best", "net"):
        G = (_elevate(_elevate(A, 1), 2) - alpha[:, None, None, :] * we
             - beta[:, None, None, :] * _elevate(_times_param(w[..., None], 1), 2)
             - gamma[:, None, None, :] * _elevate(_times_param(w[..., None], 2), 1))
        M = np.minimum(M, _local_bounds(G))
    if method in ("best", "split"):
        MA, Mw = _local_bounds(A), _local_bounds(w[..., None])
        W1 = m * np.abs(np.diff(w, axis=1)).max(axis=(1, 2)) if m else np.zeros(T)
        W2 = n * np.abs(np.diff(w, axis=2)).max(axis=(1, 2)) if n else np.zeros(T)
        Lmax = np.linalg.norm(Fk - c[:, None, :], axis=-1).max(axis=1)
        Lu, Lv = np.linalg.norm(beta, axis=-1), np.linalg.norm(gamma, axis=-1)
        Ms = MA + Mw * Lmax[:, None] + np.stack([2 * W1 * Lu, W1 * Lv + W2 * Lu, 2 * W2 * Lv], axis=-1)
        M = np.minimum(M, Ms)  # each of M1, M2, M3 proven by both routes: the smaller is proven
    Muv = _to_domain(M, box)
    # (3) in the patch's parameters and in the box's (any affine frame will do), (4) with the box
    bound = np.minimum(np.minimum(waldron_bound(tri, Muv), waldron_bound(q, M)),
                       0.125 * (M[:, 0] + 2.0 * M[:, 1] + M[:, 2])) / wmin
    wmax = np.abs(Pw[..., 3]).reshape(Pw.shape[:-3] + (-1,)).max(axis=-1)
    size = np.linalg.norm(Pw[..., :3] / Pw[..., 3:], axis=-1).reshape(Pw.shape[:-3] + (-1,)).max(axis=-1)
    e_g = 4.0 * (m + n + 4) * EPS * wmax * (2.0 * size + np.linalg.norm(alpha, axis=-1)
                                              + np.linalg.norm(beta, axis=-1) + np.linalg.norm(gamma, axis=-1))
    e_f = 4.0 * (m + 1) * (n + 1) * EPS * size * wmax / wmin
    bound = bound + (0.5 * (m + n + 2) ** 2 * e_g + wmax * e_f) / wmin
    return np.where(flat, np.inf, bound)


def curve_chord_bounds(Pw_curve, t) -> np.ndarray:
    """Proven bounds ``(N,)`` of the distance between the rational Bezier curve ``Pw_curve (p + 1, k + 1)``
    (weight last) and its chords over ``[t[i], t[i + 1]]`` (``t`` sorted in ``[0, 1]``), eq. (7), plus the
    rounding term. A polynomial curve (weights equal) gives ``(1/8)(t1 - t0)^2 max |C''|`` of its net.

    >>> round(float(curve_chord_bounds([[0, 0, 1], [1, 2, 1], [2, 0, 1]], [0.0, 1.0])[0]), 12)  # y = 4t(1-t)
    1.0
    """
    Pw = np.asarray(Pw_curve, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    return _chord_bounds_many(Pw[None], np.zeros(t.size - 1, dtype=np.int64), t[:-1], t[1:])


def _curve_points_rows(C: np.ndarray, t) -> np.ndarray:
    """:func:`curve_points` of the curve ``C[k] (p + 1, k + 1)`` at ``t[k]`` for each row ``k`` (same roundings)."""
    B = bernstein(C.shape[1] - 1, t)
    A = B[:, 0, None] * C[:, 0]
    for i in range(1, C.shape[1]):
        A = A + B[:, i, None] * C[:, i]
    return A[:, :-1] / A[:, -1:]


def _chord_bounds_many(nets: np.ndarray, e: np.ndarray, t0, t1) -> np.ndarray:
    """:func:`curve_chord_bounds` of the segments ``[t0[k], t1[k]]`` of the curves ``nets[e[k]]`` (``nets (E, p + 1,
    k + 1)`` of one degree), row by row the same operations: bitwise the bounds of one call per curve."""
    Pw = nets[e]
    p = Pw.shape[1] - 1
    S = _subdivision_matrix(p, t0, t1)
    Q = np.einsum("Nki,Nic->Nkc", S, Pw)  # (N, p+1, k+1)
    F0, F1 = _curve_points_rows(Pw, t0), _curve_points_rows(Pw, t1)
    c = 0.5 * (F0 + F1)
    A = Q[..., :-1] - c[:, None, :] * Q[..., -1:]
    w = Q[..., -1:]
    G = _elevate(A, 1) - (F0 - c)[:, None, :] * _elevate(w, 1) - (F1 - F0)[:, None, :] * _times_param(w, 1)
    wmin = _elevate(w, 1).min(axis=(1, 2))
    if not (wmin > 0).all():
        raise ValueError("the curve's weights are not positive on a segment: it has no chord bound.")
    d2 = np.linalg.norm(G[:, 2:] - 2 * G[:, 1:-1] + G[:, :-2], axis=-1).max(axis=1) if p >= 1 else 0.0
    wmax = np.abs(nets[:, :, -1]).max(axis=1)[e]
    size = np.linalg.norm(nets[:, :, :-1] / nets[:, :, -1:], axis=-1).max(axis=1)[e]
    e_g = 4.0 * (p + 4) * EPS * wmax * (2.0 * size + np.linalg.norm(F0 - c, axis=-1) + np.linalg.norm(F1 - F0, axis=-1))
    e_f = 4.0 * (p + 1) * EPS * size * wmax / wmin
    return 0.125 * (p + 1) * p * d2 / wmin + (0.5 * (p + 2) ** 2 * e_g + wmax * e_f) / wmin

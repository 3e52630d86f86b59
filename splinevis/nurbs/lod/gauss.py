"""Pseudo-Gauss maps of rational Bezier patches, normal cones, spans and the growth of super-surfaces
[Kumar1997, sec. 3].

**The pseudo-Gauss map.** A patch of degree ``(m, n)`` has the homogeneous net ``Q_ij = (w_ij P_ij, w_ij)``;
``Q(u, v) = (A, w)``, ``P = A / w``. The quotient rule gives ``P_u x P_v = G / w^3`` with

``G = w A_u x A_v - w_v A_u x A - w_u A x A_v``  [Kumar1997, eq. (1), numerator],

and ``w^3 > 0`` changes no direction. ``G = T(Q, Q_u, Q_v)`` for the alternating trilinear form
``T(X, Y, Z) = X_w (Y x Z) + Y_w (Z x X) + Z_w (X x Y)`` of 4-vectors (cross products of the first three
components): the minors of the 3x4 matrix ``[Q; Q_u; Q_v]``. Counting gives degree ``(3m - 1, 3n - 1)``, but the
top coefficients cancel: in the homogeneous parameters ``s = 1 - u, t = u`` Euler's identity
``m Q = s Q_s + t Q_t`` and ``Q_u = Q_t - Q_s`` give ``T(Q, Q_u, Q_v) = T(Q_s, Q_t, Q_v) / m`` (``s + t = 1``),
and ``m Q_v = s Q_sv + t Q_tv`` splits that into ``(1 / m^2) [s T(Q_s, Q_t, Q_sv) + t T(Q_s, Q_t, Q_tv)]``.
The same step in ``v`` (``sigma = 1 - v, tau = v``; ``n Q_s = sigma Q_s_sigma + tau Q_s_tau``,
``Q_sv = Q_s_tau - Q_s_sigma``) turns ``T(Q_s, Q_t, Q_sv)`` into ``T(Q_s_sigma, Q_t, Q_s_tau) / n``, likewise for
the ``t`` term, so

``G = (1 / (m^2 n)) [ s T(Q_s_sigma, Q_t, Q_s_tau) + t T(Q_s, Q_t_sigma, Q_t_tau) ]``,

of degree ``(3m - 2, 3n - 2)``, one less per direction than the count (the paper states ``3m x 3n``). The
partials of ``Q`` have the shifted nets as Bernstein coefficients (``Q_s <-> m Q[:-1, :]``,
``Q_t <-> m Q[1:, :]``, ``Q_s_sigma <-> m n Q[:-1, :-1]``, ...), so
``G = m n [ s T(Q00, Q1., Q01) + t T(Q0., Q10, Q11) ]`` with ``Q00 = Q[:-1, :-1]``, ``Q1. = Q[1:, :]`` and so
on, all products of Bernstein forms: exact up to rounding. A polynomial patch
(constant weight ``c``) has ``G = c A_u x A_v = c^3 P_u x P_v`` of degree ``(2m - 1, 2n - 1)``.

**Cones and spans.** ``G(u, v)`` is a positive combination of its coefficients, so a convex cone (half-angle
below ``pi / 2``) holding the coefficients holds every normal of the patch. The *span* of a set of vectors is
the largest angle between two rays through the convex hull of the set [Kumar1997, sec. 3, fig. 3]; when the
largest angle between two of the vectors is below ``pi / 2`` it is the span (the angle to a fixed ray is
quasi-convex along every great-circle arc whose ends are within ``pi / 2`` of that ray, so the maximum sits at
a vertex), otherwise :func:`span` reports ``pi`` (no bound).

**Super-surfaces.** :func:`grow_super_surfaces` is the paper's greedy growth with the span of a group bounded
by twice the half-angle of its merged cone (an upper bound of the exact span, updated in O(1) per added patch
instead of recomputing a hull).
"""

from __future__ import annotations

import heapq
import math
from math import comb
from typing import NamedTuple

import numpy as np

__all__ = ["pseudo_gauss_net", "normal_cone", "span", "merge_cones", "grow_super_surfaces", "SuperSurfaces"]

_CHUNK = 512  # patches per block of the products (keeps the temporaries in the cache, not in GBs)
_NO_CONE = math.pi

# For T(X, Y, Z)_c = sum E[c, a, b, g] X_a Y_b Z_g: component x is the minor of the columns (y, z, w),
# y of (z, x, w), z of (x, y, w).
_E = np.zeros((3, 4, 4, 4))
for _c, _cols in enumerate(((1, 2, 3), (2, 0, 3), (0, 1, 3))):
    for _perm, _sign in (((0, 1, 2), 1), ((1, 2, 0), 1), ((2, 0, 1), 1),
                         ((0, 2, 1), -1), ((2, 1, 0), -1), ((1, 0, 2), -1)):
        _E[_c, _cols[_perm[0]], _cols[_perm[1]], _cols[_perm[2]]] = _sign


def _binom(n: int) -> np.ndarray:
    return np.array([comb(n, i) for i in range(n + 1)], dtype=np.float64)


def _scale(f: np.ndarray, inverse: bool = False) -> np.ndarray:
    """Bernstein coefficients ``f (N, a+1, b+1, ...)`` to the scaled ones ``C(a, i) C(b, j) f_ij`` (the
    coefficients of the monomials ``s^(a-i) t^i sigma^(b-j) tau^j``) or back: a precomputed binomial table."""
    a, b = f.shape[1] - 1, f.shape[2] - 1
    tab = np.multiply.outer(_binom(a), _binom(b)).reshape((1, a + 1, b + 1) + (1,) * (f.ndim - 3))
    return f / tab if inverse else f * tab


def _scaled_mul(fs: np.ndarray, gs: np.ndarray) -> np.ndarray:
    """Product of scaled tensor Bernstein forms ``(N, a+1, b+1, ...)`` and ``(N, c+1, d+1, ...)`` (trailing axes
    broadcast): in the scaled basis the product is a plain convolution [Farin2002, ch. 6]."""
    a, b = fs.shape[1] - 1, fs.shape[2] - 1
    c, d = gs.shape[1] - 1, gs.shape[2] - 1
    shape = np.broadcast_shapes(fs[:, :1, :1].shape, gs[:, :1, :1].shape)
    h = np.zeros((shape[0], a + c + 1, b + d + 1) + shape[3:])
    for i in range(a + 1):
        for j in range(b + 1):
            h[:, i:i + c + 1, j:j + d + 1] += fs[:, i:i + 1, j:j + 1] * gs
    return h


def _trilinear(Xs, Ys, Zs):
    """``T(X, Y, Z)`` of three scaled 4-vector Bernstein forms (N, ., ., 4): scaled (N, ., ., 3)."""
    (a, b), (c, d), (e, f) = Xs.shape[1:3], Ys.shape[1:3], Zs.shape[1:3]
    YZ = np.einsum("cabg,npqbg->npqca", _E, _scaled_mul(Ys[..., :, None], Zs[..., None, :]))  # (N, ., ., 3, 4)
    h = np.zeros((Xs.shape[0], a + c + e - 2, b + d + f - 2, 3))
    for i in range(a):
        for j in range(b):
            h[:, i:i + c + e - 1, j:j + d + f - 1] += np.einsum("na,npqca->npqc", Xs[:, i, j], YZ)
    return h


def _gauss_rational(Q):
    m, n = Q.shape[1] - 1, Q.shape[2] - 1
    F1 = _trilinear(_scale(Q[:, :-1, :-1]), _scale(Q[:, 1:, :]), _scale(Q[:, :-1, 1:]))  # s-term, (3m-3, 3n-2)
    F2 = _trilinear(_scale(Q[:, :-1, :]), _scale(Q[:, 1:, :-1]), _scale(Q[:, 1:, 1:]))   # t-term
    G = np.zeros((Q.shape[0], 3 * m - 1) + F1.shape[2:])
    G[:, :-1] += F1  # in the scaled basis s * s^(a-i) t^i keeps its index i,
    G[:, 1:] += F2   # t * s^(a-i) t^i moves to index i + 1
    return (m * n) * _scale(G, inverse=True)


def _gauss_polynomial(Q):
    m, n = Q.shape[1] - 1, Q.shape[2] - 1
    c = Q[:, 0, 0, 3]
    A = Q[..., :3]
    Au = m * (A[:, 1:] - A[:, :-1])
    Av = n * (A[:, :, 1:] - A[:, :, :-1])
    cyc1, cyc2 = [1, 2, 0], [2, 0, 1]
    Aus, Avs = _scale(Au), _scale(Av)
    G = _scaled_mul(Aus[..., cyc1], Avs[..., cyc2]) - _scaled_mul(Aus[..., cyc2], Avs[..., cyc1])
    return _scale(G, inverse=True) * c[:, None, None, None]


def pseudo_gauss_net(Pw, rational=None) -> np.ndarray:
    """Bezier coefficients of the pseudo-Gauss map ``G = w^3 P_u x P_v`` of each patch [Kumar1997, eq. (1)].

    Parameters
    ----------
    Pw : (N, m+1, n+1, 4) array_like
        Homogeneous nets ``(w x, w y, w z, w)``, weights positive; ``m, n >= 1``.
    rational : bool or None
        False: every patch has a constant weight (then ``G`` has degree ``(2m - 1, 2n - 1)``); True: degree
        ``(3m - 2, 3n - 2)``; None: False when every patch's weights are all equal.

    Returns
    -------
    (N, 3m-1, 3n-1, 3) or (N, 2m, 2n, 3) ndarray
        ``G(u, v) = sum G_kl B_k(u) B_l(v)`` equals ``w^3 S_u x S_v`` of the patch on ``[0, 1]^2``.

    Examples
    --------
    A bilinear patch in the plane z = 0 (polynomial): ``G = P_u x P_v`` of degree (1, 1).

    >>> Pw = np.zeros((1, 2, 2, 4)); Pw[..., 3] = 1.0
    >>> Pw[0, 1, :, 0] = 2.0; Pw[0, :, 1, 1] = 1.0
    >>> pseudo_gauss_net(Pw)[0, :, :, 2]
    array([[2., 2.],
           [2., 2.]])
    >>> pseudo_gauss_net(Pw, rational=True).shape  # the rational formula: degree (3m - 2, 3n - 2)
    (1, 2, 2, 3)
    """
    Q = np.asarray(Pw, dtype=np.float64)
    if Q.ndim != 4 or Q.shape[-1] != 4 or Q.shape[1] < 2 or Q.shape[2] < 2:
        raise ValueError(f"Pw must have shape (N, m+1, n+1, 4) with m, n >= 1, got {Q.shape}.")
    w = Q[..., 3]
    if not (w > 0).all():
        raise ValueError("the weights Pw[..., 3] must be positive (a rational patch with a zero or negative weight "
                         "leaves its control points' hull).")
    constant = bool(np.all(w == w[:, :1, :1]))
    if rational is None:
        rational = not constant
    elif not rational and not constant:
        raise ValueError("rational=False needs a constant weight per patch; use rational=True (or None).")
    fn = _gauss_rational if rational else _gauss_polynomial
    parts = [fn(Q[i:i + _CHUNK]) for i in range(0, Q.shape[0], _CHUNK)]
    if not parts:
        m, n = Q.shape[1] - 1, Q.shape[2] - 1
        return np.zeros((0, 3 * m - 1, 3 * n - 1, 3) if rational else (0, 2 * m, 2 * n, 3))
    return np.concatenate(parts)


def _units(V, rel_zero):
    """Unit vectors (N, K, 3) and the mask of the non-zero ones (relative to each set's largest)."""
    norm = np.sqrt(np.einsum("...i,...i->...", V, V))
    top = norm.max(axis=-1, keepdims=True) if V.shape[-2] else np.zeros(V.shape[:-2] + (1,))
    ok = norm > rel_zero * top
    U = np.where(ok[..., None], V / np.where(ok, norm, 1.0)[..., None], 0.0)
    return U, ok


def _angle(a, b):
    """Angle between vectors along the last axis, accurate for small and large angles."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.einsum("...i,...i->...", a, b))


def normal_cone(vectors, iterations: int = 8, rel_zero: float = 1e-12):
    """Axis and half-angle of a convex cone containing every non-zero vector of each set.

    The axis starts as the normalized sum of the unit vectors and is improved by ``iterations`` steps of the
    1-centre iteration of [BadoiuClarkson2003] on the sphere (move towards the farthest vector by ``1 / (k + 1)``),
    keeping the best; the half-angle is the largest angle to the axis. A half-angle of ``pi / 2`` or more
    (a cone that is no longer convex, so it would not hold the positive combinations), an undefined axis or a
    set without non-zero vectors give half-angle ``pi``: no cone.

    Parameters
    ----------
    vectors : (..., K, 3) array_like
        E.g. the pseudo-Gauss coefficients of patches, ``G.reshape(N, -1, 3)``.
    rel_zero : float
        Vectors shorter than ``rel_zero`` times the longest of their set are ignored (degenerate corners).

    Returns
    -------
    axis : (..., 3) ndarray (unit; zero where there is no cone), half_angle : (...) ndarray

    Examples
    --------
    >>> axis, half = normal_cone([[1.0, 0.0, 1.0], [-1.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    >>> axis.round(12).tolist(), round(float(np.degrees(half)), 9)
    ([0.0, 0.0, 1.0], 45.0)
    >>> float(normal_cone([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])[1])  # opposite vectors: no cone
    3.141592653589793
    """
    V = np.asarray(vectors, dtype=np.float64)
    if V.ndim < 2 or V.shape[-1] != 3:
        raise ValueError(f"vectors must have shape (..., K, 3), got {V.shape}.")
    U, ok = _units(V, rel_zero)
    s = U.sum(axis=-2)
    ns = np.linalg.norm(s, axis=-1)
    good = ns > 1e-9 * np.maximum(ok.sum(axis=-1), 1)
    axis = s / np.where(good, ns, 1.0)[..., None]

    axis0 = axis
    p = U - axis0[..., None, :]  # small vectors when the set is narrow: accurate chords below
    sq = np.einsum("...ki,...ki->...k", p, p)

    def half_of(ax):
        # the farthest vector by chord |u - ax|^2 = |p - delta|^2 (monotone in the angle), delta = ax - axis0
        delta = ax - axis0
        d2 = sq - 2.0 * np.einsum("...ki,...i->...k", p, delta) + np.einsum("...i,...i->...", delta, delta)[..., None]
        d2 = np.where(ok, d2, -1.0)
        far = np.argmax(d2, axis=-1) if U.shape[-2] else np.zeros(ax.shape[:-1], dtype=int)
        fv = np.take_along_axis(U, far[..., None, None], axis=-2)[..., 0, :] if U.shape[-2] else ax * 0
        return _angle(ax, fv), fv

    half, far = half_of(axis)
    cur = axis
    for k in range(1, iterations + 1):
        cur = cur + (far - cur) / (k + 1)
        cur = cur / np.maximum(np.linalg.norm(cur, axis=-1, keepdims=True), 1e-300)
        h, far = half_of(cur)
        better = h < half
        half = np.where(better, h, half)
        axis = np.where(better[..., None], cur, axis)
    no = ~good | (half >= 0.5 * math.pi) | ~ok.any(axis=-1)
    half = np.where(no, _NO_CONE, half + 1e-15)  # + a rounding margin: the cone holds every vector
    axis = np.where(no[..., None], 0.0, axis)
    return axis, (half[()] if half.ndim == 0 else half)


def span(vectors, rel_zero: float = 1e-12):
    """The span of each set of vectors: the largest angle between two rays through their convex hull
    [Kumar1997, sec. 3], exact (the largest pairwise angle, O(K^2) per set) when below ``pi / 2``, else ``pi``.

    Zero vectors (relative ``rel_zero``) are ignored; a set with fewer than two non-zero vectors has span 0.
    For large sets (a whole super-surface) prefer twice the :func:`normal_cone` half-angle, an upper bound.

    Examples
    --------
    >>> round(float(np.degrees(span([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 1.0]]))), 9)
    60.0
    >>> float(span([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.1, 0.0]]))  # wider than a right angle: no bound
    3.141592653589793
    """
    V = np.asarray(vectors, dtype=np.float64)
    if V.ndim < 2 or V.shape[-1] != 3:
        raise ValueError(f"vectors must have shape (..., K, 3), got {V.shape}.")
    lead = V.shape[:-2]
    V = V.reshape((-1,) + V.shape[-2:])
    out = np.zeros(V.shape[0])
    K = V.shape[1]
    step = max(1, 1_000_000 // max(K * K, 1))
    rb = max(1, 1_000_000 // max(K * min(step, V.shape[0]), 1))  # rows per block: bounded memory for big sets
    for i in range(0, V.shape[0], step):
        U, ok = _units(V[i:i + step], rel_zero)
        n = U.shape[0]
        # squared chords |u_k - u_l|^2 (monotone in the angle) from p = u - a, a the normalized mean: a Gram
        # matrix of small vectors, so accurate also for tiny angles
        a = U.sum(axis=1)
        a /= np.maximum(np.linalg.norm(a, axis=-1, keepdims=True), 1e-300)
        p = np.where(ok[..., None], U - a[:, None, :], 0.0)
        sq = (p * p).sum(axis=-1)
        best, bk, bl = np.full(n, -1.0), np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
        for r in range(0, K, rb):
            d2 = sq[:, r:r + rb, None] + sq[:, None, :] - 2.0 * np.matmul(p[:, r:r + rb], p.transpose(0, 2, 1))
            d2 = np.where(ok[:, r:r + rb, None] & ok[:, None, :], d2, -1.0)
            flat = np.argmax(d2.reshape(n, -1), axis=1)
            val = d2.reshape(n, -1)[np.arange(n), flat]
            better = val > best
            k, l = np.divmod(flat, K)
            best, bk, bl = np.where(better, val, best), np.where(better, k + r, bk), np.where(better, l, bl)
        rows = np.arange(n)
        ang = _angle(U[rows, bk], U[rows, bl]) if K else np.zeros(n)
        out[i:i + step] = np.where(best >= 0, ang, 0.0)
    out = np.where(out >= 0.5 * math.pi, _NO_CONE, out).reshape(lead)
    return out[()] if out.ndim == 0 else out


def merge_cones(axis1, half1, axis2, half2):
    """The smallest cone containing two cones (vectorized): its axis lies on the great-circle arc between the
    axes, its half-angle is ``(d + h1 + h2) / 2`` for axes ``d`` apart unless one cone holds the other;
    ``pi`` (no cone) when that reaches ``pi / 2`` or either input is no cone.

    Examples
    --------
    >>> ax, h = merge_cones([1.0, 0.0, 0.0], 0.1, [0.0, 1.0, 0.0], 0.1)
    >>> (ax * np.sqrt(2)).round(12).tolist(), round(float(h), 12)
    ([1.0, 1.0, 0.0], 0.885398163397)
    """
    a1, a2 = (np.asarray(a, dtype=np.float64) for a in (axis1, axis2))
    h1, h2 = (np.asarray(h, dtype=np.float64) for h in (half1, half2))
    d = _angle(a1, a2)
    h = 0.5 * (d + h1 + h2)
    t = h - h1
    sd = np.sin(d)
    tiny = sd < 1e-9
    ax = (np.sin(d - t)[..., None] * a1 + np.sin(t)[..., None] * a2) / np.where(tiny, 1.0, sd)[..., None]
    mid = a1 + a2
    ax = np.where(tiny[..., None], mid / np.maximum(np.linalg.norm(mid, axis=-1, keepdims=True), 1e-300), ax)
    h = np.where(tiny, np.maximum(h1, h2) + d, h)
    in1, in2 = d + h2 <= h1, d + h1 <= h2
    ax = np.where(in1[..., None], a1, np.where(in2[..., None], a2, ax))
    h = np.where(in1, h1, np.where(in2, h2, h + 1e-15))
    no = (h >= 0.5 * math.pi) | (h1 >= 0.5 * math.pi) | (h2 >= 0.5 * math.pi)
    return np.where(no[..., None], 0.0, ax), np.where(no, _NO_CONE, h)


def _merge(a1, h1, a2, h2):
    """:func:`merge_cones` for one pair of Python 3-tuples (the inner loop of the growth)."""
    if h1 >= 0.5 * math.pi or h2 >= 0.5 * math.pi:
        return (0.0, 0.0, 0.0), _NO_CONE
    c = a1[0] * a2[0] + a1[1] * a2[1] + a1[2] * a2[2]
    x = (a1[1] * a2[2] - a1[2] * a2[1], a1[2] * a2[0] - a1[0] * a2[2], a1[0] * a2[1] - a1[1] * a2[0])
    sd = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
    d = math.atan2(sd, c)
    if d + h2 <= h1:
        return a1, h1
    if d + h1 <= h2:
        return a2, h2
    if sd < 1e-9:
        h = max(h1, h2) + d
        ax = (a1[0] + a2[0], a1[1] + a2[1], a1[2] + a2[2])
    else:
        h = 0.5 * (d + h1 + h2)
        t = h - h1
        f1, f2 = math.sin(d - t) / sd, math.sin(t) / sd
        ax = (f1 * a1[0] + f2 * a2[0], f1 * a1[1] + f2 * a2[1], f1 * a1[2] + f2 * a2[2])
        h += 1e-15
    if h >= 0.5 * math.pi:
        return (0.0, 0.0, 0.0), _NO_CONE
    nrm = math.sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2])
    return (ax[0] / nrm, ax[1] / nrm, ax[2] / nrm), h


class SuperSurfaces(NamedTuple):
    """The result of :func:`grow_super_surfaces`.

    ``labels[p]`` is the super-surface of patch ``p``; super-surface ``k`` has the cone ``axis[k]``,
    ``half_angle[k]`` (its span is at most ``2 half_angle[k]``) and the patches ``members[k]`` (in the order
    they were added, the seed first).

    Examples
    --------
    >>> ss = grow_super_surfaces(([[0.0, 0.0, 1.0]] * 2, [0.0, 0.0]), [[1, -1, -1, -1], [0, -1, -1, -1]], 0.1)
    >>> ss.labels.tolist(), [m.tolist() for m in ss.members]
    ([0, 0], [[0, 1]])
    """

    labels: np.ndarray
    axis: np.ndarray
    half_angle: np.ndarray
    members: list


def grow_super_surfaces(cones_or_vectors, neighbours, alpha: float) -> SuperSurfaces:
    """Partition patches into super-surfaces of span at most ``alpha`` by greedy growth [Kumar1997, sec. 3].

    From a seed, repeatedly add the adjacent unassigned patch whose addition gives the smallest span (steps
    1a, c-f); when that smallest span exceeds ``alpha`` the super-surface is complete (1b) and the next seed
    starts one (2). The span of a group is bounded by twice the half-angle of its cone, merged incrementally
    with :func:`merge_cones` (the smallest cone holding the group's cone and the patch's cone), so every
    super-surface of more than one patch has span <= ``alpha``; a seed wider than ``alpha`` (or without a cone)
    stays alone. Candidates sit in a priority queue with lazy re-evaluation: a key computed against an older,
    smaller cone is a lower bound, so a popped candidate is re-merged with the current cone and accepted only
    if it is still no worse than the next key.

    Seeds are deterministic: the flattest unassigned patch first (smallest cone half-angle, then lowest index),
    so super-surfaces start in flat regions rather than on creases.

    Parameters
    ----------
    cones_or_vectors : (axis (P, 3), half_angle (P,)) or (P, K, 3) array_like
        Per-patch normal cones (:func:`normal_cone`), or per-patch vectors (pseudo-Gauss coefficients) to make
        them from.
    neighbours : (P, k) int array_like
        Adjacent patches per side, ``-1`` for none (e.g. the four sides of each patch).
    alpha : float
        The largest span of a super-surface, radians.

    Examples
    --------
    A strip of four patches whose normals turn by 10 degrees each, grown with alpha = 25 degrees:

    >>> ang = np.radians([0.0, 10.0, 20.0, 30.0])
    >>> axes = np.stack([np.sin(ang), 0 * ang, np.cos(ang)], axis=1)
    >>> nb = [[1, -1], [0, 2], [1, 3], [2, -1]]
    >>> ss = grow_super_surfaces((axes, np.zeros(4)), nb, np.radians(25.0))
    >>> ss.labels.tolist(), np.degrees(2 * ss.half_angle).round(6).tolist()
    ([0, 0, 0, 1], [20.0, 0.0])
    """
    if isinstance(cones_or_vectors, tuple) and len(cones_or_vectors) == 2:
        axes = np.asarray(cones_or_vectors[0], dtype=np.float64)
        halves = np.asarray(cones_or_vectors[1], dtype=np.float64)
    else:
        V = np.asarray(cones_or_vectors, dtype=np.float64)
        axes, halves = normal_cone(V.reshape(V.shape[0], -1, 3))
    P = halves.shape[0]
    nb = np.asarray(neighbours, dtype=np.int64).reshape(P, -1)
    if axes.shape != (P, 3) or (nb.size and (nb.max() >= P or nb.min() < -1)):
        raise ValueError(f"need axes (P, 3), half-angles (P,) and neighbours (P, k) of indices in [-1, P), P = {P}.")
    limit = 0.5 * float(alpha)
    ax_list = [tuple(a) for a in axes.tolist()]
    h_list = halves.tolist()
    nb_list = [[j for j in row if j >= 0] for row in nb.tolist()]
    labels = np.full(P, -1, dtype=np.int64)
    assigned = [False] * P
    seen = [-1] * P  # super-surface that last queued the patch
    out_axes, out_halves, members = [], [], []
    for seed in np.lexsort((np.arange(P), halves)).tolist():
        if assigned[seed]:
            continue
        k = len(members)
        cax, ch = ax_list[seed], h_list[seed]
        group = [seed]
        assigned[seed] = True
        seen[seed] = k
        heap = []
        version = 0

        def push(p, _k=k):
            for j in nb_list[p]:
                if not assigned[j] and seen[j] != _k:
                    seen[j] = _k
                    _, h = _merge(cax, ch, ax_list[j], h_list[j])
                    heapq.heappush(heap, (h, j, version))

        if ch <= limit:
            push(seed)
        while heap:
            key, j, ver = heapq.heappop(heap)
            if key > limit:
                break  # a lower bound above the limit: the smallest span exceeds alpha (step 1b)
            if assigned[j]:
                continue
            nax, nh = _merge(cax, ch, ax_list[j], h_list[j])
            if ver != version:  # keyed against an older cone: re-queue unless still the smallest
                if heap and nh > heap[0][0]:
                    heapq.heappush(heap, (nh, j, version))
                    continue
            if nh > limit:
                break
            if nh != ch or nax != cax:
                version += 1
            cax, ch = nax, nh
            assigned[j] = True
            group.append(j)
            push(j)
        labels[group] = k
        out_axes.append(cax)
        out_halves.append(ch)
        members.append(np.array(group, dtype=np.int64))
    return SuperSurfaces(labels, np.array(out_axes, dtype=np.float64).reshape(-1, 3),
                         np.array(out_halves, dtype=np.float64), members)

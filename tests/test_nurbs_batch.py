"""Many patches and trim curves evaluated together (splinevis.nurbs.batch), and the passes built on them (the
inside test of many patches at once, every piece's sample parameters at once): the same values as one patch,
one curve, one piece at a time -- points bit for bit, derivatives within the rounding of summing their terms
in another order."""

import numpy as np

from splinevis.nurbs import NurbsSurface, TrimCurve
from splinevis.nurbs.basis import ders_basis_funs, find_span
from splinevis.nurbs.batch import CurveBatch, SurfaceBatch
from splinevis.nurbs.exact import CIRCLE_KNOTS, circle_net, sphere, torus
from splinevis.nurbs.shell_volume import _params_many, _piece_params, signed_volumes
from splinevis.nurbs.trim import inside, inside_many, trim_pieces

U = 2.0 ** -53  # unit roundoff [Higham2002, sec. 2.1]
RNG = np.random.default_rng(5)


def _random_surface(p, q, nu, nv, rational):
    """Clamped, with repeated and unevenly spaced inner knots."""
    def knots(d, n):
        inner = np.sort(RNG.uniform(0.0, 3.0, n - d - 1))
        if inner.size > 1 and d > 1:
            inner[1] = inner[0]  # a double knot
        return np.r_[[0.0] * (d + 1), inner, [3.0] * (d + 1)]

    w = RNG.uniform(0.5, 2.0, (nu, nv)) if rational else None
    return NurbsSurface((p, q), (knots(p, nu), knots(q, nv)), RNG.normal(size=(nu, nv, 3)) * 10, w)


def _surfaces():
    return [sphere(), torus(), _random_surface(3, 2, 7, 5, True), _random_surface(1, 3, 4, 6, False),
            _random_surface(3, 2, 6, 4, False), _random_surface(2, 2, 3, 3, True)]


def _params(surfaces, n):
    """``n`` parameters a patch, the knots themselves and the domain's ends among them."""
    face, u, v = [], [], []
    for k, s in enumerate(surfaces):
        (u0, u1), (v0, v1) = s.domain
        uu, vv = RNG.uniform(u0, u1, n), RNG.uniform(v0, v1, n)
        ku = s.knots[0][(s.knots[0] >= u0) & (s.knots[0] <= u1)]
        kv = s.knots[1][(s.knots[1] >= v0) & (s.knots[1] <= v1)]
        uu[: ku.size], vv[-kv.size:] = ku, kv
        face.append(np.full(n, k))
        u.append(uu)
        v.append(vv)
    return np.concatenate(face), np.concatenate(u), np.concatenate(v)


def test_points_are_each_patch_s_bit_for_bit_and_spans_are_find_span_s():
    surfaces = _surfaces()
    face, u, v = _params(surfaces, 40)
    order = RNG.permutation(face.size)  # the points in any order
    face, u, v = face[order], u[order], v[order]
    b = SurfaceBatch(surfaces)
    P = b.evaluate(face, u, v)
    for k, s in enumerate(surfaces):
        sel = face == k
        assert np.array_equal(P[sel], s.evaluate(u[sel], v[sel]))
        assert np.array_equal(b.U.spans(face[sel], u[sel]) - b.U.off[k], find_span(s.degree[0], s.knots[0], u[sel]))


def _sum_bound(s, u, v, order):
    """Bound on how far two orders of summation of a non-rational patch's derivatives may part. The
    homogeneous sums ``A^(k,l) = sum_a sum_b N_a^(k) N_b^(l) (P_ab, 1)`` each err by at most gamma_(p+q+2)
    times the sum of their terms' sizes [Higham2002, sec. 3.1] (twice that between two orders); the weight's
    sums (exactly 1 and 0) carry such errors into the quotient rule ``S^(k,l) = (A^(k,l) - sum binom(k, i)
    binom(l, j) w^(i,j) S^(k-i,l-j)) / w`` [PieglTiller1997, eq. (4.20)], to first order."""
    from math import comb

    (p, q), (Uk, Vk) = s.degree, s.knots
    su, sv = find_span(p, Uk, u), find_span(q, Vk, v)
    Nu, Nv = np.abs(ders_basis_funs(su, u, p, order, Uk)), np.abs(ders_basis_funs(sv, v, q, order, Vk))
    net = np.abs(s.control_points)[(su[:, None] - p + np.arange(p + 1))[:, :, None],
                                   (sv[:, None] - q + np.arange(q + 1))[:, None, :]]
    m = p + q + 2
    g = 2 * m * U / (1 - m * U)
    dA = g * np.einsum("mka,mlb,mabc->mklc", Nu, Nv, net)
    dw = g * np.einsum("mka,mlb->mkl", Nu, Nv)
    S = np.abs(s.derivatives(u, v, order))
    out = np.zeros_like(dA)
    for k in range(order + 1):
        for l in range(order + 1 - k):
            out[:, k, l] = dA[:, k, l] + sum(comb(k, i) * comb(l, j) * dw[:, i, j, None] * S[:, k - i, l - j]
                                             for i in range(k + 1) for j in range(l + 1))
    return out * (1 + 8 * g)  # the division by w and the products of the correction, each a rounding more


def test_derivatives_are_each_patch_s_to_the_rounding_of_their_sums():
    surfaces = [s for s in _surfaces() if s.weights is None]
    face, u, v = _params(surfaces, 60)
    D = SurfaceBatch(surfaces).derivatives(face, u, v, 2)
    for k, s in enumerate(surfaces):
        sel = face == k
        bound = _sum_bound(s, u[sel], v[sel], 2)
        assert (np.abs(D[sel] - s.derivatives(u[sel], v[sel], 2)) <= bound).all()


def test_grid_derivatives_are_the_points_derivatives():
    """The tensor grid of each patch (its rows contracted once) against the same points one by one, on the
    kept cells only, in u-major order."""
    surfaces = [s for s in _surfaces() if s.weights is None]
    g, h = 7, 5
    us = np.array([np.sort(RNG.uniform(*s.domain[0], g)) for s in surfaces])
    vs = np.array([np.sort(RNG.uniform(*s.domain[1], h)) for s in surfaces])
    us[:, 0] = [s.domain[0][0] for s in surfaces]
    vs[:, -1] = [s.domain[1][1] for s in surfaces]
    keep = RNG.random((len(surfaces), g, h)) < 0.6
    faces = np.arange(len(surfaces))[::-1]  # any order of patches
    D = SurfaceBatch(surfaces).grid_derivatives(faces, us, vs, keep, 1)
    k, i, j = np.nonzero(keep)
    f, u, v = faces[k], us[k, i], vs[k, j]
    assert D.shape == (keep.sum(), 2, 2, 3)
    for patch, s in enumerate(surfaces):
        sel = f == patch
        ref = s.derivatives(u[sel], v[sel], 1)
        assert (np.abs(D[sel] - ref) <= _sum_bound(s, u[sel], v[sel], 1)).all()


def _curves():
    xy, w = circle_net()
    return [TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.3 * xy, w), TrimCurve(1, [0, 0, 1, 1], [[0, 0], [1, 0]]),
            TrimCurve(3, [0, 0, 0, 0, 0.4, 0.4, 1, 1, 1, 1], RNG.normal(size=(6, 2))),
            TrimCurve(2, [2, 2, 2, 3, 5, 5, 5], RNG.normal(size=(4, 2)), RNG.uniform(0.5, 2, 4))]


def test_curve_points_are_each_curve_s_bit_for_bit():
    curves = _curves()
    idx = np.repeat(np.arange(len(curves)), 30)
    t = np.concatenate([np.r_[c.domain[0], c.knots[c.degree + 1:-c.degree - 1], c.domain[1],
                              RNG.uniform(*c.domain, 30)][:30] for c in curves])
    P = CurveBatch(curves).evaluate(idx, t)
    for k, c in enumerate(curves):
        assert np.array_equal(P[idx == k], c.evaluate(t[idx == k]))


def test_inside_many_is_inside_patch_by_patch():
    xy, w = circle_net()
    border = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in
              [((0, 0), (1, 0)), ((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))]]
    hole = [TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.3 * xy, w)]
    pieces = trim_pieces([[border, hole], None, [hole]])
    patch = RNG.integers(0, 3, 3000)
    u, v = RNG.uniform(-0.1, 1.1, 3000), RNG.uniform(-0.1, 1.1, 3000)
    u[:40], v[:40] = 0.5 + 0.3 * xy[:, 0].repeat(5)[:40], 0.5  # on the loops' rows
    got = inside_many(pieces, patch, u, v, pairs=997)  # chunks that cut through a point's pairs
    for k in range(3):
        assert np.array_equal(got[patch == k], inside(pieces, k, u[patch == k], v[patch == k]))


def test_every_piece_s_parameters_at_once_are_each_piece_s():
    breaks = [np.sort(RNG.uniform(0, 5, RNG.integers(2, 7))) for _ in range(50)]
    ns = RNG.integers(1, 300, 50)
    t, piece = _params_many(breaks, ns)
    ref = [_piece_params(b, n) for b, n in zip(breaks, ns)]
    assert np.array_equal(t, np.concatenate(ref))
    assert np.array_equal(piece, np.repeat(np.arange(50), [len(r) for r in ref]))


def test_signed_volumes_of_all_faces_at_once_are_each_face_s():
    """Untrimmed faces (Gauss nodes) and trimmed ones (the midpoint grid over their loops, masked by the inside
    test) of different degrees, all together: each face's share is what it gets alone, bit for bit."""
    s = sphere()
    (u0, u1), (v0, v1) = s.domain
    border = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in
              [((u0, v0), (u1, v0)), ((u1, v0), (u1, v1)), ((u1, v1), (u0, v1)), ((u0, v1), (u0, v0))]]
    xy, w = circle_net()
    plane = _random_surface(3, 2, 6, 4, False)
    (a0, a1), (b0, b1) = plane.domain
    hole = [TrimCurve(2, CIRCLE_KNOTS, [0.5 * (a0 + a1), 0.5 * (b0 + b1)] + 0.3 * xy, w)]
    surfaces = [s, torus(), plane, s]
    trims = [[border], None, [[TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in
                               [((a0, b0), (a1, b0)), ((a1, b0), (a1, b1)), ((a1, b1), (a0, b1)), ((a0, b1), (a0, b0))]],
                              hole], None]
    V = signed_volumes(surfaces, trims, center=[0.1, 0.2, 0.3])
    alone = [signed_volumes([f], [t] if t else None, center=[0.1, 0.2, 0.3])[0] for f, t in zip(surfaces, trims)]
    assert np.array_equal(V, alone)

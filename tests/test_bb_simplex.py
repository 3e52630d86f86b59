"""Bernstein-Bezier form on simplices: exact values, identities, properties, bad input."""

from math import comb

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from splinevis.bb import (
    bernstein_basis, blossom, de_casteljau, derivative, elevate, gradient, index_of, multi_indices,
    num_coefficients, restrict_to_segment, subdivide,
)

EPS = np.finfo(float).eps


def bary(rng, d, size=None):
    return rng.dirichlet(np.ones(d + 1), size=size)


def test_multi_indices_order_univariate_and_triangle():
    assert multi_indices(3, 1).tolist() == [[3, 0], [2, 1], [1, 2], [0, 3]]
    assert multi_indices(4, 2)[:6].tolist() == [[4, 0, 0], [3, 1, 0], [3, 0, 1], [2, 2, 0], [2, 1, 1], [2, 0, 2]]
    assert multi_indices(4, 2).shape == (15, 3)
    assert multi_indices(20, 3).shape == (comb(23, 3), 4)
    assert multi_indices(0, 3).tolist() == [[0, 0, 0, 0]]
    idx = index_of(4, 2)
    assert all(idx[tuple(a)] == q for q, a in enumerate(multi_indices(4, 2).tolist()))
    assert num_coefficients(4, 3) == 35


def test_univariate_coefficient_k_is_Bk():
    # B^3_k(1/2) = C(3,k)/8, and coefficient k multiplies (1-t)^(3-k) t^k
    t = 0.25
    for k in range(4):
        c = np.zeros(4)
        c[k] = 1.0
        assert de_casteljau(c, [1 - t, t], d=1) == pytest.approx(comb(3, k) * (1 - t) ** (3 - k) * t**k, abs=1e-16)
    assert np.array_equal(bernstein_basis(3, 1, [0.5, 0.5]), np.array([1, 3, 3, 1]) / 8)


def test_exact_values_by_hand():
    # f = B^2_(1,1,0)*2 + ... : triangle quadratic with c = multi-index "x^2 y^0" coefficients
    c = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])  # (2,0,0),(1,1,0),(1,0,1),(0,2,0),(0,1,1),(0,0,2)
    lam = np.array([0.5, 0.25, 0.25])
    expect = (1 * 0.25 + 2 * 2 * 0.125 + 3 * 2 * 0.125 + 4 * 0.0625 + 5 * 2 * 0.0625 + 6 * 0.0625)
    assert de_casteljau(c, lam, d=2) == expect  # all dyadic: exact
    # at a vertex the value is the corner coefficient
    assert de_casteljau(c, [0, 0, 1], d=2) == 6.0


@pytest.mark.parametrize("d", [1, 2, 3])
@pytest.mark.parametrize("n", [0, 1, 2, 4, 7])
def test_partition_of_unity_and_evaluation(d, n):
    rng = np.random.default_rng(n + 10 * d)
    lam = bary(rng, d, 50)
    B = bernstein_basis(n, d, lam)
    assert np.all(B >= 0)
    np.testing.assert_allclose(B.sum(-1), 1.0, rtol=0, atol=8 * EPS * (n + 1))
    c = rng.normal(size=(50, num_coefficients(n, d)))
    # de Casteljau error bound gamma_{(d+1) n} sum |c| B (each level: d+1 products, d sums)
    bound = 2 * (d + 1) * max(n, 1) * EPS * (np.abs(c) * B).sum(-1) + 1e-300
    assert np.all(np.abs(de_casteljau(c, lam, d=d) - (c * B).sum(-1)) <= bound)


@settings(max_examples=40, deadline=None)
@given(d=st.integers(1, 3), n=st.integers(1, 6), seed=st.integers(0, 2**32 - 1))
def test_blossom_symmetry_diagonal_and_multiaffinity(d, n, seed):
    rng = np.random.default_rng(seed)
    c = rng.normal(size=num_coefficients(n, d))
    pts = [bary(rng, d) for _ in range(n)]
    scale = np.abs(c).sum()
    b = blossom(c, pts, d=d)
    perm = rng.permutation(n)
    assert blossom(c, [pts[i] for i in perm], d=d) == pytest.approx(b, abs=64 * n * EPS * scale)
    lam = pts[0]
    assert blossom(c, [lam] * n, d=d) == pytest.approx(de_casteljau(c, lam, d=d), abs=64 * n * EPS * scale)
    # affine in the first argument
    q = bary(rng, d)
    a = 0.3
    mix = blossom(c, [(1 - a) * pts[0] + a * q] + pts[1:], d=d)
    lin = (1 - a) * b + a * blossom(c, [q] + pts[1:], d=d)
    assert mix == pytest.approx(lin, abs=128 * n * EPS * scale)


@settings(max_examples=40, deadline=None)
@given(d=st.integers(1, 3), n=st.integers(0, 6), seed=st.integers(0, 2**32 - 1))
def test_elevation_preserves_values(d, n, seed):
    rng = np.random.default_rng(seed)
    c = rng.normal(size=(3, num_coefficients(n, d)))
    e = elevate(c, d=d)
    assert e.shape == (3, num_coefficients(n + 1, d))
    lam = bary(rng, d, 3)
    np.testing.assert_allclose(de_casteljau(e, lam, d=d), de_casteljau(c, lam, d=d), rtol=0,
                               atol=64 * (n + 1) * EPS * np.abs(c).sum())


@settings(max_examples=30, deadline=None)
@given(d=st.integers(1, 3), n=st.integers(1, 5), seed=st.integers(0, 2**32 - 1))
def test_subdivision_reproduces_values(d, n, seed):
    rng = np.random.default_rng(seed)
    c = rng.normal(size=num_coefficients(n, d))
    scale = np.abs(c).sum()
    if d == 1:
        t = rng.uniform(0.05, 0.95)
        left, right = subdivide(c, t, d=1)
        for s in (0.0, 0.3, 1.0):
            assert de_casteljau(left, [1 - s, s], d=1) == pytest.approx(de_casteljau(c, [1 - s * t, s * t], d=1), abs=64 * n * EPS * scale)
            u = t + s * (1 - t)
            assert de_casteljau(right, [1 - s, s], d=1) == pytest.approx(de_casteljau(c, [1 - u, u], d=1), abs=64 * n * EPS * scale)
        return
    p = bary(rng, d)
    subs = subdivide(c, p, d=d)
    assert len(subs) == d + 1
    eye = np.eye(d + 1)
    for i, sub in enumerate(subs):
        mu = bary(rng, d)  # a point in sub-simplex i, in its own barycentric coordinates
        verts = np.array([p if j == i else eye[j] for j in range(d + 1)])
        lam = mu @ verts
        assert de_casteljau(sub, mu, d=d) == pytest.approx(de_casteljau(c, lam, d=d), abs=256 * n * EPS * scale)


def test_subdivision_univariate_exact():
    # c = (0, 0, 1): f = t^2; left half [0, 1/2] is (s/2)^2 = s^2 / 4 -> (0, 0, 1/4)
    left, right = subdivide([0.0, 0.0, 1.0], 0.5, d=1)
    assert left.tolist() == [0.0, 0.0, 0.25]
    assert right.tolist() == [0.25, 0.5, 1.0]


@pytest.mark.parametrize("d", [1, 2, 3])
def test_derivative_vs_finite_differences(d):
    rng = np.random.default_rng(5)
    n = 4
    c = rng.normal(size=(20, num_coefficients(n, d)))
    lam = bary(rng, d, 20)
    u = bary(rng, d, 20) - lam  # a direction: components sum to 0
    dc = derivative(c, u, d=d)
    assert dc.shape == (20, num_coefficients(n - 1, d))
    h = 1e-3
    fd = (de_casteljau(c, lam + h * u, d=d) - de_casteljau(c, lam - h * u, d=d)) / (2 * h)
    # central difference error h^2/6 |f'''| <= h^2/6 * n(n-1)(n-2) * 2^3 max|c| * |u|_1^3 (Bernstein bound)
    trunc = h**2 / 6 * n * (n - 1) * (n - 2) * 8 * np.abs(c).max(-1) * np.abs(u).sum(-1) ** 3
    np.testing.assert_array_less(np.abs(de_casteljau(dc, lam, d=d) - fd), trunc + 1e-10)
    g = gradient(c, d=d)
    assert g.shape == (20, d + 1, num_coefficients(n - 1, d))
    np.testing.assert_allclose(np.einsum("mi,mik->mk", u, g), dc, atol=1e-13)


def test_derivative_exact_univariate():
    # f = t^2 -> f' = 2t, coefficients (0, 2) of degree 1
    assert derivative([0.0, 0.0, 1.0], [-1.0, 1.0], d=1).tolist() == [0.0, 2.0]
    assert derivative([3.0], [-1.0, 1.0], d=1).tolist() == [0.0]


@settings(max_examples=40, deadline=None)
@given(d=st.integers(1, 3), n=st.integers(0, 6), seed=st.integers(0, 2**32 - 1))
def test_restriction_equals_evaluation_along_segment(d, n, seed):
    rng = np.random.default_rng(seed)
    c = rng.normal(size=(2, num_coefficients(n, d)))
    l0 = rng.normal(size=(2, d + 1)) * 0.3 + bary(rng, d, 2)
    l0 /= l0.sum(-1, keepdims=True)
    l1 = bary(rng, d, 2)
    r = restrict_to_segment(c, l0, l1, d=d)
    assert r.shape == (2, n + 1)
    # rounding scale: every blossom/de Casteljau term is bounded by sum|c| * max(|l0|_1, |l1|_1)^n
    scale = np.abs(c).sum() * max(np.abs(l0).sum(-1).max(), np.abs(l1).sum(-1).max()) ** n
    for s in (0.0, 0.2, 0.75, 1.0):
        lam = (1 - s) * l0 + s * l1
        np.testing.assert_allclose(de_casteljau(r, [1 - s, s], d=1), de_casteljau(c, lam, d=d), rtol=0,
                                   atol=64 * (n + 1) * EPS * scale)


def test_restriction_blossom_formula():
    rng = np.random.default_rng(1)
    c = rng.normal(size=15)
    l0, l1 = bary(rng, 2), bary(rng, 2)
    r = restrict_to_segment(c, l0, l1, d=2)
    for k in range(5):
        assert r[k] == pytest.approx(blossom(c, [l0] * (4 - k) + [l1] * k, d=2), abs=1e-14)


def test_broadcasting_over_patches():
    rng = np.random.default_rng(2)
    c = rng.normal(size=(4, 1, 10))  # 4 cubic triangle patches
    lam = bary(rng, 2, (1, 6))
    v = de_casteljau(c, lam, d=2)
    assert v.shape == (4, 6)
    assert v[2, 3] == pytest.approx(de_casteljau(c[2, 0], lam[0, 3], d=2))


def test_bad_inputs():
    with pytest.raises(ValueError, match=r"coefficients must have finite values; found 1 non-finite, the first (np\.float64\()?nan\)? at index \(1, 2\)"):
        de_casteljau(np.array([[0, 1, 2], [0, 1, np.nan]]), [0.5, 0.5], d=1)
    with pytest.raises(ValueError, match=r"C\(n\+2,2\) entries .* got 7"):
        de_casteljau(np.zeros(7), [0.2, 0.3, 0.5], d=2)
    with pytest.raises(ValueError, match=r"lam must be barycentric coordinates of shape \(\.\.\., 3\)"):
        de_casteljau(np.zeros(6), [0.5, 0.5], d=2)
    with pytest.raises(ValueError, match="must sum to 1"):
        de_casteljau(np.zeros(6), [0.5, 0.5, 0.5], d=2)
    with pytest.raises(ValueError, match=r"degree n must be in 0\.\.20, got 21"):
        multi_indices(21, 2)
    with pytest.raises(ValueError, match=r"simplex dimension d must be in 1\.\.3, got 4"):
        multi_indices(2, 4)
    with pytest.raises(TypeError, match="degree n must be an integer"):
        multi_indices(2.5, 1)
    with pytest.raises(ValueError, match="components summing to 0"):
        derivative(np.zeros(3), [1.0, 1.0], d=1)
    with pytest.raises(ValueError, match=r"exactly n = 2 barycentric points"):
        blossom(np.zeros(3), [[0.5, 0.5]], d=1)
    with pytest.raises(TypeError, match="coefficients must be an array of real numbers"):
        de_casteljau(["a", "b"], [0.5, 0.5], d=1)
    with pytest.raises(ValueError, match="lam1 must have finite values"):
        restrict_to_segment(np.zeros(6), [1, 0, 0], [np.inf, 0, 0], d=2)

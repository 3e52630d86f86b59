"""Terrain spline schemes (splinevis.terrain): smoothness across every interior edge, polynomial
reproduction, approximation order on Franke's function, the C1 derivation, and input checks.

Error bounds are derived from float64 rounding (unit roundoff u = 2^-53, gamma_m = m u / (1 - m u)):

* A coefficient is a dot product of S weights with heights: |error| <= gamma_(S+1) * L * Mz, where
  L = max_q sum_s |W[s, q]| (the weights are rounded once, hence S + 1) and Mz = max |padded heights|.
* The C1 weights solve their derivation system only up to its float residual rho; a coefficient relation
  (an edge condition or the exactness of a coefficient) then fails by at most rho * S_union * Mz with
  S_union <= 2 S offsets involved.
* A k-th derivative along x or y of a quartic is a combination of coefficients with absolute weight sum
  at most D_k = 4!/(4-k)! * 2^k (each step: n times differences with barycentric direction weights summing
  to 2 in absolute value), and de Casteljau adds at most gamma_(3n+2k) D_k * max|c| [Farin2002, ch. 17.3; Higham2002, sec. 3.4].
* A jump is a difference of two evaluations: twice the one-sided bound.
"""

from __future__ import annotations

from math import factorial

import numpy as np
import pytest

from datasets_synthetic.franke import franke
from splinevis.bb import simplex as bb
from splinevis.terrain import (
    C1_STENCIL,
    SCHEMES,
    c1_system,
    evaluate,
    gradient,
    resample_for_c0,
    scheme_stencil,
    terrain_coefficients,
)
from splinevis.terrain import schemes as ts

U = 2.0**-53
N = 4  # degree


def gamma(m):
    return m * U / (1 - m * U)


def padded_max(z, scheme):
    if scheme == "C2-interp":  # the C2 stencil on the prefiltered heights
        from splinevis.terrain.interpolating import prefilter_heights

        z, scheme = prefilter_heights(np.asarray(z, float)), "C2"
    st = ts._BUILDERS[scheme]()
    return float(np.abs(ts._pad_cubic(np.asarray(z, float), *st.pads())).max())


def coef_error(scheme, mz):
    """Bound on |computed coefficient - exact linear map of the (padded) heights|."""
    offs, W = scheme_stencil("C2" if scheme == "C2-interp" else scheme)
    S = len(offs)
    L = float(np.abs(W).sum(axis=0).max())
    err = gamma(S + 1) * L * mz
    if scheme == "C1":
        diag = ts._c1_solution()[1]
        err += max(diag["smoothness_residual"], diag["exactness_residual"]) * 2 * S * mz
    return err, L


def eval_bound(scheme, mz, k):
    """One-sided bound on the rounding error of a k-th derivative value (index units, cell size 1)."""
    dc, L = coef_error(scheme, mz)
    dk = factorial(N) // factorial(N - k) * 2**k
    return dk * (dc + gamma(3 * N + 2 * k) * L * mz)


# --------------------------------------------------------------------------------------------------
# edge sampling: both one-sided polynomials at points of every interior edge
# --------------------------------------------------------------------------------------------------

DLAM = {0: (np.array([-1.0, 1.0, 0.0]), np.array([0.0, -1.0, 1.0])),
        1: (np.array([0.0, 1.0, -1.0]), np.array([-1.0, 0.0, 1.0]))}
SAMPLES = np.array([0.0, 0.125, 0.375, 0.5, 0.75, 1.0])  # dyadic: exact points on the edge


def derivs(c, t, lam, k):
    """All k-th partial derivatives (x^a y^(k-a), a = k..0) of patches c (..., 15) of triangle t at lam."""
    out = []
    for a in range(k, -1, -1):
        cc = c
        for _ in range(a):
            cc = bb.derivative(cc, DLAM[t][0], d=2)
        for _ in range(k - a):
            cc = bb.derivative(cc, DLAM[t][1], d=2)
        out.append(bb.de_casteljau(cc, np.broadcast_to(lam, cc.shape[:-1] + (3,)), d=2))
    return np.stack(out, axis=-1)


def bary(t, p):
    x, y = p
    return np.array([1 - y, x, y - x]) if t == 1 else np.array([1 - x, x - y, y])


def edge_jumps(coef, k):
    """Max |jump| of the k-th derivatives over all interior edges (diagonal, horizontal, vertical)."""
    ncy, ncx = coef.shape[:2]
    worst = 0.0
    for s in SAMPLES:
        # diagonal: T0 and T1 of the same cell, point (s, s)
        a = derivs(coef[:, :, 0], 0, bary(0, (s, s)), k)
        b = derivs(coef[:, :, 1], 1, bary(1, (s, s)), k)
        worst = max(worst, np.abs(a - b).max())
        # horizontal: T0 of (i, j) at (s, 0) vs T1 of (i, j - 1) at (s, 1)
        a = derivs(coef[1:, :, 0], 0, bary(0, (s, 0.0)), k)
        b = derivs(coef[:-1, :, 1], 1, bary(1, (s, 1.0)), k)
        worst = max(worst, np.abs(a - b).max())
        # vertical: T0 of (i, j) at (1, s) vs T1 of (i + 1, j) at (0, s)
        a = derivs(coef[:, :-1, 0], 0, bary(0, (1.0, s)), k)
        b = derivs(coef[:, 1:, 1], 1, bary(1, (0.0, s)), k)
        worst = max(worst, np.abs(a - b).max())
    return worst


def random_grid(scheme, seed=0):
    n = 13 if scheme == "C0" else 12  # C0 needs sizes 4k + 1
    return np.random.default_rng(seed).uniform(-3.0, 5.0, (n, n))


@pytest.mark.parametrize("scheme", SCHEMES)
def test_smooth_across_every_interior_edge(scheme):
    z = random_grid(scheme)
    coef, info = terrain_coefficients(z, scheme)
    mz = padded_max(z, scheme)
    for k in range(info.smoothness + 1):
        jump = edge_jumps(coef, k)
        bound = 2 * eval_bound(scheme, mz, k)
        assert jump <= bound, (scheme, k, jump, bound)
    # negative control: the next derivative order does jump for generic data (the test can fail)
    k = info.smoothness + 1
    assert edge_jumps(coef, k) > 1e-3 * mz


def test_box_spline_table_identities():
    """The C2 weights satisfy the C0, C1, C2 edge conditions and linear exactness as identities, the
    translates sum to one, M(0) = 1/2 and M = 1/12 at the 6 mesh neighbours."""
    offs, W = scheme_stencil("C2")
    A, rhs, _ = c1_system(tuple(offs), smoothness=2, reproduce=1)
    w = W.reshape(-1)
    # each row has at most 30 nonzeros; weights k/24 are rounded once: gamma_31 * (|A| |w| + |rhs|)
    assert np.all(np.abs(A @ w - rhs) <= gamma(31) * (np.abs(A) @ np.abs(w) + np.abs(rhs)))
    assert np.abs(W.sum(axis=0) - 1).max() <= gamma(len(offs) + 1)
    vertex = W[:, 0]  # coefficient (4,0,0) of T0 = value at the cell corner (0, 0): M(-j)
    vals = {o: v for o, v in zip(offs, vertex)}
    assert vals[(0, 0)] == pytest.approx(0.5, abs=1e-16)
    for nb in [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1)]:
        assert vals[nb] == pytest.approx(1 / 12, abs=1e-16)
    assert sum(abs(v) for o, v in vals.items() if o not in [(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1),
                                                            (1, 1), (-1, -1)]) == 0


def test_c1_derivation():
    """The C1 weights solve the derivation system and are symmetric (the least-norm solution is)."""
    W, diag = ts._c1_solution()
    assert diag["unknowns"] == 22 * 30 and diag["rank"] < diag["unknowns"]
    assert max(diag["smoothness_residual"], diag["exactness_residual"]) < 1e-13
    # not C1 + cubic exact on the 4x4 block alone: the system is inconsistent there
    block = tuple((x, y) for y in range(-1, 3) for x in range(-1, 3))
    A, rhs, _ = c1_system(block)
    x = np.linalg.lstsq(A, rhs, rcond=None)[0]
    assert np.abs(A @ x - rhs).max() > 1e-3
    # symmetry (checked on the spline it builds): point reflection (x, y) -> (11 - x, 11 - y) of the data
    # and the swap x <-> y give the reflected / swapped spline
    z = np.random.default_rng(3).standard_normal((12, 12))
    c, info = terrain_coefficients(z, "C1")
    c_rot, _ = terrain_coefficients(z[::-1, ::-1], "C1")
    pts = np.random.default_rng(4).uniform(0, 11, (2, 500))
    assert np.allclose(evaluate(c, info, *pts), evaluate(c_rot, info, 11 - pts[0], 11 - pts[1]), atol=1e-12)
    c_sw, _ = terrain_coefficients(z.T, "C1")
    assert np.allclose(evaluate(c, info, *pts), evaluate(c_sw, info, pts[1], pts[0]), atol=1e-12)
    assert set(C1_STENCIL) == set(scheme_stencil("C1")[0])


# --------------------------------------------------------------------------------------------------
# polynomial reproduction
# --------------------------------------------------------------------------------------------------

def monomial_data(scheme, a, b):
    n = 13
    X, Y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    return X**a * Y**b


def reproduction_error(scheme, a, b, seed=0):
    z = monomial_data(scheme, a, b)
    coef, info = terrain_coefficients(z, scheme)
    pts = np.random.default_rng(seed).uniform(0, 12, (2, 400))
    err = np.abs(evaluate(coef, info, *pts) - pts[0] ** a * pts[1] ** b).max()
    g = gradient(coef, info, *pts)
    gx = a * pts[0] ** max(a - 1, 0) * pts[1] ** b
    gy = b * pts[0] ** a * pts[1] ** max(b - 1, 0)
    gerr = np.abs(g - np.stack([gx, gy], axis=-1)).max()
    return err, gerr, z


@pytest.mark.parametrize("scheme", ts.STENCIL_SCHEMES)  # C2-interp: tests/test_terrain_interpolating.py
def test_polynomial_reproduction(scheme):
    deg = {"linear": 1, "C0": 4, "C1": 3, "C2": 1, "C2-cubic": 3}[scheme]
    _, info = terrain_coefficients(np.zeros((13, 13)), scheme)
    assert info.reproduces == deg
    h = info.cell_size
    for a in range(deg + 1):
        for b in range(deg + 1 - a):
            err, gerr, z = reproduction_error(scheme, a, b)
            mz = padded_max(z, scheme)
            # padding: two extrapolation levels per axis, each |4 f0 - 6 f1 + 4 f2 - f3| rounded with
            # gamma_4 relative to 15 max|f|, change the data by <= 4 gamma_4 * 15 * mz
            pad = 4 * gamma(4) * 15 * mz * coef_error(scheme, 1.0)[1]
            # exact reference x^a y^b at a float point: (a + b) roundings relative to 12^(a+b)
            ref = gamma(a + b + 1) * 12.0 ** (a + b)
            assert err <= eval_bound(scheme, mz, 0) + 2 * pad + ref, (scheme, a, b, err)
            assert gerr <= (eval_bound(scheme, mz, 1) + 8 * pad) / h + (a + b) * ref, (scheme, a, b, gerr)


@pytest.mark.parametrize("scheme,a,b", [("linear", 2, 0), ("C2", 2, 0), ("C2", 0, 2), ("C1", 2, 2),
                                        ("C2-cubic", 2, 2), ("C1", 4, 0), ("C0", 5, 0), ("C0", 3, 2),
                                        ("C2-interp", 2, 2), ("C2-interp", 4, 0)])
def test_next_degree_is_not_reproduced(scheme, a, b):
    err, _, z = reproduction_error(scheme, a, b)
    assert err > 1e-6 * np.abs(z).max()


# --------------------------------------------------------------------------------------------------
# approximation order on Franke's function
# --------------------------------------------------------------------------------------------------

# Asymptotic order of the max error for smooth f: m + 1 where m is the degree reproduced, capped by the
# spline degree + 1 = 5 (linear 2, C2 2 -- it smooths --, C1, C2-cubic and C2-interp 4, C0 5).
ORDER = {"linear": 2, "C2": 2, "C1": 4, "C2-cubic": 4, "C0": 5, "C2-interp": 4}


@pytest.fixture(scope="module")
def franke_errors():
    pts = np.random.default_rng(7).uniform(0.0, 1.0, (2, 20000))
    fx = franke(*pts)
    out = {}
    for scheme in SCHEMES:
        errs = []
        # C0's spline cell is 4 data cells wide: at n = 64 it has only 16 cells per side and is still
        # pre-asymptotic (measured orders 3.2, 4.4, 5.1 for n = 16..128), so its finest pair is 64 -> 128
        for n in ((32, 64, 128) if scheme == "C0" else (16, 32, 64)):
            t = np.arange(n + 1) / n
            X, Y = np.meshgrid(t, t)  # z[j, i] = f(i / n, j / n)
            coef, info = terrain_coefficients(franke(X, Y), scheme)
            errs.append(np.abs(evaluate(coef, info, n * pts[0], n * pts[1]) - fx).max())
        out[scheme] = errs
    return out


@pytest.mark.parametrize("scheme", SCHEMES)
def test_approximation_order_franke(scheme, franke_errors):
    e1, e2, e3 = franke_errors[scheme]
    assert e1 > e2 > e3
    order = np.log2(e2 / e3)  # the finest pair: closest to the asymptotic regime
    p = ORDER[scheme]
    # band: at most p + 0.6 (faster convergence than the theory only pre-asymptotically), and at
    # least p - 0.5
    assert p - 0.5 < order < p + 0.6, (scheme, franke_errors[scheme], order)


# --------------------------------------------------------------------------------------------------
# bad input
# --------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("scheme", SCHEMES)
def test_nan_names_row_and_column(scheme):
    z = np.zeros((13, 13))
    z[3, 7] = np.nan
    with pytest.raises(ValueError, match=r"row 3, column 7"):
        terrain_coefficients(z, scheme)


def test_one_d_and_non_numeric():
    with pytest.raises(ValueError, match="2-D"):
        terrain_coefficients(np.zeros(10), "C1")
    with pytest.raises(TypeError, match="real numbers"):
        terrain_coefficients([["a", "b"], ["c", "d"]], "linear")


@pytest.mark.parametrize("scheme,shape,need", [("C2", (3, 5), 4), ("C1", (4, 3), 4), ("C2-cubic", (2, 9), 4),
                                               ("linear", (1, 5), 2), ("C0", (1, 1), 5)])
def test_too_small(scheme, shape, need):
    with pytest.raises(ValueError, match=rf"scheme {scheme} needs at least {need}x{need} heights, "
                                         rf"got {shape[0]}x{shape[1]}"):
        terrain_coefficients(np.zeros(shape), scheme)


def test_unknown_scheme_lists_schemes():
    with pytest.raises(ValueError) as ei:
        terrain_coefficients(np.zeros((5, 5)), "C3")
    for s in SCHEMES:
        assert repr(s) in str(ei.value)


def test_c0_size_and_resample():
    with pytest.raises(ValueError, match="resample_for_c0"):
        terrain_coefficients(np.zeros((12, 13)), "C0")
    X, Y = np.meshgrid(np.arange(12.0), np.arange(10.0))
    cubic = lambda x, y: 0.5 + 0.1 * x - 0.2 * y + 0.01 * x * y - 0.003 * x**3 + 0.002 * y**2 * x  # noqa: E731
    z = cubic(X, Y)
    z2, (sx, sy) = resample_for_c0(z)
    assert z2.shape == (13, 13) and sx == pytest.approx(11 / 12) and sy == pytest.approx(9 / 12)
    X2, Y2 = np.meshgrid(np.arange(13.0) * sx, np.arange(13.0) * sy)
    # cubic B-spline interpolation reproduces cubics; the prefilter's boundary sits 24 padded points out,
    # its influence is ~0.268^24 = 2e-14 relative to the padded data (values up to ~ 50 max|z| here)
    assert np.abs(z2 - cubic(X2, Y2)).max() < 1e-10 * np.abs(z).max()
    z3, scale = resample_for_c0(z2)
    assert scale == (1.0, 1.0) and np.array_equal(z3, z2)
    coef, info = terrain_coefficients(z2, "C0")
    assert coef.shape == (3, 3, 2, 15) and info.cell_size == 4


def test_evaluate_outside_domain():
    coef, info = terrain_coefficients(np.zeros((5, 5)), "C2")
    with pytest.raises(ValueError, match="outside"):
        evaluate(coef, info, [1.0, 4.5], [1.0, 1.0])


def test_c0_takes_any_grid_size_by_resampling_onto_4k_plus_1():
    from splinevis.terrain.model import TerrainSpline

    y, x = np.mgrid[0:23, 0:30].astype(float)
    z = 0.01 * x ** 3 + y  # a cubic: reproduced by the resampling and by C0 (quartic interpolation)
    t = TerrainSpline.from_heights(z, "C0", spacing=(2.0, 3.0), origin=(10.0, 20.0))
    assert "resampled from 30x23 to 33x25 samples for C0" in t.source
    x0, x1, y0, y1 = t.extent
    assert (x0, y0) == (10.0, 20.0) and abs(x1 - (10.0 + 29 * 2.0)) < 1e-9 and abs(y1 - (20.0 + 22 * 3.0)) < 1e-9
    xs, ys = 10.0 + 2.0 * np.array([0.0, 7.3, 29.0]), 20.0 + 3.0 * np.array([0.0, 11.1, 22.0])
    i, j = (xs - 10.0) / 2.0, (ys - 20.0) / 3.0
    assert np.allclose(t.evaluate(xs, ys), 0.01 * i ** 3 + j, atol=1e-9)

"""The interpolating C2 box spline (scheme C2-interp, splinevis.terrain.interpolating), float64.

Bounds are derived from float64 rounding (u = 2^-53, gamma_m = m u / (1 - m u)) as in
tests/test_terrain_schemes.py; the orders from the asymptotics e_h = C h^p (1 + c h + ...): the observed order
q(h -> h/2) = p + c h / (2 ln 2) + ..., so the deviation |q - p| on the finest pair is about half of that on the
pair before; we allow the whole previous deviation, plus the shortfall of a max over 100,000 random sites (mean
gap g = 1/sqrt(1e5); a ripple of scale h is under-read by at most (pi g / h)^2 / 8 = 5 % at h = 1/64, 0.07 in
log2 for each of the two errors, 0.15 in all).
"""

from __future__ import annotations

import numpy as np
import pytest

from splinevis.terrain import evaluate, gradient, scheme_stencil, terrain_coefficients
from splinevis.terrain import interpolating as ip
from splinevis.terrain import schemes as ts

U = 2.0 ** -53


def gamma(m):
    return m * U / (1 - m * U)


def test_symbol_and_kernel_are_the_c2_spline_at_the_grid_points():
    lo, hi = ip.symbol_range()
    w = np.linspace(-np.pi, np.pi, 901)
    K = ip.symbol(*np.meshgrid(w, w))
    assert (lo, hi) == (0.25, 1.0)
    assert K.min() >= lo - 4 * U and K.max() <= hi + 4 * U
    assert ip.symbol(2 * np.pi / 3, 2 * np.pi / 3) == pytest.approx(0.25, abs=4 * U)
    # the 7-point kernel is the C2 box spline M at the grid points (vertex coefficient of T0 = M(-j))
    offs, W = scheme_stencil("C2")
    assert {(-o[0], -o[1]): v for o, v in zip(offs, W[:, 0]) if v} == pytest.approx(ip.KERNEL, abs=U)
    # node_values(d) = the C2 spline of d at the grid points
    d = np.random.default_rng(1).uniform(-1, 1, (9, 11))
    coef, info = terrain_coefficients(d, "C2")
    y, x = np.mgrid[0:9, 0:11].astype(float)
    mz = float(np.abs(ts._pad_cubic(d, 1, 1, 1, 1)).max())
    assert np.abs(evaluate(coef, info, x, y) - ip.node_values(d)).max() <= (gamma(17) + gamma(14) + gamma(8)) * mz


@pytest.mark.parametrize("shape", [(37, 41), (4, 4), (5, 60)])
def test_interpolates_the_samples(shape):
    z = np.random.default_rng(0).uniform(-3.0, 5.0, shape)
    d, info = ip.prefilter_heights(z, return_info=True)
    assert info["residual"] <= info["tolerance"] and info["refinements"] <= 3
    coef, inf = terrain_coefficients(z, "C2-interp")
    assert inf.scheme == "C2-interp" and inf.smoothness == 2 and inf.reproduces == 3
    assert np.array_equal(coef, terrain_coefficients(d, "C2")[0])  # the C2 stencil on the prefiltered heights
    y, x = np.mgrid[0:shape[0], 0:shape[1]].astype(float)
    # spline at the nodes = K * pad(d) (rounded: gamma_17 for the coefficients, gamma_14 for de Casteljau at a
    # vertex, padding gamma_8) + the solve's residual
    mz = float(np.abs(ts._pad_cubic(d, 1, 1, 1, 1)).max())
    err = np.abs(evaluate(coef, info=inf, x=x, y=y) - z).max()
    assert err <= info["tolerance"] + (gamma(17) + gamma(14) + gamma(8)) * 15 * mz
    assert err <= 1e-12 * np.abs(z).max()


def test_system_condition_does_not_grow_with_the_grid():
    # the numbers docs/terrain-schemes.md and the module docstring state
    for n in (16, 32):
        A = ip.interpolation_matrix(n, n).toarray()
        s = np.linalg.svd(A, compute_uv=False)
        assert round(s[0] / s[-1], 1) == 37.5
        assert round(float(np.abs(np.linalg.inv(A)).sum(axis=1).max()), 1) == 13.9
    assert int(np.diff(ip.interpolation_matrix(16, 16).indptr).max()) <= 16


def _monomial_error(a, b, n=13, region=None):
    X, Y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    z = X ** a * Y ** b
    coef, info = terrain_coefficients(z, "C2-interp")
    pts = np.random.default_rng(0).uniform(0, n - 1, (2, 400)) if region is None else region
    err = np.abs(evaluate(coef, info, *pts) - pts[0] ** a * pts[1] ** b).max()
    g = gradient(coef, info, *pts)
    gx = a * pts[0] ** max(a - 1, 0) * pts[1] ** b
    gy = b * pts[0] ** a * pts[1] ** max(b - 1, 0)
    return err, np.abs(g - np.stack([gx, gy], -1)).max(), z


def test_reproduces_every_cubic_up_to_the_boundary():
    A = ip.interpolation_matrix(13, 13).toarray()
    inv_norm = float(np.abs(np.linalg.inv(A)).sum(axis=1).max())  # ||A^-1||_inf: residual -> error of d
    for a in range(4):
        for b in range(4 - a):
            err, gerr, z = _monomial_error(a, b)
            d, info = ip.prefilter_heights(z, return_info=True)
            mz = float(np.abs(ts._pad_cubic(d, 1, 1, 1, 1)).max())
            # d is off the exact cubic by <= ||A^-1|| (residual + rounding of the padding), padded (x 15), then
            # the C2 stencil and de Casteljau round (weights sum to 1; k-th derivative: D_k = 4!/(4-k)! 2^k)
            dd = 15 * inv_norm * (info["tolerance"] + gamma(8) * 15 * mz)
            vb = dd + (gamma(17) + gamma(14)) * mz + gamma(a + b + 1) * 12.0 ** (a + b)
            assert err <= vb, (a, b, err, vb)
            assert gerr <= 8 * (dd + (gamma(17) + gamma(16)) * mz) + (a + b) * gamma(a + b + 1) * 12.0 ** (a + b)


def test_quartics_of_the_box_spline_space_in_the_interior_only():
    # the box spline's polynomial space is the cubics and x^4 - 2 x^3 y, y^4 - 2 x y^3 (annihilated by
    # D_x^2 D_y^2, D_x^2 D_(1,1)^2, D_y^2 D_(1,1)^2): cardinal interpolation reproduces them; the cubic padding
    # does not, and its defect decays into the grid like the inverse of K (|a_m| ~ 0.27^|m| or faster: the
    # symbol's zero nearest to the real torus on an axis is at Im w = arccosh 2 = 1.317)
    n = 61
    mid = np.random.default_rng(2).uniform(28, 32, (2, 300))  # 28 cells from the boundary: 0.268^28 = 1e-16
    X, Y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    mz = 3 * 60.0 ** 4
    def err(f):
        coef, info = terrain_coefficients(f(X, Y), "C2-interp")
        return np.abs(evaluate(coef, info, *mid) - f(*mid)).max()
    inside = [err(lambda x, y: x ** 4 - 2 * x ** 3 * y), err(lambda x, y: y ** 4 - 2 * x * y ** 3)]
    outside = [err(lambda x, y: x ** 4), err(lambda x, y: x ** 2 * y ** 2)]
    # boundary defect (<= 15 max|z| after padding) x ||A^-1|| x decay, plus rounding (gamma_40 of max|z|)
    assert max(inside) <= (15 * 13.9 * 0.268 ** 28 + gamma(40)) * mz, inside
    assert min(outside) > 1e-2, outside  # an O(1) error: h^4 times the fourth derivatives (24)


def test_refused_out_of_core_with_what_to_do():
    from splinevis.outofcore import terrain_coefficients_dask

    with pytest.raises(ValueError, match=r"C2-interp is not supported out of core.*whole grid.*'C2-cubic'"):
        terrain_coefficients_dask(np.zeros((20, 20)), "C2-interp")
    with pytest.raises(ValueError, match="no local stencil"):
        scheme_stencil("C2-interp")


# --------------------------------------------------------------------------------------------------
# orders and ratios on Franke's function (the study's accuracy table, splinevis.studies.terrain)
# --------------------------------------------------------------------------------------------------

ORDERS = {"linear": (2, 1), "C2": (2, 2), "C2-interp": (4, 3)}  # (value, gradient)
SAMPLING = 0.15


@pytest.fixture(scope="module")
def franke_rows():
    from splinevis.studies.terrain import accuracy_orders, accuracy_table

    rows = accuracy_table(sizes=(17, 33, 65), schemes=tuple(ORDERS), sites=100_000)
    return accuracy_orders(rows)


@pytest.mark.parametrize("scheme", list(ORDERS))
def test_orders_value_and_gradient_inner_and_full(scheme, franke_rows):
    orders = [r for r in franke_rows[0] if r["scheme"] == scheme]
    assert [r["grids"] for r in orders] == ["17 -> 33", "33 -> 65"]
    for key, p in (("max_rel", ORDERS[scheme][0]), ("inner_max_rel", ORDERS[scheme][0]),
                   ("grad_max_rel", ORDERS[scheme][1]), ("inner_grad_max_rel", ORDERS[scheme][1])):
        q1, q2 = orders[0][f"order_{key}"], orders[1][f"order_{key}"]
        assert abs(q2 - p) <= abs(q1 - p) + SAMPLING, (scheme, key, q1, q2, p)


# Measured on 65 x 65 samples (docs/terrain-schemes.md, two digits): C2-interp's max error over linear's and
# over plain C2's, values and gradients, full square and inner square. The sites are fixed (seed 0), so the
# numbers are deterministic; the margin is half a unit of the second digit (the documented rounding).
MEASURED_65 = {
    "vs_linear_max_rel": 3.4e-3, "vs_linear_inner_max_rel": 3.1e-3,
    "vs_linear_grad_max_rel": 4.8e-3, "vs_linear_inner_grad_max_rel": 2.6e-3,
    "vs_C2_max_rel": 2.5e-3, "vs_C2_inner_max_rel": 2.2e-3,
    "vs_C2_grad_max_rel": 3.9e-2, "vs_C2_inner_grad_max_rel": 2.1e-2,
}


def test_ratios_to_linear_and_plain_c2(franke_rows):
    ratios = {(r["scheme"], r["grid"]): r for r in franke_rows[1]}
    r65 = ratios["C2-interp", "65x65"]
    for key, v in MEASURED_65.items():
        e = np.floor(np.log10(v)) - 1  # the unit of the second digit
        assert abs(r65[key] - v) <= 0.5 * 10 ** e, (key, r65[key], v)
    # better than linear and than plain C2 at every size, values and gradients, inner and full
    for n in (17, 33, 65):
        assert all(ratios["C2-interp", f"{n}x{n}"][k] < 1 for k in MEASURED_65)
    # and plain C2's values are worse than linear's (it smooths), its gradients better (order 2 against 1)
    assert ratios["C2", "65x65"]["vs_linear_max_rel"] > 1 > ratios["C2", "65x65"]["vs_linear_grad_max_rel"]

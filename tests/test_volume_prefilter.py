"""Prefiltered and interpolating volume splines, and the padding that keeps the orders up to the boundary
(splinevis.volume.prefilter, splinevis.volume.stencil.PADDINGS), on the float64 twins.

The orders follow from polynomial reproduction (a bounded linear scheme that reproduces every polynomial of
degree < p has errors O(h^p) for values and O(h^(p-1)) for gradients, by Taylor's theorem on the stencil):
the reproduction is asserted exactly (to roundoff), then the observed orders on a smooth field, with the
allowance that the pre-asymptotic term (one order higher) leaves at these grid sizes.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from splinevis.volume import approximation as ap
from splinevis.volume.model import VolumeSpline
from splinevis.volume.prefilter import centre_kernel, centre_symbol, centre_values, prefilter_data
from splinevis.volume.stencil import _pad

RNG = np.random.default_rng(7)


def _quadratic(p, c):
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    return (c[0] + c[1] * x + c[2] * y + c[3] * z + c[4] * x * x + c[5] * y * y + c[6] * z * z + c[7] * x * y
            + c[8] * y * z + c[9] * z * x)


def _grid(n):
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(float)
    return np.stack([x, y, z], axis=-1)


# ------------------------------------------------------------------------------------------- the centre stencil
def test_centre_kernels_are_the_closed_forms():
    Kq, Kc = centre_kernel("quadratic"), centre_kernel("cubic")
    faces = [(1, 1, 0), (1, 1, 2), (1, 0, 1), (1, 2, 1), (0, 1, 1), (2, 1, 1)]
    assert Kq[1, 1, 1] == 0.25 and all(Kq[f] == 0.125 for f in faces) and Kq.sum() == 1.0
    assert np.count_nonzero(Kq) == 7
    assert Kc[1, 1, 1] == 3 / 8 and all(Kc[f] == 1 / 12 for f in faces) and np.count_nonzero(Kc) == 19
    edges = [(a, b, c) for a in range(3) for b in range(3) for c in range(3) if [a, b, c].count(1) == 1]
    assert all(Kc[e] == 1 / 96 for e in edges) and math.isclose(Kc.sum(), 1.0, abs_tol=1e-15)
    # both have second moment 1/4 per axis: K f = f + (h^2 / 8) laplace f for quadratics
    for K in (Kq, Kc):
        o = np.arange(3) - 1
        assert math.isclose(float((K.sum(axis=(0, 1)) * o ** 2).sum()), 0.25, abs_tol=1e-15)


def test_symbols_quadratic_changes_sign_cubic_vanishes_only_at_the_corner():
    w = np.linspace(0, np.pi, 41)
    W = np.stack(np.meshgrid(w, w, w, indexing="ij"), axis=-1)
    Sq, Sc = centre_symbol("quadratic", W), centre_symbol("cubic", W)
    assert math.isclose(Sq.min(), -0.5, abs_tol=1e-15) and (Sq < 0).mean() > 0.1
    assert Sc.min() >= -1e-15
    corner = np.abs(W - np.pi).max(axis=-1) < 1e-12
    assert Sc[corner].max() < 1e-15 and Sc[~corner].min() > 0
    # near the corner K ~ |w - pi|^2 / 24 (the condition number grows like n^2)
    e = 1e-3
    assert math.isclose(float(centre_symbol("cubic", [np.pi - e, np.pi, np.pi])), e * e / 24, rel_tol=1e-5)


def test_quadratic_interpolation_is_ill_posed_and_refused():
    # on a periodic grid of period 4 these data give the value 0 at every data point: K has a kernel
    n = 8
    k, j, i = np.mgrid[0:n, 0:n, 0:n]
    d = (-1.0) ** i * np.cos(np.pi * j / 2) * np.cos(np.pi * k / 2)
    P = np.pad(d, 1, mode="wrap")
    assert np.abs(centre_values(P, "quadratic")).max() < 1e-15 and np.abs(d).max() == 1.0
    with pytest.raises(ValueError, match="needs scheme='cubic'.*vanishes on a whole surface"):
        VolumeSpline(np.zeros((5, 5, 5)), "quadratic", prefilter="interpolate")


def test_bad_options_say_what_to_do():
    with pytest.raises(ValueError, match="prefilter must be one of"):
        VolumeSpline(np.zeros((5, 5, 5)), prefilter="spline")
    with pytest.raises(ValueError, match="padding must be one of"):
        VolumeSpline(np.zeros((5, 5, 5)), padding="mirror")
    with pytest.raises(ValueError, match="extrapolates from 4 samples per axis.*padding='linear'"):
        VolumeSpline(np.zeros((3, 5, 5)), "cubic", padding="cubic", order="zyx")


# ---------------------------------------------------------------------------------- reproduction and interpolation
@pytest.mark.parametrize("scheme,prefilter,padding", [
    ("quadratic", "local", "quadratic"), ("quadratic", "local", "cubic"), ("cubic", "local", "quadratic"),
    ("cubic", "local", "cubic"), ("cubic", "interpolate", "quadratic"), ("cubic", "interpolate", "cubic")])
def test_prefiltered_splines_reproduce_quadratics_up_to_the_boundary(scheme, prefilter, padding):
    n = 9
    c = RNG.normal(size=10)
    f = _quadratic(_grid(n), c)
    s = VolumeSpline(f, scheme, prefilter=prefilter, padding=padding, order="zyx")
    p = RNG.uniform(-0.5, n - 0.5, (3000, 3))  # the whole domain, the outer half-cubes included
    v, g = s.evaluate(p, gradient=True)
    scale = np.abs(f).max()
    assert np.abs(v - _quadratic(p, c)).max() < 1e-12 * scale
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    grad = np.stack([c[1] + 2 * c[4] * x + c[7] * y + c[9] * z, c[2] + 2 * c[5] * y + c[7] * x + c[8] * z,
                     c[3] + 2 * c[6] * z + c[8] * y + c[9] * x], axis=1)
    assert np.abs(g - grad).max() < 1e-11 * scale
    # and not cubics: order 3 is the most these spaces give (the cubic scheme reproduces no cubic either)
    f3 = _grid(n)[..., 0] ** 3
    s3 = VolumeSpline(f3, scheme, prefilter=prefilter, padding=padding, order="zyx")
    inner = RNG.uniform(2.0, n - 3.0, (500, 3))
    assert np.abs(s3.evaluate(inner) - inner[:, 0] ** 3).max() > 1e-3


def test_the_plain_schemes_shift_quadratics_and_linear_padding_breaks_them_at_the_boundary():
    n = 9
    f = _grid(n)[..., 0] ** 2
    inner = RNG.uniform(2.0, n - 3.0, (500, 3))
    s = VolumeSpline(f, "quadratic", order="zyx")
    assert np.allclose(s.evaluate(inner), inner[:, 0] ** 2 + 0.25, atol=1e-12)  # the constant h^2 / 4
    edge = np.array([[-0.5, 4.0, 4.0]])
    assert math.isclose(float(s.evaluate(edge)[0]), -0.5, abs_tol=1e-12)  # true 0.25: the linear padding
    s2 = VolumeSpline(f, "quadratic", order="zyx", padding="quadratic")
    assert math.isclose(float(s2.evaluate(edge)[0]), 0.5,
                        abs_tol=1e-12)  # x^2 + 1/4 there too


def test_interpolating_cubic_interpolates_the_samples_even_noisy_ones():
    f = RNG.normal(size=(10, 11, 12))  # white noise: the worst conditioned data
    s = VolumeSpline(f, "cubic", prefilter="interpolate", padding="cubic", order="zyx")
    z, y, x = np.mgrid[0:10, 0:11, 0:12]
    pts = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(float)
    assert np.abs(s.evaluate(pts) - f.ravel()).max() < 1e-10
    # the price: the checkerboard content is amplified (up to ~ 0.8 n^2), so the data overshoot the samples
    d = s.padded[1:-1, 1:-1, 1:-1]
    assert np.abs(d).max() > 3 * np.abs(f).max()


def test_local_prefilter_is_one_neumann_step():
    f = RNG.normal(size=(7, 7, 7))
    for scheme in ("quadratic", "cubic"):
        d = prefilter_data(f, scheme, "local", "quadratic")
        assert np.array_equal(d, 2 * f - centre_values(_pad(f, "quadratic"), scheme))


# ---------------------------------------------------------------------------------------- measured orders and ratios
@functools.lru_cache(maxsize=None)
def _table(field, region, sizes, methods):
    F = {"smooth": ap._SmoothProduct(), "ml": ap._MarschnerLobb()}[field]
    rows = ap.approximation_table(F, sizes=sizes, schemes=methods, n_points=6000, region=region)
    return {(r["scheme"], r["n"]): r for r in rows}


def _order_ok(t, method, key, p, sizes):
    """The observed order between the two finest sizes is p up to the pre-asymptotic term: the deviation is
    O(h) and roughly halves per halving of h, so it may be at most twice the change of the observed order
    from the previous pair (plus 0.05 for the random points' share of the max)."""
    o1 = t[(method, sizes[1])]["order_" + key]
    o2 = t[(method, sizes[2])]["order_" + key]
    return abs(o2 - p) <= 2 * abs(o2 - o1) + 0.05, (o1, o2)


SMOOTH_SIZES = (17, 33, 65)


@pytest.mark.parametrize("method", ["quadratic+local/quadratic", "cubic+local/quadratic", "cubic+interpolate/cubic"])
def test_prefiltered_orders_on_the_full_region(method):
    t = _table("smooth", "full", SMOOTH_SIZES, (method,))
    for key, p in (("gradient_rms", 2), ("gradient_max", 2)):
        ok, orders = _order_ok(t, method, key, p, SMOOTH_SIZES)
        assert ok, (key, orders)
    # values: at least order 3 (the rms may converge faster where the h^3 term averages out)
    assert t[(method, 65)]["order_value_max"] >= 3 - 0.1 and t[(method, 65)]["order_value_rms"] >= 3 - 0.1


def test_linear_padding_costs_a_gradient_order_at_the_boundary_and_quadratic_padding_restores_it():
    methods = ("quadratic", "quadratic/quadratic", "cubic", "cubic/quadratic")
    full = _table("smooth", "full", SMOOTH_SIZES, methods)
    inner = _table("smooth", "inner", SMOOTH_SIZES, methods)
    for linear, quad in (("quadratic", "quadratic/quadratic"), ("cubic", "cubic/quadratic")):
        ok, orders = _order_ok(full, linear, "gradient_max", 1, SMOOTH_SIZES)
        assert ok, orders
        ok, orders = _order_ok(full, quad, "gradient_max", 2, SMOOTH_SIZES)
        assert ok, orders
        ok, orders = _order_ok(inner, linear, "gradient_max", 2, SMOOTH_SIZES)  # inside, linear padding is fine
        assert ok, orders
        # the plain schemes keep value order 2 (the shift h^2/8 laplace f)
        ok, orders = _order_ok(full, quad, "value_max", 2, SMOOTH_SIZES)
        assert ok, orders


ML_METHODS = ("trilinear", "central-differences", "quadratic", "cubic", "quadratic+local/quadratic",
              "cubic+local/quadratic")


def test_marschner_lobb_129_inner_fidelity_against_what_vtk_shades_with():
    t = _table("ml", "inner", (33, 129), ML_METHODS)  # inner: 2 cells of the 33^3 grid from the boundary, as in the study
    tri, cd = t[("trilinear", 129)], t[("central-differences", 129)]
    # the finding: the paper's quasi-interpolants are less accurate in value than trilinear
    for s in ("quadratic", "cubic"):
        assert t[(s, 129)]["value_rms"] > 1.2 * tri["value_rms"]
        assert cd["angle_mean"] / t[(s, 129)]["angle_mean"] < 3.0  # and under 3x better gradients
    # the goals: value error below trilinear's, gradient angle >= 3x below central differences (mean and median)
    for s in ("quadratic+local/quadratic", "cubic+local/quadratic"):
        r = t[(s, 129)]
        assert r["value_rms"] < tri["value_rms"] and r["value_max"] < tri["value_max"]
        assert cd["angle_mean"] >= 3.0 * r["angle_mean"]
        assert cd["angle_median"] >= 3.0 * r["angle_median"]
        assert cd["gradient_rms"] >= 3.0 * r["gradient_rms"]
        # the rms of the angle is dominated by points where |grad f| is tiny; there the ratio is below 3
        assert cd["angle_rms"] >= 2.0 * r["angle_rms"]

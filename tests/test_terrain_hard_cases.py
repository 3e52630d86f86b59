"""Terrain hard cases: flat data, a step cliff, small grids, NaN/nodata, non-uniform grids, huge offsets."""

import numpy as np
import pytest

from splinevis.studies.terrain import cliff_overshoot
from splinevis.terrain import SCHEMES
from splinevis.terrain.model import TerrainSpline

U = 2.0 ** -53


@pytest.mark.parametrize("scheme", SCHEMES)
def test_flat_terrain_is_exactly_flat(scheme):
    z = np.full((17, 17), 1234.5)
    t = TerrainSpline.from_heights(z, scheme)
    rng = np.random.default_rng(0)
    x, y = rng.uniform(0, 16, 1000), rng.uniform(0, 16, 1000)
    # heights are stored relative to their mean, so a flat grid has all-zero coefficients: exact.
    assert np.abs(t.coefficients).max() == 0.0
    assert np.all(t.evaluate(x, y) == 1234.5)
    assert np.all(t.gradient(x, y) == 0.0)


def test_step_cliff_overshoot_is_measured_and_bounded():
    from splinevis.terrain import scheme_stencil

    rows = {r["scheme"]: r for r in cliff_overshoot()[0]}
    # linear and the paper's C2 box spline take convex combinations of the data: no overshoot at all
    # (up to rounding of the 0/1 data: a few ulps).
    for s in ("linear", "C2"):
        assert rows[s]["overshoot"] <= 8 * U and rows[s]["undershoot"] <= 8 * U, rows[s]
    # The cubic-exact schemes ring (a scheme reproducing cubics cannot be monotone). Bound: each BB
    # coefficient is sum_i w_i z_i with sum w_i = 1, so for 0/1 data it lies in [-N, 1 + N] with N the
    # sum of the negative weights' magnitudes of its stencil; the spline is a convex combination of
    # coefficients, so its overshoot is at most max N over the 30 coefficient stencils.
    for s in ("C0", "C1", "C2-cubic"):
        _, w = scheme_stencil(s)
        n_neg = float(np.max(np.sum(np.clip(-np.asarray(w), 0, None), axis=0)))
        assert 1e-3 < rows[s]["overshoot"] <= n_neg + 1e-12, (rows[s], n_neg)


@pytest.mark.parametrize("scheme, shape, match", [
    ("C2", (3, 5), r"needs at least"),
    ("C1", (2, 2), r"needs at least"),
])
def test_grids_smaller_than_the_stencil_or_misfit_are_refused(scheme, shape, match):
    with pytest.raises(ValueError, match=match):
        TerrainSpline.from_heights(np.zeros(shape), scheme)


def test_c0_misfit_sizes_are_refused_by_the_low_level_scheme_and_resampled_by_the_model():
    from splinevis.terrain.schemes import terrain_coefficients

    with pytest.raises(ValueError, match=r"resample_for_c0"):
        terrain_coefficients(np.zeros((6, 6)), "C0")
    assert TerrainSpline.from_heights(np.zeros((6, 6)), "C0").shape == (2, 2)  # 9 x 9 samples: 2 x 2 macro cells


def test_nan_cells_are_refused_by_default_and_filled_on_request():
    z = np.add.outer(np.arange(9.0), np.arange(9.0))  # a plane
    z[3, 4] = np.nan
    with pytest.raises(ValueError, match=r"fill='nearest' or fill='linear'"):
        TerrainSpline.from_heights(z, "C2")
    t = TerrainSpline.from_heights(z, "C2-cubic", fill="linear")
    # linear fill restores the plane exactly and C2-cubic reproduces it
    assert abs(float(t.evaluate(4.0, 3.0)) - 7.0) < 1e-12


def test_unknown_scheme_lists_the_schemes():
    with pytest.raises(ValueError, match="'C3' is not known; choose one of"):
        TerrainSpline.from_heights(np.zeros((9, 9)), "C3")


def test_huge_origin_and_height_offset_keep_float64_geometry():
    z = 2000.0 + 0.5 * np.sin(np.add.outer(np.linspace(0, 2, 33), np.linspace(0, 3, 33)))
    t = TerrainSpline.from_heights(z, "C2-cubic", spacing=(30.0, 30.0), origin=(500_000.0, 5_100_000.0))
    assert t.origin == (500_000.0, 5_100_000.0)
    assert t.z_ref == pytest.approx(float(z.mean()), abs=0)
    # coefficients are relative heights: small numbers the GPU keeps to float32 precision
    assert np.abs(t.coefficients).max() < 1.0
    x0, x1, y0, y1 = t.extent
    assert (x1 - x0, y1 - y0) == (32 * 30.0, 32 * 30.0)
    # the grid value at a node is reproduced up to the scheme's error (data are smooth): 1e-3 m
    assert abs(float(t.evaluate(500_000.0 + 16 * 30.0, 5_100_000.0 + 16 * 30.0)) - z[16, 16]) < 1e-3

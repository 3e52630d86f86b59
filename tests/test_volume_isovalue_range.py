"""No blank isosurface without a word: the spline's range from its BB coefficients, the verdict (empty, proven
non-empty, unproven) and the error or warning add_isosurface gives; each verdict checked against a picture."""

import warnings

import numpy as np
import pytest

import splinevis
from splinevis.volume.isosurface import Isosurface
from splinevis.volume.isovalue_range import coefficient_range, isovalue_verdict, vertex_value_range
from splinevis.volume.model import VolumeSpline


def _gaussian(sigma=1.2):
    z, y, x = np.mgrid[-6:7, -6:7, -6:7].astype(float)
    return np.exp(-(x ** 2 + y ** 2 + z ** 2) / (2 * sigma ** 2))  # peak 1 on the centre sample


@pytest.mark.parametrize("scheme", ["quadratic", "cubic"])
def test_coefficient_range_is_that_of_every_coefficient(scheme):
    # the pruned search (cubes by their float32 bound, best first) against all coefficients of all cubes
    rng = np.random.default_rng(3)
    s = VolumeSpline(rng.standard_normal((7, 6, 5)), scheme, order="zyx")
    nz, ny, nx = s.shape
    k, j, i = np.mgrid[0:nz, 0:ny, 0:nx]
    every = s.cube_coefficients(np.column_stack([i.ravel(), j.ravel(), k.ravel()]))
    assert coefficient_range(s) == (float(every.min()), float(every.max()))


def test_vertex_values_are_values_of_the_spline():
    # vertex interpolation: the range found from the vertex coefficients is attained by the spline at points
    # of the relevant tetrahedra; checked against a dense evaluation of the cube of the sample nearest the peak
    s = VolumeSpline(_gaussian(), "cubic")
    lo, hi = vertex_value_range(s, s.relevant(0.5))
    t = np.linspace(-0.5, 0.5, 9)  # the centre cube spans one spacing around the centre sample
    pts = np.stack(np.meshgrid(t + 6, t + 6, t + 6, indexing="ij"), axis=-1).reshape(-1, 3)
    peak = s.evaluate(pts).max()
    assert lo <= 0.5 <= hi and hi <= peak + 1e-12  # a value the spline takes cannot exceed its sampled maximum...
    assert coefficient_range(s)[1] >= peak - 1e-12  # ... and the coefficients bound every value


@pytest.mark.parametrize("fraction", [1.0, 0.95])
def test_isovalue_above_the_smoothed_peak_warns_and_the_interpolant_draws_it(fraction):
    # the quasi-interpolant's peak is 0.78 of the data's (a Gaussian of sigma 1.2 samples): isovalue = max or
    # 0.95 max lies inside the data's range but above the spline's: a warning with the spline's range and the
    # option that reaches the samples, and the picture is indeed blank; prefilter="interpolate" draws it
    d = _gaussian()
    iso = fraction * d.max()
    pl = splinevis.Plotter(off_screen=True, window_size=(120, 90))
    with pytest.warns(UserWarning, match=r"lies inside the data's range \[[^]]+\].* but outside what the spline "
                                         r"reaches: the spline's values lie within \[-6\.77013e-05, 0\.779986\].*"
                                         r"prefilter='interpolate' makes the spline pass through the samples"):
        pl.add_isosurface(d, iso)
    blank = pl.screenshot()
    assert (np.abs(blank.astype(int) - blank[0, 0].astype(int)).sum(axis=2) > 0).sum() == 0  # no pixel drawn
    pl.close()
    pl = splinevis.Plotter(off_screen=True, window_size=(120, 90))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning: the interpolating spline reaches the samples
        actor = pl.add_isosurface(d, 0.95 * d.max(), "cubic", prefilter="interpolate")
    assert isovalue_verdict(actor.model).status == "non-empty"
    img = pl.screenshot()
    assert (np.abs(img.astype(int) - img[0, 0].astype(int)).sum(axis=2) > 30).sum() > 4  # a small sphere
    pl.close()


def test_isovalue_outside_the_data_range_is_an_error_with_both_ranges():
    with pytest.raises(ValueError, match=r"isovalue=1\.5 lies outside the volume's data range \[.*, 1\.0\] and the "
                                         r"spline's \[-6\.77013e-05, 0\.779986\]: the isosurface is empty"):
        splinevis.Plotter(off_screen=True, window_size=(40, 30)).add_isosurface(_gaussian(), 1.5)


def test_an_unproven_isosurface_at_the_peak_warns():
    # one sample of 1 among zeros: the quasi-interpolant's peak is 1/4, taken at the spike's centre only; the
    # isosurface of 1/4 is that one point: not proven non-empty, a warning that names the vertex values
    spike = np.zeros((5, 5, 5))
    spike[2, 2, 2] = 1.0
    assert isovalue_verdict(Isosurface(VolumeSpline(spike), 0.25)).status == "unproven"
    with pytest.warns(UserWarning, match=r"may be empty, a few points or tiny bubbles: the spline's values at the "
                                         r"vertices of the \d+ tetrahedra that could hold it lie in \[.*, 0\.25\]") as rec:
        splinevis.Plotter(off_screen=True, window_size=(40, 30)).add_isosurface(spike, 0.25)
    assert rec[0].filename == __file__  # attributed to the user's call, not to splinevis' internals


def test_a_proven_surface_gives_no_warning_and_pixels():
    d = _gaussian()
    pl = splinevis.Plotter(off_screen=True, window_size=(120, 90))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pl.add_isosurface(d, 0.5)
    img = pl.screenshot()
    assert (np.abs(img.astype(int) - img[0, 0].astype(int)).sum(axis=2) > 30).mean() > 0.01
    pl.close()

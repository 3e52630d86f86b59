"""smooth_heights: the GPU pass chain against its float64 numpy twin, with bounds derived from float32
rounding.

Error bound of the GPU path (``backend="gl"``), with u32 = 2**-24 (float32 unit roundoff) and
u64 = 2**-53. The grid is shifted by c = (min + max) / 2 in float64 and rounded to float32 (error
<= u32 * M, M = max |h - c|). Each of the 2 * passes one-direction steps computes
(0.25 a + 0.25 c) + 0.5 b: the scalings by powers of two are exact, the two additions each round once,
so a step adds at most gamma_2 = 2 u32 / (1 - 2 u32) times the weighted sum of |a|, |b|, |c|, which is
at most M. Earlier errors pass through later steps without growth (non-negative weights summing to 1).
Readback is exact and adding c back in float64 rounds once. In total

    |gl - exact| <= (1 + 4 * passes) * u32 * M * (1 + 1e-5) + (4 * passes + 2) * u64 * max|h|

where the factor (1 + 1e-5) covers the second-order terms ((1 + u32)^(4 passes) - 1 < 1e-5 for the
pass counts used here) and the last term covers the float64 rounding of the shift and of the twin
itself (two additions per step). The bound scales with the relief M, not with |h|: without the shift
it would be (1 + 4 * passes) * u32 * max|h| -- about 1.5 m for one pass at h ~ 5e6, more than the
noise being smoothed.
"""

import doctest

import numpy as np
import pytest

from splinevis.gl.context import max_texture_size
from splinevis.io import HeightGrid
from splinevis.terrain import prefilter
from splinevis.terrain.prefilter import smooth_heights

pytestmark = pytest.mark.gl

U32 = 2.0**-24
U64 = 2.0**-53
H, W = 37, 53  # not square: a rows/columns mix-up changes the result


def gl_bound(h, passes):
    h = np.asarray(h, dtype=np.float64)
    c = 0.5 * (h.min() + h.max())
    relief = np.abs(h - c).max()
    return (1 + 4 * passes) * U32 * relief * (1 + 1e-5) + (4 * passes + 2) * U64 * np.abs(h).max()


def reference(h, passes):
    """An independent float64 formulation: scipy's correlate1d, mode 'nearest' = replicated border."""
    from scipy.ndimage import correlate1d

    w = np.array([0.25, 0.5, 0.25])
    for _ in range(passes):
        h = correlate1d(correlate1d(h, w, axis=1, mode="nearest"), w, axis=0, mode="nearest")
    return h


@pytest.mark.parametrize("passes", [1, 2, 5])
def test_gl_matches_twin_on_random_data(passes):
    h = np.random.default_rng(passes).normal(size=(H, W)) * 10.0 + 3.0
    twin = smooth_heights(h, passes, backend="numpy")
    # the twin itself against scipy: float64 rounding only (two additions a step, |values| <= max|h|)
    assert np.abs(twin - reference(h, passes)).max() <= 2 * (4 * passes + 2) * U64 * np.abs(h).max()
    gl = smooth_heights(h, passes)
    assert gl.dtype == np.float64 and gl.shape == (H, W)
    assert np.abs(gl - twin).max() <= gl_bound(h, passes)


def test_gl_matches_twin_on_a_cliff():
    # a 1000 m cliff between columns 25 and 26 and a 300 m step between rows 10 and 11, plus noise
    rng = np.random.default_rng(7)
    jj, ii = np.mgrid[0:H, 0:W]
    h = np.where(ii < 26, 0.0, 1000.0) + np.where(jj < 11, 0.0, -300.0) + rng.normal(size=(H, W)) * 0.01
    for passes in (1, 3):
        gl = smooth_heights(h, passes)
        assert np.abs(gl - smooth_heights(h, passes, backend="numpy")).max() <= gl_bound(h, passes)
    # one pass spreads the cliff over one sample on each side: (0 + 0 + 1000 * 1/4) at column 25
    one = smooth_heights(h, 1, backend="numpy")
    assert abs(one[0, 25] - 250.0) < 0.1 and abs(one[0, 26] - 750.0) < 0.1


def test_gl_error_scales_with_the_relief_not_the_height():
    # UTM-like heights: 5e6 m plus noise of 1 m. Float32 spacing at 5e6 is 0.5 m, so filtering the raw
    # values in float32 could not even represent the noise; the shift by the midpoint keeps M ~ 4 m.
    rng = np.random.default_rng(11)
    h = 5e6 + rng.normal(size=(H, W))
    for passes in (1, 4):
        gl = smooth_heights(h, passes)
        err = np.abs(gl - smooth_heights(h, passes, backend="numpy")).max()
        bound = gl_bound(h, passes)
        assert err <= bound
        assert bound < 0.5e-3  # under a thousandth of the float32 spacing (0.5 m) at this height
    assert (smooth_heights(h, 4) - 5e6).std() < 0.5 * (h - 5e6).std()  # the noise really is smoothed


def test_passes_zero_is_the_identity_on_every_backend():
    h = 5e6 + np.random.default_rng(3).normal(size=(H, W)) * 0.1  # not representable in float32
    for backend in ("gl", "numpy"):
        out = smooth_heights(h, 0, backend=backend)
        assert out.dtype == np.float64 and np.array_equal(out, h) and out is not h


@pytest.mark.parametrize("backend", ["gl", "numpy"])
def test_one_by_one_grid_is_unchanged(backend):
    assert smooth_heights(np.array([[7.25]]), 3, backend=backend).tolist() == [[7.25]]


@pytest.mark.parametrize("backend", ["gl", "numpy"])
def test_one_row_and_one_column(backend):
    x = np.random.default_rng(5).normal(size=W)
    # a single row only smooths along x (the y neighbours clamp to the row itself), a column only along y
    row = smooth_heights(x[None, :], 2, backend=backend)
    col = smooth_heights(x[:, None], 2, backend=backend)
    ref = reference(x[None, :], 2)[0]
    # gl: its bound covers the float64 rounding of the reference too; numpy: two float64 computations
    tol = gl_bound(x, 2) if backend == "gl" else 2 * (4 * 2 + 2) * U64 * np.abs(x).max()
    assert row.shape == (1, W) and col.shape == (W, 1)
    assert np.abs(row[0] - ref).max() <= tol and np.abs(col[:, 0] - ref).max() <= tol


def test_rows_and_columns_are_not_mixed_up():
    # varies along x only: smoothing keeps every row equal to every other one, and changes the rows
    x = np.random.default_rng(9).normal(size=W)
    h = np.tile(x, (H, 1))
    gl = smooth_heights(h, 1)
    assert np.array_equal(gl, np.tile(gl[0], (H, 1)))
    assert np.abs(gl[0] - reference(x[None, :], 1)[0]).max() <= gl_bound(h, 1)
    assert np.abs(gl[0] - x).max() > 0.1
    # transposing the input transposes the output (up to rounding: x-then-y becomes y-then-x)
    assert np.abs(smooth_heights(h.T, 1) - gl.T).max() <= 2 * gl_bound(h, 1)


def test_constant_stays_constant_and_plane_stays_plane_inside_the_border():
    assert np.array_equal(smooth_heights(np.full((H, W), 1234.5), 3), np.full((H, W), 1234.5))
    jj, ii = np.mgrid[0:H, 0:W]
    plane = 2.0 * ii - 3.0 * jj + 100.0
    for backend in ("gl", "numpy"):
        out = smooth_heights(plane, 2, backend=backend)
        tol = gl_bound(plane, 2) if backend == "gl" else (4 * 2 + 2) * U64 * np.abs(plane).max()
        assert np.abs(out[2:-2, 2:-2] - plane[2:-2, 2:-2]).max() <= tol  # border effect reaches 2 samples
        assert np.abs(out[0, 0] - plane[0, 0]) > 0.1


def test_height_grid_in_height_grid_out():
    h = np.random.default_rng(4).normal(size=(H, W))
    grid = HeightGrid(h, spacing=(2.0, 3.0), origin=(5e5, 5.1e6), source="lidar.tif", crs="EPSG:32633", units="m")
    out = smooth_heights(grid, 2)
    assert isinstance(out, HeightGrid)
    assert (out.spacing, out.origin, out.source, out.crs, out.units) == ((2.0, 3.0), (5e5, 5.1e6), "lidar.tif",
                                                                         "EPSG:32633", "m")
    assert np.array_equal(out.heights, smooth_heights(h, 2))
    assert np.array_equal(grid.heights, h)  # the input is untouched


def test_bad_inputs_say_what_to_do():
    with pytest.raises(ValueError, match=r"2-D array \(ny, nx\).*got shape \(2, 3, 4\).*heights\[:, :, 0\]"):
        smooth_heights(np.zeros((2, 3, 4)))
    with pytest.raises(ValueError, match=r"at least 1 x 1 samples; got shape \(0, 5\)"):
        smooth_heights(np.zeros((0, 5)))
    bad = np.zeros((3, 4))
    bad[1, 2] = np.nan
    with pytest.raises(ValueError, match=r"finite.*at index \(1, 2\).*fill='nearest'"):
        smooth_heights(bad)
    with pytest.raises(ValueError, match=r"passes must be >= 0.*got -1"):
        smooth_heights(np.zeros((3, 3)), -1)
    for wrong in (1.5, True, "2"):
        with pytest.raises(TypeError, match=r"passes must be an integer"):
            smooth_heights(np.zeros((3, 3)), wrong)
    with pytest.raises(ValueError, match=r"backend 'cuda' is not known; choose one of: 'gl', 'numpy'"):
        smooth_heights(np.zeros((3, 3)), backend="cuda")
    with pytest.raises(TypeError, match=r"heights must be a 2-D array of real numbers"):
        smooth_heights([["a", "b"]])


def test_grid_wider_than_the_texture_limit_is_refused_on_gl_and_works_on_numpy():
    n = max_texture_size() + 1
    h = np.linspace(0.0, 1.0, n)[None, :]
    with pytest.raises(ValueError, match=rf"GL_MAX_TEXTURE_SIZE {n - 1}.*backend='numpy'"):
        smooth_heights(h, 1)
    out = smooth_heights(h, 1, backend="numpy")
    assert np.abs(out[0, 1:-1] - h[0, 1:-1]).max() < 1e-12  # a linear ramp is unchanged inside


def test_docstring_example_runs():
    result = doctest.testmod(prefilter, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0


@pytest.mark.gl
def test_add_terrain_presmooth_runs_the_gpu_filter_before_fitting():
    import splinevis
    from splinevis.terrain.model import TerrainSpline

    z = np.random.default_rng(3).normal(size=(33, 41))
    pl = splinevis.Plotter(off_screen=True, window_size=(80, 60))
    a = pl.add_terrain(z, "C1", presmooth=2, read_options={"spacing": (1.0, 1.0)})
    pl.close()
    direct = TerrainSpline.from_heights(smooth_heights(z, 2), "C1")  # the same GPU passes, by hand
    raw = TerrainSpline.from_heights(z, "C1")
    assert np.array_equal(a.model.coefficients, direct.coefficients)
    assert np.ptp(a.model.coefficients) < 0.5 * np.ptp(raw.coefficients)  # noise is damped

"""Bad input gives a clear error naming the argument, the value and what to do (not a blank picture, a
silent default or a traceback)."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

import splinevis
from splinevis.cli import main
from splinevis.terrain.limits import HEIGHT_LIMIT


@pytest.mark.parametrize("size", [(0, 0), (-5, 10), (10,), (1.5, 20), "big", (True, 10)])
def test_window_size_must_be_two_positive_ints(size, recwarn):
    with pytest.raises(ValueError, match=r"window_size=.* must be two positive pixel counts \(width, height\), "
                                         r"e\.g\. window_size=\(800, 600\)"):
        splinevis.Plotter(off_screen=True, window_size=size)


def test_a_valid_window_size_still_renders_at_that_size():
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    assert pl.screenshot().shape == (30, 40, 3)
    pl.close()


def test_heights_beyond_float32_raise_naming_the_limit_and_rescale():
    z = np.zeros((9, 9))
    z[4, 4] = 1e300
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    with pytest.raises(ValueError, match=r"largest \|height\| is 1e\+300 .*beyond the limit 3\.4e\+32 .*float32, "
                                         r"max 3\.4e38.*Rescale the heights"):
        pl.add_terrain(z)
    with pytest.raises(ValueError, match=r"span 2e\+33"):  # a span beyond the limit too
        pl.add_terrain(np.add.outer(np.zeros(5), np.linspace(-1e33, 1e33, 5)))
    z_ok = np.add.outer(np.sin(np.linspace(0, 3, 9)), np.cos(np.linspace(0, 3, 9))) * 1e6
    assert pl.add_terrain(z_ok, read_options={"spacing": (0.1, 0.1)}).model.num_patches > 0
    assert HEIGHT_LIMIT < float(np.finfo(np.float32).max)
    pl.close()


def _write_out_cases(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("x")
    cases = [str(afile), str(afile / "below")]
    if os.geteuid() != 0:  # root writes anywhere: an unwritable folder only bites ordinary users
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        cases.append(str(locked / "out"))
    cases.append("/proc/splinevis_cannot_write_here")
    return cases


def test_cli_out_not_a_writable_directory_is_one_line_and_nonzero(tmp_path, capsys):
    for out in _write_out_cases(tmp_path):
        code = main(["demo", "--out", out, "--quiet"])
        err = capsys.readouterr().err
        assert code == 4, (out, err)
        assert err.count("\n") == 1 and "Traceback" not in err, err
        assert err.startswith("splinevis: cannot write to ") and f"--out {out}" in err, err


def test_cli_out_error_through_a_subprocess_has_no_traceback(tmp_path):
    import subprocess

    afile = tmp_path / "afile"
    afile.write_text("x")
    run = subprocess.run([sys.executable, "-m", "splinevis.cli", "selftest", "--out", str(afile / "sub"),
                          "--quiet"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 4, run.stderr
    assert "Traceback" not in run.stderr and str(afile / "sub") in run.stderr


# ---------------------------------------------------------------------------------------------------
# Rasters whose CRS is wrong, unknown or reaches a pole: our ValueError naming the file, the CRS and
# what to do; a polar raster is drawn whole (UPS), not cropped
# ---------------------------------------------------------------------------------------------------
def _tif(tmp_path, name, heights, spacing, origin, epsg):
    from datasets_synthetic.dem_files import write_geotiff

    return write_geotiff(tmp_path / name, heights, spacing, origin, epsg=epsg)


def test_metres_in_a_file_labelled_epsg_4326(tmp_path):
    path = _tif(tmp_path, "metres.tif", np.random.default_rng(1).random((11, 11)), (1000.0, 1000.0), (5e5, 5e6), 4326)
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    for call in (lambda: splinevis.io.read_heights(path), lambda: pl.add_terrain(str(path))):
        with pytest.raises(ValueError, match=rf"{path.name}: coordinates x 500000\.\.510000, y 5e\+06\.\.5\.01e\+06 "
                                             r"are not degrees: the file's CRS label EPSG:4326 looks wrong; pass "
                                             r"crs='EPSG:326zz' \(read option"):
            call()
    pl.close()


def test_an_unknown_crs_read_option(tmp_path):
    lon, lat = np.meshgrid(7.0 + 0.01 * np.arange(21), 45.0 + 0.01 * np.arange(21))
    path = _tif(tmp_path, "deg.tif", lon + lat, (0.01, 0.01), (7.0, 45.0), 4326)
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    for call in (lambda: splinevis.io.read_heights(path, crs="EPSG:99999"),
                 lambda: pl.add_terrain(str(path), read_options={"crs": "EPSG:99999"})):
        with pytest.raises(ValueError, match=rf"{path.name}: crs='EPSG:99999' is not a known CRS .*pass an EPSG code "
                                             r"or WKT PROJ knows, e\.g\. 'EPSG:32633'") as info:
            call()
        assert type(info.value) is ValueError  # not rasterio's CRSError
    pl.close()


def test_a_raster_reaching_the_pole_is_drawn_whole_in_ups(tmp_path):
    # longitudes 0..10, latitudes 88..90 (pixel edges), 0.05 x 0.02 degree pixels: a thin wedge in UPS
    lon, lat = np.meshgrid(0.025 + 0.05 * np.arange(200), 88.01 + 0.02 * np.arange(100))
    path = _tif(tmp_path, "pole.tif", 100.0 * (lat - 88.0), (0.05, 0.02), (0.025, 88.01), 4326)
    with pytest.raises(ValueError, match=r"pole\.tif: .*% of the nodes of the EPSG:32661 grid .*fill='nearest'"):
        splinevis.io.read_heights(path)
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    grid = pl.add_terrain(str(path), read_options={"fill": "nearest"}).model
    pl.close()
    assert "to EPSG:32661" in grid.source and "100.00 % of the footprint kept" in grid.source
    # the grid covers the whole wedge: its corners (and the far arc's middle) in UPS lie within the extent
    from rasterio.warp import transform

    xs, ys = transform("EPSG:4326", "EPSG:32661", [0.025, 9.975, 0.025, 9.975, 5.0], [88.01, 88.01, 89.99, 89.99, 88.01])
    x0, x1, y0, y1 = grid.extent
    assert x0 <= min(xs) and max(xs) <= x1 and y0 <= min(ys) and max(ys) <= y1


def test_a_file_crs_proj_cannot_express_is_our_error(tmp_path, monkeypatch):
    # GDAL hands over a CRS that PROJ then fails to turn into an EPSG code or WKT (rasterio raises CRSError)
    import rasterio
    from rasterio.errors import CRSError

    path = _tif(tmp_path, "odd.tif", np.zeros((3, 3)), (30.0, 30.0), (5e5, 5e6), 32633)

    class OddCRS:
        def to_epsg(self):
            raise CRSError("PROJ: cannot export this CRS")

        to_wkt = to_epsg

    class Dataset:  # the real dataset, but for its CRS
        def __init__(self, ds):
            self._ds = ds

        def __getattr__(self, name):
            return OddCRS() if name == "crs" else getattr(self._ds, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self._ds.close()

    real_open = rasterio.open
    monkeypatch.setattr(rasterio, "open", lambda *a, **k: Dataset(real_open(*a, **k)))
    with pytest.raises(ValueError, match=r"odd\.tif: the file's CRS cannot be read \(PROJ: cannot export this CRS\); "
                                         r"set one PROJ knows, e\.g\. gdal_edit\.py -a_srs EPSG:32633 odd\.tif") as info:
        splinevis.io.read_heights(path)
    assert type(info.value) is ValueError


def test_a_raster_on_the_polar_cap_away_from_the_pole_goes_to_ups(tmp_path):
    # latitudes 84.5..85.5, longitudes 40..50: beyond UTM's 84 N. The former code cropped the UPS grid to the
    # inside of the footprint, fewer than 2 x 2 samples, and refused it with "is the CRS 'EPSG:4326' right?"
    # (measured on that code); now the half of the nodes outside the wedge-shaped footprint is said (with the
    # read options that fill them), and with fill= all of the area is kept.
    lon, lat = np.meshgrid(40.05 + 0.1 * np.arange(100), 84.51 + 0.02 * np.arange(50))
    path = _tif(tmp_path, "cap.tif", 100.0 * (lat - 84.0), (0.1, 0.02), (40.05, 84.51), 4326)
    with pytest.raises(ValueError, match=r"cap\.tif: the grid reaches the polar cap .* of the nodes of the "
                                         r"EPSG:32661 grid .* Pass fill='nearest'") as info:
        splinevis.io.read_heights(path)
    assert "right?" not in str(info.value)
    grid = splinevis.io.read_heights(path, fill="nearest")
    assert "to EPSG:32661" in grid.source and "100.00 % of the footprint kept" in grid.source


# ---------------------------------------------------------------------------------------------------
# USGS DEM files the former parser refused or GDAL misplaced
# ---------------------------------------------------------------------------------------------------
def test_a_usgs_dem_ending_with_a_type_c_record_reads(tmp_path):
    # The former parser took the type C (accuracy) record after the last profile for one more type B record and
    # refused the file as "truncated or malformed type B record ... download it again". Now: every sample read.
    from datasets_synthetic.dem_files import write_usgs_ascii_dem

    h = 300.0 + np.add.outer(np.arange(7.0), 2.0 * np.arange(5.0))
    path = write_usgs_ascii_dem(tmp_path / "acc.dem", h, 30.0, (5e5, 5.1e6), z_resolution=0.01,
                                accuracy=(1, 2, 3, 4, 28, 1, 0, 0, 7, 30))
    g = splinevis.io.read_heights(path)
    np.testing.assert_array_equal(g.heights, h)  # whole metres: exact in units of 0.01 m
    assert g.origin == (5e5, 5.1e6) and g.crs == "EPSG:32633"


def test_a_usgs_dem_named_tif_is_read_by_content_at_its_true_origin(tmp_path):
    # The former code sent a .tif to GDAL, whose USGSDEM driver snaps the origin to a multiple of the spacing
    # (10 m off here: 500010 -> 500000) and invents a row (on that code: "8 of 56 samples are missing", the fill
    # advice misleading); content sniffing sends it to our parser.
    from datasets_synthetic.dem_files import write_usgs_ascii_dem

    h = 200.0 + np.add.outer(np.arange(6.0), np.arange(8.0))
    dem = write_usgs_ascii_dem(tmp_path / "a.dem", h, 30.0, (500010.0, 5100020.0), z_resolution=0.01)
    tif = tmp_path / "really_a_dem.tif"
    tif.write_bytes(dem.read_bytes())
    g = splinevis.io.read_heights(tif)
    assert g.shape == (6, 8) and g.origin == (500010.0, 5100020.0)
    np.testing.assert_array_equal(g.heights, h)


# ---------------------------------------------------------------------------------------------------
# Volumes: lattice axes at the file's precision, isovalues the spline does not reach
# ---------------------------------------------------------------------------------------------------
def test_cube_axes_orthogonal_to_the_printed_decimals_read(tmp_path):
    # 0.1 Bohr steps on a rotated lattice printed with 6 decimals (%12.6f): the unit axes are orthogonal to
    # ~1e-5 only. The former fixed tolerance (1e-6) refused the file as "shear or non-orthogonal"; judged at the
    # printed precision it reads in its frame, the correction reported in a warning.
    c, s = np.cos(0.7), np.sin(0.7)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s],
                                                                           [0.0, s, c]])
    printed = np.round(0.1 * R, 6)
    unit = printed / np.linalg.norm(printed, axis=0)
    assert np.abs(unit.T @ unit - np.eye(3)).max() > 1e-6  # what the former tolerance refused
    axes = "\n".join(f"3 {printed[0, k]:12.6f}{printed[1, k]:12.6f}{printed[2, k]:12.6f}" for k in range(3))
    data = " ".join(str(float(v)) for v in range(27))
    (tmp_path / "rot.cube").write_text(f"c\nc\n1 0.0 0.0 0.0\n{axes}\n8 0.0 0.0 0.0 0.0\n{data}\n")
    with pytest.warns(UserWarning, match=r"rot\.cube: the lattice axes are orthonormal only to the precision"):
        g = splinevis.io.read_volume(tmp_path / "rot.cube")
    assert g.is_rotated and g.shape == (3, 3, 3)


def _gaussian_ball():
    z, y, x = np.mgrid[-6:7, -6:7, -6:7].astype(float)
    return np.exp(-(x ** 2 + y ** 2 + z ** 2) / (2 * 1.2 ** 2))  # one sample of 1 at the centre


@pytest.mark.parametrize("sign, fraction", [(1, 1.0), (1, 0.95), (-1, 1.0)])
def test_an_isovalue_the_spline_does_not_reach_is_said(sign, fraction):
    # The data's maximum (sign 1, fraction 1), 0.95 of it (inside the data's range) and the minimum of the
    # negated field: the quadratic quasi-interpolant smooths the one-sample peak to 0.78, so each isovalue lies
    # outside the spline's range and the picture is blank. The former code drew it without a word; now a
    # warning gives the spline's range and the option that reaches the samples.
    d = sign * _gaussian_ball()
    iso = fraction * (d.max() if sign > 0 else d.min())
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    with pytest.warns(UserWarning, match=r"outside what the spline reaches: the spline's values lie within .* "
                                         r"prefilter='interpolate' makes the spline pass through the samples"):
        pl.add_isosurface(d, iso)
    pl.close()

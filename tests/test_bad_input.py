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

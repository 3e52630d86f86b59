"""Drawing from a terrain store: the heights pyramid is the decimated heights, overview splines are the
scheme's spline of a level, a camera view reads only its tiles and draws the picture of the in-memory terrain
of the same cells, and the level drawn fits the coefficient textures. The GPU tests need GL (llvmpipe)."""

import numpy as np
import pytest

from datasets_synthetic.large_grids import large_dem
from splinevis.outofcore import write_terrain_store
from splinevis.outofcore import render as render_mod
from splinevis.outofcore.overview import overview_spline
from splinevis.outofcore.view import tiles_in_view
from splinevis.terrain.model import TerrainSpline
from splinevis.terrain.schemes import terrain_coefficients

RTOL = 1e-15  # of the largest coefficient: the BLAS product rounds a few rows by a unit in the last place
CAMERA = [(20.0, -40.0, 120.0), (70.0, 60.0, 0.0), (0.0, 0.0, 1.0)]  # oblique, over the south-west part


@pytest.fixture(scope="module")
def dem():
    return large_dem(257, chunks=64, seed=3, octaves=6, amplitude=30.0).compute()


@pytest.fixture(scope="module")
def c1_store(dem, tmp_path_factory):
    return write_terrain_store(tmp_path_factory.mktemp("c1") / "s.zarr", dem, "C1", chunks=32, progress=False)


def test_heights_pyramid_is_the_decimated_heights(dem, tmp_path):
    # a lazy DEM in chunks that do not start at multiples of 2^L: each level is exactly heights[::2^L, ::2^L]
    lazy = large_dem(257, chunks=(45, 70), seed=3, octaves=6, amplitude=30.0)
    s = write_terrain_store(tmp_path / "s.zarr", lazy, "C0", chunks=16, progress=False)
    levels = s._g["heights"]
    assert [levels[str(L)].shape for L in range(1, len(levels) + 1)] == [(129, 129), (65, 65), (33, 33), (17, 17),
                                                                          (9, 9), (5, 5)]  # C0 needs 5 samples
    for L in range(1, len(levels) + 1):
        assert np.array_equal(levels[str(L)][...], dem[::2 ** L, ::2 ** L])


@pytest.mark.parametrize("scheme", ["C0", "C1"])
def test_overview_spline_is_the_spline_of_the_level(dem, c1_store, tmp_path, scheme):
    # a rectangle of a level, read with the stencil's margin, has the cells of the spline of the whole level
    s = c1_store if scheme == "C1" else write_terrain_store(tmp_path / "s.zarr", dem, "C0", chunks=8, progress=False)
    step = 4 if scheme == "C0" else 1
    for L in (1, 2):
        z = dem[::2 ** L, ::2 ** L] - s.z_ref
        ref = terrain_coefficients(z, scheme)[0]
        t = overview_spline(s, L, rows=(8, 40), cols=(24, 64))  # store cells: rounded out to the level's
        r0, c0 = (np.array([t.origin[1], t.origin[0]]) / (2 ** L)).astype(int) // step
        want = ref[r0:r0 + t.shape[0], c0:c0 + t.shape[1]]
        assert float(np.abs(t.coefficients - want).max()) <= RTOL * np.abs(ref).max()
        assert t.cell_spacing == (2.0 ** L * step,) * 2 and t.z_ref == s.z_ref
        # it covers the rectangle asked for (cells 8..40 x 24..64 of the store)
        x0, x1, y0, y1 = t.extent
        assert x0 <= 24 * step and x1 >= 64 * step and y0 <= 8 * step and y1 >= 40 * step


def _shot(pl):
    im = pl.screenshot().astype(int)
    pl.close()
    return im


@pytest.mark.gl
def test_camera_view_reads_its_tiles_and_draws_the_in_memory_terrain(dem, c1_store, monkeypatch):
    import splinevis

    reads = []
    real = render_mod._read_tile
    monkeypatch.setattr(render_mod, "_read_tile", lambda s, iy, ix: reads.append((iy, ix)) or real(s, iy, ix))
    pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
    pl.camera_position = CAMERA
    actor = pl.add_terrain_store(c1_store, lights=1)
    view = actor.store_view
    expect = {tuple(t) for t in tiles_in_view(c1_store, planes=render_mod.camera_planes(pl.renderer)).tolist()}
    got = _shot(pl)
    # only the tiles in view were read, each once; the view is a proper part of the 8 x 8 tiles
    assert view.level == 0 and sorted(reads) == sorted(expect) and len(reads) == view.read
    assert 4 <= len(reads) < len(range(*view.rows, 32)) * len(range(*view.cols, 32)) < 64  # holes: not read
    # the in-memory terrain of the same cells, drawn from the same camera
    full = TerrainSpline.from_heights(dem, "C1")
    (r0, r1), (c0, c1) = view.rows, view.cols
    ref = TerrainSpline(full.coefficients[r0:r1, c0:c1], full.cell_spacing, (float(c0), float(r0)), full.z_ref,
                        scheme="C1")
    ref.data_range = full.data_range
    pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
    pl.add_spline(ref, lights=1)
    pl.camera_position = CAMERA
    pl.reset_camera_clipping_range()
    want = _shot(pl)
    hit = want.sum(-1) < 700
    assert hit.mean() > 0.5  # the terrain fills most of the picture
    # the tiles not in view are drawn as constants outside the view, z_ref is dask's mean (equal to numpy's
    # up to rounding), coefficients equal to an ulp: float32 on the GPU sees the same numbers almost always
    diff = np.abs(got - want).max(-1)
    assert (diff == 0).mean() > 0.999 and (diff > 8).mean() < 0.0005


@pytest.mark.gl
def test_level_fits_the_texture_limit(c1_store, monkeypatch):
    import splinevis
    from splinevis.terrain import limits

    # one texture of one row of 8192 texels: 1024 cells. 256 x 256 cells need level 3 (32 x 32 cells)
    monkeypatch.setattr(limits, "MAX_TABLE_TEXTURES", 1)
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = pl.add_terrain_store(c1_store, "all", lights=1, program_options={"rows_per_texture": 1})
    view = actor.store_view
    assert (view.level, view.cells, view.read) == (3, (32, 32), 0)
    im = _shot(pl)
    assert (im.sum(-1) < 700).mean() > 0.2  # drawn
    from splinevis.terrain.program import terrain_program

    with pytest.raises(ValueError, match="a terrain of 64 x 64 cells needs 4 textures"):  # level 2 does not fit
        terrain_program(overview_spline(c1_store, 2), rows_per_texture=1)
    # the cell budget picks a level the same way; level 0 when the view is small enough
    assert render_mod.load_view(c1_store, render_mod.view_tiles(c1_store, "all"), max_cells=4096).level == 2
    small = render_mod.view_tiles(c1_store, (0.0, 40.0, 0.0, 40.0, -1e4, 1e4))
    assert render_mod.load_view(c1_store, small, max_cells=4096).level == 0  # 2 x 2 tiles of 32^2 cells
    with pytest.raises(ValueError, match="no tile of the terrain store"):
        render_mod.load_view(c1_store, np.zeros((0, 2), int))

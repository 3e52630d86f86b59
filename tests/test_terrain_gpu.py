"""The terrain program on the GPU beyond the per-pixel hard cases (those are in
splinevis.terrain.hard_cases, checked by tests/test_program_hard_cases.py): precision at UTM coordinates,
the hierarchy changes no pixel, geo-referenced textures, the root finder compiled in on request.
Needs GL (llvmpipe)."""

import numpy as np
import pytest

from splinevis import programs
from splinevis.analysis.agreement import agreement_failures, hard_case_agreement
from splinevis.terrain.hard_cases import franke_terrain
from splinevis.terrain.model import TerrainSpline

pytestmark = pytest.mark.gl


@pytest.fixture(scope="module")
def franke_c2c():
    return franke_terrain()


@pytest.mark.parametrize("scheme", ["C2-interp"])
def test_c2_and_its_interpolating_variant_agree_with_the_twin(scheme):
    # C2-interp is the C2 program unchanged on prefiltered heights: the crater hard case of C2, oblique view
    # (the hard cases' own agreement criteria), drawn with either scheme's coefficients
    import dataclasses
    import functools

    from splinevis.terrain.hard_cases import _relief

    case = next(c for c in programs.get("terrain").hard_cases() if c.name == "crater-C2-oblique")
    case = dataclasses.replace(case, name=f"crater-{scheme}-oblique", model=functools.partial(_relief, "crater", scheme),
                               window_size=(200, 150))
    r = hard_case_agreement(case)
    assert agreement_failures(r, case) == []


def test_huge_offsets_keep_precision():
    # UTM-sized origin and heights 2000 +- 0.5 (the terrain's hard case "utm-coordinates", which
    # tests/test_program_hard_cases.py checks against the bound): the depth agreement is as good as near the
    # origin, since the bound does not include 1e6 coordinates and the local frame keeps float32 precision.
    case = next(c for c in programs.get("terrain").hard_cases() if c.name == "utm-coordinates")
    r = hard_case_agreement(case)
    assert agreement_failures(r, case) == []
    assert np.median(r["depth_error"]) < 1e-6


def test_hierarchy_full_truncated_and_off_give_identical_images(franke_c2c):
    import splinevis

    images = []
    for hierarchy in (True, False, 2):
        pl = splinevis.Plotter(off_screen=True, window_size=(240, 180))
        pl.add_spline(franke_c2c, lights=1, program_options={"hierarchy": hierarchy})
        pl.camera_position = [(-0.6, -0.9, 1.4), (0.5, 0.5, 0.3), (0, 0, 1)]
        pl.reset_camera_clipping_range()
        images.append(pl.screenshot().astype(int))
        pl.close()
    assert (images[0].sum(-1) < 700).mean() > 0.1
    # Skipping blocks must never change what a pixel shows: same hits, same shading.
    assert all(np.array_equal(images[0], im) for im in images[1:])


def test_texture_is_geo_referenced_by_its_extent():
    import splinevis

    z = np.zeros((33, 33))
    z[16, 16] = 1e-3  # not exactly flat
    t = TerrainSpline.from_heights(z, "C2", spacing=(10.0, 10.0), origin=(500_000.0, 5_100_000.0))
    x0, x1, y0, y1 = t.extent
    img = np.zeros((8, 8, 3), np.uint8)
    img[:, :4] = (255, 0, 0)   # west half of the image red
    img[:, 4:] = (0, 0, 255)   # east half blue
    xm = 0.5 * (x0 + x1)
    pl = splinevis.Plotter(off_screen=True, window_size=(320, 320))
    pl.set_background("white")
    # the image covers only the western half of the terrain
    pl.add_spline(t, lights=0, color=(0.0, 1.0, 0.0), texture=img, texture_extent=(x0, xm, y0, y1))
    cx, cy = xm, 0.5 * (y0 + y1)
    pl.camera_position = [(cx, cy, 2000.0), (cx, cy, 0.0), (0, 1, 0)]
    pl.enable_parallel_projection()
    pl.camera.parallel_scale = 0.5 * (y1 - y0)
    pl.reset_camera_clipping_range()
    im = pl.screenshot().astype(int)
    pl.close()
    row = im[160]
    def colour(col):
        r, g, b = row[col]
        return "red" if r > 200 and g < 60 else "blue" if b > 200 and r < 60 else "green" if g > 200 and r < 60 else "?"
    # screen x spans the terrain's x extent: quarters 1, 2 from the image, the east half base colour
    assert [colour(c) for c in (40, 120, 200, 280)] == ["red", "blue", "green", "green"]


def test_paper_root_finder_is_selectable_and_compiled_in_only_on_request(franke_c2c):
    import splinevis

    sources = {}
    for roots in ("bracketed", "paper"):
        pl = splinevis.Plotter(off_screen=True, window_size=(80, 60))
        a = pl.add_spline(franke_c2c, lights=0, program_options={"roots": roots})
        pl.camera_position = [(-0.6, -0.9, 1.4), (0.5, 0.5, 0.3), (0, 0, 1)]
        pl.screenshot()
        sources[roots] = a.program_sources["fragment"]
        pl.close()
    assert "return sv_first_root_bracketed(c, n, iterations);" in sources["bracketed"]
    assert "return sv_first_root_newton4(c, n, iterations);" in sources["paper"]
    assert "return sv_first_root_newton4(c, n, iterations);" not in sources["bracketed"]


def test_coefficient_table_split_into_textures_gives_the_same_image():
    # tables over 1 GiB are split by rows into up to 4 textures (llvmpipe reads zeros from larger ones); a
    # small table split on purpose (rows_per_texture) must draw exactly the picture of the unsplit one
    from datasets_synthetic.dem_files import fractal_terrain

    import splinevis

    z = np.tile(fractal_terrain(129, seed=3, amplitude=20.0)[:17], (1, 17))[:, :2049]  # 2048 x 16 cells: 32 rows
    t = TerrainSpline.from_heights(z, "C1", spacing=(1.0, 1.0))
    images = {}
    for rows in (8192, 16, 11, 8):  # 1, 2, 3, 4 textures
        pl = splinevis.Plotter(off_screen=True, window_size=(240, 180))
        a = pl.add_spline(t, lights=1, program_options={"rows_per_texture": rows})
        pl.camera_position = [(900.0, -30.0, 80.0), (1200.0, 8.0, 5.0), (0, 0, 1)]
        pl.reset_camera_clipping_range()
        images[rows] = pl.screenshot().astype(int)
        n_tex = sum(name.startswith("sv_terrain_coef") for name in a.spec.textures)
        pl.close()
        assert n_tex == {8192: 1, 16: 2, 11: 3, 8: 4}[rows]
    assert (images[8192].sum(-1) < 700).mean() > 0.05  # the strip is drawn
    assert all(np.array_equal(images[8192], im) for im in images.values())
    with pytest.raises(ValueError, match="needs 8 textures of 1024 MB.*at most 4"):
        TerrainSpline.from_heights(np.zeros((8001, 8001)), "linear")  # refused before 15 GB of coefficients


def test_colormap_spans_the_data_not_the_schemes_overshoot():
    # C0 overshoots at a cliff; the colormap's default range is the data's, so the plateau and the floor get
    # the two ends of the colormap instead of two middle colours
    z = np.zeros((17, 17))
    z[:, 9:] = 100.0
    t = TerrainSpline.from_heights(z, "C0", spacing=(1.0, 1.0))
    assert t.zrange[1] > 100.0 and t.zrange[0] < 0.0  # the overshoot exists
    from splinevis.terrain.program import terrain_program

    assert terrain_program(t).uniforms["sv_scalar_range"] == (0.0, 100.0)

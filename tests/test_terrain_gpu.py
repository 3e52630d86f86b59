"""The terrain ray caster on the GPU against the float64 reference: normal and grazing views, rays along
edges and through vertices, camera below the surface and inside the bounding box, huge offsets, extreme
zoom. Needs GL (llvmpipe)."""

import numpy as np
import pytest

from datasets_synthetic.franke import franke_grid
from splinevis.analysis.agreement import depth_agreement
from splinevis.terrain.model import TerrainSpline

pytestmark = pytest.mark.gl


def _franke_terrain(n=24, scheme="C2-cubic", spacing=(1.0 / 24, 1.0 / 24), origin=(0.0, 0.0), height_offset=0.0,
                    height_scale=1.0):
    z, _ = franke_grid(n)
    return TerrainSpline.from_heights(z.T * height_scale + height_offset, scheme, spacing=spacing, origin=origin)


def _check(r, *, depth_fraction=0.999):
    assert r["both"] > 0.05 * r["pixels"], r["both"]
    assert r["leaks"] == 0, f"{r['leaks']} background pixels leak through the closed surface"
    assert r["hit_disagree"] <= 0.001 * r["pixels"], r["hit_disagree"]
    within = r["depth_error"] <= r["depth_bound"]
    assert within.mean() >= depth_fraction, (within.mean(), float(r["depth_error"].max()))


@pytest.fixture(scope="module")
def franke_c2c():
    return _franke_terrain()


def test_oblique_view(franke_c2c):
    _check(depth_agreement(franke_c2c, [(-0.6, -0.9, 1.4), (0.5, 0.5, 0.3), (0, 0, 1)]))


def test_grazing_view_one_degree_above_horizon(franke_c2c):
    # Eye far out, looking across the terrain 1 degree above the horizontal: long rays through many cells.
    z = 1.25
    eye = (-3.0, 0.45, z)
    focal = (0.5, 0.5, z - 3.5 * np.tan(np.radians(1.0)))
    _check(depth_agreement(franke_c2c, [eye, focal, (0, 0, 1)]))


def test_rays_along_grid_lines_and_through_vertices(franke_c2c):
    # The eye sits exactly above a grid line x = 12/24 and looks along it, so a whole column of rays runs
    # along cell edges, and the central ray passes through grid vertices and along diagonals.
    x = 12 / 24
    _check(depth_agreement(franke_c2c, [(x, -1.0, 1.5), (x, 0.5, 0.2), (0, 0, 1)]))
    _check(depth_agreement(franke_c2c, [(-0.5, -0.5, 1.6), (0.5, 0.5, 0.2), (0, 0, 1)]))  # along the diagonals


def test_camera_below_the_surface_sees_its_underside(franke_c2c):
    _check(depth_agreement(franke_c2c, [(0.5, -0.8, -1.0), (0.5, 0.5, 0.3), (0, 0, 1)]))


def test_camera_inside_the_bounding_box(franke_c2c):
    eye = (0.3, 0.2, float(franke_c2c.evaluate(0.3, 0.2)) + 0.05)
    assert eye[2] < franke_c2c.zrange[1]
    r = depth_agreement(franke_c2c, [eye, (0.7, 0.7, 0.2), (0, 0, 1)],
                        plotter_hook=lambda pl: setattr(pl.camera, "clipping_range", (1e-3, 5.0)))
    _check(r)


def test_huge_offsets_keep_precision():
    # UTM-sized origin and heights 2000 +- 0.5: only the local frame keeps float32 precision here.
    t = _franke_terrain(spacing=(10.0, 10.0), origin=(500_000.0, 5_100_000.0), height_offset=2000.0, height_scale=0.5)
    x0, x1, y0, y1 = t.extent
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    r = depth_agreement(t, [(cx - 300, cy - 350, 2300.0), (cx, cy, 2000.3), (0, 0, 1)])
    _check(r)
    # and the depth agreement is as good as near the origin (the bound does not include 1e6 coordinates)
    assert np.median(r["depth_error"]) < 1e-6


def test_extreme_zoom_on_one_patch(franke_c2c):
    x, y = 0.51, 0.52
    z = float(franke_c2c.evaluate(x, y))
    r = depth_agreement(franke_c2c, [(x - 0.01, y - 0.012, z + 0.01), (x, y, z), (0, 0, 1)],
                        plotter_hook=lambda pl: setattr(pl.camera, "clipping_range", (1e-4, 2.0)))
    _check(r)


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


@pytest.mark.parametrize("heights", ["flat", "almost flat"])
def test_flat_terrain_renders_without_holes(heights):
    z = np.full((17, 17), 250.0)
    if heights == "almost flat":
        z[8, 8] += 1e-4
    t = TerrainSpline.from_heights(z, "C1", spacing=(1.0, 1.0))
    _check(depth_agreement(t, [(-6.0, -9.0, 262.0), (8.0, 8.0, 250.0), (0, 0, 1)]))


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

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

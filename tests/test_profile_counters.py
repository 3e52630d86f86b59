"""Per-fragment work counters of the terrain program's debug build (splinevis.analysis.profile): compiled in
only on request, zero off the proxy, at least one walk step and one cell on every hit, root-finder steps within
the program's iteration budget, walk steps within the number of blocks a ray can cross in the grid, and the
same pixels hit as the default build."""

import numpy as np
import pytest

from splinevis.effects import Style
from splinevis.gl.inject import make_actor
from splinevis.terrain.model import TerrainSpline
from splinevis.terrain.program import DEBUG_MODES, terrain_program

CAMERA = [(0.5, -1.0, 1.2), (0.5, 0.5, 0.0), (0, 0, 1)]
WINDOW = (120, 90)
ITERATIONS = 5
COUNTER_CODE = ("sv_count", "SV_DEBUG", "sv_counter", "sv_march_steps", "TRAVERSAL_ONLY", "NO_SHADING")


@pytest.fixture(scope="module")
def terrain():
    y, x = np.mgrid[0:17, 0:17] / 16.0
    return TerrainSpline.from_heights(0.3 * np.sin(3 * x) * np.cos(2 * y) + 0.05 * np.cos(9 * x * y), "C1",
                                      spacing=(1 / 16, 1 / 16))


def _walk_bound(terrain, hierarchy=True):
    """Most blocks one ray can visit: a straight line crosses at most nx + ny - 1 blocks of an nx x ny grid,
    and the walk visits each block along the ray at most once per level (it moves front to back)."""
    ncy, ncx = terrain.shape
    levels = len(terrain.hierarchy.levels) if hierarchy else 1
    bound = 0
    for level in range(levels):
        size = 2 ** level
        bound += -(-ncx // size) + -(-ncy // size) - 1
    return bound


def test_default_build_has_no_counter_code(terrain):
    for roots in ("bracketed", "paper"):
        default = make_actor(terrain_program(terrain, roots=roots), Style(lights=1))
        assert "lib/core/counters.glsl" not in default.assembled.files
        assert not any(word in default.assembled.text for word in COUNTER_CODE)
        assert default.assembled.text == make_actor(terrain_program(terrain, roots=roots, debug=None),
                                                    Style(lights=1)).assembled.text
    for debug in DEBUG_MODES:
        text = make_actor(terrain_program(terrain, debug=debug), Style(lights=1)).assembled.text
        assert "SV_DEBUG" in text
    counters = make_actor(terrain_program(terrain, debug="counters"), Style(lights=1)).assembled
    assert "lib/core/counters.glsl" in counters.files and "sv_count_root_steps += 1;" in counters.text


@pytest.fixture(scope="module")
def rendered(terrain):
    import splinevis
    from splinevis.analysis.profile import fragment_counters

    pl = splinevis.Plotter(off_screen=True, window_size=WINDOW)
    pl.add_spline(terrain, lights=1, newton_iterations=ITERATIONS)
    pl.camera_position = CAMERA
    pl.reset_camera_clipping_range()
    pl.screenshot()
    depth = pl.depth_buffer()
    pl.close()
    counts = fragment_counters(terrain, CAMERA, WINDOW, newton_iterations=ITERATIONS)
    return depth, counts


@pytest.mark.gl
def test_counts_are_positive_on_hits_and_zero_off_the_proxy(rendered):
    depth, c = rendered
    hit = c.shaded
    assert 0.1 < hit.mean() < 0.9 and (c.fragments & ~hit).sum() > 100  # hits, misses and background all occur
    assert not (hit & ~c.fragments).any()
    for name in ("traversal", "cells", "root_calls", "root_steps"):
        arr = c.arrays()[name]
        assert (arr[~c.fragments] == 0).all(), name
    assert (c.traversal[hit] >= 1).all() and (c.cells[hit] >= 1).all()
    assert (c.traversal[c.fragments] >= 1).all()  # every ray meets the proxy's box
    assert (c.cells <= c.traversal).all() and (c.root_calls <= 2 * c.cells).all()  # two triangles per cell


@pytest.mark.gl
def test_root_steps_within_the_iteration_budget(rendered):
    _, c = rendered
    # bracketed Newton: per call at most one extremum run on each of the three convex pieces and one root run,
    # each exactly `iterations` steps (glsl/lib/core/roots.glsl)
    assert (c.root_steps <= 4 * ITERATIONS * c.root_calls).all()
    assert (c.root_steps % ITERATIONS == 0).all()
    assert c.root_steps.max() >= ITERATIONS


@pytest.mark.gl
def test_walk_steps_bounded_by_the_blocks_a_ray_crosses(terrain, rendered):
    from splinevis.analysis.profile import fragment_counters

    _, c = rendered
    assert c.traversal.max() <= _walk_bound(terrain)
    flat = fragment_counters(terrain, CAMERA, WINDOW, program_options={"hierarchy": False, "roots": "paper"},
                             newton_iterations=ITERATIONS)
    assert 1 < flat.traversal.max() <= _walk_bound(terrain, hierarchy=False)  # cell by cell: <= ncx + ncy - 1
    assert (flat.cells <= flat.traversal).all()
    assert (flat.root_steps == ITERATIONS * flat.root_calls).all()  # four-start Newton: one run per call


@pytest.mark.gl
def test_counters_build_hits_the_same_pixels(rendered):
    depth, c = rendered
    assert np.array_equal(depth < 1.0, c.shaded)


@pytest.mark.gl
def test_plotter_without_counters_is_refused(terrain):
    import splinevis
    from splinevis.analysis.profile import fragment_counters

    pl = splinevis.Plotter(off_screen=True, window_size=(32, 24))
    pl.add_spline(terrain)
    with pytest.raises(ValueError, match="debug"):
        fragment_counters(pl)
    pl.close()


@pytest.mark.gl
def test_timing_builds_compile_and_keep_the_hits(terrain, rendered):
    # the parts the profile benchmark times alone: constant colour (same hits), no root finder and walk only
    # (every default hit is kept: a sign change / a candidate cell precedes each hit), a reference ray march
    import splinevis

    depth, _ = rendered
    hit = depth < 1.0
    masks = {}
    for debug in ("flat", "restrict", "traversal", "raymarch"):
        pl = splinevis.Plotter(off_screen=True, window_size=WINDOW)
        pl.add_spline(terrain, lights=1, newton_iterations=ITERATIONS, program_options={"debug": debug})
        pl.camera_position = CAMERA
        pl.reset_camera_clipping_range()
        image = pl.screenshot()
        masks[debug] = pl.depth_buffer() < 1.0
        pl.close()
        assert len(np.unique(image[masks[debug]], axis=0)) == 1, debug  # one constant colour
    assert np.array_equal(masks["flat"], hit)
    assert not (hit & ~masks["restrict"]).any() and not (hit & ~masks["traversal"]).any()
    assert 0.8 < masks["raymarch"].sum() / hit.sum() < 1.25

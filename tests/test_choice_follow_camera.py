"""The choice by accuracy follows the camera: moving in makes the renderer's error larger in pixels, so before
the next render the choice is made again and a finer renderer is drawn; moving back draws the first one again
without building it anew; the actor the user holds keeps the current choice."""

import numpy as np

import splinevis
from splinevis.gl.screen_error import View


def _heights():
    y, x = np.mgrid[-1:1:17j, -1:1:17j]
    return 0.4 * np.exp(-3 * (x * x + y * y)) + 0.1 * np.sin(3 * x)


def test_moving_in_chooses_again_and_moving_back_reuses_the_first():
    pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
    actor = pl.add_terrain(_heights(), "C1", read_options={"spacing": (0.125, 0.125)}, max_error_px=0.5)
    pl.screenshot()
    first = (actor.choice.renderer, actor.choice.level)
    assert first[0] == "mesh" and actor.drawn is actor
    pl.camera.zoom(6.0)  # 6x closer in angle: the same world error covers ~6x the pixels
    pl.render()  # (pyvista's screenshot renders only the first time)
    near = (actor.choice.renderer, actor.choice.level)
    assert near != first and actor.choice.meets
    assert actor.choice.error_px <= 0.5
    assert actor.drawn is not actor and actor.drawn.GetVisibility() and not actor.GetVisibility()
    # the choice was made for the view that rendered
    view = View.from_renderer(pl.renderer, pl.window_size)
    assert actor.choice.view.position == view.position
    n_actors = len(pl.renderer.actors)
    pl.camera.zoom(1.0 / 6.0)  # back
    pl.render()
    assert (actor.choice.renderer, actor.choice.level) == first and actor.drawn is actor and actor.GetVisibility()
    assert len(pl.renderer.actors) == n_actors  # nothing rebuilt
    assert actor.choices[first] == 2 and actor.choices[near] == 1
    assert pl.screenshot().std() > 5
    pl.close()


def test_unchanged_camera_does_not_choose_again():
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = pl.add_terrain(_heights(), "C1", read_options={"spacing": (0.125, 0.125)}, max_error_px=1.0)
    pl.screenshot()
    for _ in range(3):
        pl.render()
    assert sum(actor.choices.values()) == 1
    pl.close()


def test_a_geometry_image_takes_a_finer_level_when_the_camera_moves_in():
    from datasets_synthetic.closed_meshes import star_blob

    pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
    actor = pl.add_geometry_image(star_blob(level=2), n=17, max_error_px=0.5, reflection_lines=8)
    pl.screenshot()
    first = actor.choice.level
    pl.camera.zoom(4.0)
    pl.render()
    assert actor.choice.meets and actor.choice.level > first  # subdivision levels: finer when seen closer
    assert actor.drawn.GetVisibility() and not actor.GetVisibility()
    assert pl.screenshot().std() > 5
    pl.close()

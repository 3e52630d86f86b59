"""The walkthrough pipeline (splinevis.nurbs.lod.pipeline) with dynamic tessellation, and its interactive mode
driven tick by tick off screen (the window itself needs a display). No timing asserts: the waits for the worker
threads are bounded polls."""

import time

import numpy as np
import pytest
import pyvista as pv

from splinevis.nurbs.exact import sphere, torus
from splinevis.nurbs.lod.levels import build_lod
from splinevis.nurbs.lod.pipeline import Walkthrough, camera_path
from splinevis.nurbs.lod.select import select_levels


@pytest.fixture(scope="module")
def sphere_lod():
    return build_lod(sphere(), 0.05, levels=2, progress=False)


def _fly(lod, path, **options):
    pl = pv.Plotter(off_screen=True, window_size=(160, 120))
    try:
        w = Walkthrough(lod, pl, **options)
        frames = w.fly(path, progress=False)
        return frames, pl.screenshot(), w
    finally:
        pl.close()


@pytest.mark.parametrize("threaded", [False, True])
def test_a_close_approach_is_refined_dynamically_and_logged(sphere_lod, threaded):
    path = camera_path((-1, 1, -1, 1, -1, 1), 12)
    frames, img, w = _fly(sphere_lod, path, threaded=threaded, dynamic=True)
    assert w.refiner is not None
    assert [f["frame"] for f in frames] == list(range(12))
    assert all(f["triangles"] > 0 for f in frames)
    last = frames[-1]
    # at the end of the approach level 0 is too coarse near the eye: refined super-surfaces drawn
    assert last["needs_finer"] > 0 and last["refined"] > 0 and last["refined_triangles"] > 0
    assert last["refined_triangles"] <= last["triangles"]
    assert all(f["finer_pending"] >= 0 and f["tessellate_ms"] >= 0 for f in frames)
    if not threaded:  # in sequence the frames' own builds tessellate (threaded, T may have done it all before)
        assert sum(f["tessellate_ms"] for f in frames) > 0
    assert (img.sum(axis=-1) < 3 * 250).mean() > 0.5  # the sphere fills most of the close view
    static, _, w = _fly(sphere_lod, path, threaded=threaded)  # off by default
    assert w.refiner is None
    assert all(f["refined"] == 0 and f["tessellate_ms"] == 0 for f in static)
    assert static[-1]["needs_finer"] > 0 and static[-1]["triangles"] < last["triangles"]


@pytest.mark.parametrize("threaded", [False, True])
def test_refinement_goes_on_over_builds_for_a_still_camera(sphere_lod, threaded):
    from splinevis.nurbs.lod.dynamic import Refiner

    pl = pv.Plotter(off_screen=True, window_size=(160, 120))
    w = Walkthrough(sphere_lod, pl, threaded=threaded, dynamic=Refiner(sphere_lod, triangles_per_build=1))
    try:
        pl.camera_position = [(0.0, -1.3, 0.2), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
        pending, refined = [], []
        end = time.monotonic() + 120.0
        while time.monotonic() < end:  # the camera stays: T builds again while refinements are pending
            w.tick()
            pending.append(w._mesh[9]["pending"])
            refined.append(w._mesh[9]["refined"])
            if pending[-1] == 0 and refined[-1] > 1:
                break
            time.sleep(0.005)
        assert pending[0] > 0 and pending[-1] == 0  # one super-surface a build, until none is left
        assert refined[0] == 1 and refined[-1] == refined[0] + pending[0]
    finally:
        w.close()
        pl.close()


@pytest.mark.gl
def test_no_background_pixel_from_inside_with_dynamic_refinement(sphere_lod):
    pl = pv.Plotter(off_screen=True, window_size=(200, 150))
    pl.set_background("black")
    pl.camera.view_angle = 60.0
    w = Walkthrough(sphere_lod, pl, threaded=False, cull_back=False, color="white", dynamic=True)
    w.actor.prop.lighting = False
    frames = w.fly([[(0.0, 0.0, 0.8), (0.6, 0.2, 0.9), (0.0, 0.0, 1.0)]] * 3, progress=False)
    img = pl.screenshot()
    pl.close()
    assert frames[-1]["refined"] > 0 and frames[-1]["finer_pending"] == 0
    assert (img.sum(axis=-1) == 0).sum() == 0  # every pixel hits the closed sphere: no crack


def test_bad_options():
    lod = build_lod(sphere(), 0.1, levels=1, progress=False)
    pl = pv.Plotter(off_screen=True, window_size=(40, 30))
    try:
        with pytest.raises(ValueError, match="not both"):
            Walkthrough(lod, pl, dynamic=True, assemble=lambda lod, levels: None)
        with pytest.raises(ValueError, match="needs a pixel_error"):
            Walkthrough(lod, pl, dynamic=True, pixel_error=None)
        with pytest.raises(TypeError, match="dynamic must be"):
            Walkthrough(lod, pl, dynamic="yes")
        assert Walkthrough(lod, pl, pixel_error=None).refiner is None
        with pytest.raises(TypeError, match="dynamic must be"):
            Walkthrough(lod, pl, dynamic=None)
        with pytest.raises(RuntimeError, match="on-screen plotter"):
            Walkthrough(lod, pl).interact()
    finally:
        pl.close()


def _wait_for(w, seconds=120.0):
    """Tick until the mesh shown was built for the newest camera (bounded poll)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        w.tick()
        rec = w._mesh
        if rec[1] is w._shown_cells and rec[0] == w._frame and not rec[9]["pending"]:
            return rec
        time.sleep(0.01)
    raise AssertionError("the workers did not build a mesh for the new camera in time")


@pytest.mark.parametrize("threaded", [False, True])
def test_interactive_ticks_follow_the_camera(threaded):
    lod = build_lod(torus(), 0.02, levels=3, progress=False)
    pl = pv.Plotter(off_screen=True, window_size=(160, 120))
    w = Walkthrough(lod, pl, threaded=threaded, dynamic=True)
    try:
        views = [((0.0, -12.0, 4.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),  # the whole torus, far
                 ((2.0, -0.6, 0.1), (2.0, 1.0, 0.0), (0.0, 0.0, 1.0)),  # close to the tube: a part, refined
                 ((-2.0, 0.6, 0.1), (-2.0, -1.0, 0.0), (0.0, 0.0, 1.0))]  # the other side
        shown = []
        for view in views:
            pl.camera_position = view
            rec = _wait_for(w)
            # the mesh shown is the selection for this camera
            _, eye, M, H = w._camera
            np.testing.assert_allclose(eye, view[0], rtol=0, atol=1e-12)
            levels, _ = select_levels(lod, eye, M, H, 1.0, finer_ratio=w.refiner.ratio, max_finer=w.refiner.max_steps)
            np.testing.assert_array_equal(rec[4], levels)
            shown.append((rec[4].copy(), rec[9]["refined"], int(rec[2]), w.mesh.GetNumberOfPolys()))
            assert w.mesh.GetNumberOfPolys() == int(rec[2])  # the actor shows that mesh
            assert w.tick() is False  # nothing moved: nothing new
        (a, ra, ta, _), (b, rb, tb, _), (c, rc, tc, _) = shown
        assert (a >= 0).all() and (b < 0).any() and (c < 0).any()  # culled super-surfaces change with the view
        assert not np.array_equal(b >= 0, c >= 0)
        assert ra == 0 and rb > 0 and rc > 0  # near the tube level 0 is too coarse: refined
    finally:
        w.close()
        pl.close()


def test_interact_ticks_on_the_interactor_timer_and_stops_the_workers():
    """The window's event loop replaced by a stand-in that moves the camera and fires the interactor's timer
    events (no display here): the timer observer ticks, the mesh follows, closing stops the workers."""
    lod = build_lod(torus(), 0.05, levels=2, progress=False)
    pl = pv.Plotter(off_screen=True, window_size=(120, 90))
    pl.off_screen = False  # as a window would be (show is replaced below)
    w = Walkthrough(lod, pl, threaded=True, dynamic=True)
    seen = []

    def fake_show(**_):
        assert len(w._workers) == 2 and all(t.is_alive() for t in w._workers)
        pl.ren_win.Render()  # the window's first render
        pl._first_time = False  # what show does: the ticks' renders go to the render window
        for view in [((0.0, -9.0, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
                     ((2.0, -0.8, 0.1), (2.0, 1.0, 0.0), (0.0, 0.0, 1.0))]:
            pl.camera_position = view
            end = time.monotonic() + 120.0
            while time.monotonic() < end:
                pl.iren.interactor.InvokeEvent("TimerEvent")
                rec = w._mesh
                if rec[1] is w._shown_cells and rec[0] == w._frame and not rec[9]["pending"]:
                    break
                time.sleep(0.01)
            seen.append((w._frame, rec[4].copy(), w.mesh.GetNumberOfPolys()))

    pl.show = fake_show
    try:
        w.interact(interval_ms=10)
        assert w._workers == []  # stopped when the window closed
        (f1, a, n1), (f2, b, n2) = seen
        assert f2 > f1 and (a >= 0).all() and (b < 0).any() and n1 > 0 and n2 > 0
    finally:
        w.close()
        pl.off_screen = True
        pl.close()


@pytest.mark.gl
def test_the_close_approach_switches_to_exact_patches_and_back(sphere_lod):
    """With a CloseUp the fly-through draws the super-surfaces that fill the view with the per-fragment program:
    none far away, some at the end of the close approach; the log carries the close-up's statistics; closing the
    walkthrough removes the exact actors."""
    from splinevis.nurbs.lod.closeup import CloseUp

    far, near = [(0.0, -40.0, 0.0), (0, 0, 0), (0, 0, 1)], [(0.0, -1.4, 0.0), (0, 0, 0), (0, 0, 1)]
    path = [far] * 3 + [near] * 3 + [far] * 2
    pl = pv.Plotter(off_screen=True, window_size=(160, 120))
    cu = CloseUp(max_supers=2)
    w = Walkthrough(sphere_lod, pl, threaded=False, closeup=cu)
    frames = w.fly(path, progress=False)
    assert [f["closeup"] for f in frames] == [0, 0, 0, 2, 2, 2, 0, 0]
    assert [f["closeup_switch"] for f in frames] == [False, False, False, True, False, False, True, False]
    assert all("closeup_ms" in f and f["closeup"] <= 2 for f in frames)
    pl.camera_position = near
    w.fly([near], progress=False)
    img = pl.screenshot()
    assert (img.reshape(-1, 3).std(axis=0) > 0).any()  # a picture, not a blank
    shown = len(pl.renderer.actors)
    w.close()
    assert len(pl.renderer.actors) < shown
    pl.close()

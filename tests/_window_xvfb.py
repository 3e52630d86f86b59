"""Run under xvfb-run by tests/test_window_xvfb.py: the interactive window on a virtual X display. Opens a
Plotter window (not off screen), renders a terrain spline, turns the camera by simulated mouse events,
screenshots, closes; then Walkthrough.interact() until a timer ends it. Prints one JSON line."""

import json
import sys

import numpy as np

import splinevis
from splinevis.nurbs.exact import torus

out = {}
z = np.add.outer(np.sin(np.linspace(0, 3, 30)), np.cos(np.linspace(0, 4, 40))) * 50.0
pl = splinevis.Plotter(window_size=(320, 240))
pl.add_terrain(z, spacing=(10.0, 10.0), origin=(0.0, 0.0), cmap="terrain", reflection_lines=8)
pl.show(interactive_update=True, auto_close=False)
out["window_class"] = pl.render_window.GetClassName()
out["off_screen"] = bool(pl.render_window.GetOffScreenRendering())
before = np.asarray(pl.camera.position, dtype=float)
first = np.asarray(pl.screenshot())
iren = pl.iren.interactor
iren.SetEventInformation(160, 120)
iren.LeftButtonPressEvent()
for x in range(160, 240, 8):  # drag to the right: the trackball camera turns
    iren.SetEventInformation(x, 120)
    iren.MouseMoveEvent()
iren.LeftButtonReleaseEvent()
pl.render()
after = np.asarray(pl.camera.position, dtype=float)
second = np.asarray(pl.screenshot())
out["camera_moved"] = float(np.linalg.norm(after - before))
out["drawn_fraction"] = float(np.any(first != first[0, 0], axis=-1).mean())
out["picture_changed"] = float(np.abs(second.astype(int) - first.astype(int)).mean())
pl.close()

pl = splinevis.Plotter(window_size=(240, 180))
walk = pl.add_walkthrough(torus(), levels=2)
ticks = []


def stop_after_ticks(*_):
    ticks.append(1)
    if len(ticks) >= 10:
        pl.iren.interactor.TerminateApp()


pl.iren.add_observer("TimerEvent", stop_after_ticks)
walk.interact(interval_ms=20)
out["walkthrough_ticks"] = len(ticks)
out["walkthrough_frames"] = int(walk._frame) if hasattr(walk, "_frame") else None
json.dump(out, sys.stdout)
print()

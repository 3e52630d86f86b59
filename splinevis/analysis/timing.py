"""Frame timing for studies and benchmarks (never for tests)."""

from __future__ import annotations

import statistics
import time

__all__ = ["frame_times"]


def frame_times(plotter, repeats: int = 5) -> dict:
    """Time ``repeats`` frames of a :class:`splinevis.Plotter` after two warm-up frames (the first compiles
    the programs and uploads buffers). Each frame is the render window's Render() followed by
    WaitForCompletion(). Returns ``{"min_ms", "median_ms", "repeats"}``.

    Examples
    --------
    >>> import pyvista as pv
    >>> from splinevis.plotting import Plotter
    >>> pl = Plotter(off_screen=True, window_size=(32, 24))
    >>> _ = pl.add_mesh(pv.Sphere())
    >>> r = frame_times(pl, repeats=3)
    >>> r["repeats"], 0.0 < r["min_ms"] <= r["median_ms"]
    (3, True)
    >>> pl.close()
    """
    plotter.render_now()
    plotter.render_now()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        plotter.render_now()
        times.append(time.perf_counter() - t0)
    return {"min_ms": 1e3 * min(times), "median_ms": 1e3 * statistics.median(times), "repeats": repeats}

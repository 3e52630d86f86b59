"""Frame timing for studies and benchmarks (never for tests)."""

from __future__ import annotations

import statistics
import time

__all__ = ["frame_times", "interleaved_frame_times"]


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
    r = interleaved_frame_times([plotter], repeats)[0]
    return {k: r[k] for k in ("min_ms", "median_ms", "repeats")}


def interleaved_frame_times(plotters, repeats: int = 5, warmup: int = 2) -> list:
    """Time ``repeats`` rounds of frames of several plotters side by side: ``warmup`` untimed frames each first,
    then one frame of every plotter per round, so that load from other processes falls on all alike (the
    fastest frame is the quiet one). One dict per plotter: ``{"min_ms", "median_ms", "repeats", "seconds"}``
    (``seconds``: every timed frame).

    >>> import pyvista as pv
    >>> from splinevis.plotting import Plotter
    >>> pls = [Plotter(off_screen=True, window_size=(32, 24)) for _ in range(2)]
    >>> _ = pls[0].add_mesh(pv.Sphere()); _ = pls[1].add_mesh(pv.Cube())
    >>> rows = interleaved_frame_times(pls, repeats=3)
    >>> [len(r["seconds"]) for r in rows], all(0.0 < r["min_ms"] <= r["median_ms"] for r in rows)
    ([3, 3], True)
    >>> for pl in pls: pl.close()
    """
    plotters = list(plotters)
    for pl in plotters:
        for _ in range(warmup):
            pl.render_now()
    times = [[] for _ in plotters]
    for _ in range(repeats):
        for pl, t in zip(plotters, times):
            t0 = time.perf_counter()
            pl.render_now()
            t.append(time.perf_counter() - t0)
    return [{"min_ms": 1e3 * min(t), "median_ms": 1e3 * statistics.median(t), "repeats": repeats, "seconds": t}
            for t in times]

"""Where a ray-cast frame's work goes, per fragment: counters read back from a debug build of the program.

A program built with ``program_options={"debug": "counters"}`` (the terrain program; flag
``SV_DEBUG_COUNTERS``, ``glsl/lib/core/counters.glsl``) writes, instead of its colour, one of its per-fragment
work counts as a 24-bit integer in the colour channels; the uniform ``sv_counter_select`` picks which, so
:func:`fragment_counters` renders one frame per count and decodes each exactly. Misses are written at the far
plane, not discarded: their work is counted, and the depth buffer still holds exactly the hits. The default
build compiles none of this (its source is unchanged).

Counts per fragment (:data:`COUNTERS`):

``traversal``
    Iterations of the hierarchy walk: blocks visited at any level, cells included.
``cells``
    Level-0 cells whose two triangles were intersected (coefficients loaded).
``root_calls``
    Restricted quartics handed to the root finder (their control polygon changes sign).
``root_steps``
    Root-finder steps summed over those calls: bracketed-Newton steps (each one vec4 evaluation of f and
    f' at four points), or Newton steps of the four-start method (``roots="paper"``, four lanes at once).

Timing belongs to ``benchmarks/bench_profile.py``, which uses these counts to turn frame times into work rates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["COUNTERS", "FragmentCounters", "fragment_counters", "decode_counts"]

#: The counts a counters build writes, in the order of ``sv_counter_select`` = 1, 2, ... (0 is the flags).
COUNTERS = ("traversal", "cells", "root_calls", "root_steps")
_PERCENTILES = (50, 90, 99)


def decode_counts(image) -> np.ndarray:
    """The 24-bit integers of an (H, W, 3+) uint8 image written by ``sv_counters_color``: R G B = bits
    16..23, 8..15, 0..7.

    Examples
    --------
    >>> decode_counts(np.array([[[0, 0, 0], [0, 1, 2], [1, 0, 255]]], dtype=np.uint8)).tolist()
    [[0, 258, 65791]]
    """
    rgb = np.asarray(image)[..., :3].astype(np.int64)
    return (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]


@dataclass(frozen=True)
class FragmentCounters:
    """Per-pixel work counts of one frame (row 0 at the top, like a screenshot).

    Attributes
    ----------
    fragments : (H, W) bool ndarray
        A fragment of the program ran at the pixel (its proxy covers it); False: background.
    shaded : (H, W) bool ndarray
        The fragment hit the surface, so shading ran.
    traversal, cells, root_calls, root_steps : (H, W) int64 ndarray
        The counts of :data:`COUNTERS` (module docstring); 0 where no fragment ran.

    Examples
    --------
    >>> z = np.zeros((2, 3), dtype=np.int64)
    >>> c = FragmentCounters(z > 0, z > 0, z + 3, z + 1, z, z)
    >>> c.shape, int(c.arrays()["traversal"][0, 0])
    ((2, 3), 3)
    """

    fragments: np.ndarray
    shaded: np.ndarray
    traversal: np.ndarray
    cells: np.ndarray
    root_calls: np.ndarray
    root_steps: np.ndarray

    @property
    def shape(self) -> tuple:
        """(H, W) of the frame.

        Examples
        --------
        >>> z = np.zeros((3, 5), dtype=np.int64)
        >>> FragmentCounters(z > 0, z > 0, z, z, z, z).shape
        (3, 5)
        """
        return self.fragments.shape

    def arrays(self) -> dict:
        """The counts by name (:data:`COUNTERS`).

        Examples
        --------
        >>> z = np.zeros((1, 1), dtype=np.int64)
        >>> sorted(FragmentCounters(z > 0, z > 0, z, z, z, z).arrays())
        ['cells', 'root_calls', 'root_steps', 'traversal']
        """
        return {name: getattr(self, name) for name in COUNTERS}

    def lane_efficiency(self, block=(2, 4)) -> dict:
        """Per count: the work of the fragments divided by what SIMD lanes spend on it when every group of
        ``block`` = (rows, columns) pixels runs as one vector and a loop runs until its longest lane is done
        (llvmpipe with 256-bit vectors shades 8 fragments at once, two 2x2 quads side by side: ``(2, 4)``,
        blocks aligned to the window's bottom-left corner). 1.0: no lane ever waits; fragments missing from
        a group (background) count as waiting lanes.

        Examples
        --------
        >>> ran = np.ones((2, 4), dtype=bool)
        >>> steps = np.array([[1, 1, 1, 1], [1, 1, 1, 5]])  # one lane needs 5 steps, the other 7 wait
        >>> FragmentCounters(ran, ran, steps, steps, steps, steps).lane_efficiency()["traversal"]
        0.3
        """
        h, w = self.shape
        rows, cols = block
        out = {}
        for name, arr in self.arrays().items():
            a = np.where(self.fragments, arr, 0)[::-1]  # bottom row first: GL blocks start there
            a = np.pad(a, ((0, -h % rows), (0, -w % cols)))
            groups = a.reshape(a.shape[0] // rows, rows, a.shape[1] // cols, cols)
            spent = float(groups.max(axis=(1, 3)).sum()) * rows * cols
            out[name] = float(a.sum()) / spent if spent else 1.0
        return out

    def summary(self) -> dict:
        """Mean, percentiles (50, 90, 99) and maximum of each count over the fragments that ran, over the
        hits and over the misses; fragment and hit numbers; root steps per root call; the SIMD lane
        efficiency of each count (:meth:`lane_efficiency`).

        Examples
        --------
        >>> ran = np.array([[True, True, False]])
        >>> counts = np.array([[4, 2, 0]])
        >>> s = FragmentCounters(ran, np.array([[True, False, False]]), counts, counts // 2, counts // 2, 3 * counts).summary()
        >>> s["fragments"], s["hits"], s["traversal"]["mean"], s["traversal"]["max"], s["root_steps_per_call"]
        (2, 1, 3.0, 4, 6.0)
        >>> s["hit"]["traversal"]["mean"], s["miss"]["traversal"]["mean"]
        (4.0, 2.0)
        """
        ran = self.fragments
        hit = ran & self.shaded

        def stats(mask):
            out = {}
            for name, arr in self.arrays().items():
                v = arr[mask]
                if v.size == 0:
                    out[name] = {"mean": 0.0, **{f"p{q}": 0.0 for q in _PERCENTILES}, "max": 0}
                    continue
                out[name] = {"mean": float(v.mean()), **{f"p{q}": float(np.percentile(v, q)) for q in _PERCENTILES},
                             "max": int(v.max())}
            return out

        n, nh = int(ran.sum()), int(hit.sum())
        calls = int(self.root_calls[ran].sum())
        return {"fragments": n, "hits": nh, "hit_fraction": nh / n if n else 0.0, **stats(ran),
                "root_steps_per_call": float(self.root_steps[ran].sum()) / calls if calls else 0.0,
                "hit": stats(hit), "miss": stats(ran & ~self.shaded), "lane_efficiency": self.lane_efficiency()}


def _counters_actor(plotter):
    for spline in getattr(plotter, "_spline_actors", ()):
        if dict(spline.assembled.defines).get("SV_DEBUG_COUNTERS"):
            return spline
    raise ValueError("no spline actor of this plotter was built with counters: add it with "
                     "program_options={'debug': 'counters'} (a debug build; the default one counts nothing).")


def _read_plotter(plotter) -> FragmentCounters:
    spline = _counters_actor(plotter)
    renderer = plotter.renderer
    background = renderer.GetBackground()
    gradient = renderer.GetGradientBackground()
    hidden = []
    for actor in renderer.GetActors():  # only the counters actor's fragments may reach the colour buffer
        if actor is not spline.actor and actor.GetVisibility():
            actor.VisibilityOff()
            hidden.append(actor)
    renderer.SetBackground(0.0, 0.0, 0.0)  # decodes to 0: no fragment ran
    renderer.GradientBackgroundOff()
    frames = []
    try:
        for select in range(len(COUNTERS) + 1):
            spline.extra_uniforms["sv_counter_select"] = select
            plotter.render_now()  # a screenshot alone may return the last frame without drawing this one
            frames.append(decode_counts(plotter.screenshot()))
    finally:
        spline.extra_uniforms.pop("sv_counter_select", None)
        renderer.SetBackground(*background)
        renderer.SetGradientBackground(gradient)
        for actor in hidden:
            actor.VisibilityOn()
    flags = frames[0]
    return FragmentCounters((flags & 1) > 0, (flags & 2) > 0, *frames[1:])


def fragment_counters(source, camera_position=None, window_size=(400, 300), *, program_options=None,
                      newton_iterations=None) -> FragmentCounters:
    """Per-pixel work counts of a ray-cast frame (module docstring), and their summary (``.summary()``).

    Parameters
    ----------
    source : splinevis.Plotter or spline model
        A Plotter holding a spline actor built with ``program_options={"debug": "counters"}`` (its camera
        and window as they are; other actors are hidden while the counts are read), or a model (a scene:
        drawn alone with the counters build, from ``camera_position`` in a ``window_size`` window).
    camera_position : list, optional
        PyVista camera position ``[eye, focal point, view up]`` (a model only; default: PyVista's reset view).
    window_size : (int, int)
        A model only.
    program_options : dict, optional
        Further options of the model's program (``roots``, ``hierarchy``, ...); a model only.
    newton_iterations : int, optional
        A model only.

    Returns
    -------
    FragmentCounters

    Examples
    --------
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:9, 0:9] / 8.0
    >>> terrain = TerrainSpline.from_heights(0.3 * np.sin(3 * x) * np.cos(2 * y), "C1", spacing=(1 / 8, 1 / 8))
    >>> c = fragment_counters(terrain, [(0.5, -1.0, 1.2), (0.5, 0.5, 0.0), (0, 0, 1)], (48, 36))
    >>> bool(c.shaded.any()), bool((c.traversal[c.shaded] >= 1).all()), int(c.traversal[~c.fragments].max())
    (True, True, 0)
    >>> s = c.summary()
    >>> 0.0 < s["hit_fraction"] <= 1.0, s["root_steps_per_call"] <= 4 * 8  # <= 3 extremum runs + 1 root run of 8 steps
    (True, True)
    """
    from ..plotting import Plotter

    if isinstance(source, Plotter):
        return _read_plotter(source)
    options = dict(program_options or {})
    options["debug"] = "counters"
    pl = Plotter(off_screen=True, window_size=tuple(window_size))
    try:
        pl.add_spline(source, lights=0, newton_iterations=newton_iterations, program_options=options)
        if camera_position is not None:
            pl.camera_position = camera_position
        pl.reset_camera_clipping_range()
        return _read_plotter(pl)
    finally:
        pl.close()

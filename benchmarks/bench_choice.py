"""Benchmark: what the choice by accuracy (``max_error_px``, :mod:`splinevis.choice`) picks and what it costs.

The scene is the terrain study's (``splinevis.studies.terrain``: Franke's function on 33 x 33 samples, C1,
800 x 600, its camera and clipping range, one light). For each request the choice is made for that view;
every distinct renderer chosen (meshes of k x k samples per cell, the ray cast) and the ray cast itself are
then opened at once and timed in turn, one frame each per round after two warm-up frames, so that load from
other processes falls on all alike (the machine may be shared: the fastest frame is the quiet one).

    python benchmarks/bench_choice.py [--repeats 5] [--out out/bench]

Writes ``choice.json`` and ``choice.md`` to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

REQUESTS = (2.0, 1.0, 0.5, 0.25, 0.1, 0.05, 0.02, 0.01)


def _scene(terrain, k):
    from splinevis import Style
    from splinevis.gl.mesh_effects import add_mesh_with_effects
    from splinevis.plotting import Plotter
    from splinevis.studies.terrain import CAMERA, WINDOW
    from splinevis.terrain.sampled_mesh import sampled_mesh

    pl = Plotter(off_screen=True, window_size=WINDOW)
    if k is None:
        pl.add_spline(terrain, lights=1)
    else:
        add_mesh_with_effects(pl, sampled_mesh(terrain, k), Style(lights=1))
    pl.camera_position = CAMERA
    pl.camera.clipping_range = (0.05, 10.0)
    return pl


def bench_choice(repeats: int = 5) -> dict:
    """Choices per request and frame times of the chosen renderers and the ray cast, side by side."""
    from splinevis.choice import choose
    from splinevis.gl.screen_error import View
    from splinevis.studies.terrain import CAMERA, WINDOW, franke_terrain

    terrain = franke_terrain(33, "C1")
    view = View(*CAMERA, 30.0, width=WINDOW[0], height=WINDOW[1], clipping_range=(0.05, 10.0))
    cache = {}
    choices = [choose(terrain, view, e, cache=cache) for e in REQUESTS]
    levels = sorted({c.level for c in choices if c.renderer == "mesh"}) + [None]
    scenes = {k: _scene(terrain, k) for k in levels}
    for pl in scenes.values():
        pl.render_now()
        pl.render_now()
    times = {k: [] for k in levels}
    for _ in range(repeats):
        for k, pl in scenes.items():
            t0 = time.perf_counter()
            pl.render_now()
            times[k].append(1e3 * (time.perf_counter() - t0))
    for pl in scenes.values():
        pl.close()
    frame = {k: {"min_ms": min(v), "median_ms": statistics.median(v)} for k, v in times.items()}
    rows = []
    for e, c in zip(REQUESTS, choices):
        f = frame[c.level if c.renderer == "mesh" else None]
        rows.append({"max_error_px": e, "renderer": c.renderer, "k": c.level, "triangles": c.chosen.triangles,
                     "error_px": c.error_px, "proven": c.chosen.proven, "meets": c.meets,
                     "frame_min_ms": f["min_ms"], "frame_median_ms": f["median_ms"],
                     "raycast_over_chosen": frame[None]["min_ms"] / f["min_ms"]})
    return {"scene": "terrain study: Franke 33x33 C1, 800x600", "repeats": repeats, "rows": rows,
            "raycast_frame_min_ms": frame[None]["min_ms"], "raycast_frame_median_ms": frame[None]["median_ms"],
            "raycast_error_px": next(o.error_px for o in choices[0].options if o.name == "raycast")}


def choice_markdown(result: dict) -> str:
    lines = [f"# Choice by accuracy ({result['scene']})", "",
             f"Ray cast: {result['raycast_frame_min_ms']:.1f} ms fastest, {result['raycast_frame_median_ms']:.1f} ms "
             f"median; its error estimate {result['raycast_error_px']:.3g} px. Best of {result['repeats']} "
             "interleaved rounds.", "",
             "| max_error_px | chosen | k | triangles | error px | proven | meets | frame min ms | frame median ms "
             "| ray cast / chosen |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        tri = f"{r['triangles']:,}" if r["triangles"] else "-"
        lines.append(f"| {r['max_error_px']:g} | {r['renderer']} | {r['k'] or '-'} | {tri} | {r['error_px']:.3g} | "
                     f"{r['proven']} | {r['meets']} | {r['frame_min_ms']:.1f} | {r['frame_median_ms']:.1f} | "
                     f"{r['raycast_over_chosen']:.2f} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args(argv)
    result = bench_choice(args.repeats)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "choice.json").write_text(json.dumps(result, indent=1))
    (out / "choice.md").write_text(choice_markdown(result))
    print(choice_markdown(result))


if __name__ == "__main__":
    main()

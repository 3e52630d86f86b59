"""Benchmark case ``profile``: where the time of a full-screen C1 terrain frame goes.

The scene is the terrain benchmark's (``run.py``, ``bench_terrain``): a 65x65 fractal terrain in the same
full-screen oblique view at 800x600, one light, here with the C1 scheme. Measured side by side in one run:

* ``full``: the program as users get it (default build), and with 1 root-finder step instead of 8 (what the
  steps themselves cost);
* ``flat``: shading replaced by a constant colour (debug build ``debug="flat"``; the hit's normal is then not
  evaluated either);
* ``restrict``: as ``flat``, and the first sign change of a restricted quartic taken as the hit: walk, coefficient
  loads, clipping and restriction by blossoming without the root finder (``debug="restrict"``);
* ``traversal``: the hierarchy walk only, stopping at the first candidate cell (``debug="traversal"``);
* ``raymarch``: a reference program marching a fixed number of steps through the terrain's box, one texel of
  the same coefficient texture per step (``debug="raymarch"``), at 0 steps (ray set-up, box clip, rasterization
  and frame: the floor), at the full program's mean number of walk steps per fragment and at 64 steps;
* ``full`` and ``raymarch`` again in new processes with ``LP_NUM_THREADS=1`` and ``2`` (llvmpipe reads it
  once, at start-up), for the rate per rasterizer thread;
* today's build of the ray-cast families against the new one, in one process (``bench_speedup.py``: the
  terrain of this scene and Marschner-Lobb isosurfaces), with the ratios today / new.

Fragments are the pixels the proxy covers (every one runs the program, hit or miss), counted by the
counters build (:func:`splinevis.analysis.profile.fragment_counters`), whose summary (walk steps, cells tested,
root-finder calls and steps per fragment, and how many SIMD lanes of llvmpipe's 8-wide groups wait on the
longest one) is reported with the rates. Rates and differences use each configuration's fastest frame (the
machine may be shared: the median picks up other processes' load); both are in the table.

    python benchmarks/run.py --cases profile         # or: python benchmarks/bench_profile.py
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

WINDOW = (800, 600)
CAMERA = [(0.5, -0.35, 0.55), (0.5, 0.45, 0.0), (0, 0, 1)]
GRID = 65
MARCH_STEPS = 64


def _terrain(n=GRID):
    from datasets_synthetic.dem_files import fractal_terrain
    from splinevis.terrain.model import TerrainSpline

    z = fractal_terrain(n, seed=3) * 0.15
    return TerrainSpline.from_heights(z, "C1", spacing=(1.0 / (n - 1), 1.0 / (n - 1)))


def _plotter(terrain, debug=None, iterations=None):
    from splinevis.plotting import Plotter

    pl = Plotter(off_screen=True, window_size=WINDOW)
    options = {} if debug is None else {"debug": debug}
    actor = pl.add_spline(terrain, lights=1, newton_iterations=iterations, program_options=options)
    pl.camera_position = CAMERA
    pl.camera.clipping_range = (0.01, 10.0)
    return pl, actor


def measure(configs, repeats):
    """Frame times of ``configs`` (list of ``[name, debug, march_steps, newton_iterations]``) in this process.

    All configurations are open at once and timed in turn, one frame each per round (after two warm-up
    frames): load from other processes then falls on all of them alike, and each one's fastest frame is
    one taken in a quiet moment (:func:`splinevis.analysis.timing.interleaved_frame_times`).
    """
    from splinevis.analysis.timing import interleaved_frame_times

    terrain = _terrain()
    scenes = []
    for name, debug, steps, iterations in configs:
        pl, actor = _plotter(terrain, debug, iterations)
        if steps is not None:
            actor.extra_uniforms["sv_march_steps"] = int(steps)
        scenes.append(pl)
    rows = []
    for (name, _, steps, _), pl, f in zip(configs, scenes, interleaved_frame_times(scenes, repeats)):
        covered = float((pl.depth_buffer() < 1.0).mean())
        pl.close()
        rows.append({"config": name, "march_steps": steps, "hit_pixels": covered, "min_ms": f["min_ms"],
                     "median_ms": f["median_ms"], "repeats": repeats})
    return rows


def _threads_label():
    return os.environ.get("LP_NUM_THREADS") or f"default ({len(os.sched_getaffinity(0))} cpus)"


def _threads_number():
    value = os.environ.get("LP_NUM_THREADS")
    return int(value) if value else len(os.sched_getaffinity(0))


def _in_subprocess(configs, repeats, threads):
    env = dict(os.environ, LP_NUM_THREADS=str(threads))
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--measure", json.dumps(configs),
                          "--repeats", str(repeats)], capture_output=True, text=True, check=True, env=env,
                         cwd=str(Path(__file__).resolve().parents[1]))
    return json.loads(out.stdout.strip().splitlines()[-1])


def bench_profile(repeats, quick):
    """The ``profile`` case (module docstring): a dict with the scene, the frame rows and the counter summary."""
    from splinevis.analysis.profile import fragment_counters

    load_before = os.getloadavg()
    terrain = _terrain()
    pl, _ = _plotter(terrain, "counters")
    counts = fragment_counters(pl)
    pl.close()
    summary = counts.summary()
    fragments = summary["fragments"]
    walk = max(1, round(summary["traversal"]["mean"]))
    configs = [["full", None, None, None], ["full, 1 root-finder step", None, None, 1], ["flat", "flat", None, None],
               ["restrict", "restrict", None, None], ["traversal", "traversal", None, None],
               ["raymarch 0 steps", "raymarch", 0, None], [f"raymarch {walk} steps", "raymarch", walk, None],
               [f"raymarch {MARCH_STEPS} steps", "raymarch", MARCH_STEPS, None]]
    rows = [dict(r, threads=_threads_label(), thread_count=_threads_number()) for r in measure(configs, repeats)]
    per_thread = [c for c in configs if c[0] == "full" or (c[1] == "raymarch" and c[2])]
    for threads in ([1] if quick else [1, 2]):
        for r in _in_subprocess(per_thread, max(2, repeats // 2) if quick else repeats, threads):
            rows.append(dict(r, threads=str(threads), thread_count=threads))
    full = next(r["min_ms"] for r in rows if r["config"] == "full")
    for r in rows:
        rate = fragments / (r["min_ms"] * 1e-3)
        r["fragments"] = fragments
        r["mfrag_per_s"] = rate * 1e-6
        r["mfrag_per_s_per_thread"] = rate * 1e-6 / r["thread_count"]
        r["ns_per_fragment_thread"] = r["min_ms"] * 1e6 * r["thread_count"] / fragments
        r["ratio_to_full"] = r["min_ms"] / full
    ms = {r["config"]: r["min_ms"] for r in rows[: len(configs)]}
    steps = ms["full"] - ms["full, 1 root-finder step"]
    parts = [("shading and the hit's normal", ms["full"] - ms["flat"]),
             ("root finder: 7 of its 8 bracketed-Newton steps", steps),
             ("root finder: the rest (secure points, piece scan, 1 step)", ms["flat"] - ms["restrict"] - steps),
             ("coefficient loads, clipping, restriction by blossoming", ms["restrict"] - ms["traversal"]),
             ("hierarchy walk", ms["traversal"] - ms["raymarch 0 steps"]),
             ("ray set-up, box clip, rasterization, frame", ms["raymarch 0 steps"])]
    breakdown = [{"part": name, "ms": v, "share": v / ms["full"]} for name, v in parts]
    scene = (f"C1 fractal terrain {GRID}x{GRID} ({terrain.num_patches:,} patches), full-screen oblique view, "
             f"{WINDOW[0]}x{WINDOW[1]}, 1 light")
    from bench_speedup import bench_speedup

    return {"scene": scene, "frames": rows, "breakdown": breakdown, "counters": summary,
            "load_average": {"before": load_before, "after": os.getloadavg(), "cpus": len(os.sched_getaffinity(0))},
            "speedup": bench_speedup(max(3, repeats // 2) if quick else repeats)}


def _load(result, when):
    return ", ".join(f"{v:.2f}" for v in result["load_average"][when])


def profile_markdown(result) -> str:
    """Markdown tables of :func:`bench_profile`'s result."""
    from bench_speedup import speedup_markdown

    lines = [speedup_markdown(result["speedup"]) if "speedup" in result else "",
             f"\n## Where a terrain frame's time goes\n\n{result['scene']}; {result['frames'][0]['fragments']:,} "
             f"fragments (proxy pixels) per frame. Load average (1, 5, 15 min) before "
             f"{_load(result, 'before')}, after {_load(result, 'after')} on {result['load_average']['cpus']} cpus.\n",
             "| configuration | LP threads | min ms | median ms | min / full | M fragments/s | M fragments/s per thread "
             "| ns per fragment x thread |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in result["frames"]:
        lines.append(f"| {r['config']} | {r['threads']} | {r['min_ms']:.1f} | {r['median_ms']:.1f} | "
                     f"{r['ratio_to_full']:.2f} | {r['mfrag_per_s']:.2f} | {r['mfrag_per_s_per_thread']:.2f} | "
                     f"{r['ns_per_fragment_thread']:.0f} |")
    lines += ["\nThe full frame by difference (fastest frames, same process):\n", "| part | ms | share |", "|---|---:|---:|"]
    lines += [f"| {b['part']} | {b['ms']:.1f} | {b['share']:.0%} |" for b in result["breakdown"]]
    s = result["counters"]
    lines += [f"\nPer fragment (counters build, all {s['fragments']:,} fragments; {s['hit_fraction']:.1%} hit; "
              f"{s['root_steps_per_call']:.2f} root-finder steps per call):\n",
              "| count | mean | p50 | p90 | p99 | max | mean on hits | mean on misses | SIMD lane efficiency (8-wide) |",
              "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name in ("traversal", "cells", "root_calls", "root_steps"):
        c = s[name]
        lines.append(f"| {name} | {c['mean']:.2f} | {c['p50']:.0f} | {c['p90']:.0f} | {c['p99']:.0f} | {c['max']} | "
                     f"{s['hit'][name]['mean']:.2f} | {s['miss'][name]['mean']:.2f} | {s['lane_efficiency'][name]:.2f} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--measure", help="JSON list of [name, debug, march_steps, newton_iterations]: time them here")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args(argv)
    if args.measure:
        print(json.dumps(measure(json.loads(args.measure), args.repeats)))
        return 0
    result = bench_profile(args.repeats, args.quick)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "profile.json").write_text(json.dumps(result, indent=2))
    md = profile_markdown(result)
    (out / "profile.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.path[:0] = [str(Path(__file__).resolve().parents[1]), str(Path(__file__).resolve().parent)]
    sys.exit(main())

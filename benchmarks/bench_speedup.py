"""Today's ray-cast build against the new one, full-screen frames, side by side in one process.

The terrain and isosurface programs keep the code they had before the llvmpipe restructuring behind a
compile-time flag (``SV_TERRAIN_LEGACY`` in glsl/programs/terrain.glsl, ``SV_VOLUME_LEGACY`` in
glsl/programs/isosurface.glsl), selected here per actor with ``SplineActor.set_variant``; everything else
(model, proxy, textures, uniforms, camera) is the same object. Scenes:

* ``terrain``: the profile scene (``bench_profile.py``): C1 fractal terrain 65x65, full-screen oblique view;
* ``isosurface quadratic`` / ``isosurface cubic``: Marschner-Lobb 64^3, the default program (block proxies,
  data encoding, closed-form roots) in the volume benchmark's full view (``run.py``, ``VOLUME_VIEWS``).

All builds are open at once and timed in turn, one frame each per round after two warm-up frames; ratios are
today / new of the fastest frames (and of the medians). The pictures of both builds are compared too: pixels
whose colour differs, pixels where only one build hits, and the largest window-depth difference.

    python benchmarks/bench_speedup.py [--repeats N]      # also part of run.py's profile case
"""

from __future__ import annotations

import os
import statistics
import sys
from pathlib import Path

WINDOW = (800, 600)
LEGACY = {"terrain": {"SV_TERRAIN_LEGACY": True}, "isosurface": {"SV_VOLUME_LEGACY": True}}


def _volume(scheme):
    from datasets_synthetic.volumes import marschner_lobb
    from splinevis.volume.model import VolumeSpline

    field = marschner_lobb()
    return VolumeSpline(field.sample(64), scheme), field.isovalue


def _scenes():
    """(name, family, build(plotter) -> actor, camera setter) of each scene."""
    from bench_profile import CAMERA, _terrain
    from run import VOLUME_VIEWS

    terrain = _terrain()

    def terrain_scene(pl):
        actor = pl.add_spline(terrain, lights=1)
        pl.camera_position = CAMERA
        pl.camera.clipping_range = (0.01, 10.0)
        return actor

    def volume_scene(scheme):
        spline, iso = _volume(scheme)

        def build(pl):
            actor = pl.add_isosurface(spline, iso, lights=1, culling=True)
            pl.camera_position = VOLUME_VIEWS["full"]
            pl.camera.view_angle = 30
            pl.camera.clipping_range = (0.01, 10.0)
            return actor
        return build

    return [("terrain C1 65x65, oblique", "terrain", terrain_scene),
            ("isosurface quadratic, Marschner-Lobb 64^3, full view", "isosurface", volume_scene("quadratic")),
            ("isosurface cubic, Marschner-Lobb 64^3, full view", "isosurface", volume_scene("cubic"))]


def bench_speedup(repeats):
    """The frame-time ratios today / new (module docstring): a dict with the rows and the load averages."""
    import numpy as np

    from splinevis.analysis.timing import interleaved_frame_times
    from splinevis.plotting import Plotter

    load_before = os.getloadavg()
    plotters = []
    for name, family, build in _scenes():
        for which in ("today", "new"):
            pl = Plotter(off_screen=True, window_size=WINDOW)
            actor = build(pl)
            if which == "today":
                actor.set_variant(LEGACY[family])
            plotters.append((name, family, which, pl))
    times = [f["seconds"] for f in interleaved_frame_times([p[3] for p in plotters], repeats)]
    rows = []
    for k in range(0, len(plotters), 2):
        name, family, _, old = plotters[k]
        new = plotters[k + 1][3]
        img_old, img_new = old.screenshot().astype(int), new.screenshot().astype(int)
        d_old, d_new = old.depth_buffer(), new.depth_buffer()
        both = (d_old < 1.0) & (d_new < 1.0)
        t_old, t_new = times[k], times[k + 1]
        rows.append({
            "scene": name, "family": family, "repeats": repeats,
            "today_min_ms": 1e3 * min(t_old), "today_median_ms": 1e3 * statistics.median(t_old),
            "new_min_ms": 1e3 * min(t_new), "new_median_ms": 1e3 * statistics.median(t_new),
            "ratio_min": min(t_old) / min(t_new), "ratio_median": statistics.median(t_old) / statistics.median(t_new),
            "hit_pixels": int((d_new < 1.0).sum()),
            "pixels_colour_differs": int((np.abs(img_old - img_new).max(-1) > 0).sum()),
            "pixels_one_side_hits": int(((d_old < 1.0) != (d_new < 1.0)).sum()),
            "depth_max_difference": float(np.abs(d_old - d_new)[both].max()) if both.any() else 0.0})
        old.close()
        new.close()
    return {"window": list(WINDOW), "rows": rows, "volume_parts": volume_parts(repeats),
            "load_average": {"before": load_before, "after": os.getloadavg(), "cpus": len(os.sched_getaffinity(0))}}


def proxy_fragments(pl, actor) -> int:
    """Fragments the drawn proxy boxes of an isosurface raster per frame, estimated as the area of their projected
    back faces (a box's projection is the convex hull of its 8 projected corners; every box in front of the eye)."""
    import numpy as np
    from scipy.spatial import ConvexHull
    from vtkmodules.util.numpy_support import vtk_to_numpy

    w, h = WINDOW
    pts = vtk_to_numpy(actor.poly.GetPoints().GetData()) + actor.offset
    m = pl.camera.GetCompositeProjectionTransformMatrix(w / h, -1, 1)
    M = np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
    drawn = np.unique(vtk_to_numpy(actor.poly.GetPolys().GetConnectivityArray()) // 8)
    clip = np.c_[pts, np.ones(len(pts))] @ M.T
    xy = ((clip[:, :2] / clip[:, 3:] + 1.0) / 2.0 * [w, h]).reshape(-1, 8, 2)
    return int(sum(ConvexHull(xy[k]).volume for k in drawn))


def volume_parts(repeats):
    """What the new isosurface frame (quadratic, full view) spends on shading and on overdraw: the frame with
    shading replaced by a constant colour (debug flag ``SV_DEBUG_NO_SHADING``, the hit's normal then unused), with
    blocks of 16^3 cubes instead of 8^3 (fewer, larger proxies: fewer fragments, longer walks), and the proxy's
    fragments per covered pixel."""
    import statistics as st

    from run import VOLUME_VIEWS
    from splinevis.analysis.timing import interleaved_frame_times
    from splinevis.plotting import Plotter

    spline, iso = _volume("quadratic")
    configs = [("new", {}, {}), ("new, shading off", {}, {"SV_DEBUG_NO_SHADING": True}),
               ("new, blocks of 16^3 cubes", {"block_size": 16}, {})]
    scenes = []
    for label, options, variant in configs:
        pl = Plotter(off_screen=True, window_size=WINDOW)
        actor = pl.add_isosurface(spline, iso, lights=1, culling=True, program_options=options)
        if variant:
            actor.set_variant(variant)
        pl.camera_position = VOLUME_VIEWS["full"]
        pl.camera.view_angle = 30
        pl.camera.clipping_range = (0.01, 10.0)
        scenes.append((label, pl, actor))
    times = [f["seconds"] for f in interleaved_frame_times([s[1] for s in scenes], repeats)]
    rows = []
    for (label, pl, actor), t in zip(scenes, times):
        covered = int((pl.depth_buffer() < 1.0).sum())
        rows.append({"config": label, "min_ms": 1e3 * min(t), "median_ms": 1e3 * st.median(t),
                     "ratio_to_new": min(t) / min(times[0]), "fragments": proxy_fragments(pl, actor),
                     "hit_pixels": covered, "proxies": actor.poly.GetNumberOfPolys() // 12})
        pl.close()
    return rows


def speedup_markdown(result) -> str:
    """Markdown table of :func:`bench_speedup`'s result."""
    la = result["load_average"]
    load = lambda v: ", ".join(f"{x:.2f}" for x in v)  # noqa: E731
    lines = [f"\n## Today's build against the new one (full-screen frames, {result['window'][0]}x{result['window'][1]})\n",
             f"Both builds of each scene in one process, timed in turn ({result['rows'][0]['repeats']} frames each); "
             f"ratio = today / new. Load average (1, 5, 15 min) before {load(la['before'])}, after {load(la['after'])} "
             f"on {la['cpus']} cpus.\n",
             "| scene | today min ms | new min ms | ratio (min) | today median ms | new median ms | ratio (median) "
             "| hit pixels | pixels differing (colour / hit) | max depth difference |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in result["rows"]:
        lines.append(f"| {r['scene']} | {r['today_min_ms']:.1f} | {r['new_min_ms']:.1f} | {r['ratio_min']:.2f} | "
                     f"{r['today_median_ms']:.1f} | {r['new_median_ms']:.1f} | {r['ratio_median']:.2f} | "
                     f"{r['hit_pixels']:,} | {r['pixels_colour_differs']} / {r['pixels_one_side_hits']} | "
                     f"{r['depth_max_difference']:.2g} |")
    parts = result.get("volume_parts")
    if parts:
        lines += ["\nThe new isosurface frame (quadratic, full view): shading, and proxies of another size (same run). "
                  "Fragments: the projected back faces of the drawn block proxies (each runs the whole program; "
                  "llvmpipe does no early depth test for a shader that writes gl_FragDepth).\n",
                  "| configuration | min ms | median ms | min / new | proxies | fragments | fragments per hit pixel |",
                  "|---|---:|---:|---:|---:|---:|---:|"]
        lines += [f"| {r['config']} | {r['min_ms']:.1f} | {r['median_ms']:.1f} | {r['ratio_to_new']:.2f} | "
                  f"{r['proxies']} | {r['fragments']:,} | {r['fragments'] / max(r['hit_pixels'], 1):.1f} |"
                  for r in parts]
    return "\n".join(lines) + "\n"


def main(argv=None):
    import argparse
    import json

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args(argv)
    result = bench_speedup(args.repeats)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "speedup.json").write_text(json.dumps(result, indent=2))
    md = speedup_markdown(result)
    (out / "speedup.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    here = Path(__file__).resolve()
    sys.path[:0] = [str(here.parents[1]), str(here.parent)]
    sys.exit(main())

"""Benchmark: out-of-core stores of a large synthetic DEM (C1) and a large synthetic volume (quadratic).

    python benchmarks/bench_outofcore.py [--dem N] [--volume N] [--workers 1 2] [--out DIR]
                                         [--dem-scheme C1] [--dem-tile 512] [--keep STORE]
    python benchmarks/bench_outofcore.py --render STORE --out DIR
    python benchmarks/bench_outofcore.py --render-volume STORE [--isovalue 0.5] --out DIR

Each configuration runs in a fresh Python process (its peak memory, ru_maxrss, is its own) on dask's threaded
scheduler with 1 and 2 worker threads, writing to a temporary directory that is removed afterwards:

* ``dem``: :func:`datasets_synthetic.large_grids.large_dem` (n x n, computed chunk by chunk, chunked along the tiles) to
  :func:`splinevis.outofcore.write_terrain_store` with scheme C1 (``--dem-scheme``) and tiles of 512 x 512 cells:
  wall seconds (all passes: the mean, range and heights pyramid, then coefficients + pyramid), tiles and
  million cells per second, MB on disk, peak MB (ru_maxrss of the process and its children);
* ``volume``: :func:`datasets_synthetic.large_grids.large_volume` (n^3 Marschner-Lobb) to
  :func:`splinevis.outofcore.write_volume_store` (quadratic, tiles of 64^3 cubes): the same measures.

The targets are a 16k x 16k DEM and a 1024^3 volume under 4 GB of peak memory. The C1 coefficients of a
16k^2 DEM are 64 GB of float64 (the volume store of 1024^3 about 12 GB), minutes of work on a small machine,
so the sizes are parameters; ``--dem 16385 --dem-scheme C0`` builds the 16k DEM with 4 x 4 samples per cell
(4 GB of coefficients). ``--keep STORE`` keeps the last DEM store (with ``--dem 0`` the volume store),
``--render STORE`` draws it (:func:`render_store`: overview and a zoomed window, PNGs and the overview levels'
errors), ``--render-volume STORE`` an isosurface of a volume store (:func:`render_volume_store`: overview at a
decimated level and a zoomed window at full resolution); ``bench_outofcore(repeats, quick)`` is the case
function in the style of ``benchmarks/run.py`` (quick: 2048^2 and 128^3) and ``outofcore_markdown(rows)`` its table.
Results go to ``DIR/outofcore.json`` and ``DIR/outofcore.md``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

_CODE = r'''
import json, resource, shutil, tempfile, time
from pathlib import Path
import dask
from datasets_synthetic.large_grids import large_dem, large_volume
from splinevis.outofcore import write_terrain_store, write_volume_store
from splinevis.outofcore.terrain import terrain_input_chunks
from splinevis.outofcore.volume import volume_input_chunks
kind, n, workers, tile, scheme, keep = {kind!r}, {n}, {workers}, {tile}, {scheme!r}, {keep!r}
tmp = Path(tempfile.mkdtemp(prefix="bench_outofcore_", dir=keep and str(Path(keep).parent)))
try:
    with dask.config.set(scheduler="threads", num_workers=workers):
        t0 = time.perf_counter()
        if kind == "dem":
            heights = large_dem(n, chunks=terrain_input_chunks((n, n), scheme, tile))
            s = write_terrain_store(tmp / "s.zarr", heights, scheme, chunks=tile, spacing=(30.0, 30.0), progress=False)
            tiles, cells = s.tiles[0] * s.tiles[1], s.shape[0] * s.shape[1]
        else:
            samples = large_volume(n, chunks=volume_input_chunks((n, n, n), tile))
            s = write_volume_store(tmp / "s.zarr", samples, "quadratic", chunks=tile, progress=False)
            tiles, cells = -(-n // tile) ** 3, n ** 3
        wall = time.perf_counter() - t0
    disk = sum(f.stat().st_size for f in tmp.rglob("*") if f.is_file())
    if keep:
        shutil.rmtree(keep, ignore_errors=True)
        shutil.move(str(tmp / "s.zarr"), keep)
finally:
    shutil.rmtree(tmp, ignore_errors=True)
peak = max(resource.getrusage(who).ru_maxrss for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
print(json.dumps({{"case": kind, "size": n, "workers": workers, "tile": tile, "tiles": tiles, "cells": cells,
                  "scheme": scheme if kind == "dem" else "quadratic",
                  "wall_s": wall, "tiles_per_s": tiles / wall, "Mcells_per_s": cells / wall / 1e6,
                  "disk_MB": disk / 2**20, "peak_MB": peak / 1024}}))
'''


def run_case(kind, n, workers, tile, scheme="C1", keep=None):
    """One configuration in a fresh process: a dict of its measures (``keep``: move the store there instead
    of deleting it)."""
    code = _CODE.format(kind=kind, n=int(n), workers=int(workers), tile=int(tile), scheme=scheme,
                        keep=str(keep) if keep else None)
    root = Path(__file__).resolve().parents[1]
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=root)
    return json.loads(out.stdout.strip().splitlines()[-1])


def bench_outofcore(repeats, quick, *, dem=4096, volume=256, workers=(1, 2)):
    """Rows for the DEM and the volume store at each worker count (``repeats`` is unused: one build each)."""
    if quick:
        dem, volume = 2048, 128
    rows = []
    for w in workers:
        rows.append(run_case("dem", dem, w, 512))
        rows.append(run_case("volume", volume, w, 64))
    return rows


def outofcore_markdown(rows):
    """The results as a markdown table."""
    lines = ["\n## Out-of-core stores (own process, threaded scheduler)\n",
             "| data | workers | tiles | wall s | tiles/s | Mcells/s | disk MB | peak MB |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        what = (f"DEM {r['size']}^2, {r.get('scheme', 'C1')}, tiles {r['tile']}^2" if r["case"] == "dem"
                else f"volume {r['size']}^3, quadratic, tiles {r['tile']}^3")
        lines.append(f"| {what} | {r['workers']} | {r['tiles']} | {r['wall_s']:.1f} | {r['tiles_per_s']:.2f} | "
                     f"{r['Mcells_per_s']:.2f} | {r['disk_MB']:.0f} | {r['peak_MB']:.0f} |")
    return "\n".join(lines) + "\n"


def render_store(path, out, *, size=(1024, 768)):
    """Draw a terrain store twice: an overview of all of it (the finest heights level within the default cell
    budget) and a window of 2 x 2 tiles at the centre at full resolution (level 0); PNGs and a JSON of the
    levels, tiles, cells, seconds and the overview levels' distance to the full-resolution surface over the
    window (max and RMS over a 256 x 256 grid of points) go to ``out``."""
    import time

    import numpy as np

    import splinevis
    from splinevis.outofcore import open_terrain_store
    from splinevis.outofcore.overview import _levels, overview_spline

    s = open_terrain_store(path)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    x0, x1, y0, y1 = s.extent
    zlo, zhi = s.data_range
    info = {"store": repr(s), "data_range": s.data_range}
    pl = splinevis.Plotter(off_screen=True, window_size=size)
    t0 = time.perf_counter()
    a = pl.add_terrain_store(s, "all", lights=1, colormap="terrain")
    info["overview"] = {"level": a.store_view.level, "cells": a.store_view.cells, "load_s": time.perf_counter() - t0}
    cx, cy, w = 0.5 * (x0 + x1), 0.5 * (y0 + y1), x1 - x0
    pl.camera_position = [(cx - 0.3 * w, cy - 1.5 * w, 1.1 * w), (cx, cy + 0.05 * w, zlo), (0.0, 0.0, 1.0)]
    pl.reset_camera_clipping_range()
    t0 = time.perf_counter()
    pl.screenshot(str(out / "dem16k_overview.png"))
    info["overview"]["render_s"] = time.perf_counter() - t0
    pl.close()
    nty, ntx = s.tiles
    ty, tx = s.tile
    (dx, dy), (ox, oy) = s.cell_spacing, s.origin
    iy, ix = nty // 2 - 1, ntx // 2 - 1
    box = (ox + ix * tx * dx + 1, ox + (ix + 2) * tx * dx - 1, oy + iy * ty * dy + 1, oy + (iy + 2) * ty * dy - 1,
           zlo - 1e4, zhi + 1e4)
    pl = splinevis.Plotter(off_screen=True, window_size=size)
    t0 = time.perf_counter()
    a = pl.add_terrain_store(s, box, lights=1, colormap="terrain")
    v = a.store_view
    info["zoom"] = {"level": v.level, "tiles": v.tiles.tolist(), "read": v.read, "cells": v.cells,
                    "load_s": time.perf_counter() - t0}
    bw = box[1] - box[0]
    zc = float(np.median(v.terrain.coefficients)) + s.z_ref
    pl.camera_position = [(box[0] - 0.05 * bw, box[2] - 0.05 * bw, zc + 0.2 * bw),
                          (box[0] + 0.5 * bw, box[2] + 0.5 * bw, zc), (0.0, 0.0, 1.0)]
    pl.reset_camera_clipping_range()
    t0 = time.perf_counter()
    pl.screenshot(str(out / "dem16k_zoom_level0.png"))
    info["zoom"]["render_s"] = time.perf_counter() - t0
    pl.close()
    # the overview levels against the full-resolution surface over the zoomed window
    xs = np.linspace(box[0], box[1], 256)
    X, Y = np.meshgrid(xs, np.linspace(box[2], box[3], 256))
    full = v.terrain.evaluate(X, Y)
    info["level_error_m"] = {}
    for L in range(1, min(6, len(_levels(s))) + 1):
        d = overview_spline(s, L, v.rows, v.cols).evaluate(X, Y) - full
        info["level_error_m"][L] = {"max": float(np.abs(d).max()), "rms": float(np.sqrt((d * d).mean()))}
    (out / "dem16k_render.json").write_text(json.dumps(info, indent=2))
    return info


def render_volume_store(path, out, isovalue=0.5, *, size=(1024, 768), prefix="vol1024"):
    """Draw the isosurface ``isovalue`` of a volume store twice: an overview of all of it (the finest
    decimated level within the default cube budget) and a window of 2 x 2 x 2 bricks at the centre at full
    resolution (level 0, only its bricks read); PNGs and a JSON of the levels, bricks, cubes, relevant
    cubes, load and draw seconds, the decimated levels' distance to the full-resolution spline over the window
    (max and RMS of values at 20000 random points) and the peak memory go to ``out``."""
    import resource
    import time

    import splinevis
    from splinevis.outofcore import open_volume_store

    s = open_volume_store(path)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    info = {"store": repr(s), "isovalue": isovalue}
    (x0, y0, z0), (dx, dy, dz) = s.origin, s.spacing
    nz, ny, nx = s.shape
    ext = np.array([nx * dx, ny * dy, nz * dz])
    lo = np.array([x0, y0, z0]) - 0.5 * np.array([dx, dy, dz])

    def shoot(name, box, camera):
        pl = splinevis.Plotter(off_screen=True, window_size=size)
        if box is None:  # the camera's view: set it first
            pl.camera_position = camera
        t0 = time.perf_counter()
        a = pl.add_isosurface_store(s, isovalue, box, lights=1)
        v = a.store_view
        rec = {"box": box, "level": v.level, "bricks_in_view": len(v.bricks), "bricks_read": v.read,
               "cubes": [[q.start, q.stop] for q in v.cubes], "shape": list(v.shape),
               "relevant_cubes": len(v.isosurface.relevant.cubes), "load_s": time.perf_counter() - t0}
        pl.camera_position = camera
        pl.reset_camera_clipping_range()
        t0 = time.perf_counter()
        pl.screenshot(str(out / f"{prefix}_{name}.png"))
        rec["draw_s"] = time.perf_counter() - t0
        pl.close()
        info[name] = rec
        print(name, rec, flush=True)

    c = lo + 0.5 * ext
    w = float(ext.max())
    shoot("overview", "all", [tuple(c + np.array([1.3, -1.9, 1.2]) * w), tuple(c), (0.0, 0.0, 1.0)])
    info["overview"]["camera"] = "all of it"
    t = np.array(s.tiles[::-1])  # bricks along x, y, z; the window: 2 x 2 x 2 of them, at 3/4 of x
    b0 = lo + np.array([3 * t[0] // 4 - 1, t[1] // 2 - 1, t[2] // 2 - 1]) * np.array(s.tile[::-1]) * (dx, dy, dz)
    t = np.array(s.tile[::-1]) * np.array([dx, dy, dz])  # brick size (x, y, z)
    b1 = b0 + 2 * t
    box = tuple(float(v) for pair in zip(b0 + 0.25, b1 - 0.25) for v in pair)
    bc, bw = 0.5 * (b0 + b1), float((b1 - b0).max())
    shoot("zoom_level0", box, [tuple(bc + np.array([2.0, -1.2, 1.3]) * bw), tuple(bc), (0.0, 0.0, 1.0)])
    # a camera above the zoomed window choosing the bricks itself (its four side planes)
    shoot("camera", None, [tuple(bc + np.array([0.3, -0.6, 1.6]) * bw), tuple(bc), (0.0, 0.0, 1.0)])
    # the decimated levels against the full-resolution spline over the zoomed window (values at random points)
    from splinevis.outofcore.render_volume import load_volume_view, view_bricks

    bricks = view_bricks(s, isovalue, box)
    v0 = load_volume_view(s, isovalue, bricks, level=0)
    b = v0.isosurface.spline.bounds
    rng = np.random.default_rng(0)
    pts = np.array(b[::2]) + 0.5 + rng.random((20000, 3)) * (np.array(b[1::2]) - np.array(b[::2]) - 1.0)
    full = v0.isosurface.spline.evaluate(pts)
    info["level_error"] = {}
    for L in range(1, 5):
        d = load_volume_view(s, isovalue, bricks, level=L).isosurface.spline.evaluate(pts) - full
        info["level_error"][L] = {"max": float(np.abs(d).max()), "rms": float(np.sqrt((d * d).mean()))}
    info["peak_MB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    (out / f"{prefix}_render.json").write_text(json.dumps(info, indent=2))
    return info


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dem", type=int, default=16384, help="DEM side in samples (0: skip)")
    ap.add_argument("--volume", type=int, default=1024, help="volume side in samples (0: skip)")
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--dem-scheme", default="C1", help="terrain scheme (C0: sizes 4k + 1, 4 x 4 samples a cell)")
    ap.add_argument("--dem-tile", type=int, default=512, help="DEM tile in spline cells")
    ap.add_argument("--keep", default=None, help="keep the last DEM store (with --dem 0: the volume store) at this "
                    "path (e.g. to render it)")
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--render", default=None, help="draw this terrain store (overview + zoomed window) to --out")
    ap.add_argument("--render-volume", default=None, help="draw an isosurface of this volume store (overview + "
                    "zoomed window) to --out")
    ap.add_argument("--isovalue", type=float, default=0.5, help="isovalue for --render-volume")
    args = ap.parse_args(argv)
    if args.render:
        print(json.dumps(render_store(args.render, args.out), indent=1))
        return 0
    if args.render_volume:
        print(json.dumps(render_volume_store(args.render_volume, args.out, args.isovalue), indent=1))
        return 0
    rows = []
    for w in args.workers:
        if args.dem:
            keep = args.keep if w == args.workers[-1] else None
            rows.append(run_case("dem", args.dem, w, args.dem_tile, args.dem_scheme, keep))
            print(json.dumps(rows[-1]), flush=True)
        if args.volume:
            keep = args.keep if w == args.workers[-1] and not args.dem else None  # the DEM's if both
            rows.append(run_case("volume", args.volume, w, 64, keep=keep))
            print(json.dumps(rows[-1]), flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "outofcore.json").write_text(json.dumps(rows, indent=2))
    md = outofcore_markdown(rows)
    (out / "outofcore.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())

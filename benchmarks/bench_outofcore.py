"""Benchmark: out-of-core stores of a large synthetic DEM (C1) and a large synthetic volume (quadratic).

    python benchmarks/bench_outofcore.py [--dem N] [--volume N] [--workers 1 2] [--out DIR]

Each configuration runs in a fresh Python process (its peak memory, ru_maxrss, is its own) on dask's threaded
scheduler with 1 and 2 worker threads, writing to a temporary directory that is removed afterwards:

* ``dem``: :func:`datasets_synthetic.large_grids.large_dem` (n x n, computed chunk by chunk, chunked along the tiles) to
  :func:`splinevis.outofcore.write_terrain_store` with scheme C1 and tiles of 512 x 512 cells: wall seconds
  (both passes: the mean and range, then coefficients + pyramid), tiles and million cells per second, MB on
  disk, peak MB;
* ``volume``: :func:`datasets_synthetic.large_grids.large_volume` (n^3 Marschner-Lobb) to
  :func:`splinevis.outofcore.write_volume_store` (quadratic, tiles of 64^3 cubes): the same measures.

The targets are a 16k x 16k DEM and a 1024^3 volume under 4 GB of peak memory. The C1 coefficients of a
16k^2 DEM are 64 GB of float64 (the volume store of 1024^3 about 12 GB), minutes of work on a small machine,
so the sizes are parameters; ``bench_outofcore(repeats, quick)`` is the case function in the style of
``benchmarks/run.py`` (quick: 2048^2 and 128^3) and ``outofcore_markdown(rows)`` its table.
Results go to ``DIR/outofcore.json`` and ``DIR/outofcore.md``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

_CODE = r'''
import json, resource, shutil, tempfile, time
from pathlib import Path
import dask
from datasets_synthetic.large_grids import large_dem, large_volume
from splinevis.outofcore import write_terrain_store, write_volume_store
from splinevis.outofcore.terrain import terrain_input_chunks
from splinevis.outofcore.volume import volume_input_chunks
kind, n, workers, tile = {kind!r}, {n}, {workers}, {tile}
tmp = Path(tempfile.mkdtemp(prefix="bench_outofcore_"))
try:
    with dask.config.set(scheduler="threads", num_workers=workers):
        t0 = time.perf_counter()
        if kind == "dem":
            heights = large_dem(n, chunks=terrain_input_chunks((n, n), "C1", tile))
            s = write_terrain_store(tmp / "s.zarr", heights, "C1", chunks=tile, spacing=(30.0, 30.0), progress=False)
            tiles, cells = s.tiles[0] * s.tiles[1], s.shape[0] * s.shape[1]
        else:
            samples = large_volume(n, chunks=volume_input_chunks((n, n, n), tile))
            s = write_volume_store(tmp / "s.zarr", samples, "quadratic", chunks=tile, progress=False)
            tiles, cells = -(-n // tile) ** 3, n ** 3
        wall = time.perf_counter() - t0
    disk = sum(f.stat().st_size for f in tmp.rglob("*") if f.is_file())
finally:
    shutil.rmtree(tmp, ignore_errors=True)
print(json.dumps({{"case": kind, "size": n, "workers": workers, "tile": tile, "tiles": tiles, "cells": cells,
                  "wall_s": wall, "tiles_per_s": tiles / wall, "Mcells_per_s": cells / wall / 1e6,
                  "disk_MB": disk / 2**20, "peak_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}}))
'''


def run_case(kind, n, workers, tile):
    """One configuration in a fresh process: a dict of its measures."""
    code = _CODE.format(kind=kind, n=int(n), workers=int(workers), tile=int(tile))
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
        what = (f"DEM {r['size']}^2, C1, tiles {r['tile']}^2" if r["case"] == "dem"
                else f"volume {r['size']}^3, quadratic, tiles {r['tile']}^3")
        lines.append(f"| {what} | {r['workers']} | {r['tiles']} | {r['wall_s']:.1f} | {r['tiles_per_s']:.2f} | "
                     f"{r['Mcells_per_s']:.2f} | {r['disk_MB']:.0f} | {r['peak_MB']:.0f} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dem", type=int, default=16384, help="DEM side in samples (0: skip)")
    ap.add_argument("--volume", type=int, default=1024, help="volume side in samples (0: skip)")
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args(argv)
    rows = []
    for w in args.workers:
        if args.dem:
            rows.append(run_case("dem", args.dem, w, 512))
            print(json.dumps(rows[-1]), flush=True)
        if args.volume:
            rows.append(run_case("volume", args.volume, w, 64))
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

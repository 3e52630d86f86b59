"""Benchmark: seconds to read a 3000 x 3000 USGS ASCII DEM, side by side with the same heights as GeoTIFF.

The same fractal heights (0.1 m resolution, five-digit fields: GDAL cannot read touching six-digit ones) are written as a USGS ASCII DEM (1024-character records, a type C
record at the end), the same DEM with a line break after every record, and a float32 GeoTIFF; each is read
``repeats`` times in one process: ``read_heights`` (our DEM parser; rasterio for the GeoTIFF) and GDAL's
USGSDEM driver through rasterio on the DEM (the independent reader; it places the raster differently, see
``splinevis/io/dem.py``). Wall seconds, best and median, and the ratio to the GeoTIFF read of the same run.
The heights read from both DEM layouts are checked equal to the stored integers times 0.1 before timing.

    python benchmarks/bench_read_dem.py [--n 3000] [--repeats 3] [--out out/bench]

Writes ``read_dem.json`` and ``read_dem.md`` to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def _timed(fn, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times), float(np.median(times))


def bench_read_dem(n: int = 3000, repeats: int = 3) -> dict:
    import rasterio

    from datasets_synthetic.dem_files import fractal_terrain, write_geotiff, write_usgs_ascii_dem
    from splinevis.io import read_heights

    h = 1000.0 + fractal_terrain(n, seed=7, amplitude=1500.0)
    stored = np.rint(h / 0.1) * 0.1
    origin = (500010.0, 4100020.0)  # a northing off the multiples of the spacing: GDAL snaps it
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        t0 = time.perf_counter()
        dem = write_usgs_ascii_dem(folder / "big.dem", h, 30.0, origin, z_resolution=0.1, accuracy=(0,) * 10)
        broken = write_usgs_ascii_dem(folder / "big_lines.dem", h, 30.0, origin, z_resolution=0.1,
                                      accuracy=(0,) * 10, line_breaks=True)
        tif = write_geotiff(folder / "big.tif", h, (30.0, 30.0), origin, epsg=32633, dtype=np.float32)
        write_s = time.perf_counter() - t0
        for path in (dem, broken):
            np.testing.assert_array_equal(read_heights(path).heights, stored)

        def gdal(path):
            with rasterio.open(path) as ds:
                return ds.read(1)

        cases = [("USGS DEM, 1024-character records", "read_heights (splinevis parser)", dem,
                  lambda: read_heights(dem)),
                 ("USGS DEM, a line break after each record", "read_heights (splinevis parser)", broken,
                  lambda: read_heights(broken)),
                 ("USGS DEM, 1024-character records", "GDAL USGSDEM driver (rasterio)", dem, lambda: gdal(dem)),
                 ("GeoTIFF float32", "read_heights (rasterio)", tif, lambda: read_heights(tif))]
        for fmt, reader, path, fn in cases:
            best, median = _timed(fn, repeats)
            rows.append({"format": fmt, "reader": reader, "MB": path.stat().st_size / 1e6, "best_s": best,
                         "median_s": median})
    ref = next(r["best_s"] for r in rows if r["format"] == "GeoTIFF float32")
    for r in rows:
        r["ratio_to_geotiff"] = r["best_s"] / ref
    return {"n": n, "repeats": repeats, "write_s": write_s, "cpus": os.cpu_count(),
            "python": platform.python_version(), "rows": rows}


def read_dem_markdown(result: dict) -> str:
    n = result["n"]
    lines = [f"# Reading a {n} x {n} DEM ({n * n / 1e6:.0f} million heights)", "",
             f"Same heights in every file; best and median wall seconds of {result['repeats']} reads in one process "
             f"({result['cpus']} CPUs); ratio: best against the GeoTIFF read of the same run. Goal: the USGS DEM "
             "read by `read_heights` in <= 3 s.", "",
             "| file | reader | MB | best s | median s | / GeoTIFF |", "|---|---|---:|---:|---:|---:|"]
    for r in result["rows"]:
        lines.append(f"| {r['format']} | {r['reader']} | {r['MB']:.0f} | {r['best_s']:.2f} | {r['median_s']:.2f} | "
                     f"{r['ratio_to_geotiff']:.1f} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=3000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args(argv)
    result = bench_read_dem(args.n, args.repeats)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "read_dem.json").write_text(json.dumps(result, indent=1))
    (out / "read_dem.md").write_text(read_dem_markdown(result))
    print(read_dem_markdown(result))
    return result


if __name__ == "__main__":
    main()

"""Benchmark: seconds to read the Rhino ``.3dm`` files of the real-file folder with ``read_nurbs``.

Each file is read in a new process (``cold``: the first read, with the lazy imports of rhino3dm and scipy's
interpolation and k-d tree that the first file of a session pays; the interpreter and splinevis imported
before the clock starts), then ``repeats`` more times in that process (``warm``: fastest and median). Wall
and CPU seconds are both kept: on a shared machine the CPU time is the reader's own work, the wall time
what a user waits; the load average before and after each file says how shared the machine was. Faces
drawn / faces in the file (counted by rhino3dm: Brep faces, Extrusions and plain surfaces) and the
warnings' count complete a row.

    python benchmarks/bench_read_3dm.py [--data ../shared/data/nurbs] [--repeats 3] [--out out/bench]

Writes ``read_3dm.json`` and ``read_3dm.md`` to ``--out``; prints a message and writes nothing when the
data folder is absent.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
from pathlib import Path

DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "nurbs"

_CHILD = r"""
import json, os, sys, time, warnings
import numpy as np
import splinevis.io as sio
path, repeats = sys.argv[1], int(sys.argv[2])

def once():
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        t0, c0 = time.perf_counter(), time.process_time()
        m = sio.read_nurbs(path)
        return time.perf_counter() - t0, time.process_time() - c0, m, len(w)

load0 = os.getloadavg()[0]
wall, cpu, m, nwarn = once()
warm = [once()[:2] for _ in range(repeats)]
import rhino3dm
f3 = rhino3dm.File3dm.Read(path)
faces = 0
for o in f3.Objects:
    g = o.Geometry
    if isinstance(g, rhino3dm.Extrusion):
        g = g.ToBrep(False)
    if isinstance(g, rhino3dm.Brep):
        faces += len(g.Faces)
    elif isinstance(g, rhino3dm.Surface):
        faces += 1
print(json.dumps({"cold_wall_s": wall, "cold_cpu_s": cpu, "warm_wall_min_s": min(w for w, _ in warm),
                  "warm_wall_median_s": float(np.median([w for w, _ in warm])),
                  "warm_cpu_min_s": min(c for _, c in warm), "faces_drawn": len(m.surfaces),
                  "faces_in_file": faces, "warnings": nwarn, "load_before": load0,
                  "load_after": os.getloadavg()[0]}))
"""


def bench_read_3dm(data: Path, repeats: int = 3) -> dict:
    rows = []
    for f in sorted(data.glob("*.3dm")):
        r = subprocess.run([sys.executable, "-c", _CHILD, str(f), str(repeats)], capture_output=True, text=True)
        if r.returncode != 0:
            rows.append({"file": f.name, "MB": f.stat().st_size / 1e6, "error": r.stderr.strip().splitlines()[-1]})
            continue
        rows.append({"file": f.name, "MB": f.stat().st_size / 1e6, **json.loads(r.stdout.strip().splitlines()[-1])})
    return {"data": os.path.relpath(data, Path(__file__).resolve().parents[1]), "repeats": repeats, "cpus": os.cpu_count(), "python": platform.python_version(),
            "rows": rows}


def read_3dm_markdown(result: dict) -> str:
    lines = [f"# Reading Rhino .3dm files (`read_nurbs`, {result['data']})", "",
             f"Cold: first read in a new process; warm: best / median of {result['repeats']} more in that process. "
             f"{result['cpus']} CPUs, shared: the load average (1 min) before and after each file is given.", "",
             "| file | MB | faces drawn / in file | cold wall s | cold CPU s | warm wall min s | warm wall median s "
             "| warm CPU s | warnings | load before / after |", "|---|---:|---|---:|---:|---:|---:|---:|---:|---|"]
    for r in result["rows"]:
        if "error" in r:
            lines.append(f"| `{r['file']}` | {r['MB']:.2f} | error: {r['error']} | | | | | | | |")
            continue
        lines.append(f"| `{r['file']}` | {r['MB']:.2f} | {r['faces_drawn']} / {r['faces_in_file']} | "
                     f"{r['cold_wall_s']:.2f} | {r['cold_cpu_s']:.2f} | {r['warm_wall_min_s']:.2f} | "
                     f"{r['warm_wall_median_s']:.2f} | {r['warm_cpu_min_s']:.2f} | {r['warnings']} | "
                     f"{r['load_before']:.1f} / {r['load_after']:.1f} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", default=str(DEFAULT_DATA), help="folder with the .3dm files")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args(argv)
    data = Path(args.data)
    if not data.is_dir() or not any(data.glob("*.3dm")):
        print(f"bench_read_3dm: skipped: no .3dm files in {data} (the real-file folder is absent)")
        return None
    result = bench_read_3dm(data, args.repeats)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "read_3dm.json").write_text(json.dumps(result, indent=1))
    (out / "read_3dm.md").write_text(read_3dm_markdown(result))
    print(read_3dm_markdown(result))
    return result


if __name__ == "__main__":
    main()

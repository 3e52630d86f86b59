"""Benchmark: from a many-face CAD model to its first frame (target: a part of some 300 faces read, built and
drawn in <= 5 s on a 2-core machine with llvmpipe).

Each model is timed in a fresh Python process (imports done first, not timed), stage by stage:

* ``read``: :func:`splinevis.io.read_nurbs` (for the synthetic model: building it in memory);
* ``add_nurbs``: the program build (tables, certified shell, trim pieces) and the actor;
* ``first frame``: ``screenshot()`` of a 400 x 300 off-screen window from the default camera (compiles the
  shaders, uploads the tables, draws once);
* ``second frame``: one more ``render_now()`` (what every later frame costs); ``frame CPU``: the process's CPU
  seconds in that frame (llvmpipe's threads included: on a loaded machine the wall time grows, this does not);
* ``to first frame``: read + add_nurbs + first frame.

Models: ``bug27693_cornetta-step.stp`` (110 faces) and ``hammer.iges`` (45 faces) from ``../shared/data/nurbs``
(skipped with a message when that folder is absent; ``SPLINEVIS_NURBS_DATA`` points elsewhere), and the synthetic
ones that are always there: 10 Newell teapots (320 bicubic patches, untrimmed) and, with the ``cad`` extra
(OpenCASCADE), 9 filleted plates with 6 holes each written to STEP (solids) and to IGES (144 trimmed surfaces
without topology, oriented by adjacency on reading) and read back (288 trimmed faces: planes, cylinders and
spheres as CAD systems write them).

    python benchmarks/bench_nurbs_files.py [--repeats 3] [--out out/bench]

Writes ``nurbs_files.json`` and ``nurbs_files.md`` to ``--out``; ``run.py --cases nurbs_files`` runs it too.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WINDOW = (400, 300)
FILES = ("bug27693_cornetta-step.stp", "hammer.iges")

_STAGES = r'''
import json, os, resource, sys, time, warnings
warnings.simplefilter("ignore")
sys.path.insert(0, {root!r})
import numpy as np
import splinevis
from splinevis.io.nurbs_files import read_nurbs
from splinevis.nurbs.shell import tessellate
import splinevis.plotting

def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime

kind, arg = {kind!r}, {arg!r}
t0 = time.perf_counter()
if kind == "file":
    model = read_nurbs(arg)
else:
    from datasets_synthetic.large_models import teapot_field
    model = teapot_field(int(arg))
t_read = time.perf_counter() - t0
pl = splinevis.Plotter(off_screen=True, window_size={window!r})
t0 = time.perf_counter()
actor = pl.add_nurbs(model)
t_add = time.perf_counter() - t0
t0 = time.perf_counter()
img = pl.screenshot()
t_first = time.perf_counter() - t0
c0, t0 = cpu(), time.perf_counter()
pl.render_now()
t_second, c_second = time.perf_counter() - t0, cpu() - c0
covered = float((pl.depth_buffer() < 1.0).mean())
pl.close()
triangles = int(len(tessellate(model, 8, adaptive=True)[1]))
print(json.dumps({{"faces": len(model), "trimmed": sum(t is not None for t in model.trims), "triangles": triangles,
                  "read_s": t_read, "add_s": t_add, "first_frame_s": t_first, "second_frame_s": t_second,
                  "second_frame_cpu_s": c_second, "to_first_frame_s": t_read + t_add + t_first,
                  "covered": covered}}))
'''


def _data_dir() -> Path:
    return Path(os.environ.get("SPLINEVIS_NURBS_DATA", ROOT.parent / "shared" / "data" / "nurbs"))


def _plates_file(folder: Path, suffix: str = ".step") -> Path | None:
    """9 filleted plates with holes as a STEP (solids) or IGES (144 faces) file, 288 trimmed faces, or None
    without OpenCASCADE."""
    try:
        import OCP  # noqa: F401
    except ImportError:
        return None
    sys.path.insert(0, str(ROOT))
    from datasets_synthetic.cad_parts import plates

    path = folder / f"plates9{suffix}"
    plates(path, copies=9)
    return path


def _run(kind: str, arg: str) -> dict:
    code = _STAGES.format(root=str(ROOT), kind=kind, arg=arg, window=WINDOW)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    if out.returncode != 0:
        raise RuntimeError(f"{arg}: the timing process failed:\n{out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def _median(runs: list) -> dict:
    row = dict(runs[0])
    for key in runs[0]:
        if key.endswith("_s"):
            row[key] = sorted(r[key] for r in runs)[len(runs) // 2]
            row[key[:-2] + "_min_s"] = min(r[key] for r in runs)
    return row


def bench_nurbs_files(repeats: int = 3, quick: bool = False) -> list:
    """Stage times (median of ``repeats`` fresh processes, and the fastest) per model (module docstring)."""
    repeats = max(1, min(int(repeats), 2 if quick else 5))
    rows, notes = [], []
    data = _data_dir()
    with tempfile.TemporaryDirectory() as tmp:
        cases = []
        if data.is_dir():
            cases += [(name, "file", str(data / name)) for name in FILES if (data / name).is_file()]
            missing = [name for name in FILES if not (data / name).is_file()]
            if missing:
                notes.append(f"skipped (not in {data}): {', '.join(missing)}")
        else:
            notes.append(f"skipped the real files: {data} is absent (set SPLINEVIS_NURBS_DATA)")
        plates = _plates_file(Path(tmp))
        if plates is None:
            notes.append("skipped the 288-face plates: needs OpenCASCADE (the cad extra)")
        else:
            cases.append(("9 plates (STEP, synthetic)", "file", str(plates)))
            cases.append(("9 plates (IGES 144, synthetic)", "file", str(_plates_file(Path(tmp), ".igs"))))
        cases.append(("10 teapots (synthetic)", "teapots", "10"))
        for name, kind, arg in cases:
            rows.append({"model": name, **_median([_run(kind, arg) for _ in range(repeats)])})
    for note in notes:
        print(note, file=sys.stderr)
    if rows:
        rows[0]["notes"] = notes
    return rows


def nurbs_files_markdown(rows: list) -> str:
    lines = [f"\n## NURBS models to their first frame ({WINDOW[0]}x{WINDOW[1]}, fresh process, median s)\n",
             "| model | faces (trimmed) | shell triangles | read | add_nurbs | first frame | second frame | "
             "frame CPU | to first frame |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['model']} | {r['faces']} ({r['trimmed']}) | {r['triangles']:,} | {r['read_s']:.2f} | "
                     f"{r['add_s']:.2f} | {r['first_frame_s']:.2f} | {r['second_frame_s']:.2f} | "
                     f"{r['second_frame_cpu_s']:.2f} | {r['to_first_frame_s']:.2f} |")
    notes = rows[0].get("notes", []) if rows else []
    lines += [""] + [f"- {n}" for n in notes]
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    rows = bench_nurbs_files(args.repeats)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "nurbs_files.json").write_text(json.dumps(rows, indent=2))
    md = nurbs_files_markdown(rows)
    (out / "nurbs_files.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())

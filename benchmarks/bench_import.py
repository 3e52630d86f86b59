"""Benchmark: seconds of ``import splinevis`` and of the first ``splinevis.Plotter(off_screen=True)`` in a new process.

Two installs side by side: the development one (``.venv``: editable, every extra) and the wheel with only the
core dependencies in a new environment (``tools/core_venv.py``: what ``pip install splinevis`` gives, built
offline). Each is measured in ``runs`` fresh processes started from a folder outside the repository; a process
times ``import splinevis`` and then the first ``Plotter(off_screen=True)`` (which loads VTK and PyVista and opens
the off-screen render window) with ``time.perf_counter`` and lists the heavy modules the import alone loaded.
Best and median seconds are reported; interpreter start-up is not included. Goals: import <= 0.2 s, first
Plotter <= 1 s.

    python benchmarks/bench_import.py [--runs 7] [--out out/bench]

Writes ``import.json`` and ``import.md`` to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

HEAVY = ("vtkmodules", "pyvista", "scipy", "matplotlib", "skimage", "moderngl", "nibabel", "rasterio", "dask")

_PROBE = r'''
import json, sys, time
t0 = time.perf_counter()
import splinevis
t1 = time.perf_counter()
loaded = [m for m in {heavy!r} if m in sys.modules]
pl = splinevis.Plotter(off_screen=True)
t2 = time.perf_counter()
pl.close()
print(json.dumps({{"import_s": t1 - t0, "plotter_s": t2 - t1, "loaded_by_import": loaded}}))
'''


def _measure(python, runs: int, cwd: Path, env: dict) -> dict:
    samples = []
    for _ in range(runs):
        out = subprocess.run([str(python), "-c", _PROBE.format(heavy=HEAVY)], cwd=cwd, env=env, capture_output=True,
                             text=True, check=True)
        samples.append(json.loads(out.stdout.strip().splitlines()[-1]))
    row = {"loaded_by_import": samples[0]["loaded_by_import"]}
    for key in ("import_s", "plotter_s"):
        values = [s[key] for s in samples]
        row[f"{key}_best"], row[f"{key}_median"] = min(values), float(np.median(values))
    return row


def bench_import(runs: int = 7) -> dict:
    from tools.core_venv import build_wheel, clean_env, core_only_venv

    env = clean_env()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        core_python = core_only_venv(folder, build_wheel(folder / "build"))
        rows = [{"install": "development (.venv, editable, every extra)", **_measure(sys.executable, runs, folder, env)},
                {"install": "wheel, core dependencies only (new venv)", **_measure(core_python, runs, folder, env)}]
    return {"runs": runs, "cpus": os.cpu_count(), "load_avg_1min": os.getloadavg()[0],
            "python": platform.python_version(), "rows": rows}


def import_markdown(result: dict) -> str:
    lines = ["# Import and first Plotter", "",
             f"Seconds in a new process (best and median of {result['runs']} processes, {result['cpus']} CPUs, "
             f"1-minute load average {result['load_avg_1min']:.1f} when measured; interpreter start-up not included). "
             "Goals: `import splinevis` <= 0.2 s, first `splinevis.Plotter(off_screen=True)` <= 1 s.", "",
             "| install | import best s | import median s | first Plotter best s | first Plotter median s | "
             "heavy modules loaded by the import |", "|---|---:|---:|---:|---:|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['install']} | {r['import_s_best']:.3f} | {r['import_s_median']:.3f} | "
                     f"{r['plotter_s_best']:.2f} | {r['plotter_s_median']:.2f} | "
                     f"{', '.join(r['loaded_by_import']) or 'none'} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args(argv)
    result = bench_import(args.runs)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "import.json").write_text(json.dumps(result, indent=1))
    (out / "import.md").write_text(import_markdown(result))
    print(import_markdown(result))
    return result


if __name__ == "__main__":
    main()

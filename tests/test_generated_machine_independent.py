"""Every generated file is the same bytes whatever BLAS kernels and thread count the machine runs.

The generators (tools/gen_volume_glsl.py, tools/gen_scheme_weights.py, tools/gen_blossom_glsl.py) are re-run in
fresh processes under OpenBLAS core types other than this machine's own (``OPENBLAS_CORETYPE``; OpenBLAS picks
its kernels at run time, and float64 solves differ in their last bits between them) and with 1 and 2 threads,
and their output is compared with the committed files. A generated number that came from a float64 solve
would differ between kernels; the generators solve in exact rational arithmetic (splinevis/_exact.py) or snap
to exact fractions with a derived margin, so nothing may move. The core type actually used is read back
(threadpoolctl) so a run that silently kept the default kernels cannot pass for another.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_SCRIPT = r"""
import importlib.util, json, sys
from pathlib import Path
import numpy, scipy.linalg, threadpoolctl
root = Path(sys.argv[1])
stale = []
def load(name):
    spec = importlib.util.spec_from_file_location(name, root / "tools" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
for name, text in load("gen_volume_glsl").generate().items():
    if (root / "glsl" / "lib" / name).read_text() != text:
        stale.append("glsl/lib/" + name)
for rel, text in load("gen_scheme_weights").generate().items():
    if (root / rel).read_text() != text:
        stale.append(rel)
if load("gen_blossom_glsl").generate() != (root / "glsl/lib/simplex/blossom_steps.glsl").read_text():
    stale.append("glsl/lib/simplex/blossom_steps.glsl")
info = [(i.get("architecture"), i["num_threads"]) for i in threadpoolctl.threadpool_info() if i["internal_api"] == "openblas"]
print(json.dumps({"stale": stale, "openblas": info}))
"""


def _cpu_flags() -> set:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    for line in text.splitlines():
        if line.startswith("flags"):
            return set(line.split(":", 1)[1].split())
    return set()


def _core_types() -> list:
    """Two OpenBLAS x86-64 core types this CPU can run, as (OPENBLAS_CORETYPE, name OpenBLAS reports, threads):
    the oldest generic SSE kernels (Prescott, reported as Katmai) with one thread, and the newest SIMD kernels
    the CPU supports other than its own default (Haswell on an AVX-512 machine, else Sandybridge) with two."""
    flags = _cpu_flags()
    second = ("Haswell", "Haswell") if {"avx2", "avx512f"} <= flags else ("Sandybridge", "Sandybridge")
    if "avx" not in flags:
        second = ("Nehalem", "Nehalem")
    return [("Prescott", "Katmai", 1), (*second, 2)]


def _run(coretype: str, threads: int) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OPENBLAS_", "OMP_"))}
    env.update(OPENBLAS_CORETYPE=coretype, OPENBLAS_NUM_THREADS=str(threads))
    run = subprocess.run([sys.executable, "-c", _SCRIPT, str(ROOT)], capture_output=True, text=True, cwd=ROOT,
                         env=env, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_generated_files_do_not_follow_the_blas_kernels():
    assert platform.machine() in ("x86_64", "AMD64"), "the core types below are OpenBLAS's x86-64 ones"
    for coretype, reported, threads in _core_types():
        out = _run(coretype, threads)
        # the kernels really were switched (both numpy's and scipy's OpenBLAS), with the thread count asked for
        assert out["openblas"] and all(arch == reported and n == threads for arch, n in out["openblas"]), out
        assert out["stale"] == [], (f"under OPENBLAS_CORETYPE={coretype}, {threads} thread(s), the generators "
                                    f"print other text than the committed {out['stale']}")

"""``splinevis check``: does my file work, and how good is the picture?

Every file under the given paths is sorted into a family from its content (:mod:`.detect`), read with the
family's reader, built into its spline model, drawn from the default camera and one close-up beside the mesh
users draw today from the same data and cameras (:mod:`.run`), and judged PASS / WARN / FAIL with the reasons in
words (:mod:`.judge`). The report (``report.md``, ``report.json``, ``contact_sheet.png``) goes to ``out``
(:mod:`.report`).

Each file runs in a process of its own, two at a time by default: a reader that crashes or hangs fails its file,
not the check, and the peak memory reported is the file's.

Examples
--------
>>> import tempfile, pathlib, numpy as np
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> z = np.add.outer(np.sin(np.linspace(0, 3, 20)), np.cos(np.linspace(0, 2, 30))) * 50
>>> _ = (d / "hill.asc").write_text("ncols 30\\nnrows 20\\nxllcorner 0\\nyllcorner 0\\ncellsize 10\\n"
...                                 + "\\n".join(" ".join(f"{v:.3f}" for v in row) for row in z))
>>> report = check([d], out=d / "report", progress=False)
>>> [(r["name"], r["family"], r["verdict"]) for r in report["files"]]
[('hill.asc', 'terrain', 'PASS')]
>>> sorted(p.name for p in (d / "report").iterdir())
['contact_sheet.png', 'report.json', 'report.md', 'thumbs']
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

from .detect import collect_files, companion_files, detect_family

__all__ = ["check", "FILE_TIMEOUT", "FILE_TIMEOUT_DEFAULT"]

#: Seconds one file of a family may take before it is judged FAIL (a reader that never returns): about ten times the
#: family's slowest file in the whole data folder's check (CI's ``.ci/run``, two files at once on two cores), at least
#: 600: NURBS 87 s, volumes 54 s, terrains 13 s. Meshes 1800: a scan whose geometry image folds is built twice, the
#: second time at 513 x 513 (``geometry_image.auto.ESCALATE_INVERSE``), and measured on the 134 million limit
#: triangles of that image's level 4: armadillo.obj took 929 s with beast.obj judged beside it (build 635 s, measures
#: 280 s; beast.obj 877 s), and 1177 s in the whole folder's check (with another measurement running on the same two
#: cores).
FILE_TIMEOUT = {"mesh": 1800.0, "nurbs": 900.0, "volume": 600.0, "terrain": 600.0}
#: A family not in :data:`FILE_TIMEOUT`.
FILE_TIMEOUT_DEFAULT = 900.0


def _plan(paths, family: str):
    """[(path, family or None, why)] for every file, companions marked."""
    files = collect_files(paths)
    companions = companion_files(files)
    plan = []
    for f in files:
        if f in companions:
            plan.append((f, None, f"data file of {companions[f].name} (read through it)"))
            continue
        fam, fmt = detect_family(f)
        if family != "auto":
            fam = family
        plan.append((f, fam, fmt))
    return plan


def _timeout(family: str, timeout: float | None) -> float:
    """Seconds a file of ``family`` may take: ``timeout`` if given, else the family's :data:`FILE_TIMEOUT`.

    >>> _timeout("terrain", None), _timeout("mesh", None), _timeout("terrain", 5)
    (600.0, 1800.0, 5.0)
    """
    if timeout is not None:
        return float(timeout)
    return FILE_TIMEOUT.get(family, FILE_TIMEOUT_DEFAULT)


def _run_one(path: Path, family: str, out: Path, options: dict, timeout: float) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        result_path = Path(tmp) / "result.json"
        cmd = [sys.executable, "-m", "splinevis.check.run", str(path), "--family", family, "--out", str(out),
               "--options", json.dumps(options), "--result", str(result_path)]
        t = time.perf_counter()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                                  env=dict(os.environ, PYTHONFAULTHANDLER="1"))
        except subprocess.TimeoutExpired:
            return {"file": str(path), "name": path.name, "family": family, "verdict": "FAIL",
                    "findings": [{"level": "FAIL", "reason": f"took more than {timeout:.0f} s (stopped)"}],
                    "wall": time.perf_counter() - t}
        if proc.returncode != 0 or not result_path.exists():
            tail = (proc.stderr or "").strip().splitlines()[-3:]
            how = f"signal {-proc.returncode}" if proc.returncode < 0 else f"exit status {proc.returncode}"
            return {"file": str(path), "name": path.name, "family": family, "verdict": "FAIL",
                    "findings": [{"level": "FAIL", "reason": f"the process judging it crashed ({how}): "
                                                             + " | ".join(tail)}],
                    "wall": time.perf_counter() - t}
        r = json.loads(result_path.read_text())
        r["wall"] = time.perf_counter() - t
        return r


def check(paths, out="out/check", *, family: str = "auto", isovalue: float | None = None, jobs: int = 2,
          progress: bool = True, timeout: float | None = None, options: dict | None = None) -> dict:
    """Judge every file under ``paths`` and write the report to ``out`` (module docstring).

    Parameters
    ----------
    paths : path or list of paths
        Files and folders (walked; notes ``.md``/``.txt`` left out).
    out : path
        Report folder: ``report.md``, ``report.json``, ``contact_sheet.png``, ``thumbs/``.
    family : {"auto", "terrain", "volume", "nurbs", "mesh"}
        ``auto`` decides per file from its content.
    isovalue : float, optional
        Isovalue of volumes (default: from each volume's histogram).
    jobs : int
        Files judged at once (one process each).
    progress : bool
        A progress bar on stderr.
    timeout : float, optional
        Seconds a file may take (default: its family's, :data:`FILE_TIMEOUT`).
    options : dict, optional
        Passed to every family judge (e.g. ``{"scalars": "density"}``).

    Returns
    -------
    dict
        ``files`` (one result per file, as in ``report.json``), ``counts`` ({verdict: n}) and ``out``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp()); _ = (d / "notes.dat").write_bytes(bytes([0, 1]))
    >>> r = check(d, d / "report", progress=False)
    >>> r["counts"], r["files"][0]["findings"][0]["reason"][:30]
    ({'PASS': 0, 'WARN': 0, 'FAIL': 0, 'SKIP': 1}, 'not judged: no known signature')
    """
    from tqdm.auto import tqdm

    from .report import write_report
    from .run import JUDGE_MODULES

    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    if family != "auto" and family not in JUDGE_MODULES:
        raise ValueError(f"family {family!r}: choose auto or one of {', '.join(JUDGE_MODULES)}.")
    if jobs < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}.")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    opts = dict(options or {})
    if isovalue is not None:
        opts["isovalue"] = float(isovalue)
    plan = _plan(paths, family)
    results: dict = {}
    todo = [(p, fam) for p, fam, _ in plan if fam is not None]
    for p, fam, why in plan:
        if fam is None:
            results[p] = {"file": str(p), "name": p.name, "family": None, "verdict": "SKIP",
                          "findings": [{"level": "PASS", "reason": f"not judged: {why}"}]}
    with ThreadPoolExecutor(max_workers=jobs) as pool, tqdm(total=len(todo), disable=not progress, desc="check",
                                                             unit="file") as bar:
        futures = {pool.submit(_run_one, p, fam, out, opts, _timeout(fam, timeout)): p for p, fam in todo}
        for fut in as_completed(futures):
            p = futures[fut]
            results[p] = fut.result()
            bar.set_postfix_str(f"{p.name}: {results[p]['verdict']}")
            bar.update()
    files = [results[p] for p, _, _ in plan]
    counts = {v: sum(r["verdict"] == v for r in files) for v in ("PASS", "WARN", "FAIL", "SKIP")}
    report = {"files": files, "counts": counts, "out": str(out)}
    write_report(report, out)
    return report

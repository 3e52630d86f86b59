"""Judging one file: read, build, draw beside the baseline from the same cameras, measure, decide.

:func:`judge_file` runs in a process of its own (``python -m splinevis.check.run``), started by
:func:`splinevis.check.check`: a reader that crashes the interpreter (a segfault in a CAD kernel) or never
returns then fails that file only, and the process's peak resident memory is the file's. The result is a
JSON-able dict (``report.json`` holds one per file) and a row of four thumbnails (spline and baseline, default
camera and close-up) written as ``<out>/thumbs/<name>.png``.

Times (seconds, ``time.perf_counter``): ``read`` (the family reader), ``build`` (the spline model),
``baseline`` (the mesh users have), ``first_frame`` (first render: shader compile and upload),
``second_frame`` (a render of the same scene again), ``accuracy`` (the family's accuracy figure; part of the
check, not of drawing the file).
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import resource
import sys
import time
import traceback
import warnings
from pathlib import Path

import numpy as np

from .judge import Finding, picture_findings, silhouette_measures, worst_level

__all__ = ["judge_file", "JUDGE_MODULES", "WINDOW", "CLOSE_UP_ZOOM"]

JUDGE_MODULES = {"terrain": "splinevis.terrain.judge", "volume": "splinevis.volume.judge",
                 "nurbs": "splinevis.nurbs.judge", "mesh": "splinevis.geometry_image.judge"}
WINDOW = (400, 300)
CLOSE_UP_ZOOM = 3.0
BACKGROUND = (1.0, 1.0, 1.0)


def get_judge(family: str):
    """The :class:`~splinevis.check.judge.FamilyJudge` of ``family``."""
    if family not in JUDGE_MODULES:
        raise ValueError(f"family {family!r}: choose one of {', '.join(JUDGE_MODULES)} (or auto).")
    return importlib.import_module(JUDGE_MODULES[family]).JUDGE


def _render(pl):
    """(RGB image, covered mask) of a plotter's current frame (rendered first: before ``show`` pyvista's
    screenshot would return the first frame again)."""
    pl.ren_win.Render()
    img = pl.screenshot(return_img=True)
    return img, pl.depth_buffer() < 1.0


def _camera(pl):
    c = pl.camera
    return {"position": tuple(c.position), "focal_point": tuple(c.focal_point), "up": tuple(c.up),
            "view_angle": float(c.view_angle)}


def _set_camera(pl, cam):
    pl.camera_set = True  # else pyvista's first screenshot resets the camera to fit the scene
    c = pl.camera
    c.position, c.focal_point, c.up = cam["position"], cam["focal_point"], cam["up"]
    c.view_angle = cam["view_angle"]
    pl.reset_camera_clipping_range()


def _thumb_row(images, labels, path: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(images), figsize=(3.2 * len(images), 2.6), dpi=80)
    for ax, img, label in zip(np.atleast_1d(axes), images, labels):
        ax.imshow(img)
        ax.set_title(label, fontsize=9)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def _relative_paths(text: str) -> str:
    """A traceback with this installation's folders cut from its file names (``splinevis/check/run.py``, not
    the machine's absolute path): reports are shared and committed.

    >>> import splinevis, pathlib
    >>> root = str(pathlib.Path(splinevis.__file__).resolve().parents[1])
    >>> _relative_paths(f'File "{root}/splinevis/check/run.py", line 1')
    'File "splinevis/check/run.py", line 1'
    """
    import splinevis

    for folder in {Path(splinevis.__file__).resolve().parents[1], Path(sys.prefix).resolve().parent}:
        text = text.replace(str(folder) + os.sep, "")
    return text


def judge_file(path, family, out, *, options: dict | None = None) -> dict:
    """Judge one file of ``family`` (a family name or a :class:`~splinevis.check.judge.FamilyJudge`; module
    docstring); thumbnails go to ``out/thumbs``.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> z = np.add.outer(np.linspace(0, 40, 12), np.linspace(0, 30, 16) ** 1.5 / 10)
    >>> _ = (d / "ramp.asc").write_text("ncols 16\\nnrows 12\\nxllcorner 0\\nyllcorner 0\\ncellsize 5\\n"
    ...                                 + "\\n".join(" ".join(f"{v:.2f}" for v in row) for row in z))
    >>> r = judge_file(d / "ramp.asc", "terrain", d / "out")
    >>> r["verdict"], r["views"]["default"]["iou"] > 0.97, r["thumbnail"]
    ('PASS', True, 'thumbs/ramp.asc.png')
    """
    from ..plotting import Plotter
    from .judge import FamilyJudge

    path, out = Path(path), Path(out)
    options = dict(options or {})
    judge = family if isinstance(family, FamilyJudge) else get_judge(family)
    family = judge.family
    findings: list[Finding] = []
    result = {"file": str(path), "name": path.name, "family": family, "baseline": judge.baseline_name,
              "times": {}, "accuracy": {}, "views": {}, "warnings": []}
    stage = "read"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            t = time.perf_counter()
            data = judge.read(path, options, findings)
            result["times"]["read"] = time.perf_counter() - t
            stage = "build"
            t = time.perf_counter()
            model = judge.build(data, options, findings)
            result["times"]["build"] = time.perf_counter() - t
            stage = "baseline"
            t = time.perf_counter()
            base = judge.baseline(data, model, options, findings)
            result["times"]["baseline"] = time.perf_counter() - t
            stage = "draw"
            pl = Plotter(off_screen=True, window_size=WINDOW)
            pl.set_background(BACKGROUND)
            judge.add(pl, model, options)
            _set_camera(pl, _camera(pl))  # the default camera: fitted to the model when it was added
            for frame in ("first_frame", "second_frame"):  # the window's own Render: pyvista's render() waits for show()
                t = time.perf_counter()
                pl.ren_win.Render()
                result["times"][frame] = time.perf_counter() - t
            cams = {"default": _camera(pl)}
            pl.camera.zoom(CLOSE_UP_ZOOM)
            cams["close-up"] = _camera(pl)
            spline_views = {}
            for view, cam in cams.items():
                _set_camera(pl, cam)
                spline_views[view] = _render(pl)
            pl.close()
            stage = "draw the baseline"
            bl = Plotter(off_screen=True, window_size=WINDOW)
            bl.set_background(BACKGROUND)
            bl.add_mesh(base, color=(0.75, 0.75, 0.78), smooth_shading=True)
            base_views = {}
            for view, cam in cams.items():
                _set_camera(bl, cam)
                base_views[view] = _render(bl)
            bl.close()
            stage = "measure"
            for view in cams:
                m = silhouette_measures(spline_views[view][1], base_views[view][1])
                result["views"][view] = dict(m, camera=cams[view])
                findings += picture_findings(view, m)
            t = time.perf_counter()
            result["accuracy"] = judge.accuracy(path, data, model, base, options, findings)
            result["times"]["accuracy"] = time.perf_counter() - t
            thumbs = out / "thumbs"
            thumbs.mkdir(parents=True, exist_ok=True)
            images = [spline_views["default"][0], base_views["default"][0], spline_views["close-up"][0],
                      base_views["close-up"][0]]
            labels = ["splinevis", judge.baseline_name, "splinevis close-up", "baseline close-up"]
            _thumb_row(images, labels, thumbs / f"{path.name}.png")
            result["thumbnail"] = f"thumbs/{path.name}.png"
        except Exception as exc:  # any failure of the user's file is the verdict, with where it happened
            findings.append(Finding("FAIL", f"{stage} failed: {type(exc).__name__}: {exc}"))
            result["traceback"] = _relative_paths(traceback.format_exc(limit=6))
    result["warnings"] = list(dict.fromkeys(str(w.message) for w in caught))  # in the order raised, once each
    if result["warnings"]:
        findings.append(Finding("WARN", f"{len(result['warnings'])} warning(s) while reading and drawing "
                                        f"(first: {result['warnings'][0][:200]})"))
    result["peak_memory_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    result["findings"] = [f.as_dict() for f in findings]
    result["verdict"] = worst_level(findings)
    return result


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m splinevis.check.run", description="judge one file (splinevis check)")
    p.add_argument("path")
    p.add_argument("--family", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--options", default="{}", help="JSON of the judge's options")
    p.add_argument("--result", required=True, help="where to write the result JSON")
    a = p.parse_args(argv)
    r = judge_file(a.path, a.family, a.out, options=json.loads(a.options))
    Path(a.result).write_text(json.dumps(r, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())

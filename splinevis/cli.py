"""The ``splinevis`` command: ``render FILE``, ``check``, ``info``, ``selftest``, ``demo``, ``study NAME``
(:data:`splinevis.studies.STUDIES`) and ``--version``.

Exit codes: 0 success, 1 the job ran and failed (selftest over its bounds), 2 bad usage, 3 no OpenGL.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

__all__ = ["main"]


def _cmd_info(args) -> int:
    from .gl.headless import gl_info

    info = gl_info(args.backend)
    try:
        from .gl.harness import get_context

        ctx = get_context()
        info["moderngl"] = {k: ctx.info[k] for k in ("GL_VENDOR", "GL_RENDERER", "GL_VERSION")}
    except Exception as exc:  # noqa: BLE001 - reported, and the exit code says it
        info["moderngl"] = f"unavailable: {exc}"
        print(json.dumps(info, indent=2))
        return 3
    print(json.dumps(info, indent=2))
    return 0


def _cmd_selftest(args) -> int:
    from .selftest import run_selftest

    report = run_selftest(args.out, cases=args.cases, seed=args.seed, progress=not args.quiet)
    rows = report["functions"] if "functions" in report else report
    failed = [r for r in _rows(rows) if not r.get("pass", False)]
    print(f"selftest: {len(_rows(rows)) - len(failed)} of {len(_rows(rows))} functions pass (within their bounds; "
          f"first_root rows: every case beyond the bound meets its derived expectation); "
          f"report in {Path(args.out) / 'selftest.json'}")
    for r in failed:
        print(f"  FAILED {r.get('function', r.get('name'))}: max error {r.get('max_err_eps')} eps > bound {r.get('bound_eps')}"
              f"{'; unexplained ' + str(r['unexplained_total']) if 'unexplained_total' in r else ''}")
    cases = [(p, c, r) for p, rows in report.get("programs", {}).items() for c, r in rows.items()]
    bad = [(p, c, r) for p, c, r in cases if not r["pass"]]
    print(f"selftest: {len(cases) - len(bad)} of {len(cases)} program hard cases agree with their float64 twins")
    for p, c, r in bad:
        print(f"  FAILED {p} {c}: {'; '.join(r['failures'])}")
    return 1 if failed or bad else 0


def _rows(rows):
    if isinstance(rows, dict):
        return [dict(v, function=k) if isinstance(v, dict) else {"function": k, "pass": bool(v)} for k, v in rows.items()]
    return list(rows)


def _cmd_render(args) -> int:
    from .render_file import render_file

    try:
        w, h = (int(v) for v in args.window.lower().split("x"))
    except ValueError:
        raise ValueError(f"--window {args.window!r} must be WIDTHxHEIGHT in pixels, e.g. --window 1024x768.") from None
    r = render_file(args.file, args.output, effect=args.effect, isovalue=args.isovalue, window=(w, h),
                    family=args.family, supersample=args.ssaa)
    s = r["seconds"]
    print(f"{r['out']}: {r['family']} {r['effect']}, {w} x {h} (read {s['read']:.2f} s, build {s['build']:.2f} s, "
          f"draw {s['draw']:.2f} s)")
    for note in r["notes"]:
        print(f"  note: {note}")
    return 0


def _cmd_demo(args) -> int:
    from .studies.demo import render_showcase

    written = render_showcase(args.out, progress=not args.quiet)
    for name, path in written.items():
        print(f"{name}: {path}")
    return 0


def _cmd_study(args) -> int:
    from .studies import get, notes

    study = get(args.name)
    result = study.run(args.out, quick=args.quick, progress=not args.quiet)
    out = Path(args.out)
    for f in sorted(out.glob("*.md")) + sorted(out.glob("*.png")):
        print(f)
    print(study.json_file(out))
    for note in notes(result):
        print(f"note: {note}")
    return 0 if result else 1


def _cmd_check(args) -> int:
    import json

    from .check import check

    known = {}
    if args.known:
        known = json.loads(Path(args.known).read_text())
        if not isinstance(known, dict):
            raise ValueError(f"{args.known}: expected a JSON object {{file name: measured reason}}.")
    report = check(args.paths, args.out, family=args.family, isovalue=args.isovalue, jobs=args.jobs,
                   progress=not args.quiet)
    counts = report["counts"]
    print(" ".join(f"{k} {v}" for k, v in counts.items()) + f"; report: {Path(args.out) / 'report.md'}")
    unexpected = []
    for r in report["files"]:
        if r["verdict"] == "FAIL":
            reason = next((f["reason"] for f in r["findings"] if f["level"] == "FAIL"), "")
            listed = r["name"] in known
            print(f"FAIL{' (known)' if listed else ''} {r['name']}: {reason[:300]}")
            if not listed:
                unexpected.append(r["name"])
        elif r["name"] in known:
            print(f"now {r['verdict']}: {r['name']} is listed in {args.known} as failing; remove its entry")
    missing = sorted(set(known) - {r["name"] for r in report["files"]})
    if missing:
        print(f"listed in {args.known} but not checked: {', '.join(missing)}")
    return 1 if unexpected else 0


def main(argv=None) -> int:
    """Run the ``splinevis`` command with ``argv`` (default: ``sys.argv[1:]``); returns the exit code.

    Examples
    --------
    ``info`` prints what OpenGL the VTK windows and the moderngl context get, as JSON:

    >>> from splinevis.cli import main
    >>> main(["info"])
    {
      "vendor": ...
      "moderngl": {
        "GL_VENDOR": ...,
        "GL_RENDERER": ...,
        "GL_VERSION": ...
      }
    }
    0

    Bad usage exits with code 2 (argparse's message goes to stderr):

    >>> main(["study", "sphere", "--out", "results"])
    Traceback (most recent call last):
    ...
    SystemExit: 2
    """
    from .studies import STUDIES

    from . import __version__
    from .render_file import EFFECT_STYLES

    parser = argparse.ArgumentParser(prog="splinevis", description="Exact per-pixel rendering of spline models.")
    parser.add_argument("--version", action="version", version=f"splinevis {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("render", help="render a file (terrain, volume, CAD, closed mesh) exactly per pixel to a PNG")
    p.add_argument("file", help="the file; its family is found from its content")
    p.add_argument("-o", "--output", default=None, help="the PNG (default: FILE's name + .png, here)")
    p.add_argument("--effect", choices=list(EFFECT_STYLES), default="shaded",
                   help="shaded (two lights), zebra (reflection lines), isophotes or curvature (mean)")
    p.add_argument("--isovalue", type=float, default=None, help="isosurface of a volume (default: from the histogram)")
    p.add_argument("--window", default="1024x768", help="picture size WIDTHxHEIGHT (default 1024x768)")
    p.add_argument("--family", choices=["auto", "terrain", "volume", "nurbs", "mesh"], default="auto")
    p.add_argument("--ssaa", type=int, default=1, help="k: k x k samples a pixel (smooth silhouettes; default 1)")
    p.set_defaults(func=_cmd_render)
    p = sub.add_parser("info", help="print the OpenGL vendor, renderer, version and VTK window class")
    p.add_argument("--backend", choices=["egl", "osmesa", "x"], default=None, help="force an OpenGL backend")
    p.set_defaults(func=_cmd_info)
    p = sub.add_parser("selftest", help="run the GLSL-vs-float64 numeric harness")
    p.add_argument("--out", required=True, help="directory for selftest.json")
    p.add_argument("--cases", type=int, default=100_000, help="random inputs per function (default 100000)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_selftest)
    p = sub.add_parser("demo", help="render the showcase figures")
    p.add_argument("--out", required=True, help="directory for the PNG figures")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_demo)
    p = sub.add_parser("study", help="run a study (accuracy vs time) and write JSON, tables and figures")
    p.add_argument("name", choices=list(STUDIES), help="; ".join(f"{s.name}: {s.summary}" for s in STUDIES.values()))
    p.add_argument("--out", required=True, help="directory for the study's files")
    p.add_argument("--quick", action="store_true", help="smaller sizes: a few minutes")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_study)
    p = sub.add_parser("check", help="judge files: read, draw beside the mesh users have, measure; PASS/WARN/FAIL")
    p.add_argument("paths", nargs="+", help="files and folders (walked)")
    p.add_argument("--out", default="out/check", help="report folder (default out/check)")
    p.add_argument("--family", choices=["auto", "terrain", "volume", "nurbs", "mesh"], default="auto")
    p.add_argument("--isovalue", type=float, default=None, help="isovalue of volumes (default: from the histogram)")
    p.add_argument("--jobs", type=int, default=2, help="files judged at once (default 2)")
    p.add_argument("--known", default=None,
                   help="JSON {file name: reason} of files allowed to FAIL (exit status 1 on any other FAIL)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_check)
    args = parser.parse_args(argv)
    from .errors import OpenGLUnavailableError

    try:
        return args.func(args)
    except OpenGLUnavailableError as exc:
        print(f"splinevis: {exc}", file=sys.stderr)
        return 3
    except (ValueError, TypeError) as exc:
        print(f"splinevis: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # --out a file, below a file, unwritable, disk full: one line, no traceback
        where = exc.filename or getattr(args, "out", None)
        reason = exc.strerror or type(exc).__name__
        print(f"splinevis: cannot write to {where} ({reason}); --out must be a writable directory "
              f"(given: --out {getattr(args, 'out', None)}). Pick another path.", file=sys.stderr)
        return 4


if __name__ == "__main__":
    sys.exit(main())

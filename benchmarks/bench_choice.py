"""Benchmark: what the choice by accuracy (``max_error_px``, ``max_normal_error_deg``, :mod:`splinevis.choice`)
picks for each family, its proven and measured errors, and what it costs against the always-exact program.

One scene per family (its model, the view pyvista's default camera gives it in an 800 x 600 window, lights
on). For every request ``max_error_px`` in :data:`PIXELS` and ``max_normal_error_deg`` in :data:`DEGREES`
(None: positions only) the choice is made for that view through the family's declared renderers
(``SplineProgram.renderers``; this file only builds the scenes' models). Each chosen option's error is then
measured against the float64 spline by its renderer's ``measure`` (samples of what it draws against the spline
points they stand for: pixels of the view, degrees of the shading normal). Every distinct option chosen and
the program's own exact renderer are opened at once and timed in turn, one frame each per round after two
warm-up frames, so that load from other processes falls on all alike (the fastest frame is the quiet one).

    python benchmarks/bench_choice.py [--repeats 5] [--families terrain,isosurface,...] [--out out/bench]

Writes ``choice.json``, ``choice.md`` and ``choice.png`` (error against frame time per family, the chosen
options marked) to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

PIXELS = (2.0, 1.0, 0.5, 0.25, 0.1)
DEGREES = (None, 2.0, 1.0, 0.5)
WINDOW = (800, 600)


def _terrain():
    from splinevis.studies.terrain import franke_terrain

    return "terrain: Franke 33 x 33, C1", franke_terrain(33, "C1")


def _isosurface():
    from datasets_synthetic.volumes import marschner_lobb
    from splinevis.programs import get

    grid = marschner_lobb().sample(41)
    model = get("isosurface").model_from(grid.values, 0.5, "quadratic", order="zyx", spacing=tuple(grid.spacing),
                                         origin=tuple(grid.origin))
    return "isosurface: Marschner-Lobb 41^3, quadratic", model


def _blob_isosurface():
    from datasets_synthetic.volumes import blob
    from splinevis.programs import get

    field = blob()
    grid = field.sample(41)
    model = get("isosurface").model_from(grid.values, field.isovalue, "quadratic", order="zyx",
                                         spacing=tuple(grid.spacing), origin=tuple(grid.origin))
    return "isosurface: smooth blob 41^3, quadratic", model


def _torus():
    from splinevis.nurbs.exact import torus

    return "NURBS: rational torus (exact, no degenerate point)", torus()


def _nurbs():
    from datasets_synthetic.teapot import newell_teapot

    return "NURBS: Newell's teapot, 32 bicubic patches", newell_teapot()


def _geometry_image():
    import warnings

    from datasets_synthetic.closed_meshes import star_blob
    from splinevis.programs import get

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no fold or distance warning on this shape
        model = get("geometry_image").model_from(star_blob(level=3), 33, fairness=0.1)
    return "geometry image: star blob, 33 x 33", model


FAMILIES = {"terrain": _terrain, "isosurface": _isosurface, "isosurface_blob": _blob_isosurface, "nurbs": _nurbs,
            "nurbs_torus": _torus, "geometry_image": _geometry_image}


def _plotter():
    from splinevis.plotting import Plotter

    return Plotter(off_screen=True, window_size=WINDOW)


def _default_view(model, style):
    """The view pyvista's default camera gives the model (what ``add_spline(max_error_px=...)`` chooses for)."""
    from splinevis.choice import fit_default_camera

    pl = _plotter()
    view = fit_default_camera(pl, model, style)
    camera = pl.camera_position
    pl.close()
    return view, camera


def bench_family(family: str, repeats: int = 5) -> dict:
    """Choices per request, measured errors and frame times of one family's scene (module docstring)."""
    from splinevis.analysis.timing import interleaved_frame_times
    from splinevis.choice import add_renderer, choose, renderers_for
    from splinevis.effects import Style
    from splinevis.programs import program_for

    scene, model = FAMILIES[family]()
    style = Style(lights=1)
    program = program_for(model)
    rows_r, _ = renderers_for(program)
    by_name = {r.name: r for r in rows_r}
    view, camera = _default_view(model, style)
    cache = {}
    rows, measured = [], {}
    for px in PIXELS:
        for deg in DEGREES:
            c = choose(model, view, px, style, cache=cache, max_normal_error_deg=deg)
            key = (c.renderer, c.level)
            entry = by_name[c.renderer]
            if key not in measured:
                measured[key] = entry.measure(model, view, c.level, cache) if entry.measure else (None, None)
            rows.append({"max_error_px": px, "max_normal_error_deg": deg, "renderer": c.renderer, "level": c.level,
                         "triangles": c.chosen.triangles, "error_px": c.error_px, "proven": c.chosen.proven,
                         "normal_deg": c.chosen.normal_deg, "normal_proven": c.chosen.normal_proven,
                         "measured_px": measured[key][0], "measured_deg": measured[key][1], "meets": c.meets,
                         "estimated_ms": c.chosen.cost_ms})
    exact = next((r for r in rows_r if r.exact and r.build is None and not r.program_options), None)
    # the program as add_spline draws it by default: timed once, as the baseline (the always-exact program
    # where the family has one; the geometry image's default level otherwise)
    own = (exact.name, None) if exact is not None else None
    timed = sorted({(r["renderer"], r["level"]) for r in rows} - {own}, key=str) + [("exact program", None)]
    scenes = {}
    for key in timed:
        pl = _plotter()
        if key[0] == "exact program":
            pl.add_spline(model, style)
        else:
            add_renderer(pl, model, style, key[0], key[1], cache=cache)
        pl.camera_position = camera
        scenes[key] = pl
    frame = dict(zip(scenes, interleaved_frame_times(scenes.values(), repeats)))
    shots = {k: pl.screenshot(return_img=True) for k, pl in scenes.items()}
    for pl in scenes.values():
        pl.close()
    exact_ms = frame[("exact program", None)]["min_ms"]
    if own is not None:
        frame[own] = frame[("exact program", None)]
    for r in rows:
        f = frame[(r["renderer"], r["level"])]
        r.update(frame_min_ms=f["min_ms"], frame_median_ms=f["median_ms"], exact_over_chosen=exact_ms / f["min_ms"])
    blank = [str(k) for k, img in shots.items() if float(img.std()) < 5.0]
    if blank:
        raise RuntimeError(f"{family}: blank pictures from {blank}")
    return {"family": family, "scene": scene, "program": program.name,
            "baseline": exact.name if exact is not None else "the program's default level",
            "window": list(WINDOW), "repeats": repeats, "rows": rows,
            "exact_frame_min_ms": exact_ms, "exact_frame_median_ms": frame[("exact program", None)]["median_ms"],
            "options": [{"renderer": k[0], "level": k[1], **frame[k]} for k in timed]}


def _fmt(v, spec=".3g"):
    if v is None:
        return "-"
    if isinstance(v, float) and math.isinf(v):
        return "unknown"
    return format(v, spec) if isinstance(v, float) else str(v)


def choice_markdown(results: list) -> str:
    lines = ["# Choice by accuracy, every family", "",
             "For each request the family's cheapest declared renderer whose error meets it, for the scene's "
             "default view (800 x 600); proven / estimated errors as declared, measured errors against the "
             "float64 spline on samples of what is drawn (`Renderer.measure`; '-' for exact renderers, which "
             "draw the spline itself and are compared with their float64 twin in the hard-case tests). Normal "
             "errors: 0 = exact normals per pixel. Frame times: fastest of the interleaved rounds; the ratio "
             "is the baseline's frame (the always-exact program; the geometry image's default level) over the chosen "
             "one's (same run).", ""]
    for res in results:
        lines += [f"## {res['scene']}", "",
                  f"Baseline ({res['program']} as add_spline draws it: {res['baseline']}): "
                  f"{res['exact_frame_min_ms']:.1f} ms fastest, "
                  f"{res['exact_frame_median_ms']:.1f} ms median, {res['repeats']} rounds.", "",
                  "| max_error_px | max normal deg | chosen | level | triangles | error px | proven | measured px "
                  "| normal deg | proven | measured deg | meets | estimated ms | frame ms | baseline / chosen |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in res["rows"]:
            tri = f"{r['triangles']:,}" if r["triangles"] else "-"
            lines.append(
                f"| {r['max_error_px']:g} | {_fmt(r['max_normal_error_deg'], 'g')} | {r['renderer']} | "
                f"{_fmt(r['level'])} | {tri} | {_fmt(r['error_px'])} | {r['proven']} | {_fmt(r['measured_px'])} | "
                f"{_fmt(r['normal_deg'])} | {r['normal_proven'] if r['normal_deg'] else '-'} | "
                f"{_fmt(r['measured_deg'])} | {r['meets']} | {_fmt(r['estimated_ms'], '.1f')} | "
                f"{r['frame_min_ms']:.1f} | {r['exact_over_chosen']:.2f} |")
        lines.append("")
    return "\n".join(lines)


def choice_figure(results: list, path) -> None:
    """Error against frame time per family: each option chosen for some request (filled: its declared error,
    proven or estimated; open: measured against the float64 spline), the baseline's frame (dashed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = min(3, len(results))
    rows_n = -(-len(results) // cols)
    fig, axes = plt.subplots(rows_n, cols, figsize=(4.6 * cols, 3.9 * rows_n), squeeze=False)
    for ax in axes.ravel()[len(results):]:
        ax.axis("off")
    for ax, res in zip(axes.ravel(), results):
        seen = {}
        for r in res["rows"]:
            seen[(r["renderer"], r["level"])] = (r["frame_min_ms"], r["error_px"], r["measured_px"])
        for i, name in enumerate(sorted({k[0] for k in seen})):
            pts = sorted(v for k, v in seen.items() if k[0] == name)
            colour = f"C{i}"
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=colour, label=f"{name} (declared)")
            meas = [p for p in pts if p[2]]
            if meas:
                ax.plot([p[0] for p in meas], [p[2] for p in meas], "o", mfc="none", color=colour,
                        label=f"{name} (measured)")
        for (name, level), (t, e, _) in seen.items():
            if level is not None:
                ax.annotate(f"{level}", (t, e), textcoords="offset points", xytext=(4, 3), fontsize=7)
        ax.axvline(res["exact_frame_min_ms"], color="k", ls="--", lw=0.8, label=f"baseline: {res['baseline']}")
        for px in PIXELS:
            ax.axhline(px, color="0.85", lw=0.6, zorder=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("frame time, ms (fastest of the rounds)")
        ax.set_ylabel("screen-space error, px")
        ax.set_title(res["scene"], fontsize=9)
        ax.legend(fontsize=6.5)
    fig.suptitle("Choice by accuracy: the options chosen for max_error_px 2 .. 0.1 (grey lines) and normal requests; "
                 "level labels = samples per span / cell or subdivision level", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--families", default=",".join(FAMILIES))
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--figure-only", action="store_true", help="redraw choice.md and choice.png from choice.json")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if args.figure_only:
        results = json.loads((out / "choice.json").read_text())
        (out / "choice.md").write_text(choice_markdown(results))
        choice_figure(results, out / "choice.png")
        return
    results = [bench_family(f, args.repeats) for f in args.families.split(",")]
    out.mkdir(parents=True, exist_ok=True)
    (out / "choice.json").write_text(json.dumps(results, indent=1))
    (out / "choice.md").write_text(choice_markdown(results))
    choice_figure(results, out / "choice.png")
    print(choice_markdown(results))


if __name__ == "__main__":
    main()

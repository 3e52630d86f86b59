"""The walkthrough study: large NURBS models at interactive rates with levels of detail, culling and the
threaded pipeline [Kumar1997], measured on this machine (Mesa llvmpipe, no GPU).

* **(a) Triangles and frame time against delta and against pixel error.** Levels of detail
  (:func:`splinevis.nurbs.lod.levels.build_lod`, tolerances ``delta * 4**l``) of a small teapot field at several
  ``delta``; the triangles of each level and the mean frame time and triangles of the fly-through
  (:func:`splinevis.nurbs.lod.pipeline.camera_path`) at one pixel of error; then the main model's fly-through
  at pixel errors 0.5 .. 8.
* **(b) LOD against uniform tessellation and OpenCASCADE at equal measured deviation.** Every super-surface
  at one level (a static mesh) against :func:`splinevis.nurbs.tessellate.tessellate` at ``per_span = 1 .. 16``
  and against OpenCASCADE's mesher (:func:`splinevis.studies.nurbs_occ.occ_tessellate`, when OCP is importable)
  at deflections from half the finest tolerance to the coarsest, the deviation of all measured the same way
  (:func:`splinevis.studies.walkthrough_compare.measured_deviation`); for each level the coarsest uniform and
  OpenCASCADE mesh that is at least as accurate, with triangles and frame times side by side.
* **(c) Each part switched on in turn** on the main model (a teapot field, 40,000 patches in the full run,
  2,016 with ``quick``): nothing (every super-surface at the finest level), + frustum culling, + back-patch
  culling, + levels of detail (one pixel), + threads (:class:`splinevis.nurbs.lod.pipeline.Walkthrough`).
* **(d) The paper's headline** in columns labelled ``paper`` beside our fps (the ship hull too).
* **(e) Simplified levels** [Kumar1997, sec. 4] where super-surfaces span many patches: the ship hull without
  portholes built without and with :class:`splinevis.nurbs.lod.simplify.Simplifier`; per level the proven part
  ``delta_l``, ``eps_l``, the triangles, the Simplifier's measured distance against ``delta_l + eps_l`` and
  the study's measured deviation; and the fly-through of both (same path, same pixel error).
* **(f) Finer than level 0** and **(g) a trimmed CAD assembly through STEP**:
  :mod:`splinevis.studies.walkthrough_finer`.

Frames are 800x600 without multisampling (llvmpipe's 4x multisampling costs ~70 ms a frame alone and is
the same for every configuration). Level-of-detail models are cached as pickles ``(lod, build seconds)`` in
``out_dir/lod_cache``, keyed by the parameters and :func:`code_version`, and reused by later runs (building
the 40,000-patch field took 133 s here); the full run takes about 10 minutes (of them the OpenCASCADE meshes of
(b) about 2 and section (e) about 1.5, measured alone on the shared machine), ``quick`` about one.
"""

from __future__ import annotations

import os
import pickle
import time
from pathlib import Path

import numpy as np

from .report import (clean, log, md_table, paper_columns, paper_table, progress_bar, pyplot, save_figure,
                     write_json)
from .walkthrough_compare import (WINDOW, lod_bounds, lod_vs_meshes, measured_deviation, occ_deflections, plotter,
                                  simplification_levels)
from .walkthrough_finer import cad_assembly, finer_than_level0

__all__ = ["run_walkthrough_study", "measured_deviation", "code_version", "PAPER_ROWS"]

#: [Kumar1997]: SGI Onyx, three 200 MHz R4400 CPUs, RealityEngine2 graphics; the Door model (38,750 Bezier
#: patches). Abstract: "almost 40,000 Bezier patches at 7 - 15 frames a second"; sec. 6: sequential ~2 fps,
#: parallel 8 - 10 fps, dynamic tessellation without static levels of detail [21] 1.4 fps.
PAPER_ROWS = [
    {"setting": "all parts (abstract)", "patches": 40000, "fps": "7-15"},
    {"setting": "sequential (sec. 6)", "patches": 38750, "fps": "~2"},
    {"setting": "parallel, three threads (sec. 6)", "patches": 38750, "fps": "8-10"},
    {"setting": "dynamic tessellation, no static LOD, one CPU (sec. 6)", "patches": 38750, "fps": "1.4"},
]
PAPER_HARDWARE = "SGI Onyx, three 200 MHz R4400 CPUs, RealityEngine2 graphics, 1997"
PARTS = [("none (finest level, no culling)", dict(cull_frustum=False, cull_back=False, pixel_error=None, threaded=False)),
         ("+ frustum culling", dict(cull_frustum=True, cull_back=False, pixel_error=None, threaded=False)),
         ("+ back-patch culling", dict(cull_frustum=True, cull_back=True, pixel_error=None, threaded=False)),
         ("+ LOD (super-surfaces, 1 px)", dict(cull_frustum=True, cull_back=True, pixel_error=1.0, threaded=False)),
         ("+ threads (V, T, P)", dict(cull_frustum=True, cull_back=True, pixel_error=1.0, threaded=True))]


def _settings(quick):
    if quick:
        return {"main": ("teapot", 63), "main_delta": 0.1, "small": ("teapot", 2), "deltas": (0.03, 0.1, 0.3),
                "hull": ("hull", 300), "hull_delta": 0.01, "frames": 40, "pixel_errors": (0.5, 1.0, 2.0, 4.0, 8.0),
                "simplify": ("hull_noportholes", 300), "simplify_delta": 0.01, "simplify_samples": 12, "repeats": 1,
                "occ_step": 4.0, "cad_copies": 1, "cad_delta": 0.01}
    return {"main": ("teapot", 1250), "main_delta": 0.1, "small": ("teapot", 16), "deltas": (0.01, 0.03, 0.1, 0.3),
            "hull": ("hull", 10000), "hull_delta": 0.005, "frames": 120, "pixel_errors": (0.5, 1.0, 2.0, 4.0, 8.0),
            "simplify": ("hull_noportholes", 10000), "simplify_delta": 0.005, "simplify_samples": 8, "repeats": 2,
            "occ_step": np.sqrt(2.0), "cad_copies": 16, "cad_delta": 0.005}


def _model(kind, n):
    from datasets_synthetic.large_models import hull, teapot_field

    return teapot_field(n) if kind == "teapot" else hull(n, portholes=kind == "hull")


def code_version() -> str:
    """A short hash of the level-of-detail modules' source: the cache key that keeps a changed construction
    from reusing old pickles.

    Examples
    --------
    >>> len(code_version())
    10
    """
    import hashlib

    from ..nurbs import lod as package

    h = hashlib.sha1()
    for path in sorted(Path(package.__file__).parent.glob("*.py")):
        if path.stem not in ("select", "pipeline", "program"):  # the view-time modules change no model
            h.update(path.read_bytes())
    return h.hexdigest()[:10]


def _lod(cache, kind, n, delta, levels=4, progress=True, version=None, simplify=None):
    """``(lod, build seconds, patches)`` from the cache or built (and cached); ``version``: the
    :func:`code_version` of the run (taken once, so that one run uses one key); ``simplify``: a
    :class:`~splinevis.nurbs.lod.simplify.Simplifier` or None."""
    from ..nurbs.lod.levels import build_lod

    key = "" if simplify is None else f"_simplify{simplify.share:g}-{simplify.samples}-{simplify.target:g}"
    path = Path(cache) / f"{kind}{n}_delta{delta:g}_levels{levels}{key}_{version or code_version()}.pkl"
    if path.exists():
        with open(path, "rb") as f:
            lod, seconds = pickle.load(f)
        return lod, float(seconds), len(lod.bezier)
    model = _model(kind, n)
    log("walkthrough", f"building levels of detail of {model.source} at delta {delta:g}"
        f"{'' if simplify is None else ', simplified'} (cached in {cache})")
    t0 = time.perf_counter()
    lod = build_lod(model, float(delta), levels=levels, simplify=simplify, progress=progress)
    seconds = time.perf_counter() - t0
    Path(cache).mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as f:
        pickle.dump((lod, seconds), f, protocol=pickle.HIGHEST_PROTOCOL)
    return lod, seconds, len(lod.bezier)


def _path(lod, frames):
    """The fly-through, its close approach to the top of the super-surface box nearest the model's centre."""
    from ..nurbs.lod.pipeline import camera_path

    b = np.asarray(lod.boxes)
    centres = 0.5 * (b[:, 0::2] + b[:, 1::2])
    mid = 0.5 * (np.asarray(lod_bounds(lod))[0::2] + np.asarray(lod_bounds(lod))[1::2])
    k = int(np.argmin(np.linalg.norm(centres[:, :2] - mid[:2], axis=1)))
    return camera_path(lod_bounds(lod), frames, target=(centres[k, 0], centres[k, 1], b[k, 5]))


def _fly(lod, path, **options) -> tuple:
    """(summary row, per-frame rows) of one fly-through."""
    from ..nurbs.lod.pipeline import Walkthrough

    pl = plotter()
    try:
        frames = Walkthrough(lod, pl, **options).fly(path, progress=False)
    finally:
        pl.close()
    t = np.array([f["time_ms"] for f in frames])
    mean = lambda k: float(np.mean([f[k] for f in frames]))  # noqa: E731
    row = {"frames": len(frames), "frame_mean_ms": float(t.mean()), "frame_median_ms": float(np.median(t)),
           "frame_max_ms": float(t.max()), "fps": 1e3 / float(t.mean()), "triangles_mean": mean("triangles"),
           "visible_mean": mean("visible"), "mesh_age_mean": mean("mesh_age"),
           "mesh_age_max": int(max(f["mesh_age"] for f in frames)), "select_ms_mean": mean("select_ms"),
           "needs_finer": mean("needs_finer"),
           "assemble_ms_max": float(max(f["assemble_ms"] for f in frames)), "render_ms_mean": mean("render_ms"),
           "new_meshes": int(sum(f["new_mesh"] for f in frames))}
    return row, frames


def _parts(lod, path, progress) -> tuple:
    """(c): one row per configuration and the per-frame times."""
    rows, series = [], {}
    for name, options in progress_bar(PARTS, "walkthrough: parts", enabled=progress):
        row, frames = _fly(lod, path, **options)
        rows.append({"configuration": name, **row})
        series[name] = [f["time_ms"] for f in frames]
    base = rows[0]["frame_mean_ms"]
    for prev, row in zip([None] + rows[:-1], rows):
        row["speedup_vs_none"] = base / row["frame_mean_ms"]
        row["speedup_vs_previous"] = (prev["frame_mean_ms"] / row["frame_mean_ms"]) if prev else 1.0
    return rows, series


def _thread_pairs(lod, path, repeats=2) -> dict:
    """Sequential and threaded runs of the full pipeline alternated ``repeats`` times (the machine is shared:
    alternating spreads its load over both)."""
    seq, thr = [], []
    for _ in range(repeats):
        seq.append(_fly(lod, path, pixel_error=1.0, threaded=False)[0]["frame_mean_ms"])
        thr.append(_fly(lod, path, pixel_error=1.0, threaded=True)[0]["frame_mean_ms"])
    return {"sequential_ms": seq, "threaded_ms": thr, "speedup": float(np.mean(seq) / np.mean(thr))}


def _views(out, lod, path, picks=(0.0, 0.3, 0.59, 1.0)):
    """``walkthrough_views.png``: a few frames of the fly-through with every part on, side by side."""
    import tempfile

    from PIL import Image

    from ..nurbs.lod.pipeline import Walkthrough

    chosen = [path[min(int(round(t * (len(path) - 1))), len(path) - 1)] for t in picks]
    with tempfile.TemporaryDirectory() as tmp:
        pl = plotter()
        try:
            Walkthrough(lod, pl, threaded=False, pixel_error=1.0).fly(chosen, frames_dir=tmp, progress=False)
        finally:
            pl.close()
        images = [Image.open(Path(tmp) / f"frame_{i:04d}.png").convert("RGB") for i in range(len(chosen))]
        w, h = images[0].size
        sheet = Image.new("RGB", (len(images) * (w // 2) + 6 * (len(images) - 1), h // 2), "black")
        for i, im in enumerate(images):
            sheet.paste(im.resize((w // 2, h // 2)), (i * (w // 2 + 6), 0))
        sheet.save(out / "walkthrough_views.png")


def _figures(out, result):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    for name, times in result["parts_series"].items():
        ax.plot(np.arange(len(times)), times, label=name, lw=1.2)
    ax.set_yscale("log")
    ax.set_xlabel("frame of the fly-through (low pass, then close approach)")
    ax.set_ylabel("frame time (ms)")
    ax.set_title(f"{result['main']['source']}: frame time per configuration", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    save_figure(fig, out / "walkthrough_frames.png")
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    rows = result["vs_delta"]
    d = [r["delta"] for r in rows]
    for level in range(len(rows[0]["triangles_per_level"])):
        axes[0].plot(d, [r["triangles_per_level"][level] for r in rows], "o-", label=f"all at level {level}")
    axes[0].plot(d, [r["triangles_mean"] for r in rows], "ks--", label="fly-through, 1 px (mean)")
    axes[0].set_xscale("log")
    axes[0].set_yscale("log")
    axes[0].set_xticks(d, [f"{x:g}" for x in d])
    axes[0].minorticks_off()
    axes[0].set_xlabel("delta (finest bound, model units)")
    axes[0].set_ylabel("triangles")
    axes[0].set_title(result["small"]["source"], fontsize=9)
    axes[0].legend(fontsize=7)
    axes[0].grid(True, which="both", alpha=0.3)
    rows = result["vs_pixel_error"]
    pe = [r["pixel_error"] for r in rows]
    axes[1].plot(pe, [r["triangles_mean"] for r in rows], "o-", label="triangles (mean)")
    axes[1].set_xscale("log")
    axes[1].set_xticks(pe, [f"{x:g}" for x in pe])
    axes[1].minorticks_off()
    axes[1].set_ylim(0, 1.1 * max(r["triangles_mean"] for r in rows))
    axes[1].set_xlabel("pixel error")
    axes[1].set_ylabel("triangles drawn (mean)")
    ax2 = axes[1].twinx()
    ax2.plot(pe, [r["frame_mean_ms"] for r in rows], "rs--", label="frame time")
    ax2.set_ylabel("mean frame time (ms)", color="r")
    ax2.set_ylim(0, 1.1 * max(r["frame_mean_ms"] for r in rows))
    axes[1].legend(axes[1].get_lines() + ax2.get_lines(), ["triangles (mean)", "frame time (mean)"], fontsize=7,
                   loc="lower left")
    axes[1].set_title(result["main"]["source"], fontsize=9)
    axes[1].grid(True, which="both", alpha=0.3)
    save_figure(fig, out / "walkthrough_triangles.png")
    b, e = result["lod_vs_meshes"], result["simplification"]
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for rows, style, label in ((b["levels"], "ko-", "LOD levels (all super-surfaces)"),
                               (b["uniform"], "s--", "uniform per_span"), (b["occ"] if b["occ_available"] else [],
                                                                          "^--", "OpenCASCADE BRepMesh")):
        rows = sorted(rows, key=lambda r: r["deviation"])  # OpenCASCADE's deviation is not monotone in deflection
        if rows:
            axes[0].plot([r["deviation"] for r in rows], [r["triangles"] for r in rows], style, label=label, ms=4)
    axes[0].set_title(f"(b) {result['small']['source']}", fontsize=9)
    axes[1].plot([r["level"] for r in e["levels"]], [r["triangles_plain"] for r in e["levels"]], "o-", label="plain")
    axes[1].plot([r["level"] for r in e["levels"]], [r["triangles_simplified"] for r in e["levels"]], "s--",
                 label="simplified")
    axes[1].set_xticks([r["level"] for r in e["levels"]])
    axes[1].set_title(f"(e) {e['source'].split(' (')[0]} without portholes", fontsize=9)
    axes[0].set_xlabel("measured deviation (model units)")
    axes[1].set_xlabel("level")
    for ax in axes:
        ax.set_yscale("log")
        ax.set_ylabel("triangles")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    axes[0].set_xscale("log")
    save_figure(fig, out / "walkthrough_meshes.png")


def write_markdown(out, result) -> Path:
    """``out/walkthrough.md`` from a study result (the dict of ``walkthrough.json``).

    Examples
    --------
    See :func:`run_walkthrough_study` (minutes); the tables come from :func:`splinevis.studies.report.md_table`.
    """
    m, h, b, e = result["main"], result["hull"], result["lod_vs_meshes"], result["simplification"]
    for r in e["levels"]:
        r["reduced"] = f"{r['supers_reduced']} of {r['supers']}"
    fly_cols = [("frame mean (ms)", "frame_mean_ms", "f1"), ("fps", "fps", "f1"), ("frame max (ms)", "frame_max_ms", "f1"),
                ("triangles (mean)", "triangles_mean", "int"), ("visible super-surfaces", "visible_mean", "f1"),
                ("mesh age mean / max", "age", "s"), ("select (ms)", "select_ms_mean", "f2"),
                ("assemble max (ms)", "assemble_ms_max", "f1"), ("render (ms)", "render_ms_mean", "f1")]
    cad = [result["cad"]] if result["cad"].get("available") else []
    for r in (result["parts"] + result["vs_pixel_error"] + result["vs_delta"] + result["headline"] + e["flights"]
              + result["finer"]["rows"] + cad):
        if "mesh_age_mean" in r:
            r["age"] = f"{r['mesh_age_mean']:.2f} / {r['mesh_age_max']}"
    t = result["threads"]
    md = ["# Walkthrough study: large NURBS models with levels of detail [Kumar1997]", "",
          f"{WINDOW[0]}x{WINDOW[1]} pixels, no multisampling, Mesa llvmpipe on {os.cpu_count()} CPU cores (no GPU), "
          f"{result['frames']} frames per fly-through (a low pass along the model, then a close approach). "
          f"Load average at start {result['machine']['loadavg_start']}, at end {result['machine']['loadavg_end']}: "
          "the machine is shared, frame times move by 10-20 % between runs.", "",
          "## (d) Headline: the paper's numbers beside ours", "",
          md_table(result["headline"], [("model", "model", "s"), ("patches", "patches", "int"),
                                        ("super-surfaces", "super_surfaces", "int"), ("our fps", "fps", "f1"),
                                        ("our triangles (mean)", "triangles_mean", "int")]
                   + paper_columns([("fps", "paper_fps", "s"), ("patches", "paper_patches", "s"),
                                    ("hardware", "paper_hardware", "s")])), "",
          paper_table("[Kumar1997, abstract and sec. 6], " + PAPER_HARDWARE, PAPER_ROWS,
                      [("setting", "setting", "s"), ("patches", "patches", "int"), ("fps", "fps", "s")]), "",
          f"## (c) Each part switched on in turn ({m['source']}; {m['super_surfaces']:,} super-surfaces, "
          f"levels of detail built in {m['build_s']:.0f} s)", "",
          md_table(result["parts"], [("configuration", "configuration", "s")] + fly_cols
                   + [("speed-up vs none", "speedup_vs_none", "f2"), ("speed-up vs previous", "speedup_vs_previous", "f2")]),
          "", f"Threads, alternated runs: sequential {', '.join(f'{x:.1f}' for x in t['sequential_ms'])} ms, threaded "
          f"{', '.join(f'{x:.1f}' for x in t['threaded_ms'])} ms a frame: speed-up {t['speedup']:.2f}.", "",
          result["thread_note"], "", "![frame times](walkthrough_frames.png)", "",
          "Frames of the fly-through (every part on; smooth shading, every vertex carries the surface's exact "
          "normal):", "",
          "![views](walkthrough_views.png)", "",
          f"## (a) Against delta ({result['small']['source']}) and against pixel error ({m['source']})", "",
          md_table(result["vs_delta"], [("delta", "delta", "e"), ("build (s)", "build_s", "f1"),
                                        ("super-surfaces", "super_surfaces", "int"),
                                        ("triangles per level (all drawn)", "per_level", "s")] + fly_cols), "",
          md_table(result["vs_pixel_error"], [("pixel error", "pixel_error", "f2"), ("needs finer (mean)", "needs_finer", "f1")]
                   + fly_cols), "", "![triangles](walkthrough_triangles.png)", "",
          f"## (b) LOD against uniform tessellation and OpenCASCADE at equal measured deviation "
          f"({result['small']['source']}, delta {b['delta']:g})", "",
          "Every super-surface at one level against the coarsest uniform mesh and the coarsest OpenCASCADE mesh "
          "(`BRepMesh_IncrementalMesh`, linear deflections as listed, angular deflection 0.5 rad) whose measured "
          "deviation is at most the level's (all measured by `measured_deviation`; frame time of the whole model in "
          "view, flat shaded alike).", "",
          md_table(b["matches"],
                   [("LOD", "level", "s"), ("deviation", "lod_deviation", "e"), ("triangles", "lod_triangles", "int"),
                    ("frame (ms)", "lod_frame_ms", "f1"), ("uniform", "uniform", "s"),
                    ("deviation", "uniform_deviation", "e"), ("triangles", "uniform_triangles", "int"),
                    ("frame (ms)", "uniform_frame_ms", "f1"), ("uniform / LOD triangles", "uniform_ratio", "f2"),
                    ("OpenCASCADE", "occ", "s"), ("deviation", "occ_deviation", "e"),
                    ("triangles", "occ_triangles", "int"), ("frame (ms)", "occ_frame_ms", "f1"),
                    ("OpenCASCADE / LOD triangles", "occ_ratio", "f2")]), "",
          md_table(b["levels"] + b["uniform"] + b["occ"],
                   [("mesh", "mesh", "s"), ("proven bound", "bound", "e"), ("measured deviation", "deviation", "e"),
                    ("triangles", "triangles", "int"), ("frame (ms)", "frame_ms", "f1")]), "",
          "Triangles against measured deviation (left) and the simplified levels of (e) (right):", "",
          "![meshes](walkthrough_meshes.png)", "",
          f"## (e) Simplified levels: bounded by delta_l + eps_l ({e['source']}; {e['super_surfaces']} super-surfaces, "
          f"{e['patches']:,} patches)", "",
          f"The same model built without and with `Simplifier(share={e['share']:g})` (vtkDecimatePro across patch "
          "edges inside each super-surface, its border kept, eps_l = share * delta_l, level 0 never simplified; "
          f"build {e['build_plain_s']:.1f} s against {e['build_simplified_s']:.1f} s). Per level: the proven part "
          "delta_l, eps_l, the triangles, the largest distance the Simplifier measured (`lod.simplified`, held to "
          "delta_l + eps_l) and the study's `measured_deviation` of every super-surface at that level "
          f"({e['samples_per_span']} samples per span).", "",
          md_table(e["levels"], [("level", "level", "int"), ("delta_l", "delta", "e"), ("eps_l", "eps", "e"),
                                 ("bound delta_l + eps_l", "bound", "e"), ("triangles plain", "triangles_plain", "int"),
                                 ("triangles simplified", "triangles_simplified", "int"),
                                 ("simplified / plain", "ratio", "f2"), ("super-surfaces reduced", "reduced", "s"),
                                 ("Simplifier measured (max)", "simplifier_measured", "e"),
                                 ("measured deviation plain", "deviation_plain", "e"),
                                 ("measured deviation simplified", "deviation_simplified", "e")]), "",
          "A level kept unsimplified (no decimation within its bound) records its delta_l as the measured distance.",
          "", f"Fly-through of this model ({result['frames']} frames, the same path and pixel error for both, "
          f"sequential; {e['repeats']} alternated run(s), means). A simplified level's bound delta_l + eps_l is "
          "larger, so at the same pixel error the selection may draw a finer level than without simplification:", "",
          md_table(e["flights"], [("levels of detail", "lod", "s"), ("pixel error", "pixel_error", "f1")] + fly_cols),
          "",
          f"The hull ({h['source']}) in the headline table: {h['super_surfaces']} super-surfaces.", ""]
    md += _finer_markdown(result)
    md += [f"Run time {result['seconds']:.0f} s.", ""]
    for r in result["vs_delta"]:
        r.pop("per_level", None)
    for r in e["levels"]:
        r.pop("reduced", None)
    path = Path(out) / "walkthrough.md"
    path.write_text("\n".join(md))
    return path


def _finer_markdown(result) -> list:
    f, c = result["finer"], result["cad"]
    md = [f"## (f) Finer than level 0 ({f['source']}, delta {f['delta']:g}, 1 px, threaded)", "",
          "The close approach ends a few percent of the model's size from a teapot, nearer than level 0's bound allows "
          "at one pixel. Static levels draw level 0 there; dynamic tessellation refines those super-surfaces in the "
          "mesh worker (the renderer draws what is ready: 'waiting' counts the rest); exact close-ups draw the "
          "super-surfaces that fill the view with the per-fragment program.", "",
          md_table(f["rows"], [("configuration", "configuration", "s"), ("fps", "fps", "f1"),
                               ("frame mean (ms)", "frame_mean_ms", "f1"), ("frame max (ms)", "frame_max_ms", "f1"),
                               ("triangles (mean)", "triangles_mean", "int"),
                               ("wanted finer (mean)", "needs_finer", "f1"), ("refined (mean)", "refined", "f1"),
                               ("waiting (mean)", "pending", "f1"), ("mesh age mean / max", "age", "s"),
                               ("frames with exact close-ups", "closeup_frames", "int"),
                               ("exact super-surfaces (max)", "closeup_max", "int")]), ""]
    if not c.get("available"):
        return md + ["## (g) A trimmed CAD assembly through STEP", "", c.get("note", "not run"), ""]
    return md + ["## (g) A trimmed CAD assembly through STEP", "",
                 f"{c['copies']} plate(s) with filleted edges and six holes each (planes, cylinders, corner spheres; "
                 f"{c['faces']:,} trimmed faces, {c['patches']:,} Bezier patches, {c['super_surfaces']:,} "
                 f"super-surfaces), written by OpenCASCADE and read back in {c['read_s']:.1f} s ({c['source']}); "
                 "levels of detail at "
                 f"delta {c['delta']:g} built in {c['build_s']:.1f} s (trims cut, faces stitched along their trims). "
                 f"Triangles per level: {' / '.join(f'{x:,}' for x in c['triangles_per_level'])}.", "",
                 f"Open mesh edges (a closed solid has none): {c['open_edges_level0']:,} of the "
                 f"{c['triangles_level0']:,}-triangle level 0, at most {c['open_edges_mixed_max']:,} over "
                 f"{c['combos']} random level combinations.", "",
                 md_table([c], [("fps", "fps", "f1"), ("frame mean (ms)", "frame_mean_ms", "f1"),
                                ("triangles (mean)", "triangles_mean", "int"),
                                ("visible super-surfaces", "visible_mean", "f1"), ("mesh age mean / max", "age", "s")]),
                 ""]


def _thread_note(parts, threads) -> str:
    seq, thr = parts[-2], parts[-1]
    stage = seq["select_ms_mean"] + seq["assemble_ms_max"]
    return (f"V and T take {seq['select_ms_mean']:.2f} ms (selection, mean) and at most {seq['assemble_ms_max']:.1f} ms "
            f"(assembly) against {seq['render_ms_mean']:.1f} ms of rendering: moving {stage:.1f} ms or less off the "
            f"renderer's thread can gain at most that, and llvmpipe already rasterizes on every core, so the threads "
            f"compete with it. Measured speed-up of the threads: {threads['speedup']:.2f} (mean mesh age "
            f"{thr['mesh_age_mean']:.2f} frames, at most {thr['mesh_age_max']}). Processes would not help here: the "
            f"stages they could take off the renderer are this small, and each hand-over would copy the mesh.")


def _simplification(cache, s, version, progress, pixel_errors=(1.0, 4.0)) -> dict:
    """(e): the model ``s["simplify"]`` built without and with a Simplifier, per level and flown through at
    each of ``pixel_errors`` (runs alternated ``s["repeats"]`` times: the machine is shared)."""
    from ..nurbs.lod.simplify import Simplifier

    simplifier = Simplifier()
    kind, n = s["simplify"]
    model = _model(kind, n)
    plain, plain_s, patches = _lod(cache, kind, n, s["simplify_delta"], progress=progress, version=version)
    simple, simple_s, _ = _lod(cache, kind, n, s["simplify_delta"], progress=progress, version=version,
                               simplify=simplifier)
    levels = simplification_levels(plain, simple, model, s["simplify_samples"])
    path = _path(plain, s["frames"])
    flights = []
    for pe in pixel_errors:
        runs = {"plain": [], "simplified": []}
        for _ in range(s["repeats"]):
            for name, lod in (("plain", plain), ("simplified", simple)):
                runs[name].append(_fly(lod, path, pixel_error=pe, threaded=False)[0])
        for (name, rows), lod in zip(runs.items(), (plain, simple)):
            row = {k: (float(np.mean([r[k] for r in rows])) if isinstance(v, float) else max(r[k] for r in rows))
                   for k, v in rows[0].items()}  # means; the counts (frames, mesh age max, new meshes) their largest
            row["fps"] = 1e3 / row["frame_mean_ms"]
            flights.append({"lod": f"{name} (bounds {', '.join(f'{x:.3g}' for x in lod.tolerance)})",
                            "pixel_error": pe, **row})
    return {"source": model.source, "patches": patches, "super_surfaces": len(plain.supers.members),
            "delta": s["simplify_delta"], "share": simplifier.share, "samples_per_span": s["simplify_samples"],
            "build_plain_s": plain_s, "build_simplified_s": simple_s, "repeats": s["repeats"], "levels": levels,
            "flights": flights}


def run_walkthrough_study(out_dir, *, quick=False, progress=True) -> dict:
    """Run the study; returns the dict also written to ``out_dir/walkthrough.json`` (plus ``walkthrough.md`` and
    the figures ``walkthrough_frames.png``, ``walkthrough_triangles.png``, ``walkthrough_views.png``,
    ``walkthrough_meshes.png``)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cache = out / "lod_cache"
    t0 = time.perf_counter()
    s = _settings(quick)
    result = {"quick": quick, "window": list(WINDOW), "frames": s["frames"], "lod_code": code_version(),
              "machine": {"cpus": os.cpu_count(), "loadavg_start": [round(x, 2) for x in os.getloadavg()]}}
    version = result["lod_code"]
    lod, build_s, patches = _lod(cache, *s["main"], s["main_delta"], progress=progress, version=version)
    model_source = _model(*s["main"]).source
    result["main"] = {"source": model_source, "patches": patches, "super_surfaces": len(lod.supers.members),
                      "delta": s["main_delta"], "build_s": build_s, "tolerance": lod.tolerance.tolist()}
    path = _path(lod, s["frames"])
    log("walkthrough", f"(c) parts on {model_source}")
    result["parts"], result["parts_series"] = _parts(lod, path, progress)
    result["threads"] = _thread_pairs(lod, path)
    _views(out, lod, path)
    result["thread_note"] = _thread_note(result["parts"], result["threads"])
    log("walkthrough", "(a) pixel errors")
    result["vs_pixel_error"] = []
    for pe in progress_bar(s["pixel_errors"], "walkthrough: pixel error", enabled=progress):
        row, frames = _fly(lod, path, pixel_error=pe, threaded=False)
        result["vs_pixel_error"].append({"pixel_error": pe, **row})
    result["headline"] = [{"model": model_source, "patches": patches, "super_surfaces": len(lod.supers.members),
                           **result["parts"][-1], "paper_fps": "7-15", "paper_patches": "~40,000 (38,750)",
                           "paper_hardware": PAPER_HARDWARE}]
    del lod
    hl, hb, hp = _lod(cache, *s["hull"], s["hull_delta"], progress=progress, version=version)
    hsource = _model(*s["hull"]).source
    result["hull"] = {"source": hsource, "patches": hp, "super_surfaces": len(hl.supers.members), "build_s": hb}
    row, _ = _fly(hl, _path(hl, s["frames"]), pixel_error=1.0, threaded=True)
    result["headline"].append({"model": hsource, "patches": hp, "super_surfaces": len(hl.supers.members), **row,
                               "paper_fps": "7-15", "paper_patches": "~40,000 (38,750)", "paper_hardware": PAPER_HARDWARE})
    del hl
    log("walkthrough", "(a) deltas, (b) LOD against uniform tessellation")
    small_model = _model(*s["small"])
    result["small"] = {"source": small_model.source}
    result["vs_delta"] = []
    for delta in progress_bar(s["deltas"], "walkthrough: delta", enabled=progress):
        sl, sb, sp = _lod(cache, *s["small"], delta, progress=False, version=version)
        row, _ = _fly(sl, _path(sl, s["frames"]), pixel_error=1.0, threaded=False)
        per_level = sl.triangles.sum(axis=0).tolist()
        result["vs_delta"].append({"delta": delta, "build_s": sb, "super_surfaces": len(sl.supers.members),
                                   "triangles_per_level": per_level, "per_level": " / ".join(f"{x:,}" for x in per_level),
                                   **row})
    delta_b = s["deltas"][0]
    sl, _, _ = _lod(cache, *s["small"], delta_b, progress=False, version=version)
    log("walkthrough", "(b) LOD against uniform tessellation and OpenCASCADE")
    deflections = occ_deflections(sl.tolerance, s["occ_step"])
    result["lod_vs_meshes"] = {"delta": delta_b, **lod_vs_meshes(sl, small_model, deflections=deflections)}
    log("walkthrough", "(f) finer than level 0: dynamic tessellation, exact close-ups")
    result["finer"] = {"source": small_model.source, "delta": delta_b,
                       "rows": finer_than_level0(sl, _path(sl, s["frames"]), _fly)}
    log("walkthrough", "(e) simplified levels")
    result["simplification"] = _simplification(cache, s, version, progress)
    log("walkthrough", "(g) a trimmed CAD assembly through STEP")
    result["cad"] = cad_assembly(out, s["cad_copies"], s["cad_delta"], lambda lod: _path(lod, s["frames"]), _fly)
    result["machine"]["loadavg_end"] = [round(x, 2) for x in os.getloadavg()]
    result["seconds"] = time.perf_counter() - t0
    _figures(out, result)
    write_markdown(out, result)
    result = clean(result)
    write_json(out / "walkthrough.json", result)
    return result

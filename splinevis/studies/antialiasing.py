"""Antialiasing, measured side by side: how far each way of drawing reflection lines is from the picture a
pixel should show, and what it costs.

For four scenes with reflection lines -- a terrain (C1 quartic spline of a fractal DEM), an isosurface (the
cubic spline of Marschner-Lobb 41^3), a NURBS model (the Newell teapot) and a geometry image (the bent blob)
-- each renderer draws the same view at the same window size:

* ``exact, plain step`` -- the exact program, one sample per pixel, the stripes' plain step
  (``antialias=False``: the pictures before the stripes were filtered);
* ``exact, filtered`` -- the same with the stripes averaged over the pixel's footprint (``Style.antialias``,
  the default; ``glsl/lib/effects/footprint.glsl`` [ApodacaGritz2000, ch. 11]);
* ``exact, filtered, SSAA 2x2`` / ``4x4`` -- filtered and supersampled (``Plotter(anti_aliasing=k)``: rendered
  ``k`` times larger, block-averaged), which also smooths silhouettes;
* ``mesh (users')`` -- the triangle mesh users draw today with interpolated vertex normals and the same
  stripes' plain step: the linear mesh of the DEM, flying edges, the tessellated NURBS (8 per span), the input
  mesh of the geometry image.

A fifth scene has no stripes: a real USGS DEM with steep canyon walls (:data:`REAL_DEM`), lit by two lights
with a specular highlight, where one sample per pixel leaves a speckle on the slopes; there ``filtered`` is the
highlight widened by the spread of the normals over the pixel [Toksvig2005], and the users' mesh is drawn by
PyVista (``smooth_shading=True``, VTK's Phong specular and VTK's light kit): its error there is mostly the other
lighting, not aliasing.

The reference is the exact program's plain step supersampled 4 x 4 (16 point samples a pixel, averaged): the
pixel's mean colour up to the sampling of 16 points. Per pixel that is not background in either picture, the
error is the luminance difference (Rec. 709 weights, 0..1); the table gives its mean and 99th percentile. Frame
times are medians of ``render_now`` at the size each renderer draws, the renderers of a scene timed in turn
frame by frame (:func:`_interleaved_times`), so their ratios hold on a busy machine.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .report import log, md_table, progress_bar, pyplot, save_figure, write_json

__all__ = ["run_antialiasing_study", "SCENES", "RENDERERS", "luminance_error"]

SCENES = ("terrain", "isosurface", "nurbs", "geometry image", "real DEM, lit")
#: The real DEM of the last scene, in the data folder beside the repository (the scene is left out, with a note,
#: where it is not there): USGS's Cathedral Canyon, steep canyon walls.
REAL_DEM = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "terrain" / "Cathedral_Canyon.dem"
#: (label, kind, antialias, supersampling factor)
RENDERERS = (("exact, plain step", "exact", False, 1), ("exact, filtered", "exact", True, 1),
             ("exact, filtered, SSAA 2x2", "exact", True, 2), ("exact, filtered, SSAA 4x4", "exact", True, 4),
             ("mesh (users')", "mesh", False, 1))
REFERENCE = ("reference: plain step, 4x4 samples", "exact", False, 4)
_REC709 = np.array([0.2126, 0.7152, 0.0722])


def luminance_error(image, reference, background=(255, 255, 255)) -> dict:
    """Mean and 99th percentile of ``|Y(image) - Y(reference)|`` (Rec. 709 luminance of 8-bit RGB, in 0..1) over
    the pixels that are not ``background`` in either picture.

    >>> a = np.full((4, 4, 3), 255, np.uint8); b = a.copy(); a[:2] = 0; b[:2] = 51
    >>> e = luminance_error(a, b)
    >>> e["pixels"], round(e["mean"], 6), round(e["p99"], 6)
    (8, 0.2, 0.2)
    """
    a, b = (np.asarray(x, dtype=np.float64)[..., :3] for x in (image, reference))
    bg = np.asarray(background, dtype=np.float64)
    mask = np.any(a != bg, axis=-1) | np.any(b != bg, axis=-1)
    d = np.abs((a - b) @ _REC709)[mask] / 255.0
    if d.size == 0:
        return {"pixels": 0, "mean": float("nan"), "p99": float("nan")}
    return {"pixels": int(d.size), "mean": float(d.mean()), "p99": float(np.quantile(d, 0.99))}


def _scenes(quick: bool, names=SCENES):
    """{name: (spline model, users' mesh, camera, style keywords)} of the scenes ``names``."""
    from datasets_synthetic.closed_meshes import bent_blob
    from datasets_synthetic.teapot import newell_teapot
    from datasets_synthetic.volumes import marschner_lobb
    from ..geometry_image.program import model_from
    from ..nurbs.tessellate import tessellate
    from ..volume.baselines import marching_cubes_mesh
    from ..volume.isosurface import Isosurface
    from ..volume.model import VolumeSpline

    out = {}
    if "terrain" in names:
        out["terrain"] = _terrain(quick)
    if "isosurface" in names:
        field = marschner_lobb()
        vgrid = field.sample(25 if quick else 41)
        iso = Isosurface(VolumeSpline(vgrid), field.isovalue)
        cam = [(1.9, -1.5, 1.5), (0.05, 0.0, 0.0), (0.0, 0.0, 1.0)]
        out["isosurface"] = (iso, marching_cubes_mesh(vgrid, field.isovalue, method="flying_edges"), cam,
                             {"reflection_lines": 12})
    if "nurbs" in names:
        teapot = newell_teapot()
        out["nurbs"] = (teapot, tessellate(teapot, 8), [(6.0, -7.5, 4.2), (0.2, 0.0, 1.4), (0.0, 0.0, 1.0)],
                        {"reflection_lines": 24, "reflection_axis": (0.0, 0.0, 1.0)})
    if "real DEM, lit" in names and REAL_DEM.is_file():
        out["real DEM, lit"] = _terrain(quick, REAL_DEM)
    if "geometry image" in names:
        blob = bent_blob(level=3 if quick else 4)
        gi = model_from(blob, 33 if quick else 65, fairness=0.1)
        c, d = np.asarray(blob.center), blob.length
        out["geometry image"] = (gi, blob, [tuple(c + d * np.array([0.9, -1.2, 0.8])), tuple(c), (0.0, 0.0, 1.0)],
                                 {"reflection_lines": 12})
    return out


def _terrain(quick: bool, path=None):
    """The showcase's fractal DEM (UTM-sized origin), or the DEM file ``path`` (lit, no stripes), as a C1 quartic
    spline, its linear mesh, the camera."""
    import pyvista as pv
    from scipy.ndimage import gaussian_filter

    from datasets_synthetic.dem_files import fractal_terrain
    from ..io import read_heights
    from ..programs import get

    if path is None:
        n = 33 if quick else 65
        heights = 400.0 + 300.0 * gaussian_filter(fractal_terrain(n, seed=7, hurst=0.9), 1.5, mode="wrap")
        grid = read_heights(heights, spacing=(60.0, 60.0), origin=(500_010.0, 5_100_020.0))
    else:
        grid = read_heights(path, fill="nearest")
        if quick:  # every third sample: a ninth of the patches
            grid = read_heights(np.asarray(grid.heights)[::3, ::3], spacing=tuple(3 * v for v in grid.spacing),
                                origin=grid.origin)
    terrain = get("terrain").model_from(grid, "C1")
    ny, nx = grid.shape
    X, Y = np.meshgrid(grid.origin[0] + grid.spacing[0] * np.arange(nx), grid.origin[1] + grid.spacing[1] * np.arange(ny))
    users = pv.StructuredGrid(X, Y, np.asarray(grid.heights)).extract_surface(algorithm="dataset_surface").triangulate()
    x0, x1, y0, y1 = terrain.extent
    zlo, zhi = terrain.zrange
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    cam = [(cx - 0.5 * (x1 - x0), cy - 1.1 * (y1 - y0), zhi + 0.9 * (x1 - x0)), (cx, cy, zlo), (0, 0, 1)]
    style = {"reflection_lines": 30} if path is None else {"lights": 2, "specular": True}
    return terrain, users, cam, style


def _draw(model, mesh, camera, style, kind, antialias, k, window):
    from ..effects import Style
    from ..gl.mesh_effects import add_mesh_with_effects
    from ..plotting import Plotter

    pl = Plotter(off_screen=True, window_size=window, anti_aliasing=k if k > 1 else False)
    pl.set_background("white")
    opts = {"lights": 1, "color": "tan", **style, "antialias": antialias}
    if kind == "exact":
        pl.add_spline(model, **opts)
    elif style.get("specular"):  # lit, no stripes: PyVista's own Phong shading, as users draw a mesh
        pl.add_mesh(mesh, color="tan", smooth_shading=True, specular=0.5, specular_power=40.0)
    else:
        add_mesh_with_effects(pl, mesh, Style(**opts))
    pl.camera_position = camera
    pl.reset_camera_clipping_range()
    return pl


def run_antialiasing_study(out_dir, *, quick: bool = False, progress: bool = True, window=(320, 240),
                           repeats: int = 3, scenes=SCENES) -> dict:
    """Run the study (module docstring) on ``scenes``; write ``antialiasing.json``, ``antialiasing.md`` and
    ``antialiasing.png`` (each scene's renderers side by side, close-ups, with their errors; error against frame
    time) into ``out_dir``. ``quick`` uses smaller models and a 160 x 120 window (tests).

    Returns ``{"rows": [...], "window": ...}``; a row per scene and renderer: ``scene``, ``renderer``,
    ``mean``, ``p99`` (luminance error against the reference), ``frame_median_ms`` (at the size drawn),
    ``time_ratio`` (to the exact plain step's), ``closest_single_sample`` (the single-sample renderer with the
    smallest mean error of its scene).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    unknown = set(scenes) - set(SCENES)
    if unknown:
        raise ValueError(f"scenes {sorted(unknown)} are not known; the scenes are {list(SCENES)}.")
    scenes_asked = tuple(scenes)
    scenes = _scenes(quick, scenes_asked)
    w, h = (int(v) for v in ((160, 120) if quick and tuple(window) == (320, 240) else window))
    rows, pictures = [], {}
    bar = progress_bar(total=len(scenes) * (len(RENDERERS) + 1), desc="antialiasing", enabled=progress, unit="run")
    missing = [name for name in scenes_asked if name not in scenes]
    for name, (model, mesh, camera, style) in scenes.items():
        pl = _draw(model, mesh, camera, style, *REFERENCE[1:], window)
        reference = np.asarray(pl.screenshot())
        pl.close()
        bar.update()
        pictures[name] = {REFERENCE[0]: reference}
        scene_rows = []
        for label, kind, antialias, k in RENDERERS:
            pl = _draw(model, mesh, camera, style, kind, antialias, k, window)
            img = np.asarray(pl.screenshot())
            pl.close()
            pictures[name][label] = img
            scene_rows.append(dict(scene=name, renderer=label, **luminance_error(img, reference)))
            bar.update()
        for r, t in zip(scene_rows, _interleaved_times(model, mesh, camera, style, (w, h), repeats)):
            r.update(frame_median_ms=t, repeats=int(repeats))
        base = scene_rows[0]["frame_median_ms"]
        single = [r for r, (_, _, _, k) in zip(scene_rows, RENDERERS) if k == 1]
        best = min(single, key=lambda r: r["mean"])["renderer"]
        for r in scene_rows:
            r["time_ratio"] = r["frame_median_ms"] / base
            r["closest_single_sample"] = r["renderer"] == best
        rows.extend(scene_rows)
        log("antialiasing", f"{name}: " + ", ".join(f"{r['renderer']} {r['mean']:.4f}/{r['p99']:.3f} "
                                                    f"{r['frame_median_ms']:.0f} ms" for r in scene_rows))
    bar.close()
    result = {"window": [w, h], "repeats": int(repeats), "quick": bool(quick), "rows": rows}
    if missing:
        result["real_dem"] = {"available": False, "note": f"{REAL_DEM.name} is not in the data folder beside the "
                                                          "repository: the real-DEM scene is left out"}
    write_json(out / "antialiasing.json", result)
    cols = [("scene", "scene", "s"), ("renderer", "renderer", "s"), ("mean error", "mean", "e"),
            ("p99 error", "p99", "e"), ("frame ms", "frame_median_ms", "f1"), ("time / plain step", "time_ratio", "f2"),
            ("closest single-sample", "closest_single_sample", "s")]
    (out / "antialiasing.md").write_text(
        f"# Antialiasing: luminance error against a 4x4-supersampled reference, {w} x {h}\n\n"
        "Written by `splinevis.studies.antialiasing` (its docstring says what each row is).\n\n" + md_table(rows, cols))
    _figure(out / "antialiasing.png", pictures, rows)
    return result


def _interleaved_times(model, mesh, camera, style, window, repeats: int) -> list:
    """Median frame time (ms) of each renderer at the size it draws (a supersampled frame is a frame ``k`` times
    larger), the renderers timed in turn, one frame each, ``repeats`` rounds after two warm-up frames each: the
    ratios are measured side by side, so a busy machine slows all of them alike."""
    import time

    w, h = window
    plotters = [_draw(model, mesh, camera, style, kind, aa, 1, (w * k, h * k)) for _, kind, aa, k in RENDERERS]
    times = [[] for _ in plotters]
    for pl in plotters:
        pl.render_now()
        pl.render_now()
    for _ in range(max(int(repeats), 1)):
        for pl, t in zip(plotters, times):
            t0 = time.perf_counter()
            pl.render_now()
            t.append(1e3 * (time.perf_counter() - t0))
    for pl in plotters:
        pl.close()
    return [float(np.median(t)) for t in times]


def _figure(path, pictures, rows):
    from matplotlib.ticker import NullFormatter

    plt = pyplot()
    labels = [REFERENCE[0]] + [r[0] for r in RENDERERS]
    names = list(pictures)
    fig, axes = plt.subplots(len(names), len(labels) + 1, figsize=(2.9 * (len(labels) + 1), 2.6 * len(names)))
    axes = np.atleast_2d(axes)
    for i, name in enumerate(names):
        ref = pictures[name][REFERENCE[0]]
        fg = np.argwhere(np.any(ref != 255, axis=-1))
        (r0, c0), (r1, c1) = fg.min(axis=0), fg.max(axis=0)
        rc, cc = (r0 + r1) // 2, (c0 + c1) // 2
        half = max(8, min(r1 - r0, c1 - c0) // 4)
        crop = (slice(max(rc - half, 0), rc + half), slice(max(cc - half, 0), cc + half))  # a close-up
        by = {r["renderer"]: r for r in rows if r["scene"] == name}
        for j, label in enumerate(labels):
            ax = axes[i, j]
            ax.imshow(pictures[name][label][crop], interpolation="nearest")
            title = label if label not in by else f"{label}\nmean {by[label]['mean']:.3f}, p99 {by[label]['p99']:.2f}"
            ax.set_title(title, fontsize=7)
            ax.set_axis_off()
        ax = axes[i, -1]
        for label in labels[1:]:
            r = by[label]
            ax.scatter(r["frame_median_ms"], r["mean"], s=22, label=label)
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("frame ms", fontsize=7)
        ax.set_ylabel("mean luminance error", fontsize=7)
        ax.set_title(name, fontsize=8)
        ax.tick_params(labelsize=6)
    axes[0, -1].legend(fontsize=5)
    fig.suptitle("Reflection lines (and a real DEM, lit): close-ups against the 4x4-supersampled exact picture; "
                 "error against frame time",
                 fontsize=10)
    save_figure(fig, path, dpi=100)

"""Benchmark runner: frame times measured side by side in one run; JSON + markdown table out.

    python benchmarks/run.py [--out DIR] [--repeats N] [--quick]

Cases
-----
* ``raycast_vs_mesh``: the analytic quartic patch ray-cast per pixel against PyVista meshes of the same
  surface with 10^3 .. 10^6 triangles, same camera, 800x600, anti-aliasing off.
* ``effect_sets``: frame time of the ray-cast patch under each effect set (only the declared effects
  are compiled in, so the cost of an effect is the difference to the baseline).
* ``volume``: isosurface of Marschner-Lobb 64^3 in a full view and a close-up: spline programs (quadratic /
  cubic, block / cube proxies, data / coefficient encoding, culling on / off) side by side with a flying-edges
  marching cubes mesh and VTK's GPU isosurface ray caster of the same data.
* ``large_terrain``: a 3601 x 3601 terrain (an SRTM tile): construction s, program + first frame s, frame ms,
  peak MB (own process); ``cold_start``: seconds from a new process to the models and the first picture.
* ``terrain``: the terrain ray caster on 65x65 .. 1025x1025 grids in one full-screen view, with the
  min/max hierarchy on and off (the hierarchical equivalent of the front-to-back occlusion sets of [Reis2008, sec. VII]).
* ``profile``: where a full-screen C1 terrain frame's time goes (``bench_profile.py``): the full program, shading
  replaced by a constant, the hierarchy walk alone and a reference ray march, in fragments/s and per llvmpipe
  thread (new processes at ``LP_NUM_THREADS=1`` and ``2``), with the per-fragment work counters of a debug build;
  and the terrain and isosurface programs' previous builds against the current ones, full-screen frames in one
  process, with the ratios today / new (``bench_speedup.py``).
* ``mesh_guided``: the mesh-guided terrain program (``proxy="mesh"``) against the box ray cast and a plain mesh of
  the same triangles, full-screen C1 terrain, one run (``bench_mesh_guided.py``).
* ``outofcore``: terrain and volume splines built tile by tile on dask and written to zarr
  (``bench_outofcore.py``): wall time, tiles/s at 1 and 2 workers, disk and peak memory of a fresh process.
* ``nurbs_files``: many-face CAD models (real STEP/IGES files when ``../shared/data/nurbs`` is there, synthetic
  ones always) from the file to the first frame, stage by stage, in fresh processes (``bench_nurbs_files.py``).
* ``read_dem``: a 3000 x 3000 USGS ASCII DEM read by ``read_heights`` beside GDAL's USGSDEM driver and the same
  heights as GeoTIFF (``bench_read_dem.py``; 800 x 800 with ``--quick``).
* ``import``: seconds of ``import splinevis`` and of the first ``Plotter(off_screen=True)`` in new processes, the
  development install beside the wheel with only the core dependencies (``bench_import.py``).

Each configuration is warmed up (first frame compiles shaders), then timed ``repeats`` times with the
render window's Render() + WaitForCompletion(); min and median are reported. Ratios are taken against
measurements from the same run.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
from pathlib import Path

import numpy as np

WINDOW = (800, 600)


def _time_frames(pl, repeats):
    from splinevis.analysis.timing import frame_times

    return frame_times(pl, repeats)


def _scene(style=None, mesh=None):
    import pyvista as pv

    from splinevis.analytic import QuarticTrianglePatch
    from splinevis.plotting import Plotter
    from splinevis.studies.demo import CAMERA

    patch = QuarticTrianglePatch.demo()
    pl = Plotter(off_screen=True, window_size=WINDOW)
    if mesh is None:
        pl.add_spline(patch, **(style or {}))
    else:
        pts, tris = patch.triangulate(mesh)
        faces = np.c_[np.full(len(tris), 3), tris].ravel()
        pl.add_mesh(pv.PolyData(pts, faces), color="tan", smooth_shading=True)
    pl.camera_position = CAMERA
    pl.reset_camera_clipping_range()
    return pl


def bench_raycast_vs_mesh(repeats, quick):
    ks = [32, 100, 316] + ([] if quick else [1000])
    rows = []
    pl = _scene(dict(lights=1))
    r = _time_frames(pl, repeats)
    pl.close()
    rows.append({"renderer": "ray-cast quartic patch (per pixel)", "triangles": 0, **r})
    for k in ks:
        pl = _scene(mesh=k)
        r = _time_frames(pl, repeats)
        pl.close()
        rows.append({"renderer": f"PyVista mesh k={k}", "triangles": k * k, **r})
    base = rows[0]["median_ms"]
    for row in rows:
        row["ratio_to_raycast"] = row["median_ms"] / base
    return rows


def bench_effect_sets(repeats, quick):
    from splinevis.studies.demo import _checker, _sky

    sets = [
        ("unlit", dict(lights=0)),
        ("1 light", dict(lights=1)),
        ("4 lights", dict(lights=4)),
        ("4 lights + specular", dict(lights=4, specular=True)),
        ("colormap", dict(lights=1, colormap="viridis")),
        ("texture", dict(lights=1, texture=_checker())),
        ("environment", dict(lights=1, environment=_sky())),
        ("reflection lines", dict(lights=1, reflection_lines=10)),
        ("isophotes", dict(lights=1, isophotes=8)),
        ("normals", dict(output="normals")),
        ("curvature", dict(output="curvature")),
        ("everything", dict(lights=4, specular=True, colormap="viridis", environment=_sky(), reflection_lines=10,
                            isophotes=8)),
    ]
    if quick:
        sets = sets[:2] + sets[7:9]
    rows = []
    for name, style in sets:
        pl = _scene(style)
        r = _time_frames(pl, repeats)
        effects = sorted(pl._spline_actors[0].style.effect_set())
        pl.close()
        rows.append({"effect_set": name, "effects": effects, **r})
    base = rows[0]["median_ms"]
    for row in rows:
        row["ratio_to_unlit"] = row["median_ms"] / base
    return rows


def bench_terrain(repeats, quick):
    """Terrain ray casting: frame time vs grid size in one full-screen oblique view (the target is a
    1024x1024 grid within 3x the time of a 64x64 grid), and the min/max hierarchy on vs off."""
    from datasets_synthetic.dem_files import fractal_terrain
    from splinevis.plotting import Plotter
    from splinevis.terrain.model import TerrainSpline

    sizes = [65, 257] + ([] if quick else [1025])
    rows = []
    for n in sizes:
        z = fractal_terrain(n, seed=3) * 0.15
        t = TerrainSpline.from_heights(z, "C2", spacing=(1.0 / (n - 1), 1.0 / (n - 1)))
        for hierarchy in (True, False):
            if not hierarchy and n > 257:
                continue  # a cell-by-cell walk over 1024 cells per ray: minutes per frame
            pl = Plotter(off_screen=True, window_size=WINDOW)
            pl.add_spline(t, lights=1, program_options={"hierarchy": hierarchy})
            pl.camera_position = [(0.5, -0.35, 0.55), (0.5, 0.45, 0.0), (0, 0, 1)]
            pl.camera.clipping_range = (0.01, 10.0)
            r = _time_frames(pl, repeats)
            covered = float((pl.depth_buffer() < 1.0).mean())
            pl.close()
            rows.append({"grid": f"{n}x{n}", "patches": t.num_patches, "hierarchy": hierarchy,
                         "screen_covered": covered, **r})
    base = next(r["median_ms"] for r in rows if r["hierarchy"])
    for r in rows:
        r["ratio_to_smallest_grid"] = r["median_ms"] / base
    return rows


VOLUME_VIEWS = {"full": [(2.6, -2.2, 2.0), (0.0, 0.0, 0.0), (0, 0, 1)],
                "close-up": [(0.9, 0.7, 0.9), (0.3, 0.2, 0.3), (0, 0, 1)]}


def bench_volume(repeats, quick):
    """Volume isosurfaces: what each program choice costs per frame, against the users' tools (at most 3
    repeats: a spline frame takes seconds at 800x600 on llvmpipe)."""
    repeats = min(repeats, 3)
    from datasets_synthetic.volumes import marschner_lobb
    from splinevis.plotting import Plotter
    from splinevis.volume.baselines import add_vtk_isosurface, marching_cubes_mesh
    from splinevis.volume.model import VolumeSpline

    field = marschner_lobb()
    grid = field.sample(64)
    iso = field.isovalue
    splines = {s: VolumeSpline(grid, s) for s in ("quadratic", "cubic")}
    configs = [("marching cubes (flying edges, 1x)", None, {}), ("VTK ray caster (sample h/4)", None, {}),
               ("quadratic, blocks, data", "quadratic", {}), ("cubic, blocks, data", "cubic", {})]
    if not quick:
        configs += [("quadratic, cubes, data", "quadratic", {"proxy": "cubes"}),
                    ("quadratic, blocks, coefficients", "quadratic", {"encoding": "coefficients"}),
                    ("quadratic, blocks, no culling", "quadratic", {"culling": False})]
    rows = []
    for view, cam in VOLUME_VIEWS.items():
        for name, scheme, opts in configs:
            pl = Plotter(off_screen=True, window_size=WINDOW)
            opts = dict(opts)
            culling = opts.pop("culling", True)
            if scheme is not None:
                pl.add_isosurface(splines[scheme], iso, lights=1, culling=culling, program_options=opts)
            elif name.startswith("marching"):
                pl.add_mesh(marching_cubes_mesh(grid, iso, method="flying_edges"), color="tan", smooth_shading=True)
            else:
                add_vtk_isosurface(pl, grid, iso, sample_distance=grid.spacing[0] / 4)
            pl.camera_position = cam
            pl.camera.view_angle = 30
            pl.camera.clipping_range = (0.01, 10.0)
            r = _time_frames(pl, repeats)
            pl.close()
            rows.append({"view": view, "program": name, **r})
        base = next(r["median_ms"] for r in rows if r["view"] == view and r["program"].startswith("marching"))
        for r in rows:
            if r["view"] == view:
                r["ratio_to_mesh"] = r["median_ms"] / base
    return rows


def _section(lines, results, case, title, columns, row):
    """One markdown table per benchmark case present in ``results``: ``columns`` as (header, alignment) pairs,
    ``row(r)`` the cells of one result."""
    if case not in results:
        return
    lines.append(f"\n## {title}\n")
    lines.append("| " + " | ".join(h for h, _ in columns) + " |")
    lines.append("|" + "|".join("---:" if right else "---" for _, right in columns) + "|")
    lines.extend("| " + " | ".join(row(r)) + " |" for r in results[case])


def _markdown(results):
    lines = [f"# splinevis benchmarks\n\n{results['machine']}"]
    num, text = True, False
    _section(lines, results, "raycast_vs_mesh", f"Ray-cast patch vs PyVista meshes ({WINDOW[0]}x{WINDOW[1]}, AA off)",
             [("renderer", text), ("triangles", num), ("min ms", num), ("median ms", num), ("median / ray-cast", num)],
             lambda r: [r["renderer"], f"{r['triangles']:,}", f"{r['min_ms']:.1f}", f"{r['median_ms']:.1f}",
                        f"{r['ratio_to_raycast']:.2f}"])
    _section(lines, results, "effect_sets", "Effect sets on the ray-cast patch",
             [("effect set", text), ("compiled effects", text), ("min ms", num), ("median ms", num),
              ("median / unlit", num)],
             lambda r: [r["effect_set"], ", ".join(r["effects"]) or "-", f"{r['min_ms']:.1f}", f"{r['median_ms']:.1f}",
                        f"{r['ratio_to_unlit']:.2f}"])
    _section(lines, results, "large_terrain", "Large terrain (own process)",
             [("grid", text), ("patches", num), ("construction s", num), ("program + first frame s", num),
              ("frame median ms", num), ("covered", num), ("peak MB", num)],
             lambda r: [r["grid"], f"{r['patches']:,}", f"{r['construction_s']:.1f}",
                        f"{r['program_and_first_frame_s']:.1f}", f"{r['frame_median_ms']:.0f}",
                        f"{r['screen_covered']:.2f}", f"{r['peak_MB']:.0f}"])
    _section(lines, results, "cold_start", "Cold start (new process, median)",
             [("import s", num), ("C1 terrain 65^2 + quadratic and cubic volume 16^3 s", num),
              ("first terrain picture s", num)],
             lambda r: [f"{r['import_s']:.2f}", f"{r['models_s']:.2f}", f"{r['first_picture_s']:.2f}"])
    _section(lines, results, "terrain", "Terrain ray casting: grid size and hierarchy (same full-screen oblique view)",
             [("grid", text), ("patches", num), ("hierarchy", text), ("screen covered", num), ("min ms", num),
              ("median ms", num), ("median / 65x65", num)],
             lambda r: [r["grid"], f"{r['patches']:,}", "min/max quadtree" if r["hierarchy"] else "off (cell walk)",
                        f"{r['screen_covered']:.2f}", f"{r['min_ms']:.1f}", f"{r['median_ms']:.1f}",
                        f"{r['ratio_to_smallest_grid']:.2f}"])
    _section(lines, results, "volume", "Volume isosurfaces: Marschner-Lobb 64^3 (same data, same views)",
             [("view", text), ("program", text), ("min ms", num), ("median ms", num), ("median / marching cubes", num)],
             lambda r: [r["view"], r["program"], f"{r['min_ms']:.1f}", f"{r['median_ms']:.1f}",
                        f"{r['ratio_to_mesh']:.1f}"])
    if "profile" in results:
        from bench_profile import profile_markdown

        lines.append(profile_markdown(results["profile"]))
    if "mesh_guided" in results:
        from bench_mesh_guided import mesh_guided_markdown

        lines.append(mesh_guided_markdown(results["mesh_guided"]))
    if "outofcore" in results:
        from bench_outofcore import outofcore_markdown

        lines.append(outofcore_markdown(results["outofcore"]))
    if "nurbs_files" in results:
        from bench_nurbs_files import nurbs_files_markdown

        lines.append(nurbs_files_markdown(results["nurbs_files"]))
    if "read_dem" in results:
        from bench_read_dem import read_dem_markdown

        lines.append(read_dem_markdown(results["read_dem"]))
    if "import" in results:
        from bench_import import import_markdown

        lines.append(import_markdown(results["import"]))
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--quick", action="store_true", help="fewer configurations (smoke run)")
    ap.add_argument("--cases", nargs="+", default=None, help="run only these cases (default: all)")
    args = ap.parse_args(argv)
    from tqdm import tqdm

    from splinevis.gl.headless import gl_info

    info = gl_info()
    results = {"machine": f"{platform.node()} | {platform.processor() or platform.machine()} | {info['renderer']} | "
                          f"{info['window_class']} | Python {platform.python_version()}", "gl": info}
    from bench_import import bench_import
    from bench_mesh_guided import bench_mesh_guided
    from bench_nurbs_files import bench_nurbs_files
    from bench_outofcore import bench_outofcore
    from bench_profile import bench_profile
    from bench_read_dem import bench_read_dem
    from bench_scale import bench_cold_start, bench_large_terrain

    cases = [("raycast_vs_mesh", bench_raycast_vs_mesh), ("effect_sets", bench_effect_sets), ("terrain", bench_terrain),
             ("volume", bench_volume), ("large_terrain", bench_large_terrain), ("cold_start", bench_cold_start),
             ("profile", bench_profile), ("mesh_guided", bench_mesh_guided), ("outofcore", bench_outofcore),
             ("nurbs_files", bench_nurbs_files),
             ("read_dem", lambda repeats, quick: bench_read_dem(800 if quick else 3000, min(repeats, 3))),
             ("import", lambda repeats, quick: bench_import(3 if quick else repeats))]
    known = [name for name, _ in cases]
    if args.cases:
        unknown = sorted(set(args.cases) - set(known))
        if unknown:
            ap.error(f"unknown case(s) {', '.join(unknown)}; known: {', '.join(known)}")
        cases = [c for c in cases if c[0] in args.cases]
    for name, fn in tqdm(cases, desc="benchmarks"):
        results[name] = fn(args.repeats, args.quick)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps(results, indent=2))
    md = _markdown(results)
    (out / "results.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())

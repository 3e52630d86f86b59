"""The geometry-image study: smooth geometry images [Losasso2003] measured on this machine (Mesa llvmpipe, no
GPU) against what users have today.

* **(a) Subdivision time per level**: the GPU passes (:func:`splinevis.geometry_image.gpu.subdivide_gpu`, limit
  positions and normals, timed between two ``glFinish``, as the paper) against the numpy float64 twin
  (:func:`splinevis.geometry_image.subdivision.subdivide`) on 31 x 31 (the paper's Table 2 size, its numbers in
  columns labelled ``paper``) and 65 x 65 images; median of several runs after a warm-up (shader compilation
  excluded); also with the read-back of the results to host memory.
* **(b) Accuracy against triangles**: a star-shaped blob with known surface and normals, given as a mesh of
  5,120 triangles; the geometry image fitted to it (33 x 33 and 65 x 65) at levels 0..3 against the raw mesh and
  its Loop (MeshLab, VTK) and Catmull-Clark (MeshLab) subdivisions
  (:mod:`splinevis.studies.geometry_image_compare`), all measured where drawn: distance to the exact surface
  and the vertex normals' angle to the exact normals; the rows nearest in triangle count side by side.
* **(c) Preprocessing time per stage** (check, parametrization and its stages, sampling, fit, measure) for meshes
  of 5k to ~330k triangles, with the parametrization's stretch and the fit's distance to the mesh; the paper's
  10-27 minutes for 70k-200k faces in a ``paper`` column.
* **(d) Fairness**: the fairness weight against the distance to the input mesh, the normal error against the
  exact normals and the roughness of the control net.
* **(e) Level of detail**: continuous levels from the octahedron to level 3, triangles and distance to the
  exact surface; the largest vertex motion per 1/8 level (geomorphs: no pops).
* **(f) Displacement**: the distance of the limit points to the input mesh before and after a displacement
  map at each level.
* **(g) Real meshes** (:mod:`splinevis.studies.geometry_image_real`): the seven closed genus-0 meshes of the data
  folder beside the repository (``../shared/data/meshes``; absent: the section says so and is skipped), each
  built with ``n="auto"``: triangles in, the size chosen, stretch, distance to the input, folds, seconds per
  stage; at equal triangle counts the image at the drawn level 3 against MeshLab's Loop and Catmull-Clark
  subdivisions of the input (distance, normal error against the input's interpolated vertex normals, folds,
  time); a row of reflection-line renders per mesh (input, Loop, Catmull-Clark, image; one camera).
  ``quick`` skips it.
* Figures (:mod:`splinevis.studies.geometry_image_figures`): the pipeline (mesh, sphere, octahedron, image,
  smooth surface, reflection lines), error against triangles, fairness, levels of detail, and section (g)'s
  reflection lines.

Sections (a)-(f) take a few minutes, ``quick`` well under one; section (g) about 20 to 40 minutes more (seven
builds of 10k-100k triangles and subdivisions of up to 17 million triangles, up to 5 GB of memory).
"""

from __future__ import annotations

import os
import time
import warnings
from pathlib import Path

import numpy as np

from .report import log, md_table, paper_table, progress_bar, write_json

__all__ = ["run_geometry_image_study", "PAPER_TABLE2", "subdivision_times"]

#: [Losasso2003, Table 2]: subdividing a 31 x 31 geometry image, limit positions and normals included; ATI Radeon
#: 9800 (GPU) and an Intel P4 2.5 GHz (CPU, no SIMD). Milliseconds.
PAPER_TABLE2 = [{"level": 1, "gpu_ms": 0.93, "cpu_ms": 1.3}, {"level": 2, "gpu_ms": 1.30, "cpu_ms": 5.5},
                {"level": 3, "gpu_ms": 2.91, "cpu_ms": 22.8}, {"level": 4, "gpu_ms": 9.06, "cpu_ms": 90.7}]
PAPER_PREPROCESS = "10-27 min for 70k-200k faces, 3 GHz Pentium 4 [Losasso2003, sec. 4]"


def _settings(quick):
    if quick:
        return {"sizes": (31, 65), "levels": (1, 2, 3, 4), "repeats": 3, "input_level": 3, "images": (17, 33),
                "gi_levels": (0, 1, 2), "sub_steps": (1, 2), "pre_levels": (3, 4), "fairness": (0.0, 1e-2, 1.0),
                "fair_n": 33, "lod_n": 33}
    return {"sizes": (31, 65), "levels": (1, 2, 3, 4, 5), "repeats": 7, "input_level": 4, "images": (33, 65),
            "gi_levels": (0, 1, 2, 3), "sub_steps": (1, 2, 3), "pre_levels": (4, 5, 6, 7),
            "fairness": (0.0, 1e-3, 1e-2, 0.1, 1.0), "fair_n": 65, "lod_n": 65}


def _test_image(n):
    """A bumpy closed image of ``n x n`` samples (the octahedral sphere, stretched and perturbed)."""
    from ..geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere, symmetrize

    G = octahedral_to_sphere(image_uv(n)) * [2.0, 1.0, 0.7]
    G = G + 0.02 * np.random.default_rng(n).normal(size=G.shape)
    return apply_cut_constraint(symmetrize(G))


def subdivision_times(n: int, levels, repeats: int) -> list:
    """Rows ``{size, level, gpu_ms, gpu_readback_ms, numpy_ms, triangles}``: median milliseconds to subdivide an
    ``n x n`` image to each level with limit positions and normals (section a).

    >>> rows = subdivision_times(9, [1], 1)
    >>> rows[0]["level"], rows[0]["triangles"], rows[0]["gpu_ms"] > 0
    (1, 512, True)
    """
    from ..geometry_image.gpu import subdivide_gpu
    from ..geometry_image.subdivision import subdivide
    from ..gl.context import current

    G = _test_image(n)
    rows = []
    for k in levels:
        gpu, readback, cpu = [], [], []
        with current() as ctx:
            for r in range(repeats + 1):
                ctx.finish()
                t0 = time.perf_counter()
                textures = subdivide_gpu(G, k, readback=False)
                ctx.finish()
                t1 = time.perf_counter()
                for tex in textures:
                    tex.release()
                t2 = time.perf_counter()
                subdivide_gpu(G, k, readback=True)
                t3 = time.perf_counter()
                if r:  # the first run compiles the programs
                    gpu.append(t1 - t0)
                    readback.append(t3 - t2)
        for _ in range(repeats):
            t0 = time.perf_counter()
            subdivide(G, k)
            cpu.append(time.perf_counter() - t0)
        m = (n - 1) << k
        rows.append({"size": f"{n}x{n}", "level": k, "gpu_ms": 1e3 * float(np.median(gpu)),
                     "gpu_readback_ms": 1e3 * float(np.median(readback)), "numpy_ms": 1e3 * float(np.median(cpu)),
                     "triangles": 2 * m * m})
    for row in rows:
        row["numpy_over_gpu"] = row["numpy_ms"] / row["gpu_ms"]
        paper = next((p for p in PAPER_TABLE2 if p["level"] == row["level"]), None) if n == 31 else None
        if paper:
            row["paper_gpu_ms"], row["paper_cpu_ms"] = paper["gpu_ms"], paper["cpu_ms"]
    return rows


def _blob_truth():
    from datasets_synthetic.closed_meshes import star_blob_normals, star_blob_radius

    return (lambda d: star_blob_radius(d, 0.25)), (lambda X: star_blob_normals(X, 0.25))


def _accuracy(s, progress):
    """Section (b): rows of every method's drawn mesh against the exact blob."""
    import igl

    from datasets_synthetic.closed_meshes import star_blob

    from ..geometry_image.build import geometry_image_from_mesh
    from ..geometry_image.program import surface_arrays
    from ..geometry_image.subdivision import grid_faces
    from .geometry_image_compare import catmull_clark_meshlab, loop_meshlab, loop_vtk, mesh_rows, vertex_normals

    mesh = star_blob(level=s["input_level"])
    V, F = np.asarray(mesh.points, dtype=np.float64), mesh.faces.reshape(-1, 4)[:, 1:].astype(np.int64)
    rho, exact = _blob_truth()
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))

    def to_input(P):
        d = np.sqrt(igl.point_mesh_squared_distance(np.ascontiguousarray(P), V, F)[0]) / diag
        return {"to_input_max": float(d.max()), "to_input_rms": float(np.sqrt((d ** 2).mean()))}

    rows = [{"method": "input mesh", "step": 0, **mesh_rows(V, F, vertex_normals(V, F), rho, exact, diag),
             **to_input(V)}]
    for name, fn in progress_bar([("Loop (MeshLab)", loop_meshlab), ("Catmull-Clark (MeshLab)", catmull_clark_meshlab),
                                  ("Loop (VTK)", loop_vtk)], "geometry-image: subdivision", enabled=progress):
        for k in s["sub_steps"]:
            t0 = time.perf_counter()
            Vs, Fs = fn(V, F, k)
            rows.append({"method": name, "step": k, "seconds": time.perf_counter() - t0,
                         **mesh_rows(Vs, Fs, vertex_normals(Vs, Fs), rho, exact, diag), **to_input(Vs)})
    for n in progress_bar(s["images"], "geometry-image: fits", enabled=progress):
        image, report = geometry_image_from_mesh(mesh, n, measure=False)
        for k in s["gi_levels"]:
            P, N, _ = surface_arrays(image, k, backend="numpy")
            M = P.shape[0]
            rows.append({"method": f"geometry image {n}x{n}", "step": k,
                         **mesh_rows(P.reshape(-1, 3), grid_faces(M), N.reshape(-1, 3), rho, exact, diag),
                         **to_input(P.reshape(-1, 3))})
    return rows


def _side_by_side(rows):
    """For each geometry-image row, the other methods' rows nearest in triangle count (within 2x)."""
    gi = [r for r in rows if r["method"].startswith("geometry image")]
    others = [r for r in rows if not r["method"].startswith("geometry image")]
    out = []
    for r in gi:
        best = min(others, key=lambda o: abs(np.log(o["triangles"] / r["triangles"])))
        if abs(np.log(best["triangles"] / r["triangles"])) <= np.log(2.0):
            out.append({"geometry_image": f"{r['method']} level {r['step']}", "gi_triangles": r["triangles"],
                        "gi_distance_max": r["distance_max"], "gi_normal_rms": r["normal_rms_deg"],
                        "gi_normal_max": r["normal_max_deg"], "other": f"{best['method']} step {best['step']}",
                        "other_triangles": best["triangles"], "other_distance_max": best["distance_max"],
                        "other_normal_rms": best["normal_rms_deg"], "other_normal_max": best["normal_max_deg"]})
    return out


def _preprocess(s, progress):
    """Section (c): times per stage for growing meshes."""
    from datasets_synthetic.closed_meshes import bent_blob, star_blob

    from ..geometry_image.build import geometry_image_from_mesh

    rows = []
    cases = [("star blob", star_blob, lv) for lv in s["pre_levels"]] + [("bent blob", bent_blob, s["pre_levels"][-2])]
    for name, make, lv in progress_bar(cases, "geometry-image: preprocessing", enabled=progress):
        mesh = make(level=lv)
        t0 = time.perf_counter()
        with warnings.catch_warnings():  # the folded fraction is a column of the table
            warnings.simplefilter("ignore")
            _, report = geometry_image_from_mesh(mesh, 65, name=f"{name} level {lv}", progress=progress)
        total = time.perf_counter() - t0
        rows.append({"mesh": f"{name} (level {lv})", "triangles": report.triangles, "total_s": total,
                     **{f"{k.replace('/', '_')}_s": v for k, v in report.seconds.items()},
                     "stretch_l2": report.stretch.get("l2"), "stretch_max": report.stretch.get("l2_max"),
                     "flipped": report.stretch.get("flipped"), "folded": report.folded,
                     "hausdorff": report.distance.get("hausdorff"),
                     "rms": report.distance.get("rms"), "paper": PAPER_PREPROCESS})
    return rows


def _fairness(s, progress):
    """Section (d)."""
    from datasets_synthetic.closed_meshes import star_blob

    from ..geometry_image.build import geometry_image_from_mesh
    from ..geometry_image.measure import normal_angles
    from ..geometry_image.program import surface_arrays

    mesh = star_blob(level=s["input_level"])
    _, exact = _blob_truth()
    rows = []
    for lam in progress_bar(s["fairness"], "geometry-image: fairness", enabled=progress):
        image, report = geometry_image_from_mesh(mesh, s["fair_n"], fairness=lam)
        P, N, _ = surface_arrays(image, 1, backend="numpy")
        ang = normal_angles(N.reshape(-1, 3), exact(P.reshape(-1, 3)))
        rows.append({"fairness": lam, "hausdorff": report.distance["hausdorff"], "rms": report.distance["rms"],
                     "normal_rms_deg": ang["rms"], "normal_max_deg": ang["max"], "fit_rms": report.fit_rms})
    return rows


def _lod(s, progress):
    """Section (e): continuous levels from the octahedron to level 3, and (f) displacement per level."""
    import igl

    from datasets_synthetic.closed_meshes import star_blob

    from ..geometry_image.build import geometry_image_from_mesh
    from ..geometry_image.program import displacement_map, min_level, surface_arrays
    from ..geometry_image.subdivision import grid_faces, linear_subdivide
    from .geometry_image_compare import mesh_rows

    mesh = star_blob(level=s["input_level"])
    V, F = np.asarray(mesh.points, dtype=np.float64), mesh.faces.reshape(-1, 4)[:, 1:].astype(np.int64)
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    rho, exact = _blob_truth()
    image, _ = geometry_image_from_mesh(mesh, s["lod_n"], measure=False)
    lo = min_level(image.n)
    levels = np.arange(lo, 3 + 1e-9, 0.125)
    rows, prev = [], None
    for lv in progress_bar(levels, "geometry-image: levels", enabled=progress):
        P, N, _ = surface_arrays(image, float(lv), backend="numpy")
        row = {"level": float(lv), **mesh_rows(P.reshape(-1, 3), grid_faces(P.shape[0]), N.reshape(-1, 3), rho, exact,
                                               diag)}
        if not float(lv).is_integer():  # the geomorph's step from the previous 1/8, on this level's connectivity:
            if prev.shape != P.shape:  # after a whole level k, its points linearly subdivided
                prev = linear_subdivide(prev)
            row["motion_max"] = float(np.linalg.norm(P - prev, axis=-1).max()) / diag
        rows.append(row)
        prev = P
    for row in rows:  # the largest step within [k, k + 1) on the whole level's row
        if float(row["level"]).is_integer():
            steps = [r["motion_max"] for r in rows if "motion_max" in r and np.floor(r["level"]) == row["level"]]
            row["motion_per_eighth"] = max(steps) if steps else None
    displacement = []
    for k in range(0, 3):
        P = surface_arrays(image, k, backend="numpy")[0]
        d = displacement_map(image, mesh, k)
        Q = surface_arrays(image, k, displacement=d, backend="numpy")[0]
        before = np.sqrt(igl.point_mesh_squared_distance(np.ascontiguousarray(P.reshape(-1, 3)), V, F)[0]) / diag
        after = np.sqrt(igl.point_mesh_squared_distance(np.ascontiguousarray(Q.reshape(-1, 3)), V, F)[0]) / diag
        displacement.append({"level": k, "samples": int(P.shape[0] ** 2), "before_max": float(before.max()),
                             "after_max": float(after.max()), "before_rms": float(np.sqrt((before ** 2).mean())),
                             "after_rms": float(np.sqrt((after ** 2).mean())), "d_max": float(np.abs(d).max()) / diag})
    return rows, displacement, image


def _markdown(result) -> str:
    q = " (quick)" if result["quick"] else ""
    md = [f"# Geometry-image study{q}\n\nMachine: {result['machine']['cpus']} CPUs, Mesa llvmpipe (no GPU). "
          f"Distances in units of the input mesh's bounding-box diagonal; normals in degrees.\n"]
    md.append("\n## (a) Subdivision time per level (limit positions and normals)\n\n")
    md.append(md_table(result["subdivision"], [
        ("image", "size", "s"), ("level", "level", "s"), ("triangles", "triangles", "int"),
        ("GPU passes ms", "gpu_ms", "f2"), ("GPU + read-back ms", "gpu_readback_ms", "f2"),
        ("numpy twin ms", "numpy_ms", "f2"), ("numpy / GPU", "numpy_over_gpu", "f2"),
        ("paper GPU ms", "paper_gpu_ms", "f2"), ("paper CPU ms", "paper_cpu_ms", "f2")]))
    md.append("\n" + paper_table("[Losasso2003, Table 2], 31x31, ATI Radeon 9800 / Intel P4 2.5 GHz", PAPER_TABLE2,
                                 [("level", "level", "s"), ("GPU ms", "gpu_ms", "f2"), ("CPU ms", "cpu_ms", "f2")]))
    md.append("\n## (b) Accuracy against triangles: star blob given as a mesh of "
              f"{result['accuracy'][0]['triangles']:,} triangles\n\n")
    md.append(md_table(result["accuracy"], [
        ("method", "method", "s"), ("step/level", "step", "s"), ("triangles", "triangles", "int"),
        ("dist. max", "distance_max", "e"), ("dist. RMS", "distance_rms", "e"), ("normal max", "normal_max_deg", "f2"),
        ("normal RMS", "normal_rms_deg", "f2"), ("to input max", "to_input_max", "e")]))
    md.append("\nNearest in triangles (within 2x):\n\n")
    md.append(md_table(result["side_by_side"], [
        ("geometry image", "geometry_image", "s"), ("triangles", "gi_triangles", "int"),
        ("dist. max", "gi_distance_max", "e"), ("normal RMS", "gi_normal_rms", "f2"),
        ("normal max", "gi_normal_max", "f2"), ("other", "other", "s"), ("triangles ", "other_triangles", "int"),
        ("dist. max ", "other_distance_max", "e"), ("normal RMS ", "other_normal_rms", "f2"),
        ("normal max ", "other_normal_max", "f2")]))
    md.append("\n## (c) Preprocessing time per stage (65x65 image)\n\n")
    md.append(md_table(result["preprocess"], [
        ("mesh", "mesh", "s"), ("triangles", "triangles", "int"), ("check s", "check_s", "f2"),
        ("parametrize s", "parametrize_s", "f2"), ("sample s", "sample_s", "f2"), ("fit s", "fit_s", "f2"),
        ("measure s", "measure_s", "f2"), ("total s", "total_s", "f1"), ("stretch L2", "stretch_l2", "f2"),
        ("stretch max", "stretch_max", "f2"), ("flipped", "flipped", "s"), ("folded", "folded", "e"),
        ("Hausdorff", "hausdorff", "e"),
        ("paper", "paper", "s")]))
    md.append("\n## (d) Fairness (distance to the input mesh, normals against the exact blob at level 1)\n\n")
    md.append(md_table(result["fairness"], [
        ("fairness", "fairness", "s"), ("Hausdorff", "hausdorff", "e"), ("RMS", "rms", "e"),
        ("normal RMS", "normal_rms_deg", "f2"), ("normal max", "normal_max_deg", "f2"), ("fit RMS", "fit_rms", "e")]))
    md.append("\n## (e) Continuous level of detail (every whole level; the JSON has every 1/8)\n\n")
    md.append(md_table([r for r in result["lod"] if float(r["level"]).is_integer()], [
        ("level", "level", "f1"), ("triangles", "triangles", "int"), ("dist. max", "distance_max", "e"),
        ("dist. RMS", "distance_rms", "e"), ("normal RMS", "normal_rms_deg", "f2"),
        ("largest vertex step per 1/8 level up to the next", "motion_per_eighth", "e")]))
    md.append("\nThe geomorph moves every vertex on a straight line from its place on the coarser level's mesh to the "
              "finer level's: the steps per 1/8 level are equal, 1/8 of the largest difference between the two "
              "meshes (no pops).\n")
    md.append("\n## (f) Displacement: distance of the limit points to the input mesh\n\n")
    md.append(md_table(result["displacement"], [
        ("level", "level", "s"), ("samples", "samples", "int"), ("before max", "before_max", "e"),
        ("after max", "after_max", "e"), ("before RMS", "before_rms", "e"), ("after RMS", "after_rms", "e")]))
    if "real" in result:
        from .geometry_image_real import real_mesh_markdown

        md.append(real_mesh_markdown(result["real"]))
    return "".join(md)


def run_geometry_image_study(out_dir, *, quick=False, progress=True) -> dict:
    """Run the study; returns the dict also written to ``out_dir/geometry-image.json`` (plus ``geometry-image.md``
    and the figures of :mod:`splinevis.studies.geometry_image_figures`)."""
    from .geometry_image_figures import accuracy_figure, fairness_figure, lod_figure, pipeline_figure

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    s = _settings(quick)
    t0 = time.perf_counter()
    result = {"quick": quick, "machine": {"cpus": os.cpu_count(),
                                          "loadavg_start": [round(x, 2) for x in os.getloadavg()]}}
    log("geometry-image", "(a) subdivision time per level")
    result["subdivision"] = []
    for n in s["sizes"]:
        result["subdivision"] += subdivision_times(n, s["levels"], s["repeats"])
    log("geometry-image", "(b) accuracy against triangles")
    result["accuracy"] = _accuracy(s, progress)
    result["side_by_side"] = _side_by_side(result["accuracy"])
    log("geometry-image", "(c) preprocessing")
    result["preprocess"] = _preprocess(s, progress)
    log("geometry-image", "(d) fairness")
    result["fairness"] = _fairness(s, progress)
    log("geometry-image", "(e) levels of detail, (f) displacement")
    result["lod"], result["displacement"], image = _lod(s, progress)
    if quick:
        result["real"] = {"available": None, "skipped": True,
                          "note": "quick runs skip the real meshes (the full run builds all seven)."}
    else:
        from .geometry_image_real import real_mesh_section

        log("geometry-image", "(g) real meshes")
        result["real"] = real_mesh_section(out, progress=progress)
    log("geometry-image", "figures")
    result["figures"] = [p.name for p in (pipeline_figure(out / "geometry-image_pipeline.png", quick=quick),
                                          accuracy_figure(out / "geometry-image_accuracy.png", result["accuracy"]),
                                          fairness_figure(out / "geometry-image_fairness.png", result["fairness"]),
                                          lod_figure(out / "geometry-image_lod.png", image, result["lod"]))]
    result["figures"] += result["real"].get("figures", [])
    result["seconds"] = time.perf_counter() - t0
    (out / "geometry-image.md").write_text(_markdown(result))
    write_json(out / "geometry-image.json", result)
    return result

"""The terrain study (``splinevis study terrain --out DIR [--quick]``): what accuracy costs in time.

Writes ``DIR/terrain.json`` and figures:

* ``accuracy_table.md`` -- relative RMS and max errors on Franke's function per scheme and data size over
  >= 1e5 random sites ([Reis2008, Table I]; the paper's legible values as a labelled column "paper");
* ``comparison_normals_shading_lines.png`` -- colour-coded normals, shading and reflection lines for
  linear vs C0/C1/C2 at the same data count, and a linear mesh with 25x the data ([Reis2008, Figs. 14-16]);
* ``pareto.png`` + ``pareto.md`` -- per-pixel normal-angle error against the analytic surface vs frame
  time, for PyVista meshes from coarse to millions of triangles and for every spline scheme at root
  iteration counts 1..6; where the spline becomes cheaper than a mesh of the same accuracy;
* ``throughput.md`` -- construction throughput (patches per second) per scheme on a 1024x1024 grid;
* ``scaling.md`` -- frame time of a 1024x1024 vs a 64x64 grid in the same full-screen oblique view.

Accuracy of what is *shown*: normal errors are computed with the float64 twins of the programs (the
spline ray caster at the same iteration count, the mesh's interpolated vertex normals at its exact
ray hit), on a random subset of pixels; the tests prove the GPU matches these twins per pixel. Frame
times are measured on the GPU (llvmpipe here), anti-aliasing off, min and median of repeated frames.

Tables, JSON, timing rows and figures are written with the helpers of :mod:`splinevis.studies.report`.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from .report import error_summary, md_table, paper_columns, progress_bar, pyplot, save_figure, timed, write_json

__all__ = ["run_terrain_study", "accuracy_table", "accuracy_orders", "write_accuracy", "PAPER_TABLE_I"]

WINDOW = (800, 600)
CAMERA = [(-0.35, -0.75, 1.55), (0.5, 0.48, 0.25), (0.0, 0.0, 1.0)]

#: [Reis2008, Table I], row "144 data points" (the only row fully legible in the text extraction):
#: (relative RMS, relative max) per method. Shown only in the column labelled "paper".
PAPER_TABLE_I = {
    ("C2", 144): (7.9e-3, 2.9e-2),
    ("C1", 144): (3.3e-3, 2.2e-2),
    ("C0", 144): (2.4e-3, 2.2e-2),
    ("linear", 144): (5.5e-3, 2.7e-2),
}


def _franke():
    from datasets_synthetic.franke import franke, franke_gradient

    return franke, franke_gradient


def franke_terrain(n: int, scheme: str):
    """Spline of Franke's function sampled on an n x n grid over [0, 1]^2."""
    from ..terrain.model import TerrainSpline

    franke, _ = _franke()
    t = np.linspace(0.0, 1.0, n)
    x, y = np.meshgrid(t, t, indexing="xy")  # rows = y
    z = franke(x, y)
    return TerrainSpline.from_heights(z, scheme, spacing=(1.0 / (n - 1), 1.0 / (n - 1)), origin=(0.0, 0.0))


ACCURACY_SCHEMES = ("linear", "C0", "C1", "C2", "C2-cubic", "C2-interp")

#: The inner region of the accuracy table: sites at least this far (in [0, 1] units) from the boundary.
INNER_MARGIN = 0.25


def accuracy_table(sizes=(13, 25, 49, 97), schemes=ACCURACY_SCHEMES, sites=100_000, seed=0):
    """Relative errors of values and gradients over random sites in [0,1]^2, in the full square and in the inner
    square ``[0.25, 0.75]^2``: values relative to the max data amplitude, gradients (physical units) relative to
    the largest gradient of Franke's function at the sites.

    Keys per row: ``rms_rel``, ``max_rel`` (values, full), ``inner_max_rel`` (values, inner), ``grad_max_rel``,
    ``grad_rms_rel`` (gradients, full), ``inner_grad_max_rel`` (gradients, inner), and the paper's numbers.

    Examples
    --------
    13x13 samples of Franke's function, beside the numbers of the paper's Table I:

    >>> from splinevis.studies.terrain import accuracy_table
    >>> rows = accuracy_table(sizes=(13,), schemes=("linear", "C1"), sites=1000)
    >>> [(r["scheme"], r["patches"], r["paper_rms_rel"]) for r in rows]
    [('linear', 288, 0.0055), ('C1', 288, 0.0033)]
    >>> rows[1]["rms_rel"] < rows[0]["rms_rel"]  # the C1 quartic beats the linear mesh
    True
    """
    franke, franke_gradient = _franke()
    rng = np.random.default_rng(seed)
    xy = rng.random((sites, 2))
    exact = franke(xy[:, 0], xy[:, 1])
    exact_g = franke_gradient(xy[:, 0], xy[:, 1])
    inner = np.all((xy >= INNER_MARGIN) & (xy <= 1.0 - INNER_MARGIN), axis=1)
    gamp = float(np.linalg.norm(exact_g, axis=-1).max())
    rows = []
    for n in sizes:
        amp = float(np.abs(franke(*np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n)))).max())
        for scheme in schemes:
            terrain = franke_terrain(n, scheme)
            err = terrain.evaluate(xy[:, 0], xy[:, 1]) - exact
            gerr = np.linalg.norm(terrain.gradient(xy[:, 0], xy[:, 1]) - exact_g, axis=-1)
            paper = PAPER_TABLE_I.get((scheme, (n - 1) ** 2))  # the paper counts 144 = 12^2 for 13x13 samples
            rows.append({
                "scheme": scheme, "grid": f"{n}x{n}", "n": n, "data_points": n * n, "patches": terrain.num_patches,
                "rms_rel": float(np.sqrt(np.mean(err ** 2)) / amp), "max_rel": float(np.abs(err).max() / amp),
                "inner_max_rel": float(np.abs(err[inner]).max() / amp),
                "grad_rms_rel": float(np.sqrt(np.mean(gerr ** 2)) / gamp), "grad_max_rel": float(gerr.max() / gamp),
                "inner_grad_max_rel": float(gerr[inner].max() / gamp),
                "paper_rms_rel": paper[0] if paper else None, "paper_max_rel": paper[1] if paper else None,
            })
    return rows


_ORDER_KEYS = ("max_rel", "inner_max_rel", "grad_max_rel", "inner_grad_max_rel")


def accuracy_orders(rows):
    """Observed orders ``log2(e_n / e_2n')`` between consecutive sizes of :func:`accuracy_table` (sizes
    ``2^k + 1``, so h halves), and each scheme's error ratios to ``linear`` and (when in the rows) to ``C2`` at
    the same size.

    Returns rows ``{"scheme", "grids", "order_max_rel", "order_inner_max_rel", ...}`` and
    ``{"scheme", "grid", "vs_linear_max_rel", ..., "vs_C2_max_rel", ...}``.

    Examples
    --------
    >>> orders, ratios = accuracy_orders(accuracy_table(sizes=(17, 33), schemes=("linear",), sites=2000))
    >>> round(orders[0]["order_max_rel"], 1), ratios[0]["vs_linear_max_rel"]
    (1.9, 1.0)
    """
    orders, ratios = [], []
    by = {(r["scheme"], r["n"]): r for r in rows}
    schemes = list(dict.fromkeys(r["scheme"] for r in rows))
    sizes = sorted({r["n"] for r in rows})
    for s in schemes:
        for a, b in zip(sizes, sizes[1:]):
            if (s, a) in by and (s, b) in by:
                orders.append({"scheme": s, "grids": f"{a} -> {b}",
                               **{f"order_{k}": float(np.log(by[s, a][k] / by[s, b][k]) / np.log((b - 1) / (a - 1)))
                                  for k in _ORDER_KEYS}})
        for n in sizes:
            if (s, n) in by and ("linear", n) in by:
                ratios.append({"scheme": s, "grid": f"{n}x{n}",
                               **{f"vs_{base}_{k}": by[s, n][k] / by[base, n][k]
                                  for base in ("linear", "C2") if (base, n) in by for k in _ORDER_KEYS}})
    return orders, ratios


def _normal_angles(n_render, n_true):
    a = n_render / np.linalg.norm(n_render, axis=-1, keepdims=True)
    b = n_true / np.linalg.norm(n_true, axis=-1, keepdims=True)
    return np.degrees(np.arccos(np.clip(np.einsum("...i,...i->...", a, b), -1.0, 1.0)))


def _true_normals(points):
    _, grad = _franke()
    g = grad(points[:, 0], points[:, 1])
    return np.c_[-g, np.ones(len(g))]


def _camera_rays(pixels, seed=1):
    """The study camera's rays through a random subset of pixels (float64)."""
    from ..gl.camera import pixel_rays
    from ..plotting import Plotter

    pl = Plotter(off_screen=True, window_size=WINDOW)
    from ..analytic import QuarticTrianglePatch

    pl.add_spline(QuarticTrianglePatch.demo())  # any actor; only the camera matters
    pl.camera_position = CAMERA
    pl.camera.clipping_range = (0.05, 10.0)
    matrix = pl.camera_matrix()
    pl.close()
    o, d = pixel_rays(matrix, *WINDOW)
    rng = np.random.default_rng(seed)
    pick = rng.choice(o.shape[0] * o.shape[1], size=pixels, replace=False)
    return o.reshape(-1, 3)[pick], d.reshape(-1, 3)[pick]


def spline_normal_error(terrain, o, d, iterations):
    """Normal-angle errors (degrees) the ray-cast spline shows at the given iteration count."""
    from ..programs import program_for

    hits = program_for(terrain).raycast(terrain, o, d, method="bracketed", iterations=iterations)
    h = hits.hit
    return _normal_angles(hits.normals[h], _true_normals(hits.points[h]))


def mesh_normal_error(n, o, d):
    """Normal-angle errors (degrees) of a PyVista mesh of Franke's function with n x n vertices, smooth
    shading: the pixel shows the barycentric interpolation of the vertex normals (VTK averages the unit
    normals of the faces around a vertex) at the ray's hit on the triangles."""
    from ..programs import program_for
    from ..terrain.model import cell_barycentric

    terrain = franke_terrain(n, "linear")
    franke, _ = _franke()
    t = np.linspace(0, 1, n)
    x, y = np.meshgrid(t, t, indexing="xy")
    z = franke(x, y)
    h = 1.0 / (n - 1)
    # unit face normals of T0 = [(i,j),(i+1,j),(i+1,j+1)] and T1 = [(i,j),(i+1,j+1),(i,j+1)]
    z00, z10, z11, z01 = z[:-1, :-1], z[:-1, 1:], z[1:, 1:], z[1:, :-1]
    n0 = np.stack([-(z10 - z00) / h, -(z11 - z10) / h, np.ones_like(z00)], -1)
    n1 = np.stack([-(z11 - z01) / h, -(z01 - z00) / h, np.ones_like(z00)], -1)
    n0 /= np.linalg.norm(n0, axis=-1, keepdims=True)
    n1 /= np.linalg.norm(n1, axis=-1, keepdims=True)
    vn = np.zeros((n, n, 3))
    for face, corners in ((n0, ((0, 0), (0, 1), (1, 1))), (n1, ((0, 0), (1, 1), (1, 0)))):
        for dj, di in corners:
            vn[dj: dj + n - 1, di: di + n - 1] += face
    vn /= np.linalg.norm(vn, axis=-1, keepdims=True)
    hits = program_for(terrain).raycast(terrain, o, d)
    hit = hits.hit
    p = hits.points[hit]
    u, v = p[:, 0] / h, p[:, 1] / h
    i = np.clip(np.floor(u).astype(int), 0, n - 2)
    j = np.clip(np.floor(v).astype(int), 0, n - 2)
    lu, lv = u - i, v - j
    tri = (lv > lu).astype(int)
    lam = cell_barycentric(lu, lv, tri)
    a = vn[j, i]
    c = vn[j + 1, i + 1]
    b = np.where(tri[:, None] == 0, vn[j, i + 1], vn[j + 1, i])  # T0: (i+1, j); T1: (i, j+1)
    shown = lam[:, :1] * a + lam[:, 1:2] * np.where(tri[:, None] == 0, b, c) + lam[:, 2:] * np.where(tri[:, None] == 0, c, b)
    return _normal_angles(shown, _true_normals(p))


def _scene_spline(terrain, iterations, style=None, program_options=None):
    from ..plotting import Plotter

    pl = Plotter(off_screen=True, window_size=WINDOW)
    pl.add_spline(terrain, newton_iterations=iterations, program_options=program_options or {},
                  **(style or dict(lights=1)))
    pl.camera_position = CAMERA
    pl.camera.clipping_range = (0.05, 10.0)
    return pl


def _scene_mesh(n):
    import pyvista as pv

    from ..plotting import Plotter

    franke, _ = _franke()
    t = np.linspace(0, 1, n)
    x, y = np.meshgrid(t, t, indexing="xy")
    grid = pv.StructuredGrid(x, y, franke(x, y)).extract_surface(algorithm='dataset_surface').triangulate()
    pl = Plotter(off_screen=True, window_size=WINDOW)
    pl.add_mesh(grid, color="tan", smooth_shading=True)
    pl.camera_position = CAMERA
    pl.camera.clipping_range = (0.05, 10.0)
    return pl, grid.n_cells


def accuracy_vs_time(*, quick=False, repeats=5, pixels=20_000, progress=True):
    """Rows (kind, config, triangles/patches, frame ms, normal error median/p95 in degrees)."""
    o, d = _camera_rays(pixels)
    mesh_sizes = [17, 33, 65, 129, 257] + ([] if quick else [513, 1025])
    schemes = ["linear", "C0", "C1", "C2", "C2-cubic"]
    data_n = 25 if quick else 33
    iterations = [1, 2, 3, 4, 6] if quick else [1, 2, 3, 4, 5, 6]
    jobs = ([("mesh", n, None) for n in mesh_sizes] + [("spline", s, k) for s in schemes for k in iterations]
            + [("mesh-guided", s, None) for s in schemes])
    rows = []
    terrains = {s: franke_terrain(data_n, s) for s in schemes}
    for kind, a, b in progress_bar(jobs, "accuracy vs time", enabled=progress):
        if kind == "mesh":
            pl, ntri = _scene_mesh(a)
            frames = timed(pl, repeats, with_repeats=False)
            pl.close()
            err = mesh_normal_error(a, o, d)
            rows.append({"kind": "PyVista mesh", "config": f"{a}x{a} vertices", "elements": int(ntri),
                         **frames, **_stats(err)})
        elif kind == "mesh-guided":
            # the same picture as the box ray cast (the hard cases agree with the twin): the twin's error, its time
            pl = _scene_spline(terrains[a], None, program_options={"proxy": "mesh"})
            frames = timed(pl, repeats, with_repeats=False)
            pl.close()
            err = spline_normal_error(terrains[a], o, d, 8)
            rows.append({"kind": f"mesh-guided {a}", "config": f"{data_n}x{data_n} data, proxy='mesh'",
                         "elements": terrains[a].num_patches, "iterations": None, **frames, **_stats(err)})
        else:
            pl = _scene_spline(terrains[a], b)
            frames = timed(pl, repeats, with_repeats=False)
            pl.close()
            err = spline_normal_error(terrains[a], o, d, b)
            rows.append({"kind": f"spline {a}", "config": f"{data_n}x{data_n} data, {b} iterations",
                         "elements": terrains[a].num_patches, "iterations": b, **frames, **_stats(err)})
    return rows


def _stats(err):
    return {**error_summary(err, "normal", "deg"), "pixels": int(err.size)}


def crossover(rows):
    """For each spline row: the mesh frame time needed for the same median normal error (log-log
    interpolation along the mesh curve), and whether the spline is cheaper."""
    mesh = sorted((r for r in rows if r["kind"] == "PyVista mesh"), key=lambda r: -r["normal_err_median_deg"])
    errs = np.log([r["normal_err_median_deg"] for r in mesh])
    times = np.log([r["frame_median_ms"] for r in mesh])
    tris = np.log([r["elements"] for r in mesh])
    out = []
    for r in rows:
        if r["kind"] == "PyVista mesh":
            continue
        e = math.log(r["normal_err_median_deg"])
        if e > errs[0]:
            need = None  # even the coarsest mesh is more accurate
        elif e < errs[-1]:
            need = "beyond"  # finer than the finest mesh measured
        else:
            need = (float(np.exp(np.interp(-e, -errs, times))), float(np.exp(np.interp(-e, -errs, tris))))
        out.append({"spline": r["kind"], "iterations": r.get("iterations"), "spline_ms": r["frame_median_ms"],
                    "normal_err_median_deg": r["normal_err_median_deg"],
                    "mesh_ms_for_same_error": None if need in (None, "beyond") else need[0],
                    "mesh_triangles_for_same_error": None if need in (None, "beyond") else need[1],
                    "note": {None: "coarsest mesh already as accurate", "beyond": "more accurate than the finest mesh"}.get(need, "") if not isinstance(need, tuple) else "",
                    "spline_cheaper": (isinstance(need, tuple) and r["frame_median_ms"] < need[0]) or need == "beyond"})
    return out


def construction_throughput(n=1025, schemes=("linear", "C0", "C1", "C2", "C2-cubic"), repeats=3):
    from ..terrain.schemes import terrain_coefficients

    rng = np.random.default_rng(0)
    z = rng.standard_normal((n, n))
    rows = []
    for s in schemes:
        best = math.inf
        patches = 0
        for _ in range(repeats):
            t0 = time.perf_counter()
            coef, _info = terrain_coefficients(z, s)
            best = min(best, time.perf_counter() - t0)
            patches = coef.shape[0] * coef.shape[1] * 2
        rows.append({"scheme": s, "grid": f"{n}x{n}", "patches": int(patches), "seconds": best,
                     "patches_per_s": patches / best})
    return rows


def scaling(repeats=5, sizes=(65, 1025)):
    """Frame time of the spline of an n x n grid in the same full-screen oblique view."""
    from ..plotting import Plotter
    from ..terrain.model import TerrainSpline
    from datasets_synthetic.dem_files import fractal_terrain

    rows = []
    for n in sizes:
        z = fractal_terrain(n, seed=3) * 0.15
        t = TerrainSpline.from_heights(z, "C2", spacing=(1.0 / (n - 1), 1.0 / (n - 1)))
        pl = Plotter(off_screen=True, window_size=WINDOW)
        pl.add_spline(t, lights=1)
        pl.camera_position = [(0.5, -0.35, 0.55), (0.5, 0.45, 0.0), (0, 0, 1)]
        pl.camera.clipping_range = (0.01, 10.0)
        frames = timed(pl, repeats, with_repeats=False)
        covered = float((pl.depth_buffer() < 1.0).mean())
        pl.close()
        rows.append({"grid": f"{n}x{n}", "patches": t.num_patches, **frames, "screen_covered": covered})
    rows.append({"ratio_largest_to_smallest": rows[-1]["frame_median_ms"] / rows[0]["frame_median_ms"]})
    return rows


def comparison_figure(path, *, n=13, fine_factor=5):
    """Normals, shading and reflection lines for linear vs C0/C1/C2 at n x n data, and linear at
    (fine_factor (n-1) + 1)^2 data (fine_factor 5: 25x the cells, about 22x the samples) -- [Reis2008, Figs. 14-16]."""
    from ..plotting import Plotter

    plt = pyplot()

    columns = [("linear", n), ("C0", n), ("C1", n), ("C2", n), ("linear", fine_factor * (n - 1) + 1)]
    rows = [("normals", dict(output="normals")), ("shading", dict(lights=2, specular=True)),
            ("reflection lines", dict(lights=1, reflection_lines=14))]
    fig, axes = plt.subplots(len(rows), len(columns), figsize=(3.3 * len(columns), 2.7 * len(rows)))
    for ci, (scheme, m) in enumerate(columns):
        terrain = franke_terrain(m, scheme)
        for ri, (rname, style) in enumerate(rows):
            pl = Plotter(off_screen=True, window_size=(420, 330))
            pl.set_background("white")
            pl.add_spline(terrain, **style)
            pl.camera_position = CAMERA
            pl.camera.clipping_range = (0.05, 10.0)
            axes[ri, ci].imshow(pl.screenshot())
            pl.close()
            axes[ri, ci].set_axis_off()
            if ri == 0:
                axes[ri, ci].set_title(f"{scheme}, {m}x{m} data", fontsize=10)
        for ri, (rname, _) in enumerate(rows):
            axes[ri, 0].text(-0.05, 0.5, rname, transform=axes[ri, 0].transAxes, rotation=90, va="center", ha="right")
    save_figure(fig, path)


def pareto_figure(rows, path):
    """Median normal error against median frame time: the meshes as one curve, each spline scheme over its
    iteration counts, from :func:`accuracy_vs_time`."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 5.5))
    mesh = [r for r in rows if r["kind"] == "PyVista mesh"]
    ax.plot([r["frame_median_ms"] for r in mesh], [r["normal_err_median_deg"] for r in mesh], "k-o", label="PyVista mesh (smooth shading)")
    for r in mesh:
        ax.annotate(f"{r['elements'] / 1e3:.0f}k tri", (r["frame_median_ms"], r["normal_err_median_deg"]), fontsize=7,
                    xytext=(3, 3), textcoords="offset points")
    for kind in sorted({r["kind"] for r in rows if r["kind"].startswith("spline")}):
        rs = sorted((r for r in rows if r["kind"] == kind), key=lambda r: r["iterations"])
        ax.plot([r["frame_median_ms"] for r in rs], [r["normal_err_median_deg"] for r in rs], "-s", label=f"{kind} (1..6 iterations)")
    guided = [r for r in rows if r["kind"].startswith("mesh-guided")]
    if guided:
        ax.plot([r["frame_median_ms"] for r in guided], [r["normal_err_median_deg"] for r in guided], "r*", ms=11,
                label="mesh-guided ray cast (same spline, proxy='mesh')")
        for r in guided:
            ax.annotate(r["kind"].split()[-1], (r["frame_median_ms"], r["normal_err_median_deg"]), fontsize=7,
                        color="r", xytext=(4, -9), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"frame time, median ms ({WINDOW[0]}x{WINDOW[1]}, llvmpipe)")
    ax.set_ylabel("median per-pixel normal error vs Franke (degrees)")
    ax.set_title("Accuracy vs time: ray-cast splines vs triangle meshes")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path, dpi=110)


def _write_pareto(out, result):
    """From ``result["accuracy_vs_time"]``: the crossover rows (into ``result``), ``pareto.png`` and ``pareto.md``."""
    out = Path(out)
    result["crossover"] = crossover(result["accuracy_vs_time"])
    pareto_figure(result["accuracy_vs_time"], out / "pareto.png")
    (out / "pareto.md").write_text(
        "# Accuracy vs time\n\n" + md_table(
            result["accuracy_vs_time"],
            [("renderer", "kind", "s"), ("config", "config", "s"), ("triangles/patches", "elements", "int"),
             ("frame min ms", "frame_min_ms", "f1"), ("frame median ms", "frame_median_ms", "f1"),
             ("normal err median °", "normal_err_median_deg", "e"), ("p95 °", "normal_err_p95_deg", "e")])
        + "\n## Where the spline becomes cheaper\n\n" + md_table(
            result["crossover"],
            [("spline", "spline", "s"), ("iterations", "iterations", "s"), ("spline ms", "spline_ms", "f1"),
             ("normal err °", "normal_err_median_deg", "e"), ("mesh ms for same error", "mesh_ms_for_same_error", "f1"),
             ("mesh triangles for same error", "mesh_triangles_for_same_error", "int"), ("spline cheaper", "spline_cheaper", "s"),
             ("note", "note", "s")]))


def write_accuracy(out, result, sizes):
    """The accuracy table, its orders and ratios to linear: ``result["accuracy"]``, ``["accuracy_orders"]``,
    ``["accuracy_vs_linear"]`` and ``out/accuracy_table.md`` (``splinevis study terrain`` calls it; alone it
    takes a few seconds: ``write_accuracy(dir, {}, (13, 25, 49))``).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     result = {}
    ...     write_accuracy(d, result, (5, 9))
    ...     md = (Path(d) / "accuracy_table.md").read_text()
    >>> sorted(result), "C2-interp" in md
    (['accuracy', 'accuracy_orders', 'accuracy_vs_linear'], True)
    """
    out = Path(out)
    result["accuracy"] = accuracy_table(sizes=sizes, sites=100_000)
    result["accuracy_orders"], result["accuracy_vs_linear"] = accuracy_orders(result["accuracy"])
    err_cols = [("value max (inner)", "inner_max_rel", "e"), ("gradient max (full)", "grad_max_rel", "e"),
                ("gradient max (inner)", "inner_grad_max_rel", "e")]
    order_cols = [("value (full)", "order_max_rel", "f2"), ("value (inner)", "order_inner_max_rel", "f2"),
                  ("gradient (full)", "order_grad_max_rel", "f2"), ("gradient (inner)", "order_inner_grad_max_rel", "f2")]
    ratio_cols = [("value (full)", "vs_linear_max_rel", "e"), ("value (inner)", "vs_linear_inner_max_rel", "e"),
                  ("gradient (full)", "vs_linear_grad_max_rel", "e"), ("gradient (inner)", "vs_linear_inner_grad_max_rel", "e")]
    (out / "accuracy_table.md").write_text(
        "# Franke's function: relative errors over 100,000 random sites\n\n" + md_table(
            result["accuracy"],
            [("scheme", "scheme", "s"), ("grid", "grid", "s"), ("data", "data_points", "int"), ("patches", "patches", "int"),
             ("rms (rel)", "rms_rel", "e"), ("max (rel)", "max_rel", "e")] + err_cols
            + paper_columns([("rms", "paper_rms_rel", "e"), ("max", "paper_max_rel", "e")]))
        + "\n'paper' = [Reis2008, Table I] at 144 data points (12x12); our grids have n x n points with n = 4k+1 so the C0 "
          "scheme's 4x4 macro cells fit; the 13x13 row is the nearest size. Values relative to the largest |height|, "
          "gradients (physical units) to the largest |gradient| of Franke's function; inner = the sites in "
          f"[{INNER_MARGIN}, {1 - INNER_MARGIN}]^2, full = all of [0, 1]^2 (the boundary included).\n"
        + "\n## Observed orders (log2 of the max error's ratio from one grid to the next, h halved)\n\n"
        + md_table(result["accuracy_orders"], [("scheme", "scheme", "s"), ("grids", "grids", "s")] + order_cols)
        + "\n## Max error relative to linear interpolation on the same grid\n\n"
        + md_table(result["accuracy_vs_linear"], [("scheme", "scheme", "s"), ("grid", "grid", "s")] + ratio_cols)
        + "\n## Max error relative to the plain C2 box spline (data as coefficients) on the same grid\n\n"
        + md_table(result["accuracy_vs_linear"], [("scheme", "scheme", "s"), ("grid", "grid", "s")]
                   + [(t, k.replace("vs_linear", "vs_C2"), f) for t, k, f in ratio_cols]))


def run_terrain_study(out_dir, *, quick=False, progress=True) -> dict:
    """Run the study; returns the dict also written to ``out_dir/terrain.json``.

    Parameters
    ----------
    out_dir : str or Path
        Created if missing; receives ``terrain.json``, the markdown tables and the figures.
    quick : bool, optional
        Smaller sizes and fewer configurations (a few minutes).
    progress : bool, optional
        Progress bars on stderr.

    Returns
    -------
    dict
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    result = {"quick": quick}
    sizes = (13, 25, 49) if quick else (13, 25, 49, 97)
    write_accuracy(out, result, sizes)
    comparison_figure(out / "comparison_normals_shading_lines.png")
    result["accuracy_vs_time"] = accuracy_vs_time(quick=quick, progress=progress)
    _write_pareto(out, result)
    result["throughput"] = construction_throughput(n=257 if quick else 1025)
    (out / "throughput.md").write_text("# Construction throughput\n\n" + md_table(
        result["throughput"], [("scheme", "scheme", "s"), ("grid", "grid", "s"), ("patches", "patches", "int"),
                               ("seconds", "seconds", "f2"), ("patches/s", "patches_per_s", "e")]))
    result["scaling"] = scaling(sizes=(65, 257) if quick else (65, 1025))
    (out / "scaling.md").write_text("# Frame time vs grid size (same view)\n\n" + md_table(
        result["scaling"][:-1], [("grid", "grid", "s"), ("patches", "patches", "int"), ("frame min ms", "frame_min_ms", "f1"),
                                 ("frame median ms", "frame_median_ms", "f1"), ("screen covered", "screen_covered", "f2")])
        + f"\nratio largest / smallest: {result['scaling'][-1]['ratio_largest_to_smallest']:.2f}\n")
    rows, xs, profiles = cliff_overshoot()
    result["cliff"] = rows
    fig, ax = pyplot().subplots(figsize=(7, 4))
    for s, prof in profiles.items():
        ax.plot(xs, prof, label=s)
    ax.set_xlim(0.3, 0.7)
    ax.set_xlabel("x (cliff at x = 0.5, data 0 | 1 on a 17x17 grid)")
    ax.set_ylabel("spline height")
    ax.set_title("Step cliff: overshoot of each scheme")
    ax.legend()
    ax.grid(alpha=0.3)
    save_figure(fig, out / "cliff.png", dpi=110)
    (out / "cliff.md").write_text("# Step cliff (0 | 1)\n\n" + md_table(
        rows, [("scheme", "scheme", "s"), ("overshoot above 1", "overshoot", "e"), ("undershoot below 0", "undershoot", "e")]))
    write_json(out / "terrain.json", result)
    return result


def cliff_overshoot(n=17, schemes=("linear", "C0", "C1", "C2", "C2-cubic")):
    """A unit step cliff along x = 1/2 (heights 0 then 1): max overshoot above 1 and undershoot below 0
    of each scheme, sampled densely across the cliff. Returns rows and the profiles (for a figure)."""
    t = np.linspace(0.0, 1.0, n)
    x, y = np.meshgrid(t, t, indexing="xy")
    z = (x > 0.5).astype(np.float64)
    xs = np.linspace(0.0, 1.0, 2001)
    rows, profiles = [], {}
    from ..terrain.model import TerrainSpline

    for s in schemes:
        terr = TerrainSpline.from_heights(z, s, spacing=(1.0 / (n - 1), 1.0 / (n - 1)))
        prof = terr.evaluate(xs, np.full_like(xs, 0.5 + 0.3 / (n - 1)))
        grid = np.linspace(0.0, 1.0, 401)
        gx, gy = np.meshgrid(grid, grid)
        vals = terr.evaluate(gx.ravel(), gy.ravel())
        rows.append({"scheme": s, "overshoot": float(max(vals.max() - 1.0, 0.0)),
                     "undershoot": float(max(-vals.min(), 0.0))})
        profiles[s] = prof
    return rows, xs, profiles

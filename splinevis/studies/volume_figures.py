"""The volume study's figures: approximation errors against the grid spacing, accuracy against frame time
(the Pareto plot) and a side-by-side close-up of every method on Marschner-Lobb (see
:mod:`splinevis.studies.volume` for what each shows)."""

from __future__ import annotations

import math

import numpy as np

from .report import pyplot, save_figure
from .volume_accuracy import set_camera

__all__ = ["ML_CAMERA", "approximation_figure", "fidelity_figure", "pareto_figure", "side_by_side_figure"]

#: Close-up of Marschner-Lobb (side-by-side figure).
ML_CAMERA = [(0.55, -0.95, 0.75), (0.05, -0.05, -0.05), (0.0, 0.0, 1.0)]


def approximation_figure(rows, path):
    """Value and gradient error against h (log-log) per field and scheme, with the slope between the two
    finest grids, from :func:`splinevis.studies.volume_accuracy.approximation_rows`.

    Examples
    --------
    Rows need ``field``, ``scheme``, ``h``, ``value_max`` and ``gradient_max``; here made up, second
    order in the values and first order in the gradients:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from splinevis.studies.volume_figures import approximation_figure
    >>> rows = [{"field": "blob", "scheme": "trilinear", "h": h, "value_max": h ** 2, "gradient_max": h}
    ...         for h in (0.1, 0.05, 0.025)]
    >>> with tempfile.TemporaryDirectory() as d:
    ...     approximation_figure(rows, Path(d) / "approximation.png")
    ...     (Path(d) / "approximation.png").read_bytes()[1:4]
    b'PNG'
    """
    plt = pyplot()
    fields = sorted({r["field"] for r in rows})
    fig, axes = plt.subplots(1, 2 * len(fields), figsize=(4.2 * 2 * len(fields), 4))
    for fi, name in enumerate(fields):
        for ki, (key, label) in enumerate((("value_max", "max value error"), ("gradient_max", "max gradient error"))):
            ax = axes[2 * fi + ki]
            for s in ("trilinear", "quadratic", "cubic"):
                rs = [r for r in rows if r["field"] == name and r["scheme"] == s]
                if not rs:
                    continue
                h = [r["h"] for r in rs]
                e = [r[key] for r in rs]
                slope = math.log(e[-2] / e[-1]) / math.log(h[-2] / h[-1]) if len(rs) > 1 else float("nan")
                ax.loglog(h, e, "-o", label=f"{s} (slope {slope:.2f})")
            ax.set_xlabel("grid spacing h")
            ax.set_title(f"{name}: {label}", fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8, title="slope between the two finest", title_fontsize=7)
    save_figure(fig, path)


def fidelity_figure(rows, path):
    """Data fidelity at the finest grid: value RMS error and mean gradient angle of every method, per field and
    region (log-scale bars), from :func:`splinevis.studies.volume_accuracy.fidelity_rows`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> rows = [{"field": "ml", "region": "inner", "scheme": m, "n": 65, "value_rms": v, "angle_mean": a}
    ...         for m, v, a in (("trilinear", 1e-2, 3.0), ("quadratic+local/quadratic", 1e-3, 0.5))]
    >>> with tempfile.TemporaryDirectory() as d:
    ...     fidelity_figure(rows, Path(d) / "fidelity.png")
    ...     (Path(d) / "fidelity.png").read_bytes()[1:4]
    b'PNG'
    """
    plt = pyplot()
    panels = sorted({(r["field"], r["region"]) for r in rows}, key=lambda fr: (fr[0], fr[1] != "inner"))
    fig, axes = plt.subplots(2, len(panels), figsize=(3.9 * len(panels), 7.0), squeeze=False)
    for j, (field, region) in enumerate(panels):
        rs = [r for r in rows if r["field"] == field and r["region"] == region]
        n = max(r["n"] for r in rs)
        rs = [r for r in rs if r["n"] == n]
        names = [r["scheme"] for r in rs]
        base = {r["scheme"]: r for r in rs}
        for i, (key, label, ref) in enumerate((("value_rms", "value RMS error", "trilinear"),
                                                ("angle_mean", "mean gradient angle (deg)", "central-differences"))):
            ax = axes[i, j]
            vals = [r[key] for r in rs]
            colours = ["0.6" if nm in ("trilinear", "central-differences") else
                       ("tab:blue" if "+" not in nm else "tab:green") for nm in names]
            ax.barh(range(len(vals)), vals, color=colours)
            if ref in base:
                ax.axvline(base[ref][key], color="k", lw=0.8, ls="--")
            ax.set_xscale("log")
            ax.xaxis.set_minor_formatter(plt.NullFormatter())  # decade labels only: no overlapping minor labels
            ax.set_yticks(range(len(vals)))
            ax.set_yticklabels(names if j == 0 else [""] * len(names), fontsize=7)
            ax.invert_yaxis()
            ax.set_title(f"{field.replace('marschner_lobb', 'Marschner-Lobb')}, {region}, n = {n}\n{label}", fontsize=8)
            ax.grid(True, axis="x", which="both", alpha=0.3)
    fig.suptitle("grey: what VTK uses (dashed: its value); blue: the paper's splines; green: prefiltered", fontsize=9)
    save_figure(fig, path)


def _short(r):
    if r["method"].startswith("MC"):
        return f"{r['upsample']}x"
    if r["method"] == "VTK volume":
        return r["config"].replace("sample distance ", "")
    return (("" if r.get("proxy", "blocks") == "blocks" else "cubes ") + {"data": "D", "coefficients": "C"}.get(r["encoding"], "S") + "/"
            + r["roots"][:2] + ("" if r["iterations"] is None else str(r["iterations"])))


def pareto_figure(rows, setup, path):
    """Median normal error and coverage mismatch against median frame time, one series per method, from
    :func:`splinevis.studies.volume_accuracy.accuracy_vs_time`.

    Examples
    --------
    Two made-up rows (the keys the figure reads: ``method``, ``frame_median_ms``, the two errors and what
    labels a point) and the set-up they were measured in:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from splinevis.studies.volume_figures import pareto_figure
    >>> rows = [
    ...     {"method": "MC flying_edges", "upsample": 1, "frame_median_ms": 5.0, "normal_err_median_deg": 2.0,
    ...      "coverage_mismatch": 30},
    ...     {"method": "quadratic spline", "encoding": "data", "roots": "analytic", "iterations": None,
    ...      "frame_median_ms": 9.0, "normal_err_median_deg": 0.1, "coverage_mismatch": 0}]
    >>> setup = {"field": "torus", "grid": "24^3", "h": 2 / 23, "window": [200, 150]}
    >>> with tempfile.TemporaryDirectory() as d:
    ...     pareto_figure(rows, setup, Path(d) / "pareto.png")
    ...     (Path(d) / "pareto.png").read_bytes()[1:4]
    b'PNG'
    """
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(20, 5.8))
    styles = {"MC skimage": ("k", "o"), "MC flying_edges": ("0.5", "s"), "VTK volume": ("tab:green", "^"),
              "quadratic spline": ("tab:blue", "D"), "cubic spline": ("tab:red", "v")}
    # the prefiltered splines (method "quadratic spline (local prefilter, ...)"): one series each, lighter colours
    extra = {"quadratic": ["tab:cyan", "deepskyblue"], "cubic": ["tab:orange", "tab:purple", "tab:pink"]}
    for m in dict.fromkeys(r["method"] for r in rows):
        if m not in styles and m.split(" spline")[0] in extra and extra[m.split(" spline")[0]]:
            styles[m] = (extra[m.split(" spline")[0]].pop(0), "D" if m.startswith("quadratic") else "v")
    for key, (ykey, ylabel) in enumerate((("normal_err_median_deg", "median normal error (degrees)"),
                                          ("coverage_mismatch", "coverage mismatch (pixels) + 1"),
                                          ("position_err_median_h", "median position error (grid spacings h)"))):
        ax = axes[key]
        for method, (col, mk) in styles.items():
            rs = [r for r in rows if r["method"] == method and r.get(ykey) is not None]
            if not rs:
                continue
            xs = [r["frame_median_ms"] for r in rs]
            ys = [r[ykey] + (1 if ykey == "coverage_mismatch" else 0) for r in rs]
            if method.startswith("MC") or method == "VTK volume":
                ax.plot(xs, ys, "-", color=col, marker=mk, label=method)
            else:
                ax.plot(xs, ys, linestyle="none", color=col, marker=mk, label=method)
            for i, (r, x, y) in enumerate(zip(rs, xs, ys)):
                ax.annotate(_short(r), (x, y), fontsize=6, xytext=(4, 6 - 7 * (i % 3)), textcoords="offset points")
        if ykey == "normal_err_median_deg":
            fl = [r["quantisation_floor_median_deg"] for r in rows if r.get("quantisation_floor_median_deg") is not None]
            if fl:
                ax.axhline(max(fl), color="tab:green", ls=":", lw=1, label="VTK normal read-out floor (8 bit)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"frame time, median ms ({setup['window'][0]}x{setup['window'][1]}, llvmpipe, 2 cores)")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:  # a panel no method measured (e.g. positions) stays without a legend
            ax.legend(fontsize=7)
    fig.suptitle(f"Accuracy vs time: {setup['field']}, {setup['grid']} samples (h = {setup['h']:.4f});\nspline labels: "
                 "D/C/S = data texture / coefficient table / determining set, an = closed form, br = bracketed, pa = paper's Newton + iterations",
                 fontsize=9)
    save_figure(fig, path)


def side_by_side_figure(path, *, n=41, cubic=True, window=(420, 330)):
    """Marching cubes 1x | VTK ray caster (trilinear) | quadratic | cubic on Marschner-Lobb n^3, close-up;
    row 1 shading, row 2 reflection lines (splines and the mesh, same GLSL; VTK's volume mapper shows plain
    shading again). Returns the covered fraction of each panel."""
    from datasets_synthetic.volumes import marschner_lobb
    from ..plotting import Plotter
    from ..gl.mesh_effects import add_mesh_with_reflection_lines
    from ..volume.baselines import add_vtk_isosurface, marching_cubes_mesh
    from ..volume.model import VolumeSpline

    plt = pyplot()
    field = marschner_lobb()
    grid = field.sample(n)
    iso = field.isovalue
    cols = [("marching cubes 1x (flying edges)", "mc"), ("VTK ray caster (trilinear)", "vtk"), ("quadratic spline", "quadratic")]
    if cubic:
        cols.append(("cubic spline", "cubic"))
    fig, axes = plt.subplots(2, len(cols), figsize=(3.6 * len(cols), 6.2))
    shots = {}
    for ci, (title, kind) in enumerate(cols):
        for ri, lines in enumerate((False, True)):
            pl = Plotter(off_screen=True, window_size=window)
            pl.set_background("white")
            if kind == "mc" and lines:
                # the same reflection-line GLSL on the mesh's interpolated vertex normals
                add_mesh_with_reflection_lines(pl, marching_cubes_mesh(grid, iso, method="flying_edges"), 12)
            elif kind == "mc":
                pl.add_mesh(marching_cubes_mesh(grid, iso, method="flying_edges"), color="tan", smooth_shading=True)
            elif kind == "vtk":
                add_vtk_isosurface(pl, grid, iso, sample_distance=grid.spacing[0] / 4, color=(0.82, 0.71, 0.55))
            else:
                style = dict(lights=1, reflection_lines=12) if lines else dict(lights=1)
                pl.add_isosurface(VolumeSpline(grid, kind), iso, newton_iterations=4, **style)
            set_camera(pl, ML_CAMERA, (0.05, 5.0))
            img = pl.screenshot()
            pl.close()
            shots[(kind, lines)] = img
            ax = axes[ri, ci]
            ax.imshow(img)
            ax.set_axis_off()
            if ri == 0:
                ax.set_title(title, fontsize=10)
            elif kind == "vtk":
                ax.set_title("(VTK's volume mapper takes no shader\neffects: plain shading)", fontsize=8)
            else:
                ax.set_title("reflection lines (12)", fontsize=9)
    fig.suptitle(f"Marschner-Lobb, {n}^3 samples, isovalue {iso}: the same close-up")
    save_figure(fig, path)
    return {f"{k}{' lines' if l else ''}": float((np.abs(v.astype(int) - 255).sum(-1) > 30).mean()) for (k, l), v in shots.items()}

"""A CAD-style surface-quality report of a multi-patch NURBS model: zebra, highlight lines, Gaussian
curvature and draft angle per pixel, the patch seams coloured by continuity (G2 green, G1 yellow, G0 orange,
open red), and a markdown table of every seam's measures.

    python examples/nurbs_quality_report.py [path/to/model] [out_dir]

Without a path: the synthetic hood panel cut into its bicubic Bezier patches, with one patch edited so
that it meets its neighbours with kinks (G0 seams the report must find).
"""

import sys
from pathlib import Path

import numpy as np

import splinevis
from splinevis.nurbs import NurbsModel, NurbsSurface
from splinevis.nurbs.continuity import CLASS_COLORS, find_seams, seam_lines

if len(sys.argv) > 1 and sys.argv[1]:
    from splinevis.io.nurbs_files import read_nurbs

    model = read_nurbs(sys.argv[1])
else:
    from datasets_synthetic.nurbs_models import hood
    from splinevis.nurbs.operations import bezier_patches

    patches = [p for p, _ in bezier_patches(hood())]
    k = len(patches) // 2
    P = np.array(patches[k].control_points)
    P[1:3, 1:3, 2] += 0.02  # lift the inner control points: the tangent planes break along its four seams
    patches[k] = NurbsSurface(patches[k].degree, patches[k].knots, P, name=f"{patches[k].name} (edited)")
    model = NurbsModel(patches, source="hood panel as Bezier patches, one edited")
out = Path(sys.argv[2] if len(sys.argv) > 2 else "nurbs_quality_report")
out.mkdir(parents=True, exist_ok=True)

seams = find_seams(model.surfaces)
lines = seam_lines(seams)
x0, x1, y0, y1, z0, z1 = model.bounds()
c = np.array([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
size = max(x1 - x0, y1 - y0, z1 - z0)
camera = [tuple(c + size * np.array([0.15, -0.9, 1.1])), tuple(c), (0, 0, 1)]
panels = {
    "zebra and seams": {"lights": 1, "reflection_lines": 14, "reflection_axis": (1, 0, 0)},
    "highlight lines": {"lights": 1, "highlight_lines": 0.08, "highlight_axis": (0, 1, 0)},
    "Gaussian curvature": {"output": "curvature", "curvature": "gaussian"},
    "draft angle (pull (0, 0.8, 0.6), 3 deg)": {"output": "draft", "pull_direction": (0, 0.8, 0.6), "draft_angle": 3.0},
}
K = model.curvature_samples(41)["K"]
panels["Gaussian curvature"]["curvature_scale"] = float(np.nanmax(np.abs(K)))
images = {}
for title, style in panels.items():
    pl = splinevis.Plotter(off_screen=True, window_size=(560, 420))
    pl.set_background("white")
    pl.add_spline(model, **style)
    if title == "zebra and seams" and lines.n_points:
        pl.add_mesh(lines, scalars="rgb", rgb=True, line_width=4, render_lines_as_tubes=False)
    pl.camera_position = camera
    pl.reset_camera_clipping_range()
    images[title] = pl.screenshot()
    pl.close()

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

fig, axes = plt.subplots(2, 2, figsize=(11, 8.4))
for ax, (title, img) in zip(axes.ravel(), images.items()):
    ax.imshow(img)
    ax.set_title(title)
    ax.axis("off")
handles = [plt.Line2D([], [], color=col, lw=4, label=name) for name, col in CLASS_COLORS.items()]
axes[0, 0].legend(handles=handles, loc="lower left", fontsize=8, title="seam continuity")
fig.suptitle(f"{model.source}: {len(model)} patches, {len(seams)} seams", fontsize=11)
fig.tight_layout()
fig.savefig(out / "report.png", dpi=100)

rows = sorted((s.summary() for s in seams), key=lambda r: ["open", "G0", "G1", "G2"].index(r["level"]))
md = [f"# Surface quality: {model.source}", "", f"{len(model)} patches, {len(seams)} seams; "
      + ", ".join(f"{sum(r['level'] == lv for r in rows)} {lv}" for lv in ("G2", "G1", "G0", "open")) + ".",
      f"Gaussian curvature on the surface: [{np.nanmin(K):.4g}, {np.nanmax(K):.4g}] (float64, 41 x 41 per patch).", "",
      "| patches | sides | level | max gap | max normal angle (deg) | max curvature jump |", "|---|---|---|---|---|---|"]
md += [f"| {a} / {b} | {sa} / {sb} | {r['level']} | {r['max_gap']:.3g} | {r['max_angle_deg']:.3g} | "
       f"{r['max_curvature_jump']:.3g} |" for r in rows for (a, b), (sa, sb) in [(r["patches"], r["sides"])]]
md += ["", "![report](report.png)", ""]
(out / "report.md").write_text("\n".join(md))
print(f"wrote {out / 'report.png'} and {out / 'report.md'}: " + md[2])

"""From a NURBS file to a zebra and a curvature figure, evaluated exactly per pixel.

    python examples/nurbs_zebra.py [path/to/model.3dm|.igs|.stp|.g2|.json|.bpt] [out.png]

Without a path the synthetic "hood" panel (a bicubic B-spline with non-uniform knots) is drawn. Left:
reflection lines (zebra) of light lines along x; right: the mean curvature per pixel, with a legend whose
range is the true range of the surface (float64, sampled densely on every patch).
"""

import sys

import numpy as np

import splinevis
from splinevis.nurbs import NurbsModel

if len(sys.argv) > 1 and sys.argv[1]:
    from splinevis.io.nurbs_files import read_nurbs

    model = read_nurbs(sys.argv[1])
else:
    from datasets_synthetic.nurbs_models import hood

    model = NurbsModel([hood()], source="synthetic hood panel")
out = sys.argv[2] if len(sys.argv) > 2 else "nurbs_zebra.png"
print(f"read {model.source or 'model'}: {len(model)} patches")

# the true curvature range on the surface (float64), for the legend
H = model.curvature_samples(101)["H"]
scale = float(np.nanmax(np.abs(H)))

x0, x1, y0, y1, z0, z1 = model.bounds()
c = np.array([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
size = max(x1 - x0, y1 - y0, z1 - z0)
camera = [tuple(c + size * np.array([0.2, -1.1, 1.0])), tuple(c), (0, 0, 1)]
images = []
for style in ({"lights": 1, "reflection_lines": 12, "reflection_axis": (1, 0, 0)},
              {"output": "curvature", "curvature": "mean", "curvature_scale": scale}):
    pl = splinevis.Plotter(off_screen=True, window_size=(640, 480))
    pl.set_background("white")
    pl.add_spline(model, **style)
    pl.camera_position = camera
    pl.reset_camera_clipping_range()
    images.append(pl.screenshot())
    pl.close()

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.colors import LinearSegmentedColormap, Normalize

fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
axes[0].imshow(images[0])
axes[0].set_title("reflection lines (zebra), per fragment")
axes[1].imshow(images[1])
axes[1].set_title("mean curvature, per fragment")
for ax in axes:
    ax.axis("off")
cmap = LinearSegmentedColormap.from_list("sv", [(0.23, 0.30, 0.75), (1, 1, 1), (0.71, 0.02, 0.15)])
bar = fig.colorbar(plt.cm.ScalarMappable(Normalize(-scale, scale), cmap), ax=axes[1], fraction=0.046)
bar.set_label(f"H (1/length); true range on the surface [{np.nanmin(H):.3g}, {np.nanmax(H):.3g}]")
fig.tight_layout()
fig.savefig(out, dpi=100)
print(f"wrote {out}")

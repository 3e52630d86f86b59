"""Isosurface of a volume FILE, ray-cast per pixel as a cubic spline, with reflection lines.

    python examples/volume_isosurface.py [out.png] [--scheme quadratic|cubic]

A user starts from a file: this example first writes one (a smooth blob sampled on 40^3 points, saved as
.vti in a temporary directory), then reads it back exactly as a user would, by path.
"""

import sys
import tempfile
from pathlib import Path

import splinevis
from datasets_synthetic.volumes import blob, write_volume
from splinevis.io import read_volume

out = next((a for a in sys.argv[1:] if not a.startswith("--")), "volume_isosurface.png")
scheme = sys.argv[sys.argv.index("--scheme") + 1] if "--scheme" in sys.argv else "cubic"

field = blob()
with tempfile.TemporaryDirectory() as tmp:
    path = Path(tmp) / "blob.vti"
    write_volume(field.sample(40), path)  # the "user's" file

    grid = read_volume(path)  # what a user does
    nz, ny, nx = grid.shape
    print(f"{path.name}: {nx}x{ny}x{nz} samples, spacing {tuple(round(s, 4) for s in grid.spacing)}, "
          f"values {grid.value_range[0]:.3f}..{grid.value_range[1]:.3f}")

    pl = splinevis.Plotter(off_screen=True, window_size=(640, 480))
    pl.set_background("white")
    actor = pl.add_isosurface(path, field.isovalue, scheme, lights=1, reflection_lines=12, newton_iterations=4)
    pl.camera_position = [(2.2, -2.6, 1.8), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    pl.camera.clipping_range = (0.5, 8.0)
    pl.screenshot(out)
    pl.close()
rel = actor.model.relevant
print(f"{scheme} spline, isovalue {field.isovalue}: {len(rel.cubes)} relevant cubes, {rel.num_tets} tetrahedra; wrote {out}")

"""From a DEM file to a figure with reflection lines, on the exact C1 quartic spline.

    python examples/dem_reflection_lines.py [path/to/dem.dem|.tif] [out.png]

Without a path, a synthetic USGS ASCII DEM (fractal relief, UTM-sized origin) is written first, so the
example runs anywhere. Reflection lines show the smoothness of the surface: on a C1 spline they are
continuous; on a triangle mesh they break at every edge.
"""

import sys
import tempfile
from pathlib import Path

import splinevis
from datasets_synthetic.dem_files import fractal_terrain, write_usgs_ascii_dem

if len(sys.argv) > 1 and sys.argv[1]:
    path = Path(sys.argv[1])
else:
    path = Path(tempfile.mkdtemp()) / "synthetic.dem"
    from scipy.ndimage import gaussian_filter

    # fractal relief, smoothed over ~3 cells (real DEMs are smoother than fBm at the sample scale)
    heights = 400.0 + 300.0 * gaussian_filter(fractal_terrain(129, seed=7, hurst=0.9), 2.0, mode="wrap")
    write_usgs_ascii_dem(path, heights, spacing=(30.0, 30.0), origin=(500_010.0, 5_100_020.0))
out = sys.argv[2] if len(sys.argv) > 2 else "dem_reflection_lines.png"

grid = splinevis.read_heights(path)  # keeps spacing, origin and (for GeoTIFF) nodata and the CRS
print(f"read {grid.source}: {grid.shape[1]}x{grid.shape[0]} heights, spacing {grid.spacing}, origin {grid.origin}")

pl = splinevis.Plotter(off_screen=True, window_size=(1000, 700))
pl.set_background("white")
actor = pl.add_terrain(grid, "C1", colormap="terrain", lights=2, reflection_lines=40)
x0, x1, y0, y1 = actor.model.extent
zlo, zhi = actor.model.zrange
cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
pl.camera_position = [(cx - 0.55 * (x1 - x0), cy - 1.05 * (y1 - y0), zhi + 0.9 * (x1 - x0)), (cx, cy, zlo), (0, 0, 1)]
pl.reset_camera_clipping_range()
pl.add_text(f"{actor.model.scheme} quartic spline, {actor.model.num_patches:,} patches, ray-cast per pixel",
            font_size=10, color="black")
pl.screenshot(out)
print(f"wrote {out}")

"""A ray-cast quartic patch beside an ordinary PyVista mesh, with reflection lines.

    python examples/analytic_patch_with_mesh.py  [out.png]

Every pixel of the patch is computed on the smooth surface (no triangles); the sphere is a normal mesh
and the two hide each other correctly because the ray caster writes gl_FragDepth.
"""

import sys

import pyvista as pv

import splinevis
from splinevis.analytic import QuarticTrianglePatch

out = sys.argv[1] if len(sys.argv) > 1 else "analytic_patch.png"
pl = splinevis.Plotter(off_screen=True, window_size=(800, 600))
pl.set_background("white")
patch = QuarticTrianglePatch.demo()
pl.add_spline(patch, lights=2, specular=True, reflection_lines=12)
pl.add_mesh(pv.Sphere(radius=0.3, center=(0.05, -0.15, 0.22)), color="steelblue", smooth_shading=True)
pl.camera_position = [(2.5, -3.3, 2.4), (0.05, -0.1, 0.05), (0.0, 0.0, 1.0)]
pl.screenshot(out)
print(f"wrote {out}")

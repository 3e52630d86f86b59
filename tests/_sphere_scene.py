"""The ray-cast sphere isosurface the effect tests draw (tests/test_effects_interrogation.py,
tests/test_stripes_antialias.py): a distance field on a 40^3 lattice at level 0.7, seen unlit in white on black
through one fixed camera, so every pixel's colour is the effect's factor alone."""

import numpy as np

import splinevis
from splinevis.io import VolumeGrid
from splinevis.volume.isosurface import Isosurface
from splinevis.volume.model import VolumeSpline

N = 40
WINDOW = (160, 120)
CAMERA = [(2.6, -1.9, 1.7), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]


def sphere():
    """The isosurface ``|x| = 0.7`` of the cubic spline of ``|x|`` sampled on ``N^3`` points of ``[-1, 1]^3``."""
    x = np.linspace(-1, 1, N)
    z, y, xx = np.meshgrid(x, x, x, indexing="ij")
    grid = VolumeGrid(np.sqrt(xx**2 + y**2 + z**2), spacing=(2 / (N - 1),) * 3, origin=(-1, -1, -1))
    return Isosurface(VolumeSpline(grid), 0.7)


def render(model, camera=CAMERA, **style):
    """``(image in [0, 1], camera matrix)`` of ``model`` drawn unlit in white on black with ``style``'s effects, seen
    from ``camera`` (``[eye, focal point, up]``)."""
    pl = splinevis.Plotter(off_screen=True, window_size=WINDOW)
    pl.set_background("black")
    pl.add_spline(model, lights=0, color=(1.0, 1.0, 1.0), **style)
    pl.camera_position = camera
    pl.camera.clipping_range = (1.0, 8.0)
    img = pl.screenshot().astype(np.float64) / 255.0
    matrix = pl.camera_matrix()
    pl.close()
    return img, matrix

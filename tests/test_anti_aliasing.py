"""Plotter(anti_aliasing=k): the whole scene, spline actors and meshes together, supersampled k x k."""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

import splinevis
from splinevis.analytic import QuarticTrianglePatch

pytestmark = pytest.mark.gl

WINDOW = (80, 60)


def _scene(anti_aliasing=False, window=WINDOW):
    pl = splinevis.Plotter(off_screen=True, window_size=window, anti_aliasing=anti_aliasing)
    pl.set_background("black")
    pl.add_spline(QuarticTrianglePatch.demo(), lights=0, color=(1.0, 1.0, 1.0))
    pl.add_mesh(pv.Sphere(radius=0.25, center=(0.0, 0.0, 0.6)), color=(0.0, 0.0, 1.0), lighting=False)
    pl.camera_position = [(0.0, -2.5, 2.0), (0.0, 0.0, 0.1), (0.0, 0.0, 1.0)]
    pl.camera.clipping_range = (0.5, 8.0)
    img = pl.screenshot().astype(np.int64)
    pl.close()
    return img


def test_supersampled_screenshot_is_the_block_mean_of_the_large_render():
    k = 2
    small = _scene(anti_aliasing=k)
    big = _scene(window=(WINDOW[0] * k, WINDOW[1] * k))
    assert small.shape == (WINDOW[1], WINDOW[0], 3)
    blocks = big.reshape(WINDOW[1], k, WINDOW[0], k, 3).mean(axis=(1, 3))
    assert np.array_equal(small, np.rint(blocks).astype(np.int64))  # the same frame, averaged: nothing else


def test_silhouettes_get_partial_coverage_and_the_mesh_still_occludes():
    plain, ss = _scene(), _scene(anti_aliasing=4)

    def grey(im):  # the white spline partly covering black: a grey between
        return (im[..., 0] > 0) & (im[..., 0] < 255) & (im[..., 0] == im[..., 2])

    assert grey(plain).sum() == 0   # one sample: every pixel is surface or background
    assert grey(ss).sum() > 40      # 4 x 4 samples: the outline's pixels are partly covered
    blue = (plain[..., 2] == 255) & (plain[..., 0] == 0)
    core = blue & np.roll(blue, 2, 0) & np.roll(blue, -2, 0) & np.roll(blue, 2, 1) & np.roll(blue, -2, 1)
    assert core.sum() > 20 and np.all(ss[core] == [0, 0, 255])  # depth compositing intact: the sphere in front


def test_bad_anti_aliasing_is_named():
    with pytest.raises(ValueError, match="anti_aliasing=True is ambiguous"):
        splinevis.Plotter(off_screen=True, window_size=WINDOW, anti_aliasing=True)
    with pytest.raises(ValueError, match="anti_aliasing='smaa' is not known"):
        splinevis.Plotter(off_screen=True, window_size=WINDOW, anti_aliasing="smaa")


def test_vtk_ssaa_pass_draws_the_injected_programs():
    # PyVista's "ssaa" (VTK's vtkSSAAPass) renders larger and filters down: our programs' fragments are drawn in
    # it (the picture is not blank) and the outline gets partly covered pixels, as with anti_aliasing=k
    plain, ss = _scene(), _scene(anti_aliasing="ssaa")
    assert np.abs(ss - plain).mean() < 20  # the same picture ...
    grey = (ss[..., 0] > 0) & (ss[..., 0] < 255) & (ss[..., 0] == ss[..., 2])
    assert grey.sum() > 40  # ... with smoothed silhouettes

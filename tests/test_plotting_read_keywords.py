"""The reader's keywords of ``Plotter.add_isosurface`` / ``add_terrain`` (``order``, ``spacing``, ``origin``,
splinevis.plotting_options.split_read_options) read the same data given plainly or in ``read_options``, with or
without ``max_error_px``; ``order=`` on a terrain says why it does not apply."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import splinevis

pytestmark = pytest.mark.gl

# a z-first volume: arr[k, j, i] at (x_i, y_j, z_k), nz != nx so that the two axis orders read different lattices
# (read without order= it would warn, read 'xyz' it would be a (10, 8, 6) lattice)
SPACING = (2 / 9, 2 / 7, 2 / 5)
ORIGIN = (-1.0, -1.0, -1.0)
_z, _y, _x = np.mgrid[-1:1:6j, -1:1:8j, -1:1:10j]
ZYX = np.sqrt(_x ** 2 + _y ** 2 + (0.8 * _z) ** 2)


def _spline(actor):
    return actor.model.spline


def test_isosurface_order_and_spacing_keywords_read_the_same_model_with_and_without_max_error_px():
    pl = splinevis.Plotter(off_screen=True, window_size=(80, 60))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an order lost on the way would warn (shape[0] != shape[2])
        plain = pl.add_isosurface(ZYX, 0.7, order="zyx", spacing=SPACING, origin=ORIGIN)
        accurate = pl.add_isosurface(ZYX, 0.7, order="zyx", spacing=SPACING, origin=ORIGIN, max_error_px=1.0)
        given = pl.add_isosurface(ZYX, 0.7, read_options={"order": "zyx", "spacing": SPACING, "origin": ORIGIN},
                                  max_error_px=1.0)
    pl.close()
    assert accurate.renderer_choice.max_error_px == 1.0  # the accuracy path was taken
    reference = _spline(plain).grid
    assert reference.shape == ZYX.shape  # read as arr[k, j, i]: (nz, ny, nx) = (6, 8, 10)
    np.testing.assert_array_equal(reference.values, ZYX)
    assert reference.spacing == SPACING and reference.origin == ORIGIN
    for actor in (accurate, given):
        # the same reading is the same bits: equal arrays and lattices, no tolerance
        grid = _spline(actor).grid
        np.testing.assert_array_equal(grid.values, reference.values)
        assert (grid.spacing, grid.origin, grid.bounds) == (reference.spacing, reference.origin, reference.bounds)
        np.testing.assert_array_equal(_spline(actor).padded, _spline(plain).padded)
        assert tuple(_spline(actor).bounds) == tuple(_spline(plain).bounds)


def test_terrain_spacing_keyword_reads_the_same_model_with_and_without_max_error_px():
    z = np.add.outer(np.sin(np.linspace(0, 3, 9)), np.cos(np.linspace(0, 3, 13)))  # (ny, nx) = (9, 13)
    pl = splinevis.Plotter(off_screen=True, window_size=(80, 60))
    plain = pl.add_terrain(z, "C1", spacing=(0.25, 0.5), origin=(1.0, 2.0))
    accurate = pl.add_terrain(z, "C1", spacing=(0.25, 0.5), origin=(1.0, 2.0), max_error_px=1.0)
    pl.close()
    assert accurate.model.extent == plain.model.extent == (1.0, 4.0, 2.0, 6.0)  # x: 12 * 0.25, y: 8 * 0.5


@pytest.mark.parametrize("how", ["keyword", "read_options", "max_error_px"])
def test_terrain_refuses_order_saying_how_a_height_array_is_read(how):
    z = np.zeros((4, 5))
    kwargs = {"keyword": {"order": "zyx"}, "read_options": {"read_options": {"order": "xyz"}},
              "max_error_px": {"order": "zyx", "max_error_px": 1.0}}[how]
    pl = splinevis.Plotter(off_screen=True, window_size=(80, 60))
    with pytest.raises(TypeError, match=r"^order= applies to volumes") as info:
        pl.add_terrain(z, **kwargs)
    pl.close()
    message = str(info.value)
    assert "heights[j, i] is the height at (x0 + i*dx, y0 + j*dy), rows along y" in message
    assert "heights.T" in message and "unexpected keyword" not in message

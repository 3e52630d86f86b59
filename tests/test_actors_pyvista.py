"""Every add_* returns a pyvista.Actor carrying .model and .style; remove_actor, visibility and PyVista's
keyword names work as PyVista users expect."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import pyvista as pv

import splinevis

pytestmark = pytest.mark.gl


def _adders():
    z = np.add.outer(np.sin(np.linspace(0, 3, 20)), np.cos(np.linspace(0, 4, 25))) * 50.0
    x, y, w = np.mgrid[-1:1:16j, -1:1:16j, -1:1:16j]
    u, v = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 4), indexing="ij")
    patch = splinevis.NurbsSurface((3, 3), ([0] * 4 + [1] * 4, [0] * 4 + [1] * 4), np.dstack([u, v, 0.3 * u * v]))
    blob = pv.ParametricEllipsoid(1.0, 0.6, 0.4).triangulate().clean()
    return {
        "terrain": lambda pl, **k: pl.add_terrain(z, spacing=(10.0, 10.0), origin=(0.0, 0.0), **k),
        "isosurface": lambda pl, **k: pl.add_isosurface(np.sqrt(x**2 + y**2 + w**2), 0.7, spacing=(2 / 15,) * 3, **k),
        "nurbs": lambda pl, **k: pl.add_nurbs(patch, **k),
        "geometry image": lambda pl, **k: pl.add_geometry_image(blob, n=17, **k),
    }


@pytest.mark.parametrize("family", ["terrain", "isosurface", "nurbs", "geometry image"])
def test_add_returns_a_pyvista_actor_with_model_and_style(family):
    pl = splinevis.Plotter(off_screen=True, window_size=(80, 60))
    pl.set_background("black")
    with warnings.catch_warnings():  # a coarse geometry image may warn of its distance to the mesh
        warnings.simplefilter("ignore")
        actor = _adders()[family](pl, reflection_lines=6, color="white")
    assert isinstance(actor, pv.Actor) and actor.model is not None and actor.style.reflection_lines == 6

    def shot():
        pl.render()
        return np.asarray(pl.screenshot())

    assert shot().max() > 100  # drawn
    actor.visibility = False
    assert shot().max() == 0  # hidden like any PyVista actor
    actor.visibility = True
    assert shot().max() > 100
    assert pl.remove_actor(actor) and shot().max() == 0
    pl.close()


def test_pyvista_keyword_names():
    pl = splinevis.Plotter(off_screen=True, window_size=(80, 60))
    actor = _adders()["terrain"](pl, cmap="viridis", clim=(-60.0, 60.0))
    assert actor.style.colormap == "viridis" and actor.style.scalar_range == (-60.0, 60.0)
    with pytest.raises(TypeError, match="smooth_shading does not apply to a spline actor: every pixel is shaded"):
        _adders()["terrain"](pl, smooth_shading=True)
    with pytest.raises(TypeError, match="give cmap .* or colormap, not both"):
        _adders()["terrain"](pl, cmap="viridis", colormap="terrain")
    pl.close()


def test_add_scalar_bar_shows_the_actors_colours():
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = _adders()["terrain"](pl, cmap="viridis")
    bar = pl.add_scalar_bar("height")
    lo, hi = actor.model.data_range  # the program's range: the heights of the data (the spline's overshoot aside)
    assert np.allclose(bar.GetLookupTable().GetRange(), (lo, hi))
    pl.close()
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    _adders()["nurbs"](pl, output="curvature", curvature_scale=2.0)
    bar = pl.add_scalar_bar("mean curvature")
    assert np.allclose(bar.GetLookupTable().GetRange(), (-2.0, 2.0))
    assert np.asarray(pl.screenshot()).std() > 5
    pl.close()

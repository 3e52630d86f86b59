"""Normal error in the choice by accuracy (``max_normal_error_deg``): the terrain mesh's proven bound on the
angle between the normal it shades with and the spline's (splinevis.terrain.renderers.mesh_normal_error_deg)
holds against the float64 spline on hard terrains, and the isosurface mesh's estimate against the normal
at the surface point a mesh point stands for; the choice takes the coarsest mesh meeting both requests,
an exact renderer when no mesh can, and says what it did."""

import numpy as np
import pytest

import splinevis
from datasets_synthetic.dem_files import fractal_terrain
from splinevis.choice import choose
from splinevis.gl.screen_error import View
from splinevis.terrain.model import TerrainSpline
from splinevis.terrain.renderers import mesh_normal_error_deg
from splinevis.terrain.sampled_mesh import sampled_mesh

N = 17


def _bump():
    y, x = np.mgrid[-1:1:N * 1j, -1:1:N * 1j]
    return np.exp(-4 * (x * x + y * y))


def _ridge():
    y, x = np.mgrid[0:N, 0:N].astype(float)
    return np.tanh(2.0 * (x - 0.4 * y - 5.0))


TERRAINS = {"bump": _bump, "ridge": _ridge, "fractal": lambda: fractal_terrain(N, seed=5)}


def _shading_normals(t, k, x, y):
    """The mesh's vertex normals interpolated linearly on each sub-triangle (split along u = v) and normalized:
    what the rasterizer shades with at (x, y)."""
    mesh = sampled_mesh(t, k)
    ncy, ncx = t.shape
    n = mesh.point_data["Normals"].reshape(k * ncy + 1, k * ncx + 1, 3)
    u, v = t.to_index(x, y)
    a = np.minimum(np.floor(u * k).astype(int), k * ncx - 1)
    b = np.minimum(np.floor(v * k).astype(int), k * ncy - 1)
    lu, lv = (u * k - a)[:, None], (v * k - b)[:, None]
    n00, n10, n11, n01 = n[b, a], n[b, a + 1], n[b + 1, a + 1], n[b + 1, a]
    lower = n00 + lu * (n10 - n00) + lv * (n11 - n10)
    upper = n00 + lv * (n01 - n00) + lu * (n11 - n01)
    s = np.where(lv > lu, upper, lower)
    return s / np.linalg.norm(s, axis=1, keepdims=True)


def _spline_normals(t, x, y):
    g = t.gradient(x, y)
    n = np.column_stack([-g[:, 0], -g[:, 1], np.ones(len(x))])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


@pytest.mark.parametrize("name", sorted(TERRAINS))
@pytest.mark.parametrize("scheme", ["C1", "C2"])
@pytest.mark.parametrize("k", [1, 3, 8])
def test_terrain_mesh_normal_bound_holds(name, scheme, k):
    t = TerrainSpline.from_heights(TERRAINS[name](), scheme, spacing=(0.1, 0.15))
    rng = np.random.default_rng(11)
    x0, x1, y0, y1 = t.extent
    x, y = rng.uniform(x0, x1, 20_000), rng.uniform(y0, y1, 20_000)
    cos = np.clip(np.einsum("ij,ij->i", _shading_normals(t, k, x, y), _spline_normals(t, x, y)), -1.0, 1.0)
    measured = float(np.degrees(np.arccos(cos)).max())
    bound, proven = mesh_normal_error_deg(t, None, k, {})
    assert proven
    assert measured <= bound
    assert measured > 0.0  # the sampling reaches inside triangles: the comparison is not vacuous


def _view():
    return View((0.8, -1.6, 1.4), (0.8, 0.8, 0.0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.3, 6))


def test_choice_meets_the_normal_request_with_the_coarsest_mesh():
    t = TerrainSpline.from_heights(_bump(), "C1", spacing=(0.1, 0.1))
    loose = choose(t, _view(), 2.0)
    both = choose(t, _view(), 2.0, max_normal_error_deg=10.0)  # a first-order bound: ~150 deg / k here
    assert (loose.renderer, both.renderer) == ("mesh", "mesh")
    assert both.level > loose.level  # the normals ask for more samples than the positions
    assert both.chosen.normal_deg <= 10.0 and both.chosen.normal_proven
    earlier = [o for o in both.options if o.name == "mesh" and o.level < both.level]
    assert earlier and all(o.normal_deg > 10.0 or o.error_px > 2.0 for o in earlier)
    assert "max_normal_error_deg=10" in both.message and "deg (proven)" in both.message


def test_normal_request_alone_and_exact_renderers():
    t = TerrainSpline.from_heights(_bump(), "C1", spacing=(0.1, 0.1))
    only = choose(t, _view(), None, max_normal_error_deg=20.0)
    assert only.renderer == "mesh" and only.max_error_px == float("inf") and only.chosen.normal_deg <= 20.0
    capped = choose(t, _view(), None, max_normal_error_deg=1.0, triangle_cap=20_000)
    assert capped.renderer == "raycast" and capped.chosen.normal_deg == 0.0  # exact normals, per pixel
    assert "exact normals" in capped.message
    with pytest.raises(ValueError, match="give max_error_px"):
        choose(t, _view(), None)
    with pytest.raises(ValueError, match="max_normal_error_deg must be a positive finite number of degrees"):
        choose(t, _view(), 1.0, max_normal_error_deg=float("nan"))


def test_plotter_takes_the_normal_request():
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = pl.add_terrain(_bump(), "C1", read_options={"spacing": (0.1, 0.1)}, max_normal_error_deg=15.0,
                           reflection_lines=8)
    # the mesh that proves 15 degrees or the ray cast, whichever is estimated cheaper in this small window
    assert actor.choice.meets and actor.choice.chosen.normal_deg <= 15.0
    img = pl.screenshot()
    assert img.std() > 10
    pl.close()


def _blobs():
    z, y, x = np.mgrid[-1:1:18j, -1:1:18j, -1:1:18j]
    return np.exp(-6 * ((x - 0.35) ** 2 + y * y + z * z)) + np.exp(-6 * ((x + 0.35) ** 2 + y * y + z * z))


def _ball():
    z, y, x = np.mgrid[-1:1:18j, -1:1:18j, -1:1:18j]
    return np.sqrt(x * x + y * y + z * z)


@pytest.mark.parametrize("field,iso", [(_ball, 0.6), (_blobs, 0.6)])
@pytest.mark.parametrize("k", [1, 2, 4])
def test_isosurface_mesh_normal_estimate_holds(field, iso, k):
    from splinevis.volume.isosurface import Isosurface
    from splinevis.volume.model import VolumeSpline
    from splinevis.volume.renderers import mesh_normal_error_deg
    from splinevis.volume.sampled_mesh import sampled_mesh

    s = VolumeSpline(field(), order="zyx", spacing=(2 / 17,) * 3, origin=(-1, -1, -1))
    surface = Isosurface(s, iso)
    mesh = sampled_mesh(s, iso, k, surface.relevant)
    tri = mesh.faces.reshape(-1, 4)[:, 1:]
    rng = np.random.default_rng(3)
    w = rng.dirichlet([1.0, 1.0, 1.0], len(tri))
    p = np.einsum("tk,tkc->tc", w, mesh.points[tri])
    shading = np.einsum("tk,tkc->tc", w, mesh.point_data["Normals"][tri])
    shading /= np.linalg.norm(shading, axis=1, keepdims=True)
    q = p.copy()
    for _ in range(6):  # Newton along the gradient onto the surface: the point p stands for
        v, g = s.evaluate(q, gradient=True)
        q -= ((v - iso) / np.einsum("ij,ij->i", g, g))[:, None] * g
    v, g = s.evaluate(q, gradient=True)
    assert np.abs(v - iso).max() < 1e-9  # converged: q is on the surface
    exact = g / np.linalg.norm(g, axis=1, keepdims=True)
    measured = float(np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", shading, exact), -1, 1))).max())
    bound, proven = mesh_normal_error_deg(surface, None, k, {})
    assert not proven and 0.0 < measured <= bound


def test_walkthrough_takes_max_error_px_and_a_normal_request():
    from splinevis.nurbs.exact import torus

    pl = splinevis.Plotter(off_screen=True, window_size=(64, 48))
    walk = pl.add_walkthrough(torus(), max_error_px=0.5, levels=2)
    assert walk.pixel_error == 0.5 and walk.max_normal_error_deg is None
    walk = pl.add_walkthrough(torus(), levels=2, max_normal_error_deg=1.0)  # proven per level (LodModel.normal_bounds)
    frames = walk.fly([[(0.0, -4.0, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]], progress=False)
    assert walk.max_normal_error_deg == 1.0 and frames[0]["triangles"] > 0 and "normal_unmet" in frames[0]
    with pytest.raises(ValueError, match="bound positions only"):  # dynamic tessellation: positions only
        pl.add_walkthrough(torus(), levels=2, max_normal_error_deg=1.0, dynamic=True)
    pl.close()


def test_the_choice_draws_the_meeting_renderer_of_least_estimated_time():
    t = TerrainSpline.from_heights(_bump(), "C1", spacing=(0.1, 0.1))
    for request in (2.0, 0.5, 0.05, 0.02):
        c = choose(t, _view(), request)
        meeting = [o for o in c.options if o.meets]
        assert meeting and all(o.cost_ms is not None and o.cost_ms > 0 for o in meeting)
        assert c.chosen.cost_ms == min(o.cost_ms for o in meeting)
    # a coarse request: the mesh is cheaper; a fine one needs a mesh estimated dearer than the ray cast
    assert choose(t, _view(), 2.0).renderer == "mesh" and choose(t, _view(), 0.02).renderer == "raycast"


def test_when_nothing_meets_the_exact_renderer_closest_to_the_request_is_drawn():
    from datasets_synthetic.closed_meshes import star_blob
    from splinevis.geometry_image.program import model_from

    gi = model_from(star_blob(level=3), 17)
    view = View((0.0, -4.0, 2.0), (0.0, 0.0, 0.0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 20))
    c = choose(gi, view, 5.0, max_normal_error_deg=1e-3)  # no level proves a thousandth of a degree
    assert not c.meets
    pool = [o for o in c.options if not o.reason]
    shortfall = [max(o.error_px / 5.0, o.normal_deg / 1e-3) for o in pool]
    assert max(c.chosen.error_px / 5.0, c.chosen.normal_deg / 1e-3) == min(shortfall)
    assert "nothing meets" in c.message

"""Effects on ordinary meshes (splinevis.gl.mesh_effects): isophotes and the curvature output through the same
GLSL as the spline programs, checked against what the GLSL formulas predict on a sphere with exact normals;
the shader code of an effect is compiled in only when declared; a mesh without curvature is refused."""

import numpy as np
import pytest
import pyvista as pv

import splinevis
from splinevis import Style
from splinevis.gl.mesh_effects import add_mesh_with_effects, add_mesh_with_reflection_lines

SIZE = 240  # square window; the parallel scale makes a unit of length SIZE / (2 * SCALE) pixels
SCALE = 1.25


def _sphere(radius, resolution=240):
    """A fine sphere with its exact normals points / radius."""
    mesh = pv.Sphere(radius=radius, theta_resolution=resolution, phi_resolution=resolution)
    mesh.point_data["Normals"] = mesh.points / radius
    mesh.point_data.active_normals_name = "Normals"
    return mesh


def _render(mesh, style, eye=(0.0, 0.0, 10.0), up=(0.0, 1.0, 0.0), save=None):
    """Offscreen picture of ``mesh`` with ``style`` on black, parallel projection centred on the origin, and
    the actor (its compiled sources)."""
    pl = splinevis.Plotter(off_screen=True, window_size=(SIZE, SIZE))
    pl.set_background("black")
    actor = add_mesh_with_effects(pl, mesh, style)
    pl.camera_position = [eye, (0.0, 0.0, 0.0), up]
    pl.enable_parallel_projection()
    pl.camera.parallel_scale = SCALE
    pl.camera.clipping_range = (0.1, 30.0)
    img = pl.screenshot().astype(float) / 255.0
    if save is not None:
        pl.screenshot(save)
    pl.close()
    return img, actor


def _pixel_plane():
    """Camera-plane coordinates (x right, y up) of the pixel centres, in world units."""
    c = (np.arange(SIZE) + 0.5 - SIZE / 2) / (SIZE / 2) * SCALE
    return np.meshgrid(c, -c)  # row 0 at the top


def _isophote_dark(c, bands):
    """lib/effects/isophotes.glsl: dark where fract(c * bands) < 0.5."""
    return np.mod(c * bands, 1.0) < 0.5


def _curvature_color(h, k, kind, scale):
    """lib/effects/curvature.glsl's sv_curvature_color of (H, K), in numpy."""
    d = np.sqrt(np.maximum(h * h - k, 0.0))
    value = {"mean": h, "gaussian": k, "k1": h + d, "k2": h - d,
             "max": np.where(np.abs(h + d) >= np.abs(h - d), h + d, h - d)}[kind]
    x = np.clip(value / scale, -1.0, 1.0)[..., None]
    white = np.ones(3)
    return np.where(x < 0, white + (np.array([0.23, 0.30, 0.75]) - white) * -x,
                    white + (np.array([0.71, 0.02, 0.15]) - white) * x)


def _runs(mask):
    """Number of runs of equal values along a 1-d boolean array."""
    return int(1 + np.count_nonzero(mask[1:] != mask[:-1])) if mask.size else 0


def _boundaries(c0, c1, bands):
    """How many isophote boundaries (c * bands a multiple of 1/2) lie strictly between c0 and c1."""
    lo, hi = sorted((c0 * bands, c1 * bands))
    return int(np.floor(2 * hi - 1e-12) - np.floor(2 * lo))


@pytest.mark.gl
@pytest.mark.parametrize("eye, up", [((0.0, 0.0, 10.0), (0.0, 1.0, 0.0)), ((6.0, -5.0, 4.0), (0.0, 0.0, 1.0))])
def test_isophote_bands_on_a_sphere_are_those_of_dot_n_l(eye, up, tmp_path):
    # Parallel view of a unit sphere: the pixel at camera-plane (x, y) sees the normal (x, y, sqrt(1 - x^2 - y^2))
    # in camera coordinates, and the Style's first light is fixed in camera coordinates, so every camera sees
    # the same bands c = n . L (the oblique camera checks that L is turned into model coordinates).
    bands = 5
    style = Style(lights=1, isophotes=bands, color="white", ambient=1.0, diffuse=0.0)  # lit = flat white
    img, actor = _render(_sphere(1.0), style, eye, up, save=tmp_path / "isophotes.png")
    light = style.light_directions_camera()[0]
    x, y = _pixel_plane()
    rho2 = x**2 + y**2
    inside = rho2 < 0.97**2
    n = np.stack([x, y, np.sqrt(np.clip(1 - rho2, 0, None))], -1)
    expected = _isophote_dark(n @ light, bands)
    dark = img.sum(-1) < 1.5  # bright bands 1.0 * white, dark ones 0.2 * white
    assert (img.sum(-1)[~(rho2 < 1.03**2)] < 0.1).all()  # black outside the disc
    assert 0.2 < dark[inside].mean() < 0.8
    assert (dark == expected)[inside].mean() > 0.97
    # along the diameter of the disc through the light's projection u = (Lx, Ly) / |(Lx, Ly)|: at s u the
    # normal is (s u, sqrt(1 - s^2)), so c(s) = s |(Lx, Ly)| + Lz sqrt(1 - s^2) rises from c(-0.99) to 1 at
    # n = L (s = |(Lx, Ly)|) and falls to c(0.99): the bands are the multiples of 1 / (2 bands) it crosses
    lxy = np.hypot(light[0], light[1])
    u = light[:2] / lxy
    ends = [s * lxy + light[2] * np.sqrt(1 - s * s) for s in (-0.99, 0.99)]
    predicted = 1 + _boundaries(ends[0], 1.0, bands) + _boundaries(1.0, ends[1], bands)
    s = np.linspace(-0.99, 0.99, 4 * SIZE)
    cols = np.floor(SIZE / 2 + s * u[0] * SIZE / (2 * SCALE)).astype(int)
    rows = np.floor(SIZE / 2 - s * u[1] * SIZE / (2 * SCALE)).astype(int)
    measured = _runs(dark[rows, cols])
    assert abs(measured - predicted) <= 1, (measured, predicted)
    assert predicted >= 3 * bands  # c crosses [-0.38, 1] and [0.62, 1]: 1.38 + 0.38 of 2 * bands boundaries per unit


@pytest.mark.gl
@pytest.mark.parametrize("kind, scale", [("mean", 1.0), ("gaussian", 1.0), ("k1", 0.8), ("k2", 2.0),
                                         ("max", 0.3)])
def test_curvature_of_a_sphere_is_the_color_the_glsl_predicts(kind, scale, tmp_path):
    # radius 2: (H, K) = (1/2, 1/4) everywhere; the curvature output is unlit, so every pixel of the disc
    # has the same colour (lights in the Style do not enter an output mode)
    mesh = _sphere(2.0, resolution=64)
    mesh.point_data["curvature"] = np.tile([0.5, 0.25], (mesh.n_points, 1))
    style = Style(lights=3, reflection_lines=6, output="curvature", curvature=kind, curvature_scale=scale)
    img, actor = _render(mesh, style, save=tmp_path / "curvature.png")
    expected = _curvature_color(np.array(0.5), np.array(0.25), kind, scale)
    x, y = _pixel_plane()
    inside = x**2 + y**2 < 2.0**2  # the radius-2 sphere covers the whole window
    assert inside.all()
    assert np.abs(img[inside] - expected).max() <= 1.0 / 255 + 1e-9, (img[SIZE // 2, SIZE // 2], expected)
    assert "sv_reflection_lines" not in actor.program_sources["fragment"]  # an output mode replaces shading


@pytest.mark.gl
def test_curvature_is_interpolated_per_vertex():
    # H = z / 2 at each vertex (K = 0): linear in z, so the interpolated value is exact at every fragment and
    # a side view shows the diverging map from blue (bottom) through white to red (top)
    mesh = _sphere(1.0, resolution=120)
    mesh.point_data["curvature"] = np.column_stack([mesh.points[:, 2] / 2, np.zeros(mesh.n_points)])
    img, _ = _render(mesh, Style(output="curvature", curvature_scale=0.5), eye=(10.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))
    x, y = _pixel_plane()  # y is world z in this view
    inside = x**2 + y**2 < 0.97**2
    expected = _curvature_color(y / 2, np.zeros_like(y), "mean", 0.5)
    assert np.abs(img - expected)[inside].max() < 3.0 / 255
    assert img[SIZE // 2 - 90, SIZE // 2, 0] > img[SIZE // 2 + 90, SIZE // 2, 0]  # red above, blue below


@pytest.mark.gl  # a Plotter (nothing is rendered)
@pytest.mark.parametrize("make, match", [
    (lambda m: m,
     r"'curvature' of \(mean H, Gaussian K\) per vertex; this mesh has none\. .*mesh\.curvature\('mean'\)"),
    (lambda m: m.point_data.update({"curvature": np.zeros(m.n_points)}) or m, r"must be \(\d+, 2\) finite"),
    (lambda m: m.point_data.update({"curvature": np.full((m.n_points, 2), np.nan)}) or m, "non-finite"),
    (lambda m: m.cell_data.update({"curvature": np.zeros((m.n_cells, 2))}) or m, "it is cell data"),
])
def test_a_mesh_without_its_curvature_is_refused(make, match):
    pl = splinevis.Plotter(off_screen=True, window_size=(32, 32))
    try:
        with pytest.raises(ValueError, match=match):
            add_mesh_with_effects(pl, make(pv.Sphere()), Style(output="curvature"))
        assert pl.renderer.GetActors().GetNumberOfItems() == 0
    finally:
        pl.close()


@pytest.mark.gl
@pytest.mark.parametrize("style, present, absent", [
    (Style(lights=1, isophotes=4),
     ["sv_isophotes(", "uniform vec3 sv_light_dir[", "#define SV_NUM_LIGHTS 1", "#define SV_ISOPHOTES"],
     ["sv_reflection_lines", "sv_curvature_color", "svMeshCurvature"]),
    (Style(lights=2, reflection_lines=8), ["sv_reflection_lines("], ["sv_isophotes", "sv_light_dir", "sv_curvature"]),
    (Style(lights=2, reflection_lines=8, isophotes=3, opacity=0.6), ["sv_reflection_lines(", "sv_isophotes("],
     ["sv_curvature"]),
    (Style(output="curvature"), ["sv_curvature_color(", "svMeshCurvatureVS"],
     ["sv_isophotes", "sv_reflection_lines", "sv_light_dir"]),
])
def test_effect_code_is_compiled_in_only_when_declared(style, present, absent):
    mesh = _sphere(1.0, resolution=32)
    mesh.point_data["curvature"] = np.tile([1.0, 1.0], (mesh.n_points, 1))
    pl = splinevis.Plotter(off_screen=True, window_size=(48, 48))
    actor = add_mesh_with_effects(pl, mesh, style)
    img = pl.screenshot()
    pl.close()
    src = actor.program_sources["fragment"]
    assert [s for s in present if s not in src] == []
    assert [s for s in absent if s in src] == []
    assert img.std() > 10  # drawn, not blank
    if "sv_curvature_color(" not in present:
        assert "svMeshCurvature" not in actor.program_sources["vertex"]


@pytest.mark.gl
def test_effects_combine_and_unlit_meshes_keep_their_stripes():
    # lights + reflection lines + isophotes: both stripe families multiply into the lighting; lights=0 draws
    # the base colour (VTK declares no normals then: the mesh's own normals reach the shader regardless)
    mesh = _sphere(1.0, resolution=120)
    both, _ = _render(mesh, Style(lights=1, reflection_lines=6, isophotes=3, color="white", ambient=1.0, diffuse=0.0))
    zebra, _ = _render(mesh, Style(lights=1, reflection_lines=6, color="white", ambient=1.0, diffuse=0.0))
    unlit, _ = _render(mesh, Style(lights=0, reflection_lines=6, color="white"))
    x, y = _pixel_plane()
    inside = x**2 + y**2 < 0.95**2
    levels = np.round(both.sum(-1)[inside] / 3, 2)
    # products of the two families' factors: 1, 0.2 (isophote), 0.15 (stripe), 0.03 (both)
    for level in (1.0, 0.2, 0.15, 0.03):
        assert (np.abs(levels - level) < 0.015).mean() > 0.03, level
    assert np.abs(zebra - unlit)[inside].max() < 2.0 / 255  # white at ambient 1 == unlit white


@pytest.mark.gl
def test_reflection_lines_keep_their_public_function():
    # a study's call: pyvista colours as 0..255 triples, flat white stripes (ambient 1) 1.0 and 0.15 on black
    pl = splinevis.Plotter(off_screen=True, window_size=(64, 64))
    pl.set_background("black")
    actor = add_mesh_with_reflection_lines(pl, pv.Sphere(), 8, color=(255, 255, 255), ambient=1.0, diffuse=0.0,
                                           antialias=False)  # the plain step: two colours exactly
    img = pl.screenshot().astype(int)
    pl.close()
    assert "sv_reflection_lines(" in actor.program_sources["fragment"]
    counts = {v: int(np.count_nonzero(img.sum(-1) == v)) for v in (0, 3 * round(0.15 * 255), 765)}
    assert min(counts.values()) > 200, counts
    with pytest.raises(ValueError, match="stripes must be a positive integer"):
        add_mesh_with_reflection_lines(pl, pv.Sphere(), 0)


def test_the_callers_mesh_is_not_moved():
    """The mesh is drawn relative to its centre on a copy with its own points: the caller's mesh (drawn again in
    another panel, as the showcase does) keeps its coordinates."""
    import pyvista as pv

    import splinevis
    from splinevis.gl.mesh_effects import add_mesh_with_reflection_lines

    mesh = pv.Sphere(center=(5.0, -3.0, 2.0))
    before = np.array(mesh.points, copy=True)
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    add_mesh_with_reflection_lines(pl, mesh, 8)
    pl.close()
    np.testing.assert_array_equal(np.asarray(mesh.points), before)

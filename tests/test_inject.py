"""The VTK side: injection, compositing with meshes, effects compiled on demand, errors. Needs GL (llvmpipe)."""

import numpy as np
import pytest
import pyvista as pv

import splinevis
from splinevis import Style
from splinevis.analysis.composite import UNLIT, front_surface_agreement
from splinevis.analytic import QuarticTrianglePatch
from splinevis.errors import ShaderCompileError
from splinevis.studies.demo import composite_scene

pytestmark = pytest.mark.gl


def test_raycast_surface_and_mesh_occlude_each_other_both_ways():
    r = front_surface_agreement(*composite_scene((400, 300), style=UNLIT)[:2])
    sphere_in_front, patch_in_front = r["both_ways"]
    # The scene is built so that each surface hides the other over a sizeable area.
    assert sphere_in_front > 500 and patch_in_front > 500
    assert r["compared"] > 10_000
    assert r["agreement"] >= 0.999, f"{r['disagree_count']} of {r['compared']} pixels disagree"


def _fragment_source(style):
    pl, _, actor = composite_scene((64, 48), style=style, sphere=False)
    pl.screenshot()
    src = actor.program_sources["fragment"]
    pl.close()
    return src, actor


@pytest.mark.parametrize("effect, style, marker", [
    ("reflection_lines", dict(reflection_lines=6), "sv_reflection_lines"),
    ("isophotes", dict(isophotes=6), "sv_isophotes"),
    ("specular", dict(specular=True), "sv_specular_power"),
    ("colormap", dict(colormap="viridis"), "sv_colormap_tex"),
    ("normals", dict(output="normals"), "sv_normal_color"),
    ("curvature", dict(output="curvature"), "sv_curvature_color"),
])
def test_undeclared_effect_compiles_no_code_of_it(effect, style, marker):
    with_src, actor = _fragment_source(style)
    without_src, _ = _fragment_source(dict(lights=1))
    assert marker in with_src            # the final program VTK compiled contains the effect ...
    assert marker not in without_src     # ... and a scene without it compiles none of it
    assert any(effect in f or marker in f for f in actor.assembled.files) or marker in actor.assembled.text


def test_same_effect_set_shares_one_compiled_program():
    pl = splinevis.Plotter(off_screen=True, window_size=(64, 48))
    a = pl.add_spline(QuarticTrianglePatch.demo(), lights=2, color="red")
    b = pl.add_spline(QuarticTrianglePatch.demo(), lights=2, color="blue")
    c = pl.add_spline(QuarticTrianglePatch.demo(), lights=2, specular=True)
    pl.screenshot()
    pl.close()
    assert a.assembled is b.assembled and a.assembled is not c.assembled
    assert a.program_ids == b.program_ids and a.program_ids != c.program_ids


def test_every_effect_renders_something_different():
    images = {}
    for name, style in [("plain", dict(lights=1)), ("lines", dict(reflection_lines=8)), ("normals", dict(output="normals")),
                        ("cmap", dict(colormap="viridis", lights=1))]:
        pl, _, _ = composite_scene((120, 90), style=style, sphere=False)
        images[name] = pl.screenshot().astype(int)
        pl.close()
    background = np.all(images["plain"] == 255, axis=-1)
    assert (~background).mean() > 0.1
    for name in ("lines", "normals", "cmap"):
        assert np.abs(images[name] - images["plain"])[~background].mean() > 10, name


def test_broken_glsl_raises_with_log_and_source(tmp_path, monkeypatch):
    import splinevis.gl.assembler as asm

    root = tmp_path / "glsl"
    import shutil

    shutil.copytree(asm.glsl_root(), root)
    bad = root / "lib" / "effects" / "isophotes.glsl"
    bad.write_text(bad.read_text().replace("return fract", "return undeclared_thing + fract"))
    monkeypatch.setattr(asm, "glsl_root", lambda: root)
    asm._assemble_cached.cache_clear()
    try:
        pl = splinevis.Plotter(off_screen=True, window_size=(64, 48))
        pl.add_spline(QuarticTrianglePatch.demo(), isophotes=4)
        with pytest.raises(ShaderCompileError, match="undeclared_thing") as info:
            pl.screenshot()
        pl.close()
    finally:
        asm._assemble_cached.cache_clear()
    err = info.value
    assert err.stage == "fragment"
    assert any(where and where.startswith("lib/effects/isophotes.glsl:") for _, _, where in err.locations)
    assert "undeclared_thing + fract" in str(err)


def test_add_spline_rejects_unknown_options_and_models():
    pl = splinevis.Plotter(off_screen=True, window_size=(32, 32))
    with pytest.raises(TypeError, match="'reflection_line' \\(did you mean 'reflection_lines'\\?\\)"):
        pl.add_spline(QuarticTrianglePatch.demo(), reflection_line=3)
    with pytest.raises(TypeError, match="no spline program draws a PolyData"):
        pl.add_spline(pv.Sphere())
    with pytest.raises(ValueError, match="newton_iterations must be in 1..8, got 9"):
        pl.add_spline(QuarticTrianglePatch.demo(), newton_iterations=9)
    pl.close()


def test_camera_inside_the_proxy_still_sees_the_surface():
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    patch = QuarticTrianglePatch.demo()
    pl.add_spline(patch, lights=0, color=(1.0, 0.0, 0.0))
    # Inside the prism, above the surface at the centroid, looking down and sideways.
    c = patch.vertices.mean(axis=0)
    z = float(patch.evaluate(c)) + 0.02
    assert z < patch.zrange[1]
    pl.camera_position = [(c[0], c[1], z), (c[0] + 0.3, c[1], z - 0.3), (0, 0, 1)]
    pl.camera.clipping_range = (1e-3, 10.0)
    img = pl.screenshot()
    pl.close()
    red = (img[..., 0] > 200) & (img[..., 1] < 60)
    assert red.mean() > 0.3


def test_float_texture_and_vertex_attribute_path_gives_the_same_image():
    images = []
    for where in ("uniform", "texture"):
        pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
        pl.set_background("white")
        pl.add_spline(QuarticTrianglePatch.demo(), lights=1, program_options={"coefficients_in": where})
        from splinevis.studies.demo import CAMERA

        pl.camera_position = CAMERA
        pl.reset_camera_clipping_range()
        images.append(pl.screenshot().astype(int))
        pl.close()
    surface = ~np.all(images[0] == 255, axis=-1)
    assert surface.mean() > 0.1
    # Same float32 coefficients either way (RGBA32F texels are exact copies), so the same pixels.
    assert np.array_equal(images[0], images[1])


def test_depth_buffer_before_any_render_renders_first():
    # reading the framebuffer of a window never rendered returned uninitialised memory (NaN and garbage)
    pl = splinevis.Plotter(off_screen=True, window_size=(64, 48))
    pl.add_spline(QuarticTrianglePatch.demo())
    depth = pl.depth_buffer()
    pl.close()
    assert np.isfinite(depth).all() and depth.max() == 1.0 and 0.0 < depth.min() < 1.0

"""Style: effect sets decide code, parameters are uniforms; bad input is named (no GPU needed)."""

import numpy as np
import pytest

from splinevis import Style
from splinevis.effects import EFFECTS


def test_effect_set_and_defines_follow_declarations():
    s = Style(lights=3, specular=True, colormap="viridis", reflection_lines=8, antialias=False)
    assert s.effect_set() == {"lights", "specular", "colormap", "reflection_lines"}
    assert s.defines() == {"SV_NUM_LIGHTS": 3, "SV_SPECULAR": True, "SV_COLORMAP": True, "SV_REFLECTION_LINES": True}
    assert s.include_files() == ["lib/effects/lights.glsl", "lib/effects/colormap.glsl", "lib/effects/reflection_lines.glsl"]
    # the stripes' filter is on by default, and compiled in only with a stripe effect
    assert s.replace(antialias=True).defines()["SV_ANTIALIAS"] is True
    assert "antialias" not in Style(lights=3, colormap="viridis").effect_set()


def test_unlit_style_declares_nothing():
    assert Style(lights=0).effect_set() == frozenset()
    assert Style(lights=0).include_files() == []


def test_parameters_do_not_change_the_effect_set():
    a = Style(lights=2, color="red", ambient=0.3)
    b = Style(lights=2, color=(0.1, 0.2, 0.3), ambient=0.1)
    assert a.effect_set() == b.effect_set() and a.defines() == b.defines()
    assert a.uniforms()["sv_color"] == (1.0, 0.0, 0.0)


def test_every_effect_has_a_file_and_a_flag():
    from splinevis.gl.assembler import glsl_root

    for name, (flag, path) in EFFECTS.items():
        assert flag.startswith("SV_")
        assert (glsl_root() / path).is_file(), name


@pytest.mark.parametrize("kwargs, match", [
    (dict(lights=5), r"lights must be an integer in 0..4, got 5"),
    (dict(lights=0, specular=True), "needs at least one light"),
    (dict(colormap="no_such_map"), "'no_such_map' is not a matplotlib colormap"),
    (dict(color="notacolour"), "'notacolour' is not a colour name"),
    (dict(color=(2.0, 0.0, 0.0)), r"RGB components in \[0, 1\]"),
    (dict(color=(np.nan, 0.0, 0.0)), "finite"),
    (dict(output="wireframe"), "output 'wireframe' is not known"),
    (dict(reflection_lines=0), "positive integer"),
    (dict(texture=np.zeros((4, 4), np.uint8)), r"\(H, W, 3 or 4\) uint8"),
    (dict(scalar_range=(1.0, 0.0)), "low < high"),
    (dict(antialias="yes"), "antialias must be True or False"),
])
def test_bad_style_input_is_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Style(**kwargs)


def test_replace_rejects_unknown_fields():
    with pytest.raises(TypeError, match=r"no field\(s\) \['reflection'\]"):
        Style().replace(reflection=3)


def test_output_modes_compile_nothing_else():
    s = Style(lights=3, specular=True, reflection_lines=5, output="normals")
    assert s.effect_set() == {"normals"}
    assert s.include_files() == ["lib/effects/normals.glsl"]


@pytest.mark.gl
def test_mesh_reflection_lines_match_the_ray_cast_sphere():
    # The same stripes GLSL on a fine sphere mesh (interpolated normals) and on a ray-cast spline sphere: the
    # normals differ by the mesh's and the spline's approximation errors (< 1 deg here), so only pixels near
    # stripe boundaries may differ; 8 stripes over this disc put ~1/30 of the pixels within 1 deg of a boundary.
    import pyvista as pv

    import splinevis
    from splinevis.gl.mesh_effects import add_mesh_with_reflection_lines
    from splinevis.io.volumes import VolumeGrid

    x = np.linspace(-1, 1, 40)
    z, y, xx = np.meshgrid(x, x, x, indexing="ij")
    grid = VolumeGrid(np.sqrt(xx**2 + y**2 + z**2), spacing=(2 / 39,) * 3, origin=(-1, -1, -1))
    dark, grey = [], []
    for kind in ("mesh", "spline"):
        pl = splinevis.Plotter(off_screen=True, window_size=(240, 180))
        pl.set_background("white")
        if kind == "mesh":
            add_mesh_with_reflection_lines(pl, pv.Sphere(radius=0.7, theta_resolution=200, phi_resolution=200), 8,
                                           ambient=1.0, diffuse=0.0)
        else:
            pl.add_isosurface(grid, 0.7, lights=0, reflection_lines=8, color="tan")
        pl.camera_position = [(3, 2, 1.5), (0, 0, 0), (0, 0, 1)]
        pl.camera.clipping_range = (0.5, 10)
        img = pl.screenshot().astype(int)
        pl.close()
        dark.append((img.sum(-1) < 300, img.sum(-1) < 760))
        grey.append(img.sum(-1) / 3.0)
    fg = dark[0][1] | dark[1][1]
    assert fg.sum() > 5000
    assert 0.35 < dark[0][0][fg].mean() < 0.65  # stripes, not a uniform surface
    # Both filtered over the pixel (the default): a pixel's grey moves with the share of it each stripe
    # covers, so the normals' < 1 deg difference moves it by more than a quarter of the dark-bright range
    # only where an edge passes within that angle of it: the ~1/30 of the pixels above.
    bright_minus_dark = 0.85 * (210 + 180 + 140) / 3  # tan, bright (1) minus dark (0.15)
    assert (np.abs(grey[0] - grey[1]) < 0.25 * bright_minus_dark)[fg].mean() > 0.95

"""The NURBS fragment program (glsl/programs/nurbs.glsl) against its float64 twin (splinevis/nurbs/raycast.py):
normals per pixel, silhouettes of a sphere and a torus. The hard cases (depths per pixel within the derived
bound) run with every other program's in tests/test_program_hard_cases.py."""

import numpy as np
import pytest

import splinevis
from splinevis import programs
from splinevis.gl.camera import pixel_rays
from splinevis.nurbs.exact import sphere, torus
from splinevis.nurbs.model import NurbsModel
from splinevis.nurbs.program import PROGRAM, nurbs_program

pytestmark = pytest.mark.gl

def _render(model, camera, size=(160, 120), **style):
    pl = splinevis.Plotter(off_screen=True, window_size=size)
    actor = pl.add_spline(model, **style)
    pl.camera_position = camera
    pl.reset_camera_clipping_range()
    img = pl.screenshot()
    depth, matrix = pl.depth_buffer(), pl.camera_matrix()
    pl.close()
    return actor, img, depth, matrix


def test_nurbs_is_registered_as_a_surface_program():
    program = programs.get("nurbs")
    assert program is PROGRAM and program.kind == "surface"
    assert programs.program_for(NurbsModel([sphere()])) is PROGRAM
    assert PROGRAM.model_from(torus()).names == ("torus",)


@pytest.mark.parametrize("name, model, camera", [
    ("sphere", NurbsModel([sphere()]), [(3.0, -4.0, 2.5), (0, 0, 0), (0, 0, 1)]),
    ("torus", NurbsModel([torus()]), [(4.0, -5.0, 3.0), (0, 0, 0), (0, 0, 1)]),
])
def test_sphere_and_torus_are_drawn_with_the_twins_silhouette(name, model, camera, tmp_path):
    actor, img, depth, matrix = _render(model, camera, lights=1, color="tan")
    import imageio

    imageio.imwrite(tmp_path / f"{name}.png", img)
    assert "sv_surface_eval" in actor.program_sources["fragment"]
    gpu_hit = depth < 1.0
    assert gpu_hit.mean() > 0.2 and img[gpu_hit].std() > 10  # shaded, not blank or flat
    o, d = pixel_rays(matrix, *img.shape[1::-1])
    ref_hit = PROGRAM.raycast(model, o, d).hit
    assert (gpu_hit != ref_hit).sum() <= 0.001 * gpu_hit.size


def test_normals_per_pixel_match_the_twin():
    model = NurbsModel([torus()])
    camera = [(4.0, -5.0, 3.0), (0, 0, 0), (0, 0, 1)]
    _, img, depth, matrix = _render(model, camera, output="normals")
    o, d = pixel_rays(matrix, *img.shape[1::-1])
    ref = PROGRAM.raycast(model, o, d)
    both = (depth < 1.0) & ref.hit
    gpu_n = img[both, :3].astype(float) / 255.0 * 2.0 - 1.0
    ref_n = ref.normals[both] / np.linalg.norm(ref.normals[both], axis=-1, keepdims=True)
    cos = np.abs(np.einsum("ij,ij->i", gpu_n / np.linalg.norm(gpu_n, axis=-1, keepdims=True), ref_n))
    assert both.sum() > 3000
    assert np.quantile(cos, 0.999) > 0.999 and cos.min() > 0.99  # 8-bit colours: about 1/128 per component


def test_options_are_checked():
    with pytest.raises(ValueError, match="newton_iterations must be 1..16"):
        nurbs_program(NurbsModel([sphere()]), newton_iterations=0)
    with pytest.raises(TypeError, match="has no option 'roots'"):
        PROGRAM.make(NurbsModel([sphere()]), None, roots="paper")


@pytest.mark.parametrize("kind", ["gaussian", "mean"])
def test_curvature_per_pixel_matches_the_exact_torus(kind):
    # torus R = 2, r = 0.5: K = cos(phi) / (r (R + r cos phi)), H = -(R + 2 r cos phi) / (2 r (R + r cos phi))
    # (outward normal), with cos(phi) = (rho - R) / r at the twin's hit point. The colour encodes value /
    # scale on a white-red (positive) or white-blue (negative) ramp in 8 bits: decoding the channel that
    # falls (green 0.98, red 0.77 per unit) is good to 1/255 / 0.77 of the scale; the program's float32
    # curvature adds far less. The sign of H depends on the normal's orientation: compared in magnitude.
    R, r = 2.0, 0.5
    model = NurbsModel([torus(R, r)])
    scale = 1.5
    camera = [(4.0, -5.0, 3.0), (0, 0, 0), (0, 0, 1)]
    _, img, depth, matrix = _render(model, camera, output="curvature", curvature=kind, curvature_scale=scale)
    o, d = pixel_rays(matrix, *img.shape[1::-1])
    ref = PROGRAM.raycast(model, o, d)
    from scipy import ndimage

    both = ndimage.binary_erosion((depth < 1.0) & ref.hit, iterations=2)
    p = ref.points[both]
    c = (np.hypot(p[:, 0], p[:, 1]) - R) / r
    want = c / (r * (R + r * c)) if kind == "gaussian" else (R + 2 * r * c) / (2 * r * (R + r * c))
    col = img[both, :3].astype(float) / 255.0
    positive = col[:, 2] < col[:, 0]  # red side
    x = np.where(positive, (1 - col[:, 1]) / 0.98, -(1 - col[:, 0]) / 0.77)
    got = np.clip(x, -1, 1) * scale
    ok = np.abs(want) < 0.98 * scale  # not clamped
    assert both.sum() > 3000 and ok.sum() > 1000
    err = np.abs((got if kind == "gaussian" else np.abs(got)) - (want if kind == "gaussian" else np.abs(want)))[ok]
    assert err.max() <= 1.5 / 255 / 0.77 * scale


def test_a_single_surface_is_drawn_as_a_one_patch_model():
    assert programs.program_for(torus()) is PROGRAM  # NurbsSurface: converted by the program's model_from
    actor, img, depth, _ = _render(torus(), [(4.0, -5.0, 3.0), (0, 0, 0), (0, 0, 1)], lights=1)
    assert isinstance(actor.model, NurbsModel) and actor.model.names == ("torus",)
    assert (depth < 1.0).mean() > 0.2


def test_the_certified_shell_push_is_at_least_the_densely_sampled_chord_deviation():
    # the shell's push is the Bernstein bound of S - L over each cell (shell.certified_deviation): it must
    # exceed the deviation sampled at 32 x 32 points on every cell of the test models (a bound can't be beaten
    # by a sample); and it stays within 10x of it (not uselessly loose)
    from datasets_synthetic.nurbs_models import degree_patch, hood, vase
    from splinevis.nurbs.hard_cases import crease, degree7
    from splinevis.nurbs.shell import _chord_deviation, certified_deviation
    from splinevis.nurbs.tessellate import span_grid

    models = [sphere(), torus(), crease(), degree7(), hood(), degree_patch(5)] + list(vase().surfaces[:8])
    for s in models:
        us, vs = span_grid(s, 8)
        bound, dense = certified_deviation(s, us, vs), _chord_deviation(s, us, vs, 1.0, k=32)
        assert (bound >= dense).all(), s.name
        assert (bound <= 10 * dense + 1e-9 * np.abs(s.control_points).max()).all(), s.name

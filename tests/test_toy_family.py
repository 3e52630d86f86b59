"""A family from the tests folder joins splinevis through the registry alone: drawn by add_spline, checked
per pixel against its float64 twin on its hard cases, listed by the self-test, removed again. No package file
knows it (docs/architecture.md)."""

import numpy as np
import pytest

import splinevis
from splinevis import programs
from splinevis.analysis.agreement import agreement_failures, hard_case_agreement
from splinevis.selftest import program_hard_cases

from toy_family import MESH, RAYCAST, ToyMeshSphere, ToySphere, build

pytestmark = pytest.mark.gl


@pytest.fixture
def toys():
    programs.register(RAYCAST)
    programs.register(MESH)
    yield
    programs.unregister(RAYCAST.name)
    programs.unregister(MESH.name)


def test_toy_raycast_family_draws_and_matches_its_twin(toys):
    assert programs.program_for(ToySphere()) is RAYCAST
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = pl.add_spline(ToySphere(), lights=1, color="tan")
    pl.camera_position = [(3.0, -4.0, 2.0), (0.0, 0.0, 0.0), (0, 0, 1)]
    img = pl.screenshot()
    assert actor.program is RAYCAST and "sv_toy_radius" in actor.program_sources["fragment"]
    assert (pl.depth_buffer() < 1).sum() > 2000 and img.std() > 10
    pl.close()
    for case in RAYCAST.hard_cases():
        r = hard_case_agreement(case)
        assert agreement_failures(r, case) == [], case.name


def test_selftest_runs_registered_families(toys):
    # only the toys' cases (the built-in families' run in tests/test_program_hard_cases.py); the mesh toy's
    # would be named if the selftest took programs without a float64 twin
    only = {f"toy_sphere/{c.name}" for c in RAYCAST.hard_cases()} | {"toy_mesh_sphere/front"}
    report = program_hard_cases(progress=False, only=only)
    assert set(report["toy_sphere"]) == {c.name for c in RAYCAST.hard_cases()}
    assert all(row["pass"] for row in report["toy_sphere"].values())
    assert "toy_mesh_sphere" not in report  # no float64 ray caster: nothing to compare per pixel


def test_toy_mesh_family_is_drawn_as_a_mesh_with_effects(toys):
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = pl.add_spline(ToyMeshSphere(), reflection_lines=8, program_options={"resolution": 48})
    pl.camera_position = [(3.0, -4.0, 2.0), (0.0, 0.0, 0.0), (0, 0, 1)]
    img = pl.screenshot().astype(int)
    assert actor.GetMapper().GetInput().GetNumberOfPoints() == 48 * 46 + 2
    assert (pl.depth_buffer() < 1).sum() > 2000
    assert img[..., 0].std() > 20  # stripes, not a flat disc
    pl.close()
    with pytest.raises(ValueError, match="cannot show the effects colormap"):
        pl2 = splinevis.Plotter(off_screen=True, window_size=(40, 30))
        try:
            pl2.add_spline(ToyMeshSphere(), colormap="viridis")
        finally:
            pl2.close()


def test_registry_refuses_bad_programs_and_duplicates(toys):
    with pytest.raises(ValueError, match="registered already"):
        programs.register(RAYCAST)
    bad = RAYCAST.__class__(name="toy_bad", kind="raycast", model_type=ToySphere, build=lambda m: None,
                            reference=RAYCAST.reference, depth_bound=RAYCAST.depth_bound)
    with pytest.raises(TypeError, match="does not follow the contract"):
        programs.register(bad)
    with pytest.raises(ValueError, match="kind must be one of raycast, surface, passes, mesh"):
        RAYCAST.__class__(name="x", kind="shader", model_type=ToySphere, build=build)
    with pytest.raises(ValueError, match="needs its float64 twin"):
        RAYCAST.__class__(name="x", kind="raycast", model_type=ToySphere, build=build)
    with pytest.raises(TypeError, match="has no option 'radius'"):
        splinevis.Plotter(off_screen=True).add_spline(ToySphere(), program_options={"radius": 2})


def test_after_unregistering_the_toy_is_unknown():
    with pytest.raises(TypeError, match="no spline program draws a ToySphere"):
        programs.program_for(ToySphere())
    assert [p.name for p in programs.all_programs()] == ["analytic_patch", "terrain", "isosurface", "nurbs_lod", "nurbs",
                                                          "geometry_image"]


def test_every_builtin_program_follows_the_contract():
    for p in programs.all_programs():
        assert p.signature_problems() == [], p.name
        assert p.kind in ("raycast", "surface", "passes", "mesh")
        assert p.hard_cases is not None and len(p.hard_cases()) >= 3, p.name


def test_toy_surface_family_evaluates_per_fragment():
    # The "surface" kind: the fragment evaluates S(u, v) at the interpolated parameters and writes its depth.
    # For a parallelogram the mesh is the surface, so the depth buffer must equal the float64 window depth of
    # the plane hit of every pixel's ray (within float32 arithmetic on coordinates of size ~2: 1e-6) and the
    # normals output must show the plane's normal.
    from splinevis.gl.camera import pixel_rays, window_depth

    from toy_family import SURFACE, ToyPlane

    programs.register(SURFACE)
    try:
        plane = ToyPlane()
        pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
        actor = pl.add_spline(plane, output="normals")
        pl.camera_position = [(2.0, -3.0, 3.0), (0.0, 0.0, 0.2), (0, 0, 1)]
        pl.reset_camera_clipping_range()
        img = pl.screenshot().astype(float) / 255
        depth = pl.depth_buffer()
        matrix = pl.camera_matrix()
        pl.close()
    finally:
        programs.unregister(SURFACE.name)
    assert actor.kind == "surface" and "sv_surface_eval" in actor.program_sources["fragment"]
    o, d = pixel_rays(matrix, 160, 120)
    n = np.cross(plane.e1, plane.e2)
    t = ((plane.p0 - o) @ n) / (d @ n)
    ref = window_depth(matrix, o + t[..., None] * d)
    drawn = depth < 1
    assert drawn.sum() > 3000
    assert np.abs(depth[drawn] - ref[drawn]).max() < 1e-5
    unit = n / np.linalg.norm(n)
    expected = 0.5 * (unit + 1)  # normal-colour convention of lib/effects/normals.glsl (faces the viewer here)
    assert np.abs(img[drawn] - expected).max() < 2.5 / 255

"""A family from the tests folder joins splinevis through the registry alone: drawn by add_spline, checked
per pixel against its float64 twin on its hard cases, listed by the self-test, drawn the cheapest way its own
declared renderers allow for a requested screen-space error, removed again. No package file knows it
(docs/architecture.md)."""

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


def test_toy_mesh_bound_holds_and_is_attained():
    # toy_family/renderers.py: every point of a triangle inscribed in the sphere is within the sagitta
    # r - sqrt(r^2 - rho^2) of the sphere, attained at the circumcentre of a triangle that contains it (the
    # quads between two circles of latitude are cyclic: one of their two triangles holds the centre). The
    # distances are float64 from float32 vertices (|v| = r within 5e-8 r, measured): 1e-6 r covers them.
    from toy_family.renderers import sagitta_bounds, sphere_mesh, world_error

    rng = np.random.default_rng(3)
    model = ToySphere(2.0, (1.0, -2.0, 0.5))
    for n in (8, 16, 32):
        mesh = sphere_mesh(model, n)
        tri = np.asarray(mesh.points, dtype=np.float64)[mesh.faces.reshape(-1, 4)[:, 1:]]
        sag = sagitta_bounds(model, mesh)
        lam = rng.dirichlet(np.ones(3), (len(tri), 64))
        pts = np.einsum("tsi,tij->tsj", lam, tri)
        dist = model.radius - np.linalg.norm(pts - model.center, axis=2)
        assert (dist <= sag[:, None] + 1e-6 * model.radius).all() and (dist > -1e-6 * model.radius).all()
        assert world_error(model, n) >= sag.max()
        # circumcentres: the foot of the centre on each triangle's plane; inside the triangle -> attained
        e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        normal = np.cross(e1, e2)
        foot = model.center + np.einsum("ti,ti->t", tri[:, 0] - model.center, normal)[:, None] * normal / (
            np.einsum("ti,ti->t", normal, normal)[:, None])
        gram = np.stack([np.stack([(e1 * e1).sum(1), (e1 * e2).sum(1)], 1), np.stack([(e1 * e2).sum(1), (e2 * e2).sum(1)], 1)], 1)
        rhs = np.stack([((foot - tri[:, 0]) * e1).sum(1), ((foot - tri[:, 0]) * e2).sum(1)], 1)
        uv = np.linalg.solve(gram, rhs[..., None])[..., 0]
        inside = (uv >= -1e-9).all(1) & (uv.sum(1) <= 1 + 1e-9)
        attained = (model.radius - np.linalg.norm(foot[inside] - model.center, axis=1)).max()
        assert attained == pytest.approx(sag.max(), abs=1e-6 * model.radius)


def _silhouette(actor_maker, camera):
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    pl.camera_position = camera
    actor = actor_maker(pl)
    pl.camera.clipping_range = (1.0, 10.0)
    pl.render()
    mask = pl.depth_buffer() < 1
    pl.close()
    return actor, mask


def test_toy_declares_its_renderers_and_add_spline_chooses_among_them(toys):
    # Plotter.add_spline(model, max_error_px=...) walks the toy's own renderers (toy_family/renderers.py): a
    # request its mesh's proven bound meets draws the smallest such mesh; one nothing meets draws the exact
    # ray cast, and renderer_choice says so.
    from scipy.ndimage import binary_dilation

    from toy_family.renderers import sphere_mesh

    camera = [(3.0, -4.0, 2.0), (0.0, 0.0, 0.0), (0, 0, 1)]
    mesh_actor, mesh_mask = _silhouette(lambda pl: pl.add_spline(ToySphere(), max_error_px=2.0, lights=1), camera)
    c = mesh_actor.renderer_choice
    assert (c.renderer, c.level, c.meets, c.chosen.proven) == ("mesh", 32, True, True), c.message
    assert [o.level for o in c.options if o.name == "mesh"] == [8, 16, 32]
    assert all(o.error_px > 2.0 for o in c.options if o.name == "mesh" and o.level < 32)
    assert mesh_actor.GetMapper().GetInput().GetNumberOfCells() == sphere_mesh(ToySphere(), 32).n_cells
    assert "considered: mesh k=8" in c.message and "raycast" in c.message

    exact_actor, exact_mask = _silhouette(lambda pl: pl.add_spline(ToySphere(), max_error_px=1e-3, lights=1), camera)
    c = exact_actor.renderer_choice
    assert c.renderer == "raycast" and not c.meets and "nothing meets max_error_px=0.001" in c.message, c.message
    assert exact_actor.program is RAYCAST and [o.level for o in c.options if o.name == "mesh"] == [8, 16, 32, 64, 128, 256]
    # the pictures agree within the mesh's bound: every point of it moves at most e = 0.71 px, so a pixel
    # covered by one silhouette is within e + sqrt(2) (the nearest covered pixel centre of a blob ~40 px
    # across) of one covered by the other: chessboard dilation by ceil(e + 1.5) contains it
    k = int(np.ceil(mesh_actor.renderer_choice.error_px + 1.5))
    eight = np.ones((3, 3), bool)
    assert exact_mask.sum() > 3000
    assert not (mesh_mask & ~binary_dilation(exact_mask, eight, k)).any()
    assert not (exact_mask & ~binary_dilation(mesh_mask, eight, k)).any()


def test_a_program_without_renderers_is_drawn_by_its_own(toys):
    # the mesh toy and the surface toy declare none: the choice draws their own program and says so (their
    # error unknown: no float64 twin, so no request is met); the plane has no bounds: the default camera is
    # fitted to what its program builds
    from toy_family import SURFACE, ToyPlane

    programs.register(SURFACE)
    try:
        for model, kind in ((ToyMeshSphere(), "mesh"), (ToyPlane(), "surface")):
            pl = splinevis.Plotter(off_screen=True, window_size=(80, 60))
            actor = pl.add_spline(model, max_error_px=1.0)
            c = actor.renderer_choice
            assert (c.renderer, c.meets) == (kind, False)
            assert "declares no renderers: drawn by its own" in c.message and "error unknown" in c.message
            assert (pl.depth_buffer() < 1).sum() > 300
            pl.close()
    finally:
        programs.unregister(SURFACE.name)

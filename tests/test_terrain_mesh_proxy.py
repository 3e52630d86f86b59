"""The terrain's mesh proxy (option proxy="mesh": splinevis.terrain.mesh_proxy, glsl/lib/terrain/mesh_guided.glsl):
the lifted mesh lies above the spline, the default program is unchanged, the eye-inside build is compiled only
while the eye may be inside, and on the GPU a selection of the terrain's hard cases (those the tracing found
hardest while it was built: grazing, flat, underside, C0 cliffs) agrees with the float64 twin as the box proxy's
ray cast does (7 of them here), also with a mesh over blocks of cells. All 44 hard cases agree (run them with splinevis.programs:
see the module docstring of splinevis.terrain.mesh_proxy)."""

import dataclasses

import numpy as np
import pytest

from splinevis import programs
from splinevis.analysis.agreement import agreement_failures, hard_case_agreement
from splinevis.terrain.hard_cases import franke_terrain, high_relief
from splinevis.terrain.mesh_proxy import cell_lifts, lifted_mesh, mesh_above, second_derivative_bounds
from splinevis.terrain.model import TerrainSpline
from splinevis.terrain.program import terrain_program


@pytest.mark.parametrize("scheme", ["linear", "C0", "C1", "C2-cubic", "C2-interp"])
@pytest.mark.parametrize("k", [1, 3])
def test_lifted_mesh_lies_above_the_spline(scheme, k):
    t = TerrainSpline.from_heights(high_relief("crater", 33), scheme, spacing=(1.0, 1.0))
    m = lifted_mesh(t, k)
    ncy, ncx = t.shape
    uv = np.random.default_rng(1).uniform(0.0, 1.0, (40_000, 2)) * (ncx, ncy)
    assert mesh_above(t, m, uv[:, 0], uv[:, 1]).min() > 0.0


def test_second_derivative_bound_holds_on_samples():
    # finite second differences of the spline inside cells never exceed the bound of M (|f_uu| <= M)
    t = franke_terrain(8, "C1")
    m = second_derivative_bounds(t.coefficients)
    h = 1e-3
    rng = np.random.default_rng(2)
    ij = rng.integers(0, 8, (2000, 2))
    loc = rng.uniform(0.1, 0.9, (2000, 2))
    loc[:, 1] = np.where(np.abs(loc[:, 1] - loc[:, 0]) < 3 * h, loc[:, 1] * 0.5, loc[:, 1])  # off the diagonal
    u, v = ij[:, 0] + loc[:, 0], ij[:, 1] + loc[:, 1]
    sx, sy = t.cell_spacing
    f = lambda uu, vv: t.evaluate(uu * sx, vv * sy)
    fuu = (f(u + h, v) - 2 * f(u, v) + f(u - h, v)) / h**2
    same_tri = (np.floor(u + h) == np.floor(u - h)) & (np.sign(loc[:, 1] - loc[:, 0] - h) == np.sign(loc[:, 1] - loc[:, 0] + h))
    assert (np.abs(fuu[same_tri]) <= m[ij[same_tri, 1], ij[same_tri, 0]] * (1 + 1e-6) + 1e-6).all()
    assert (cell_lifts(t, 2) > 0).all()


def test_default_program_is_the_box():
    t = franke_terrain(6)
    box = terrain_program(t)
    assert "SV_TERRAIN_MESH" not in box.defines and box.cull_front is None and len(box.points) == 8
    mesh = terrain_program(t, proxy="mesh", mesh_samples=2)
    assert mesh.defines["SV_TERRAIN_MESH"] and mesh.cull_front is False
    assert mesh.attributes["sv_mesh_cell"].shape == (len(mesh.points), 2)
    with pytest.raises(ValueError, match="proxy"):
        terrain_program(t, proxy="sphere")


MESH_CASES = ["grazing-1-degree", "underside", "camera-inside-box", "flat", "cliff-linear-oblique", "cliff-C0-oblique",
              "crater-C0-overview"]


def test_eye_inside_build_only_while_the_eye_may_be_inside():
    from splinevis.plotting import Plotter

    t = franke_terrain(6)
    pl = Plotter(off_screen=True, window_size=(80, 60))
    actor = pl.add_spline(t, program_options={"proxy": "mesh"})
    x0, x1, y0, y1 = t.extent
    zmax = float(t.coefficients.max() + t.z_ref)
    pl.camera_position = [(0.5 * (x0 + x1), y0 - 2.0, zmax + 2.0), (0.5 * (x0 + x1), 0.5 * (y0 + y1), zmax), (0, 0, 1)]
    pl.render_now()
    assert actor._variant == () and "#define SV_TERRAIN_MESH_INSIDE" not in actor.assembled.text
    assert actor.actor.GetProperty().GetBackfaceCulling() and not actor.actor.GetProperty().GetFrontfaceCulling()
    pl.camera_position = [(0.5 * (x0 + x1), 0.5 * (y0 + y1), float(t.coefficients.min() + t.z_ref)),
                          (x1, y1, zmax), (0, 0, 1)]
    pl.camera.clipping_range = (1e-3, 100.0)
    pl.render_now()
    assert actor._variant == (("SV_TERRAIN_MESH_INSIDE", True),) and "#define SV_TERRAIN_MESH_INSIDE" in actor.assembled.text
    assert actor.actor.GetProperty().GetFrontfaceCulling()
    pl.close()


@pytest.mark.gl
@pytest.mark.parametrize("name", MESH_CASES)
def test_mesh_proxy_agrees_with_the_twin(name):
    case = next(c for c in programs.get("terrain").hard_cases() if c.name == name)
    case = dataclasses.replace(case, program_options={**case.program_options, "proxy": "mesh"})
    r = hard_case_agreement(case)
    assert agreement_failures(r, case) == []


@pytest.mark.gl
@pytest.mark.parametrize("name", ["cliff-C0-oblique", "crater-C1-oblique"])
def test_block_mesh_agrees_with_the_twin(name, monkeypatch):
    # a grid over MAX_MESH_CELLS gets one mesh square per block of cells (here blocks of 8 x 8 and 2 x 2)
    import splinevis.terrain.mesh_proxy as mp

    monkeypatch.setattr(mp, "MAX_MESH_CELLS", 300)
    case = next(c for c in programs.get("terrain").hard_cases() if c.name == name)
    assert mp.mesh_block(case.model()) > 1
    case = dataclasses.replace(case, program_options={**case.program_options, "proxy": "mesh"})
    r = hard_case_agreement(case)
    assert agreement_failures(r, case) == []

"""The NURBS family's renderers (splinevis.nurbs.renderers): the mesh's proven position and normal bounds hold
against the float64 surface at random points inside the triangles of tessellate(model, k) (rational shapes
with poles and double knots, repeated knots, a C0 crease, degree 7, nonuniform rational patches, a model far
from the origin), the choice walks from coarse meshes to the per-fragment program as the request tightens,
refuses the mesh for trimmed models, and add_nurbs draws the choices."""

import numpy as np
import pytest

import splinevis
from splinevis.choice import choose, renderers_for
from splinevis.effects import Style
from splinevis.gl.screen_error import View
from splinevis.nurbs.exact import cylinder, saddle, sphere, torus
from splinevis.nurbs.hard_cases import bumpy, crease, degree7, trimmed_plate, unequal_arcs_sphere
from splinevis.nurbs.lod.bezier import bezier_set
from splinevis.nurbs.model import NurbsModel
from splinevis.nurbs.renderers import chord_bounds, nurbs_mesh_refuses, normal_bounds
from splinevis.nurbs.tessellate import tessellate

MODELS = {
    "torus": lambda: NurbsModel([torus()]),
    "sphere-poles": lambda: NurbsModel([sphere()]),
    "cylinder": lambda: NurbsModel([cylinder(1.0, 2.0)]),
    "saddle": lambda: NurbsModel([saddle()]),
    "crease": lambda: NurbsModel([crease()]),  # u knot of multiplicity p: C0 ridge
    "degree-7": lambda: NurbsModel([degree7()]),
    "mixed-nonuniform": lambda: NurbsModel([bumpy(1, 1, 3, 3, -4.4), bumpy(3, 1, 6, 2, -2.2), bumpy(2, 5, 5, 7)]),
    "unequal-arcs-sphere": lambda: NurbsModel([unequal_arcs_sphere()]),
    "far-torus": lambda: NurbsModel([torus(2.0, 0.5, (1.0e6, -2.0e6, 5.0e5))]),
}


def _samples(model, k, n=6000, seed=0):
    """Random points inside random triangles of tessellate(model, k): the mesh point and its shading normal
    (barycentric interpolation, normalized), the exact point and normal at the interpolated (u, v), and the
    Bezier patch and sub-square (i, j) of the triangle."""
    mesh = tessellate(model, k)
    tri = mesh.faces.reshape(-1, 4)[:, 1:]
    rng = np.random.default_rng(seed)
    t = rng.integers(0, len(tri), n)
    lam = rng.dirichlet(np.ones(3), n)
    P, UV, N, ID = (mesh.points, mesh.point_data["uv"], mesh.point_data["Normals"], mesh.point_data["patch_id"])
    x = np.einsum("nk,nkc->nc", lam, P[tri[t]])
    uv = np.einsum("nk,nkc->nc", lam, UV[tri[t]])
    shade = np.einsum("nk,nkc->nc", lam, N[tri[t]])
    shade /= np.linalg.norm(shade, axis=1, keepdims=True)
    centre = UV[tri[t]].mean(axis=1)
    surface = ID[tri[t, 0]]
    bs = bezier_set(model)
    exact, normal = np.empty((n, 3)), np.empty((n, 3))
    patch, ij = np.empty(n, dtype=int), np.empty((n, 2), dtype=int)
    for s_i, s in enumerate(model.surfaces):
        sel = np.flatnonzero(surface == s_i)
        exact[sel] = s.evaluate(uv[sel, 0], uv[sel, 1])
        normal[sel] = s.normal(uv[sel, 0], uv[sel, 1])
        mine = np.flatnonzero(bs.parent == s_i)
        rect, c = bs.rect[mine], centre[sel]
        inside = ((rect[None, :, 0] <= c[:, None, 0]) & (c[:, None, 0] <= rect[None, :, 1])
                  & (rect[None, :, 2] <= c[:, None, 1]) & (c[:, None, 1] <= rect[None, :, 3]))
        j = inside.argmax(axis=1)
        patch[sel], r = mine[j], rect[j]
        ij[sel, 0] = np.minimum(((c[:, 0] - r[:, 0]) / (r[:, 1] - r[:, 0]) * k).astype(int), k - 1)
        ij[sel, 1] = np.minimum(((c[:, 1] - r[:, 2]) / (r[:, 3] - r[:, 2]) * k).astype(int), k - 1)
    dist = np.linalg.norm(x - exact, axis=1)
    angle = np.arctan2(np.linalg.norm(np.cross(shade, normal), axis=1), np.einsum("ij,ij->i", shade, normal))
    return dist, angle, patch, ij


@pytest.mark.parametrize("name", sorted(MODELS))
@pytest.mark.parametrize("k", [1, 3, 8])
def test_mesh_bounds_hold_against_the_float64_surface(name, k):
    model = MODELS[name]()
    dist, angle, patch, ij = _samples(model, k)
    cache = {}
    chord = chord_bounds(model, k, cache)[patch, ij[:, 0], ij[:, 1]]
    normal = normal_bounds(model, k, cache)[patch, ij[:, 0], ij[:, 1]]
    # both sides are float64 evaluations of the model: the chord bound includes the vertices' evaluation error;
    # the test's own barycentric sums and the model's evaluation at the sample add a few roundings of the
    # coordinates' size, and the normals' a few eps (radians)
    size = float(np.abs(model.bounds()).max())
    assert (dist <= chord + 64 * np.finfo(float).eps * size).all(), float((dist - chord).max())
    assert (angle <= normal + 1e-12).all(), float(np.degrees(angle - normal).max())
    assert dist.max() > 0.0 and angle.max() > 0.0  # points inside the triangles: the comparison is not vacuous
    # not vacuous either: a finite position bound everywhere, within a few times the measured maximum
    assert np.isfinite(chord).all() and chord.max() <= 40.0 * dist.max()


def test_normal_bound_is_infinite_only_where_the_mesh_cannot_follow():
    # the C0 crease: the ridge vertices carry one side's normal, 90 degrees off the other side's
    dist, angle, *_ = _samples(NurbsModel([crease()]), 8)
    assert np.degrees(angle.max()) > 80.0 and np.isinf(normal_bounds(NurbsModel([crease()]), 8)).any()
    # G1 seams at double knots (torus, sphere with its poles): finite, and second order in 1 / k
    for model in (NurbsModel([torus()]), NurbsModel([sphere()])):
        b = [float(normal_bounds(model, k).max()) for k in (8, 16, 32)]
        assert np.isfinite(b).all() and b[0] > b[1] > b[2]
    t = NurbsModel([torus()])
    assert normal_bounds(t, 16).max() / normal_bounds(t, 32).max() == pytest.approx(4.0, rel=0.05)


def _view():
    return View((4.0, -5.0, 3.0), (0, 0, 0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(1, 20))


def test_choice_refines_the_mesh_then_draws_the_program():
    cache = {}
    picks = [choose(torus(), _view(), e, cache=cache) for e in (4.0, 1.0, 0.3)]
    assert [c.renderer for c in picks] == ["mesh"] * 3
    ks = [c.level for c in picks]
    assert ks == sorted(ks) and ks[0] < ks[-1]
    assert all(c.meets and c.chosen.proven for c in picks)
    tight = choose(torus(), _view(), 0.01, cache=cache)  # below what the 64-per-span mesh proves here
    assert tight.renderer == "per_fragment" and "per_fragment" in tight.message
    normals = choose(torus(), _view(), 1.0, cache=cache, max_normal_error_deg=0.5)  # normals ask for more samples
    assert normals.renderer == "mesh" and normals.level > picks[1].level and normals.chosen.normal_deg <= 0.5
    assert normals.chosen.normal_proven and "deg (proven)" in normals.message
    crease_choice = choose(crease(), _view(), 1.0, max_normal_error_deg=5.0)
    assert crease_choice.renderer == "per_fragment"  # the crease's mesh normals are never within 5 degrees


def test_declared_renderers_and_refusals():
    rows, note = renderers_for("nurbs")
    assert [(r.name, r.rank, r.exact) for r in rows] == [("mesh", 0, False), ("per_fragment", 10, True)] and note == ""
    assert "trim loops" in nurbs_mesh_refuses(trimmed_plate(), Style())
    c = choose(trimmed_plate(), View((0.3, -2.2, 2.4), (0, 0, 0), (0, 0, 1), 30.0), 5.0)
    assert c.renderer == "per_fragment" and "trim loops" in c.message


@pytest.mark.parametrize("request_", [{"max_error_px": 0.5}, {"max_error_px": 2.0, "max_normal_error_deg": 2.0}])
def test_add_nurbs_draws_the_choice(request_):
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    pl.camera_position = [(4.0, -5.0, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]  # the choice is for this camera
    actor = pl.add_nurbs(torus(), reflection_lines=8, **request_)
    choice = actor.renderer_choice
    assert choice.renderer == "mesh" and choice.meets, choice.message
    image = pl.screenshot()
    assert image.std() > 10
    pl.close()

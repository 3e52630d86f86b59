"""Levels of detail of NURBS models (splinevis.nurbs.lod.levels): every level within its proven bound of the
surface, and no crack at any combination of levels, shown three ways: the assembled mesh of a closed model is
a closed 2-manifold (every mesh edge used by exactly two triangles), no background pixel shows from a camera
inside a closed model, and on an open model the mesh's border is exactly the model's open edges."""

import numpy as np
import pytest
import pyvista as pv

from splinevis.nurbs.exact import sphere, torus
from splinevis.nurbs.operations import refine_knots
from splinevis.nurbs.lod.bezier import evaluate
from splinevis.nurbs.lod.levels import assemble, build_lod
from splinevis.nurbs.lod.simplify import Simplifier

from _camera import background_from_inside

LEVELS = 3


@pytest.fixture(scope="module")
def lods():
    return {"sphere": build_lod(sphere(), 0.01, levels=LEVELS, progress=False),
            "torus": build_lod(torus(), 0.01, levels=LEVELS, progress=False),
            # decimated across patch edges: 64 patches of 45 x 45 degrees, super-surfaces of several at 100 deg
            "torus-simplified": build_lod(_fine_torus(), 0.01, levels=LEVELS, alpha=np.radians(100.0),
                                          simplify=Simplifier(), progress=False)}


def _fine_torus():
    s = torus()
    for d in (0, 1):
        k = np.unique(s.knots[d])
        s = refine_knots(s, d, 0.5 * (k[:-1] + k[1:]))
    return s


def _combos(lod, count=12, seed=0):
    S = len(lod.supers.members)
    rng = np.random.default_rng(seed)
    yield from (np.full(S, k) for k in range(lod.levels))
    for _ in range(count):
        yield rng.integers(0, lod.levels, S)


def _edge_use(tri):
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


def _mesh(points, tri):
    return pv.PolyData(points, np.column_stack([np.full(len(tri), 3), tri]).ravel())


@pytest.mark.parametrize("name", ["sphere", "torus", "torus-simplified"])
def test_closed_model_stays_a_closed_manifold_at_every_level_combination(lods, name):
    lod = lods[name]
    assert lod.edges.counts()["open"] == 0
    fanned = 0
    for level in _combos(lod):
        points, tri, info = assemble(lod, level)
        fanned += info["fans"]
        counts = _edge_use(tri)
        assert counts.min() == 2 and counts.max() == 2  # no border (crack), no T-junction, no fold
        area = np.linalg.norm(np.cross(points[tri[:, 1]] - points[tri[:, 0]], points[tri[:, 2]] - points[tri[:, 0]]), axis=1)
        assert (area > 0).all() or name == "sphere"  # only the sphere's poles give fans of zero area
    assert fanned > 0  # mixed levels did split triangles along the finer neighbours' edges


@pytest.mark.parametrize("name", ["sphere", "torus", "torus-simplified"])
def test_every_drawn_level_is_within_its_proven_bound_of_the_surface(lods, name):
    lod = lods[name]
    bs = lod.bezier
    t = np.linspace(0.0, 1.0, 13)
    U, V = (x.ravel() for x in np.meshgrid(t, t))
    ids = np.repeat(np.arange(len(bs)), U.size)
    surface = evaluate(bs, ids, np.tile(U, len(bs)), np.tile(V, len(bs)))
    for level in list(_combos(lod, count=3, seed=1)):
        points, tri, info = assemble(lod, level)
        mesh = _mesh(points, tri)
        d = np.abs(pv.PolyData(surface).compute_implicit_distance(mesh)["implicit_distance"])
        # the distance from F(x) to the mesh is at most |F(x) - L(x)| <= the proven bound of the level drawn
        # there (fans keep it); plus float64 rounding of points of size ~1.5 (a few ulps, far below)
        assert d.max() <= info["bound"] + 1e-12
        if level.min() == level.max():  # one level everywhere: its own bound
            assert d.max() <= lod.tolerance[level[0]] + 1e-12


@pytest.mark.gl
@pytest.mark.parametrize("name, eye, focus", [("sphere", (0.0, 0.0, 0.1), (1.0, 0.3, 0.2)),
                                               ("sphere", (0.1, 0.0, 0.0), (0.0, 0.2, -1.0)),
                                               ("torus", (2.0, 0.0, 0.0), (2.0, 1.0, 0.1)),
                                               ("torus-simplified", (2.0, 0.0, 0.0), (2.0, 1.0, 0.1))])
def test_no_background_pixel_from_inside_a_closed_model(lods, name, eye, focus):
    lod = lods[name]
    for level in list(_combos(lod, count=4, seed=2)):
        points, tri, _ = assemble(lod, level)
        assert background_from_inside(points, tri, eye, focus) == 0  # every pixel hits the closed surface: no crack


def test_open_model_border_is_exactly_its_open_edges():
    from datasets_synthetic.teapot import newell_teapot

    lod = build_lod(newell_teapot(), 0.02, levels=LEVELS, progress=False)
    edges = lod.edges
    for level in _combos(lod, count=4, seed=3):
        points, tri, _ = assemble(lod, level)
        e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        uniq, counts = np.unique(e, axis=0, return_counts=True)
        assert counts.max() == 2
        border = {tuple(x) for x in uniq[counts == 1]}
        # the open edges' chains at the level of their one super-surface, as vertex pairs
        expected = set()
        for k in np.flatnonzero(edges.count == 1):
            patch = edges.edge_side[k] // 4
            keep = lod.edge_birth[k] >= level[lod.supers.labels[patch]]
            ids = lod.edge_ids[k][keep]
            expected |= {tuple(sorted(p)) for p in zip(ids[:-1].tolist(), ids[1:].tolist())}
        assert border == expected


def test_simplified_levels_have_fewer_triangles_and_stay_within_their_bound(lods):
    simple = lods["torus-simplified"]
    assert simple.simplified[:, 0].max() == 0.0  # level 0 is the proven tessellation itself
    assert (simple.simplified[:, 1:] <= simple.tolerance[1:]).all()  # measured distance held to delta + eps
    assert (simple.simplified[:, 1:] > 0).all()
    assert len(simple.supers.members) < len(simple.bezier)  # super-surfaces of several patches: edges to remove
    # fewer triangles than the proven tessellations of the same super-surfaces at the same level
    unsimplified = build_lod(_fine_torus(), 0.01, levels=LEVELS, alpha=np.radians(100.0), progress=False)
    assert (simple.triangles[:, 1:].sum(axis=0) < unsimplified.triangles[:, 1:].sum(axis=0)).all()


@pytest.mark.gl
def test_the_mesh_program_is_chosen_by_name_and_draws_the_level_it_reports():
    import splinevis
    from splinevis import programs
    from splinevis.analytic import QuarticTrianglePatch
    from splinevis.nurbs import NurbsModel

    model = NurbsModel([torus()])
    assert programs.program_for(model).name == "nurbs"  # by type: the per-fragment program
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = pl.add_spline(model, program="nurbs_lod", program_options={"delta": 0.05, "levels": 2})
    mesh = actor.GetMapper().GetInput()
    level = int(mesh.GetFieldData().GetArray("lod_level").GetValue(0))
    assert level in (0, 1) and mesh.GetNumberOfCells() > 0
    pl.camera_position = [(4.0, -5.0, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    img = pl.screenshot()
    assert (img.sum(axis=-1) < 3 * 250).mean() > 0.1  # the torus covers a good part of the picture
    with pytest.raises(TypeError, match="program 'nurbs_lod' draws NurbsModel"):
        pl.add_spline(QuarticTrianglePatch.demo(), program="nurbs_lod")
    pl.close()


@pytest.mark.parametrize("name", ["sphere", "torus-simplified"])
def test_vertex_normals_are_the_surface_normals(lods, name):
    lod = lods[name]
    n, v = lod.normals, lod.vertices
    assert n.shape == v.shape
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=4e-16)
    if name == "sphere":  # outward radius; at the poles the normal is taken 1e-6 inside: within ~1e-6 rad
        assert (np.einsum("ij,ij->i", n, v / np.linalg.norm(v, axis=1)[:, None]) > 1 - 1e-11).all()
    else:  # torus (R 2, r 0.5 around z): the normal points from the tube's centre circle to the point
        c = v * [1.0, 1.0, 0.0]
        c = 2.0 * c / np.linalg.norm(c, axis=1)[:, None]
        out = (v - c) / np.linalg.norm(v - c, axis=1)[:, None]
        assert (np.einsum("ij,ij->i", n, out) > 1 - 1e-12).all()

"""Dynamic tessellation finer than level 0 (splinevis.nurbs.lod.dynamic): every refined mesh within its proven bound
of the surface, and no crack at any mixture of static levels and refined steps, shown as for the static levels
(tests/test_lod_levels.py): a closed model's mesh is a closed 2-manifold, a camera inside sees no background pixel,
an open model's border is its open edges at the chains drawn there. No timing."""

import numpy as np
import pytest
import pyvista as pv

from _camera import background_from_inside

from splinevis.nurbs.exact import sphere, torus
from splinevis.nurbs.lod.bezier import evaluate
from splinevis.nurbs.lod.dynamic import Refiner
from splinevis.nurbs.lod.levels import build_lod

LEVELS, DELTA, RATIO = 3, 0.02, 4.0
ALL = 10**9  # no budget per build: every refined mesh asked for is made at once (the budget is tested apart)


@pytest.fixture(scope="module")
def lods():
    return {"sphere": build_lod(sphere(), DELTA, levels=LEVELS, progress=False),
            "torus": build_lod(torus(), DELTA, levels=LEVELS, progress=False)}


@pytest.fixture(scope="module")
def teapot():
    from datasets_synthetic.teapot import newell_teapot

    return build_lod(newell_teapot(), 0.05, levels=LEVELS, progress=False)


def _mixtures(lod, count=8, seed=0, max_step=3):
    """Levels and finer steps: every super-surface refined 1..max_step, then random mixtures of static levels
    and refined steps (a refined one is at level 0)."""
    S = len(lod.supers.members)
    rng = np.random.default_rng(seed)
    for j in range(1, max_step + 1):
        yield np.zeros(S, dtype=np.int64), np.full(S, j)
    for _ in range(count):
        levels = rng.integers(0, lod.levels, S)
        steps = np.where((levels == 0) & (rng.random(S) < 0.7), rng.integers(1, max_step + 1, S), 0)
        yield levels, steps


def _edge_use(tri):
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0, return_counts=True)


def _mesh(points, tri):
    return pv.PolyData(points, np.column_stack([np.full(len(tri), 3), tri]).ravel())


def _samples(bs, patches, n=33):
    t = np.linspace(0.0, 1.0, n)
    U, V = (x.ravel() for x in np.meshgrid(t, t))
    patches = np.asarray(patches)
    return evaluate(bs, np.repeat(patches, U.size), np.tile(U, patches.size), np.tile(V, patches.size))


@pytest.mark.parametrize("name", ["sphere", "torus", "teapot"])
def test_every_refined_mesh_is_within_its_tolerance_of_the_surface(lods, teapot, name):
    lod = teapot if name == "teapot" else lods[name]
    r = Refiner(lod, ratio=RATIO, triangles_per_build=ALL)
    S = len(lod.supers.members)
    rng = np.random.default_rng(1)
    for j in (1, 2, 3):
        steps = np.full(S, j)
        steps[rng.random(S) < 0.3] = 0  # static neighbours: their fans must not break the refined meshes
        points, _, tri, info = r.build(np.zeros(S, dtype=np.int64), steps)
        assert info["refined"] == int((steps > 0).sum()) and info["pending"] == 0
        tolerance = lod.tolerance[0] / RATIO ** j
        for s in np.flatnonzero(steps > 0):
            own, _, bound, _ = r._meshes[(int(s), j)]
            # the mesh's bound is the largest proven bound of its triangles: the step's tolerance for the
            # polynomial teapot; on a rational patch the (D w)(D L) term across a fixed chain segment may leave
            # triangles a little above it (adaptive module docstring), and the mesh reports that bound
            assert bound == tolerance if name == "teapot" else tolerance <= bound
            surface = _samples(lod.bezier, lod.supers.members[s])
            d = np.abs(pv.PolyData(surface).compute_implicit_distance(_mesh(points, own))["implicit_distance"])
            # the distance from F(x) to the mesh is at most |F(x) - L(x)| <= the proven bound; plus float64
            # rounding of points of size <= 3.5 (a few ulps, far below 1e-12)
            assert d.max() <= bound + 1e-12
            assert d.max() > tolerance / RATIO ** 2  # the samples do see the mesh's deviation (not a trivial pass)
        # the assembled mesh as a whole: each point within the bound drawn there (fans keep it)
        surface = _samples(lod.bezier, np.arange(len(lod.bezier)), 13)
        d = np.abs(pv.PolyData(surface).compute_implicit_distance(_mesh(points, tri))["implicit_distance"])
        assert d.max() <= info["bound"] + 1e-12


@pytest.mark.parametrize("name", ["sphere", "torus"])
def test_closed_model_stays_a_closed_manifold_with_refined_super_surfaces(lods, name):
    lod = lods[name]
    assert lod.edges.counts()["open"] == 0
    shared = Refiner(lod, ratio=RATIO, triangles_per_build=ALL)  # one cache across the mixtures: reused
    fanned = refined = 0
    for n, (levels, steps) in enumerate(_mixtures(lod)):
        # the shared cache on every mixture; a fresh refiner (nothing cached) beside it on the uniform steps and
        # the first random mixture, then on every third: each mesh a fresh one makes is made again, at full cost.
        # Not on the first mixture (step 1): the shared refiner is still empty there, a fresh one would repeat its
        # build exactly.
        fresh = n > 0 and (n < 4 or n % 3 == 0)
        for r in (shared, Refiner(lod, ratio=RATIO, triangles_per_build=ALL)) if fresh else (shared,):
            points, normals, tri, info = r.build(levels, steps)
            _, counts = _edge_use(tri)
            assert counts.min() == 2 and counts.max() == 2  # no border (crack), no T-junction, no fold
            assert tri.max() < len(points) == len(normals)
            fanned += info["fans"]
            refined += info["refined"]
    assert fanned > 0 and refined > 0
    # a small budget per build: refined meshes come over several builds, each build closed
    r = Refiner(lod, ratio=RATIO, triangles_per_build=1)  # one mesh a build
    levels, steps = list(_mixtures(lod, count=1, seed=5))[-1]
    pending = []
    for _ in range(len(lod.supers.members) + 1):
        _, _, tri, info = r.build(levels, steps)
        _, counts = _edge_use(tri)
        assert counts.min() == 2 and counts.max() == 2
        pending.append(info["pending"])
    assert pending[0] > 0 and pending[-1] == 0 and np.all(np.diff(pending) <= 0)


def test_open_model_border_is_exactly_its_open_edges(teapot):
    lod = teapot
    r = Refiner(lod, ratio=RATIO, triangles_per_build=ALL)
    edges = lod.edges
    for levels, steps in _mixtures(lod, count=4, seed=3):
        points, _, tri, info = r.build(levels, steps)
        uniq, counts = _edge_use(tri)
        assert counts.max() == 2
        border = {tuple(x) for x in uniq[counts == 1]}
        expected = set()
        for k in np.flatnonzero(edges.count == 1):  # an open edge: its one super-surface's chain
            s = lod.supers.labels[edges.edge_side[k] // 4]
            if steps[s] > 0:
                t, ids, birth = r._chains[int(k)]
                ids = ids[birth <= steps[s]]
            else:
                ids = lod.edge_ids[k][lod.edge_birth[k] >= levels[s]]
            expected |= {tuple(sorted(p)) for p in zip(ids[:-1].tolist(), ids[1:].tolist())}
        assert border == expected


def test_refined_chains_are_nested_and_share_the_model_vertices(lods):
    lod = lods["torus"]
    r = Refiner(lod, ratio=RATIO, triangles_per_build=ALL)
    S = len(lod.supers.members)
    r.build(np.zeros(S, dtype=np.int64), np.full(S, 3))
    from splinevis.nurbs.lod.adaptive import curve_chain
    from splinevis.nurbs.lod.bounds import curve_points, side_net

    for e, (t, ids, birth) in r._chains.items():
        f = int(lod.edges.edge_side[e])
        net = side_net(lod.bezier.control(f // 4), f % 4)
        for j in range(4):  # the chain of step j is curve_chain at delta_0 / ratio**j exactly
            np.testing.assert_array_equal(t[birth <= j], curve_chain(net, DELTA / RATIO ** j))
        np.testing.assert_array_equal(ids[birth == 0], lod.edge_ids[e])  # level 0's vertices kept
        points = r.arrays()[0]
        np.testing.assert_array_equal(points[ids[1:-1]], curve_points(net, t[1:-1]))


def test_caps_and_cache_bounds():
    lod = build_lod(torus(), 0.05, levels=2, progress=False)
    S = len(lod.supers.members)
    tiny = Refiner(lod, mesh_triangles=int(lod.triangles[:, 0].max()) * 5)  # one step of ratio 4 fits, two do not
    j, capped = tiny.plan(np.zeros(S, dtype=np.int64), np.full(S, 3))
    assert (j == 1).all() and capped == S
    r = Refiner(lod, cache_triangles=1, triangles_per_build=ALL)  # keeps only what the last build drew
    r.build(np.zeros(S, dtype=np.int64), np.array([2] * 4 + [0] * (S - 4)))
    r.build(np.zeros(S, dtype=np.int64), np.array([0] * 4 + [1] * 4 + [0] * (S - 8)))
    assert set(r._meshes) == {(s, 1) for s in range(4, 8)}
    with pytest.raises(ValueError, match="levels and steps must be"):
        r.build(np.zeros(S, dtype=np.int64), np.zeros(S - 1, dtype=np.int64))
    with pytest.raises(ValueError, match="ratio must be"):
        Refiner(lod, ratio=1.0)
    with pytest.raises(TypeError, match="LodModel"):
        Refiner(object())


@pytest.mark.gl
@pytest.mark.parametrize("name, eye, focus", [("sphere", (0.0, 0.0, 0.1), (1.0, 0.3, 0.2)),
                                               ("sphere", (0.1, 0.0, 0.0), (0.0, 0.2, -1.0)),
                                               ("torus", (2.0, 0.0, 0.0), (2.0, 1.0, 0.1))])
def test_no_background_pixel_from_inside_a_closed_model_with_refined_super_surfaces(lods, name, eye, focus):
    lod = lods[name]
    r = Refiner(lod, ratio=RATIO, triangles_per_build=ALL)
    refined = 0
    for levels, steps in list(_mixtures(lod, count=4, seed=2))[2:]:
        points, _, tri, info = r.build(levels, steps)
        refined += info["refined"]
        assert background_from_inside(points, tri, eye, focus) == 0  # every pixel hits the closed surface
    assert refined > 0


def test_trimmed_model_refines_around_its_trims_without_cracks():
    """A torus with a hole across knot lines (tests/test_lod_trims.py): super-surfaces with a trimmed patch, and
    those across an edge holding trim crossings, stay static; the rest refine; the only border is the hole's."""
    from datasets_synthetic.large_models import ellipse_loop, rectangle_loop
    from splinevis.nurbs.lod.levels import assemble
    from splinevis.nurbs.model import NurbsModel
    from splinevis.nurbs.operations import refine_knots

    s = torus()
    for d in (0, 1):
        k = np.unique(s.knots[d])
        s = refine_knots(s, d, 0.5 * (k[:-1] + k[1:]))
    loops = [rectangle_loop(0.0, 1.0, 0.0, 1.0), ellipse_loop(0.37, 0.41, 0.17, 0.17)]
    lod = build_lod(NurbsModel([s], trims=[loops]), 0.02, levels=2, progress=False, workers=1)
    trimmed = {int(x) for x in lod.supers.labels[np.flatnonzero(lod.status != 0)]}
    assert trimmed
    r = Refiner(lod, ratio=RATIO, triangles_per_build=ALL)
    refined = 0
    for levels, steps in _mixtures(lod, count=3, seed=4, max_step=2):
        _, _, tri, info = r.build(levels, steps)
        refined += info["refined"]
        uniq, counts = _edge_use(tri)
        assert counts.max() == 2
        _, static_tri, _ = assemble(lod, levels)
        s_uniq, s_counts = _edge_use(static_tri)
        hole_edges = {tuple(x) for x in s_uniq[s_counts == 1]}
        assert hole_edges and {tuple(x) for x in uniq[counts == 1]} == hole_edges  # no crack, hole kept
        assert trimmed <= r._static and info["capped"] >= int((steps[sorted(r._static)] > 0).sum())
    assert refined > 0

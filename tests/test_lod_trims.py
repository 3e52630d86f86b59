"""Trim loops in the levels of detail [Kumar1997, sec. 4.1]: every level of a trimmed model stays within its bound
both ways (surface to mesh, mesh to surface), holes stay open, and the mesh's only border is its trims.

The models: a torus (rational, 64 patches) with a circular hole across knot lines; a bicubic B-spline (3 x 3
spans) cut to an ellipse through all its outer patches, with a circular hole across a knot line and a square
hole that is its centre patch; the ship hull with portholes inside patches.
"""

import numpy as np
import pytest
import pyvista as pv

from datasets_synthetic.large_models import ellipse_loop, hull, rectangle_loop
from splinevis.nurbs.exact import torus
from splinevis.nurbs.lod.levels import assemble, build_lod
from splinevis.nurbs.lod.trims import gradient_bound, merge_params
from splinevis.nurbs.model import NurbsModel
from splinevis.nurbs.operations import refine_knots
from splinevis.nurbs.surface import NurbsSurface
from splinevis.nurbs.trim import inside, trim_pieces

LEVELS = 3


def _torus_with_hole():
    s = torus()
    for d in (0, 1):
        k = np.unique(s.knots[d])
        s = refine_knots(s, d, 0.5 * (k[:-1] + k[1:]))
    return NurbsModel([s], trims=[[rectangle_loop(0.0, 1.0, 0.0, 1.0), ellipse_loop(0.37, 0.41, 0.17, 0.17)]])


def _window():
    rng = np.random.default_rng(3)
    g = np.linspace(0.0, 1.0, 6)
    X, Y = np.meshgrid(g, g, indexing="ij")
    P = np.stack([X, Y, 0.3 * rng.standard_normal(X.shape)], axis=-1)
    knots = [0, 0, 0, 0, 1 / 3, 2 / 3, 1, 1, 1, 1]
    s = NurbsSurface((3, 3), (knots, knots), P, None, "window")
    # an ellipse leaving the corners out; a circular hole across knot lines; a square hole that is one whole patch
    # (its sides on knot lines and on the border)
    return NurbsModel([s], trims=[[ellipse_loop(0.5, 0.5, 0.49, 0.46), ellipse_loop(0.22, 0.3, 0.09, 0.1),
                                   rectangle_loop(1 / 3, 2 / 3, 1 / 3, 2 / 3)]])


@pytest.fixture(scope="module")
def models():
    out = {}
    for name, model, delta in (("torus-hole", _torus_with_hole(), 0.01), ("window", _window(), 0.002),
                               ("hull", hull(200, portholes=True), 0.05)):
        out[name] = (model, build_lod(model, delta, levels=LEVELS, progress=False, workers=1))
    return out


def _true_samples(model, n=161):
    """Points of the true trimmed surfaces on an ``n x n`` parameter grid (exact inside test), per surface."""
    pieces = trim_pieces(model.trims)
    out = []
    for f, s in enumerate(model.surfaces):
        (a, b), (c, d) = s.domain
        u, v = (x.ravel() for x in np.meshgrid(np.linspace(a, b, n), np.linspace(c, d, n)))
        keep = inside(pieces, f, u, v)
        out.append(s.evaluate(u[keep], v[keep]))
    return np.concatenate(out)


def _levels(lod):
    S = len(lod.supers.members)
    yield from (np.full(S, k) for k in range(lod.levels))
    yield np.random.default_rng(5).integers(0, lod.levels, S)


def _mesh(points, tri):
    return pv.PolyData(points, np.column_stack([np.full(len(tri), 3), tri]).ravel())


@pytest.mark.parametrize("name", ["torus-hole", "window", "hull"])
def test_the_true_trimmed_surface_is_within_the_level_bound_of_the_mesh(models, name):
    model, lod = models[name]
    assert lod.delta_trim == pytest.approx(0.125 * lod.tolerance[0])
    samples = pv.PolyData(_true_samples(model))
    for level in _levels(lod):
        points, tri, info = assemble(lod, level)
        d = np.abs(samples.compute_implicit_distance(_mesh(points, tri))["implicit_distance"])
        # module docstring of trims: a point inside the trims is within delta_l of the mesh (triangles held to
        # delta_l - delta_trim, the trim polyline within delta_trim / Lip in the domain); float64 rounding far below
        assert d.max() <= info["bound"] * (1 + 1e-9)


def _parent_uv(lod):
    """Each vertex's parameters on its surface (the model has one surface)."""
    rect = lod.bezier.rect[lod.vertex_patch]
    s, t = lod.vertex_uv[:, 0], lod.vertex_uv[:, 1]
    return np.column_stack([rect[:, 0] + s * (rect[:, 1] - rect[:, 0]), rect[:, 2] + t * (rect[:, 3] - rect[:, 2])])


@pytest.mark.parametrize("name", ["torus-hole", "window"])
def test_every_mesh_point_is_within_the_level_bound_of_the_true_trimmed_surface(models, name):
    """Mesh to surface: a mesh point L_T(x) at domain point x (barycentric in the triangle's vertices' parameters)
    is within its triangle's bound of F(x); x lies in the trimmed domain or within h (the polylines' domain
    tolerance) of a trim curve. Both are what the bound of the trims module rests on; a triangle across a hole
    fails the second by the hole's radius."""
    model, lod = models[name]
    s = model.surfaces[0]
    pieces = trim_pieces(model.trims)
    h = lod.delta_trim / max(gradient_bound(lod.bezier.control(i), lod.bezier.rect[i]) for i in range(len(lod.bezier)))
    curve = np.concatenate([c.evaluate(np.linspace(*c.domain, 4001)) for loop in model.trims[0] for c in loop])
    uv = _parent_uv(lod)
    w = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1], [2, 1, 1], [1, 2, 1], [1, 1, 2]], dtype=float)
    w /= w.sum(axis=1, keepdims=True)
    periodic = name == "torus-hole"
    for level in _levels(lod):
        points, tri, info = assemble(lod, level)
        T = uv[tri]  # (N, 3, 2)
        if periodic:  # a triangle across the seam u = 0 = 1 (or v): unwrap to its first vertex
            T = T - np.round(T - T[:, :1])
        x = np.einsum("sk,nkc->nsc", w, T).reshape(-1, 2)
        y = np.einsum("sk,nkc->nsc", w, points[tri]).reshape(-1, 3)
        xw = np.mod(x, 1.0) if periodic else np.clip(x, 0.0, 1.0)
        assert np.linalg.norm(s.evaluate(xw[:, 0], xw[:, 1]) - y, axis=1).max() <= info["bound"] * (1 + 1e-9) + 1e-12
        out = ~inside(pieces, 0, xw[:, 0], xw[:, 1])
        if out.any():
            from scipy.spatial import cKDTree

            gap, _ = cKDTree(curve).query(xw[out])
            spacing = max(np.linalg.norm(np.diff(c.evaluate(np.linspace(*c.domain, 4001)), axis=0), axis=1).max()
                          for loop in model.trims[0] for c in loop)
            assert gap.max() <= h + spacing  # within the polyline's tolerance of the curve (+ the sampling of it)


@pytest.mark.parametrize("name", ["torus-hole", "window"])
def test_the_mesh_border_is_the_trims_at_every_level_combination(models, name):
    """No crack: every mesh edge is in two triangles, except the border's, and every border vertex lies on a trim
    curve (within h in the domain) with two border edges (closed loops)."""
    model, lod = models[name]
    h = lod.delta_trim / max(gradient_bound(lod.bezier.control(i), lod.bezier.rect[i]) for i in range(len(lod.bezier)))
    curve = np.concatenate([c.evaluate(np.linspace(*c.domain, 20001)) for loop in model.trims[0] for c in loop])
    uv = _parent_uv(lod)
    from scipy.spatial import cKDTree

    tree = cKDTree(curve)
    fanned = 0
    for level in list(_levels(lod)) + [np.random.default_rng(k).integers(0, lod.levels, len(lod.supers.members))
                                       for k in range(6)]:
        points, tri, info = assemble(lod, level)
        fanned += info["fans"]
        e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        edges, counts = np.unique(e, axis=0, return_counts=True)
        assert counts.max() == 2
        border = edges[counts == 1]
        assert border.size > 0
        verts, degree = np.unique(border, return_counts=True)
        assert (degree == 2).all()
        gap, _ = tree.query(uv[verts])
        # vertices of the polylines lie on the curve; sampling the curve at 20001 points adds its spacing
        assert gap.max() <= 1e-3 * h + 2e-4
    assert fanned > 0


def test_holes_are_cut_and_whole_patches_outside_are_dropped(models):
    # window: 3 x 3 patches; the square hole is the centre patch, whole; the ellipse crosses the 8 others
    _, lod = models["window"]
    assert np.flatnonzero(lod.status == -1).tolist() == [4]
    assert (lod.status == 1).sum() == 8
    # the hull: a porthole lies inside one patch of its band; the bilge and topside are not trimmed
    model, hull_lod = models["hull"]
    assert (hull_lod.status == 1).sum() == sum(len(loops) - 1 for loops in model.trims if loops)
    assert (hull_lod.status == -1).sum() == 0


def test_merge_params_keeps_chains_sorted_and_drops_near_duplicates():
    c, new = merge_params(np.array([0.0, 0.4, 1.0]), np.array([0.7, 0.7 + 1e-13, 0.4 + 1e-14, 0.1]))
    assert c.tolist() == [0.0, 0.1, 0.4, 0.7, 1.0]
    assert new.tolist() == [False, True, False, True, False]

"""Spherical parametrization of smooth geometry images: every genus-0 shape maps one-to-one onto the sphere,
the sphere onto itself, the stretch reported is Sander et al.'s L2 stretch recomputed here by their formulas, bad
inputs fail the check they are built to fail, and point location inverts the map."""

import dataclasses

import numpy as np
import pytest

from datasets_synthetic.closed_meshes import (bent_blob, ellipsoid_mesh, nonmanifold_edge, open_cup, sphere_mesh,
                                              star_blob, stretched_blob, torus_mesh, two_spheres)
from splinevis.errors import MeshTopologyError
from splinevis.geometry_image.mobius import center_on_sphere, mobius_transform
from splinevis.geometry_image.sphere import locate, spherical_parametrization, surface_points

GENUS0 = [sphere_mesh, ellipsoid_mesh, star_blob, stretched_blob, bent_blob]
_CACHE = {}


def _map(make, level=3):
    if (make, level) not in _CACHE:
        _CACHE[make, level] = spherical_parametrization(make(level=level), name=make.__name__)
    return _CACHE[make, level]


def _dets(X, F):
    return np.einsum("ij,ij->i", X[F[:, 0]], np.cross(X[F[:, 1]], X[F[:, 2]]))


def _lhuilier_areas(X, F):
    """Spherical triangle areas by L'Huilier's theorem, ``tan(E/4)^2 = tan(s/2) tan((s-a)/2) tan((s-b)/2)
    tan((s-c)/2)`` over the arc lengths (another formula than the module's), signed by orientation."""
    A, B, C = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]

    def arc(u, v):
        return 2.0 * np.arcsin(np.clip(0.5 * np.linalg.norm(u - v, axis=1), 0.0, 1.0))

    a, b, c = arc(B, C), arc(C, A), arc(A, B)
    s = 0.5 * (a + b + c)
    t = np.tan(s / 2) * np.tan((s - a) / 2) * np.tan((s - b) / 2) * np.tan((s - c) / 2)
    return np.sign(_dets(X, F)) * 4.0 * np.arctan(np.sqrt(np.maximum(t, 0.0)))


@pytest.mark.parametrize("make", GENUS0)
def test_every_genus0_shape_maps_one_to_one(make):
    """No triangle flipped, and the spherical areas sum to 4 pi: the sum is 4 pi times the map's degree, so a
    map wrapping the sphere twice (no flip either) fails it by 4 pi; rounding in L'Huilier's formula is far below
    1e-8 over a few thousand triangles."""
    smap = _map(make)
    X, F = smap.sphere, smap.faces
    assert smap.flipped == 0 and (_dets(X, F) > 0).all()
    assert np.abs(np.linalg.norm(X, axis=1) - 1.0).max() < 1e-14
    assert abs(_lhuilier_areas(X, F).sum() - 4 * np.pi) < 1e-8
    assert np.array_equal(F, make(level=3).faces.reshape(-1, 4)[:, 1:]) and np.array_equal(smap.points,
                                                                                           make(level=3).points)


def test_bent_blob_is_not_star_shaped_yet_maps_one_to_one():
    """Central projection from the centroid folds the bent blob (its centroid is outside it); the map does not."""
    m = bent_blob(level=3)
    F = m.faces.reshape(-1, 4)[:, 1:]
    central = m.points - m.points.mean(axis=0)
    central /= np.linalg.norm(central, axis=1, keepdims=True)
    assert (_dets(central, F) <= 0).sum() > len(F) // 10
    assert (_dets(_map(bent_blob).sphere, F) > 0).all()


def test_the_sphere_maps_to_itself_up_to_a_rotation():
    """The identity is the optimum up to ``O(h^4)`` (the vertices are on the unit sphere; its l2 exceeds 1 only
    by the spread of the flat-to-spherical area ratios, 1e-7 here). With ``h`` the mean edge length, the map must
    be within ``h / 10`` of a rotation of it at every vertex (the rotation fitted by Kabsch's SVD), and its
    stretch excess below 5e-5: ``l2 - 1 ~ e^2 / 2`` for a Jacobian error ``e``, so a map everywhere within 1% of
    a rotation."""
    smap = _map(sphere_mesh)
    P, X, F = smap.points, smap.sphere, smap.faces
    U, _, Vt = np.linalg.svd(X.T @ P)
    R = U @ Vt
    assert np.linalg.det(R) > 0  # a rotation, not a reflection
    h = np.linalg.norm(P[F[:, 0]] - P[F[:, 1]], axis=1).mean()
    assert np.linalg.norm(P @ R.T - X, axis=1).max() < h / 10
    assert 1.0 <= smap.stretch["l2"] < 1.0 + 5e-5


def _sander_l2(P, X, F):
    """Sander et al.'s L2 stretch by their formulas: each flat spherical triangle in a 2D frame ``(s, t)``,
    ``S_s = sum p_i (t_j - t_k) / 2A``, ``S_t = sum p_i (s_k - s_j) / 2A``, ``L2^2 = (S_s.S_s + S_t.S_t) / 2``,
    scaled by flat over spherical area; over the mesh ``sqrt(sum A_P L2^2 / sum A_P)``, times
    ``sqrt(4 pi / sum A_P)``."""
    q1, q2, q3 = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    e1, e2 = q2 - q1, q3 - q1
    s_axis = e1 / np.linalg.norm(e1, axis=1, keepdims=True)
    n = np.cross(e1, e2)
    t_axis = np.cross(n / np.linalg.norm(n, axis=1, keepdims=True), s_axis)
    s = np.column_stack([np.zeros(len(F)), np.linalg.norm(e1, axis=1), np.einsum("ij,ij->i", e2, s_axis)])
    t = np.column_stack([np.zeros(len(F)), np.zeros(len(F)), np.einsum("ij,ij->i", e2, t_axis)])
    A = 0.5 * ((s[:, 1] - s[:, 0]) * (t[:, 2] - t[:, 0]) - (s[:, 2] - s[:, 0]) * (t[:, 1] - t[:, 0]))
    p = P[F]
    Ss = sum(p[:, i] * (t[:, (i + 1) % 3] - t[:, (i + 2) % 3])[:, None] for i in range(3)) / (2 * A[:, None])
    St = sum(p[:, i] * (s[:, (i + 2) % 3] - s[:, (i + 1) % 3])[:, None] for i in range(3)) / (2 * A[:, None])
    L2sq = 0.5 * ((Ss * Ss).sum(axis=1) + (St * St).sum(axis=1)) * A / _lhuilier_areas(X, F)
    AP = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    return float(np.sqrt((AP @ L2sq) / AP.sum()) * np.sqrt(4 * np.pi / AP.sum()))


@pytest.mark.parametrize("make", GENUS0)
def test_the_stretch_reported_is_sanders_and_finite(make):
    smap = _map(make)
    st = smap.stretch
    assert all(np.isfinite(v) for v in st.values())
    assert abs(st["l2"] - _sander_l2(smap.points, smap.sphere, smap.faces)) < 1e-9
    # Cauchy-Schwarz: the normalized stretch is at least 1; the relaxation lowers it
    assert 1.0 - 1e-12 <= st["l2"] <= st["l2_start"]
    assert st["l2_max"] >= st["l2_p95"] and st["area_ratio_max"] >= st["area_ratio_p95"] >= 1.0
    assert set(smap.timings) == {"validate", "tutte", "mobius", "hierarchy", "relax", "check", "total"}
    assert smap.start == "tutte" and smap.start_levels == 0 and smap.timings["hierarchy"] == 0.0


def test_the_anisotropy_is_the_ratio_of_the_singular_values():
    """Random planar triangles ``Q`` mapped to ``P = Q A`` by random 2 x 2 maps ``A`` (one per triangle, then put
    in a random plane of space): :meth:`StretchEnergy.anisotropy` equals ``sigma_1 / sigma_2`` of ``A`` from
    LAPACK's SVD (another computation than its invariants); rounding in ``f = |J|^2 / det J`` and the square root
    is a few ulps of ``f`` times ``f / sqrt(f^2 - 4)``, at most 1e-9 relative for the conditions drawn here."""
    from splinevis.geometry_image.stretch import StretchEnergy

    rng = np.random.default_rng(7)
    k = 200
    Q2 = rng.normal(size=(k, 3, 2))
    A = rng.normal(size=(k, 2, 2))
    A[np.linalg.det(A) < 0, :, 0] *= -1.0  # orientation kept: a mirror is not a map of the sphere
    P2 = np.einsum("tvi,tij->tvj", Q2, A)
    frame, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    P = np.einsum("tvi,ji->tvj", np.concatenate([P2, np.zeros((k, 3, 1))], axis=2), frame).reshape(-1, 3)
    Q = np.concatenate([Q2, np.zeros((k, 3, 1))], axis=2).reshape(-1, 3)
    F = np.arange(3 * k).reshape(k, 3)
    sv = np.linalg.svd(A, compute_uv=False)
    want = sv[:, 0] / sv[:, 1]
    keep = want < 1e3  # a nearly singular draw: f - 2 loses all digits, not what the map meets
    got = StretchEnergy(P, F).anisotropy(Q)
    assert np.allclose(got[keep], want[keep], rtol=1e-9, atol=0.0)
    assert keep.sum() > 190


def test_the_anisotropy_is_reported_and_1_on_the_sphere():
    st = _map(sphere_mesh).stretch
    assert 1.0 <= st["anisotropy_median"] <= st["anisotropy_p95"] < 1.0 + 1e-3
    long = _map(stretched_blob).stretch
    assert long["anisotropy_p95"] > st["anisotropy_p95"]


def test_long_shapes_have_more_stretch_than_round_ones():
    l2 = {make.__name__: _map(make).stretch["l2"] for make in GENUS0}
    assert l2["sphere_mesh"] < l2["star_blob"] < l2["ellipsoid_mesh"] < l2["stretched_blob"]
    assert l2["stretched_blob"] > l2["sphere_mesh"] + 0.1 and l2["bent_blob"] > l2["star_blob"] + 0.1


def test_the_relaxation_lowers_the_stretch_of_the_conformal_start():
    start = spherical_parametrization(stretched_blob(level=3), iterations=0)
    relaxed = _map(stretched_blob)
    assert start.stretch["steps"] == 0 and start.stretch["l2"] == start.stretch["l2_start"]
    assert relaxed.stretch["l2"] < start.stretch["l2"] - 0.3


@pytest.mark.parametrize("make, check", [(torus_mesh, "genus 0"), (open_cup, "manifold edges"),
                                         (two_spheres, "one component"), (nonmanifold_edge, "manifold edges")])
def test_bad_inputs_raise_the_check_they_fail(make, check):
    with pytest.raises(MeshTopologyError) as err:
        spherical_parametrization(make(), name="bad input")
    assert err.value.check == check and "bad input" in str(err.value)


def test_the_result_is_immutable():
    smap = _map(sphere_mesh)
    with pytest.raises(dataclasses.FrozenInstanceError):
        smap.sphere = None
    with pytest.raises(ValueError):
        smap.sphere[0, 0] = 2.0


@pytest.mark.parametrize("make", [stretched_blob, bent_blob])
def test_locate_finds_the_triangle_of_every_direction(make):
    """Barycentrics at least -1e-12 summing to 1, and ``bary @ sphere[face]`` along the direction: the ray meets
    the flat triangle inside it."""
    smap = _map(make)
    q = np.random.default_rng(3).normal(size=(5000, 3))
    face, bary = locate(smap, q)
    assert face.shape == (5000,) and (bary >= -1e-12).all() and np.abs(bary.sum(axis=1) - 1.0).max() < 1e-12
    hit = np.einsum("ni,nij->nj", bary, smap.sphere[smap.faces[face]])
    assert np.abs(np.cross(hit, q)).max() < 1e-12 * np.abs(q).max() and (np.einsum("ij,ij->i", hit, q) > 0).all()


@pytest.mark.parametrize("make", [ellipsoid_mesh, bent_blob])
def test_surface_points_of_the_vertex_images_are_the_vertices(make):
    smap = _map(make)
    assert np.abs(surface_points(smap, smap.sphere) - smap.points).max() < 1e-12
    # edge midpoints on the sphere go to points of the mesh's edges
    F = smap.faces
    mid = smap.sphere[F[:, 0]] + smap.sphere[F[:, 1]]
    back = surface_points(smap, mid)
    A, B = smap.points[F[:, 0]], smap.points[F[:, 1]]
    assert np.linalg.norm(np.cross(back - A, B - A), axis=1).max() < 1e-12


def test_locate_refuses_zero_directions():
    with pytest.raises(ValueError, match="nonzero"):
        locate(_map(sphere_mesh), [[0.0, 0.0, 0.0]])


def test_mobius_transformations_keep_the_map_one_to_one():
    m = sphere_mesh(level=3)
    F = m.faces.reshape(-1, 4)[:, 1:]
    Y = mobius_transform(m.points, [0.3, 0.2, -0.6])
    assert np.abs(np.linalg.norm(Y, axis=1) - 1.0).max() < 1e-14
    assert (_dets(Y, F) > 0).all() and abs(_lhuilier_areas(Y, F).sum() - 4 * np.pi) < 1e-8
    back = center_on_sphere(Y, np.ones(len(Y)))  # the icosphere's vertices are centred: undo the crowding
    assert np.linalg.norm(back.mean(axis=0)) < 1e-12 and (_dets(back, F) > 0).all()


def test_a_20k_triangle_mesh_runs_and_matches_the_coarse_one(capsys):
    """``star_blob(level=5)``: 20,480 triangles in a few seconds; its stretch is the level-3 one's up to a tenth
    of the excess over 1 (the discretization changes it by O(h^2))."""
    fine = spherical_parametrization(star_blob(level=5), progress=True)
    assert "stretch relaxation" in capsys.readouterr().err  # the progress bar
    assert fine.faces.shape == (20480, 3) and fine.flipped == 0
    assert abs(_lhuilier_areas(fine.sphere, fine.faces).sum() - 4 * np.pi) < 1e-8
    coarse = _map(star_blob).stretch["l2"]
    assert abs(fine.stretch["l2"] - coarse) < 0.1 * (coarse - 1.0)
    assert fine.timings["total"] < 60.0


def test_a_cut_vertex_with_a_chord_in_its_ring_is_passed_over():
    """On a subdivided cube the vertex of largest area has a ring with a chord (two ring vertices joined by an
    edge across the flat face): the triangle on three ring vertices would face inward on the sphere. The start
    cuts the mesh open at another vertex and the map is one-to-one."""
    import pyvista as pv

    cube = pv.Cube().triangulate().clean().subdivide(4, "linear").clean()
    smap = spherical_parametrization(cube, name="cube")
    assert smap.flipped == 0 and abs(_lhuilier_areas(smap.sphere, smap.faces).sum() - 4 * np.pi) < 1e-8
    assert smap.stretch["l2"] < 1.05  # a cube is nearly round: most of it maps with little stretch


def test_locate_widens_its_search_and_never_fails_silently():
    smap = _map(bent_blob)
    q = np.random.default_rng(5).normal(size=(2000, 3))
    assert np.array_equal(locate(smap, q, k=1)[0], locate(smap, q)[0])  # one candidate, widened where it misses
    holed = dataclasses.replace(smap, faces=smap.faces[1:])  # a hole where triangle 0 was
    inside = smap.sphere[smap.faces[0]].mean(axis=0)
    with pytest.raises(ValueError, match="in no spherical triangle"):
        locate(holed, [inside])

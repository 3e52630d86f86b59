"""The sample smoothing along the mesh (splinevis.geometry_image.regularize): samples stay on the mesh, the
X-cut's identified samples stay identical, and on a shape whose map has kinks the fit folds less while the
guards keep the samples at the features (the distance to the mesh does not grow as an unguarded smoothing's
does)."""

from __future__ import annotations

import warnings

import igl
import pytest
import numpy as np

import datasets_synthetic.closed_meshes as cm
from splinevis.geometry_image.build import geometry_image_from_mesh
from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
from splinevis.geometry_image.judge import surface_measures
from splinevis.geometry_image.regularize import smooth_samples, smoothing_steps
from splinevis.geometry_image.sphere import locate, spherical_parametrization


def test_samples_stay_on_the_mesh_and_identified_samples_stay_identical():
    smap = spherical_parametrization(cm.legged_blob(level=3))
    M = 65
    face, bary = locate(smap, octahedral_to_sphere(image_uv(M)).reshape(-1, 3))
    X = np.einsum("ni,nij->nj", bary, smap.points[smap.faces[face]]).reshape(M, M, 3)
    Y, kept = smooth_samples(smap.points, smap.faces, X, face, smoothing_steps(2))
    diag = np.linalg.norm(np.ptp(smap.points, axis=0))
    d2, _, _ = igl.point_mesh_squared_distance(Y.reshape(-1, 3), smap.points, smap.faces)
    # closest points of libigl: on the mesh up to the rounding of a point-in-triangle computation (~1e-15 diag)
    assert np.sqrt(d2.max()) <= 1e-12 * diag
    assert np.abs(Y - X).max() > 1e-3 * diag and 0.0 <= kept < 1.0  # it moved samples, and kept some
    N = M - 1
    # each border is its own mirror image across the X-cut: the mirrored directions agree to rounding (~1e-16),
    # the map multiplies that by its stretch (< 1e3 here) and the averaging steps do not amplify it
    for border in (Y[0], Y[N], Y[:, 0], Y[:, N]):
        assert np.abs(border - border[::-1]).max() <= 1e-12 * diag


def test_smoothing_folds_the_legged_blob_less_and_keeps_its_legs():
    mesh = cm.legged_blob(level=3)
    smap = spherical_parametrization(mesh)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain, _ = geometry_image_from_mesh(mesh, 33, fairness=0.1, sphere_map=smap, measure=False, smoothing=0)
        smooth, _ = geometry_image_from_mesh(mesh, 33, fairness=0.1, sphere_map=smap, measure=False)
    a, b = surface_measures(plain, mesh, 3), surface_measures(smooth, mesh, 3)
    assert b["folded_triangles"] < a["folded_triangles"] and b["reversed_points"] < a["reversed_points"]
    # the guards keep the samples at the legs' tips, so the farthest point hardly moves (measured 3.17 % -> 3.21 %
    # of the diagonal); without them the smoothing tends to a harmonic map and loses the tips (8.1 %)
    assert b["hausdorff"] <= 1.05 * a["hausdorff"]


def test_auto_turn_guard_tries_the_unguarded_smoothing_and_keeps_the_legs():
    mesh = cm.legged_blob(level=3)
    smap = spherical_parametrization(mesh)
    M = 65
    face, bary = locate(smap, octahedral_to_sphere(image_uv(M)).reshape(-1, 3))
    X = np.einsum("ni,nij->nj", bary, smap.points[smap.faces[face]]).reshape(M, M, 3)
    _, kept_guarded = smooth_samples(smap.points, smap.faces, X, face, smoothing_steps(2))
    _, kept_free = smooth_samples(smap.points, smap.faces, X, face, smoothing_steps(2), turn_guard=False)
    assert kept_free < kept_guarded  # without the turn guard only the jump guard holds samples back
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, guarded = geometry_image_from_mesh(mesh, 33, fairness=0.1, sphere_map=smap, turn_guard=True)
        _, auto = geometry_image_from_mesh(mesh, 33, fairness=0.1, sphere_map=smap)
    tried = auto.folds["turn_guard_tried"]
    # the guarded fit folds (above the thresholds), so "auto" measured the unguarded one too; that one loses the
    # legs' tips (the smoothing tends to a harmonic map: measured 3.2 % -> 8.1 % of the diagonal), so the guarded
    # fit is kept: the report is the guarded build's
    assert set(tried) == {"turn guard", "no turn guard"}
    assert tried["no turn guard"][2] > 2 * tried["turn guard"][2]
    assert auto.distance["hausdorff"] == guarded.distance["hausdorff"] and auto.folds["fraction"] == guarded.folds["fraction"]
    with pytest.raises(ValueError, match="turn_guard"):
        geometry_image_from_mesh(mesh, 33, sphere_map=smap, turn_guard="sometimes")

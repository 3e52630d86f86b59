"""Mesh to smooth geometry image on every synthetic genus-0 shape: the parametrization is bijective, the fitted
surface is C1 at the four cut vertices (the second-order terms there span a plane), it stays close to the mesh,
and where the parametrization undersamples the mesh (the bent blob's inner bend) the report and a warning say
so. Bad inputs fail with the check that names them."""

import warnings

import numpy as np
import pytest

from _cut_vertex import cone_measure
from datasets_synthetic import closed_meshes as cm
from splinevis.errors import MeshTopologyError
from splinevis.geometry_image.build import FOLDED_WARNING, FOLD_LEVEL, geometry_image_from_mesh

SHAPES = ["sphere_mesh", "ellipsoid_mesh", "star_blob", "stretched_blob", "bent_blob"]


@pytest.mark.parametrize("shape", SHAPES)
def test_every_shape_is_bijective_c1_and_close(shape):
    mesh = getattr(cm, shape)(level=3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        image, report = geometry_image_from_mesh(mesh, 33, name=shape)
    assert report.stretch["flipped"] == 0
    assert cone_measure(image.control).max() < 1e-12  # C1 at the cut vertices (see test_geometry_image_model)
    # distance to the mesh: the fit's order-2 error at n = 33 plus the mesh's own facets; 0.05 of the diagonal
    # is the bent blob's (the others are within 0.01)
    assert report.distance["hausdorff"] < (0.05 if shape == "bent_blob" else 0.01), report.distance
    folds = [w for w in caught if "folds over" in str(w.message)]
    # the build warns on the check's count (level FOLD_LEVEL, away from the cut vertices)
    assert bool(folds) == (report.folds["fraction"] > FOLDED_WARNING)
    assert report.folds["level"] == FOLD_LEVEL and report.folds["triangles"] == 2 * (2 ** FOLD_LEVEL * 32) ** 2
    if shape != "bent_blob":
        assert report.folds["fraction"] < FOLDED_WARNING, report.folds


def test_folds_are_reported_and_warned():
    """A known weakness: the bent blob's inner bend is compressed ~13x in area on the sphere; sampled through the
    parametrization's own orientation, the fitted surface folds over there and the build says so."""
    with pytest.warns(UserWarning, match="folds over in .* undersamples part of the mesh") as caught:
        _, report = geometry_image_from_mesh(cm.bent_blob(level=3), 33, name="bent blob", orientation=None)
    assert report.folded > FOLDED_WARNING and "bent blob" in str(caught[0].message)
    assert "orientation=None" not in str(caught[0].message)  # the caller chose the rotation: not suggested


@pytest.mark.parametrize("bad, check", [("torus_mesh", "genus 0"), ("open_cup", "manifold edges"),
                                        ("two_spheres", "one component"), ("nonmanifold_edge", "manifold edges")])
def test_bad_inputs_fail_with_their_check(bad, check):
    with pytest.raises(MeshTopologyError, match=f"^{check}: {bad}"):
        geometry_image_from_mesh(getattr(cm, bad)(), 9, name=bad)


def test_a_mesh_file_is_read(tmp_path):
    path = tmp_path / "blob.ply"
    cm.star_blob(level=2).save(path)
    image, report = geometry_image_from_mesh(path, 17)
    assert report.name == str(path) and report.triangles == 320 and image.n == 17


def test_orientation_samples_the_compressed_part_better():
    """Rotating the sphere so that the most compressed part of the stretched blob lands where the octahedral map
    samples densest (up to 3 sqrt 3 more image area per sphere area) improves the fit: measured 2.4x closer at
    n = 33 (asserted: at least 1.5x), and never a worse sampling criterion than the identity."""
    from splinevis.geometry_image.orient import best_orientation, sampling_criterion
    from splinevis.geometry_image.sphere import spherical_parametrization

    mesh = cm.stretched_blob(level=3)
    _, plain = geometry_image_from_mesh(mesh, 33, orientation=None)
    _, oriented = geometry_image_from_mesh(mesh, 33)
    assert oriented.distance["hausdorff"] < plain.distance["hausdorff"] / 1.5
    assert oriented.distance["rms"] < plain.distance["rms"]
    smap = spherical_parametrization(mesh)
    R, rows = best_orientation(smap)
    assert np.allclose(R, oriented.orientation) and np.allclose(R @ R.T, np.eye(3)) and np.linalg.det(R) > 0
    assert sampling_criterion(smap.points, smap.faces, smap.sphere, R) == min(r["criterion"] for r in rows)
    assert rows[0]["candidate"] == "identity" and min(r["criterion"] for r in rows) <= rows[0]["criterion"]
    with pytest.raises(ValueError, match="3x3 rotation"):
        geometry_image_from_mesh(mesh, 9, orientation=np.diag([1.0, 1.0, -1.0]))


def test_a_parametrization_made_already_is_used():
    """The showcase parametrizes once for its sphere panel and hands it over: the same image as parametrizing
    inside (the parametrization is deterministic), and a map of another mesh is refused."""
    from splinevis.geometry_image.sphere import spherical_parametrization

    mesh = cm.star_blob(level=2)
    smap = spherical_parametrization(mesh)
    inside, _ = geometry_image_from_mesh(mesh, 9)
    given, report = geometry_image_from_mesh(mesh, 9, sphere_map=smap)
    np.testing.assert_array_equal(given.control, inside.control)
    assert "parametrize" not in report.seconds
    with pytest.raises(ValueError, match="not a parametrization of mesh"):
        geometry_image_from_mesh(cm.sphere_mesh(level=2), 9, sphere_map=smap)


def test_auto_fairness_smooths_ripples_within_the_distance_budget(monkeypatch):
    # A coarse legged blob at n = 33 folds (274 level-4 triangles at fairness 0.1, 2.7 % from the mesh); with a
    # 4 % budget "auto" tries 0.3 (95 folds, 3.4 %), then 1 (4.6 %: beyond the budget, its folds not counted) and
    # keeps 0.3: fewer folds, never beyond the budget. (The real budget, 1 %, is met on the real scans.) Without
    # the sample smoothing (smoothing=0), which folds this blob less: the fairness logic is what is tested here.
    import splinevis.geometry_image.build as build

    monkeypatch.setattr(build, "AUTO_FAIRNESS_HAUSDORFF", 0.04)
    mesh = cm.legged_blob(level=3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _, fixed = geometry_image_from_mesh(mesh, 33, fairness=0.1, smoothing=0)
        _, auto = geometry_image_from_mesh(mesh, 33, fairness="auto", smoothing=0)
    tried = auto.folds["fairness_tried"]
    assert list(tried) == [0.1, 0.3, 1.0]
    assert tried[0.1] == (fixed.folds["fraction"], fixed.distance["hausdorff"])  # the same first fit
    assert auto.fairness == 0.3 and auto.folds["folded"] < fixed.folds["folded"]
    assert auto.distance["hausdorff"] == tried[0.3][1] <= 0.04 < tried[1.0][1]
    # still above the fold threshold: the warning lists what was tried
    assert any("fairness tried (folds, distance): 0.1:" in str(w.message) and "kept 0.3" in str(w.message)
               for w in caught)
    with pytest.raises(ValueError, match=r"fairness must be 'auto' or a number >= 0, got 'strong'"):
        geometry_image_from_mesh(mesh, 33, fairness="strong")


def test_auto_size_builds_again_finer_from_a_nearer_conformal_map_where_the_image_folds(monkeypatch):
    # n="auto" with the sizes scaled down (9, 17, then at most 33 instead of 33 ... 257, then 513). The small
    # six-legged blob from the coarse-to-fine start: its 17 x 17 image folds and is inside out (measured 0.30 % /
    # 12 %, 6.9 % from the mesh), so the build parametrizes again with level_inverse = 1 and builds 33 x 33
    # (0.15 % / 1.4 %, 2.9 %): less past the thresholds and nearer, so it is kept. It must be exactly what asking
    # for it directly gives, and asking for level_inverse turns the second build off.
    import splinevis.geometry_image.build as build

    monkeypatch.setattr(build, "AUTO_SIZES", (9, 17))
    monkeypatch.setattr(build, "ESCALATE_MAX", 33)
    mesh = cm.legged_blob(level=2)
    start = {"start": "hierarchy"}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        image, report = geometry_image_from_mesh(mesh, name="legs", parametrization_options=start)
        direct, report_direct = geometry_image_from_mesh(mesh, 33, name="legs",
                                                         parametrization_options=dict(start, level_inverse=1.0))
    tried = report.folds["escalation_tried"]
    assert list(tried) == ["n = 17, level_inverse 0", "n = 33, level_inverse 1"]
    first, finer = tried["n = 17, level_inverse 0"], tried["n = 33, level_inverse 1"]
    badness = [max(f / build.FOLDED_WARNING, r / build.REVERSED_WARNING) for f, r, _ in (first, finer)]
    assert badness[0] > 1.0 and badness[1] < badness[0] and finer[2] <= max(build.AUTO_FAIRNESS_HAUSDORFF, first[2])
    assert report.n == 33 and report.stretch["level_inverse"] == 1.0
    assert finer == (report.folds["fraction"], report.folds["reversed"], report.distance["hausdorff"])
    assert list(report.distance["sizes_tried"]) == [9, 17, 33]
    np.testing.assert_array_equal(image.control, direct.control)  # the same map, size, smoothing and fairness
    assert "escalation_tried" not in report_direct.folds and report_direct.stretch["level_inverse"] == 1.0
    assert any("rebuilt from a parametrization nearer conformal (folds, inside out, distance: n = 17, level_inverse"
               in str(w.message) for w in caught)
    # the rotation was chosen by the build: the warning names it as the other lever
    assert any("rebuilt from" in str(w.message) and "orientation=None (the map's own)" in str(w.message)
               for w in caught)


def test_the_escalation_doubles_the_size_while_the_last_image_still_folds_reusing_a_tutte_map(monkeypatch):
    # The Tutte-started legged blob (level 3) with the sizes scaled down (5, 9, then at most 33): its 9 x 9 image
    # folds, and so does the 17 x 17 one (measured 0.16 % / 2.5 %), so the build goes on to 33 x 33 (0.024 % /
    # 0.16 %): every image tried is listed, the least past the thresholds is kept. The inverse weight acts on the
    # coarse-to-fine levels only: a Tutte start would come out the same with it, so the finer images are built
    # from the same map, labelled with the weight it had, 0, and the kept one is exactly the image of that size
    # asked for directly.
    import splinevis.geometry_image.build as build

    monkeypatch.setattr(build, "AUTO_SIZES", (5, 9))
    monkeypatch.setattr(build, "ESCALATE_MAX", 33)
    mesh = cm.legged_blob(level=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        image, report = geometry_image_from_mesh(mesh, name="legs")
        direct, _ = geometry_image_from_mesh(mesh, report.n, name="legs")
    tried = report.folds["escalation_tried"]
    assert list(tried) == ["n = 9, level_inverse 0", "n = 17, level_inverse 0", "n = 33, level_inverse 0"]
    badness = {k: max(f / build.FOLDED_WARNING, r / build.REVERSED_WARNING) for k, (f, r, _) in tried.items()}
    assert badness["n = 9, level_inverse 0"] > 1.0 and badness["n = 17, level_inverse 0"] > 1.0  # both went on
    assert list(report.distance["sizes_tried"])[-2:] == [17, 33]
    kept = f"n = {report.n}, level_inverse 0"
    assert tried[kept] == (report.folds["fraction"], report.folds["reversed"], report.distance["hausdorff"])
    assert report.stretch["level_inverse"] == 0.0
    np.testing.assert_array_equal(image.control, direct.control)


def test_the_distance_warning_names_the_fairness_that_moved_the_surface():
    from splinevis.geometry_image.build import _distance_words

    kept_against_folds = _distance_words("m", 129, 3.0, 0.0051, {0.1: (4e-6, 0.0011), 3.0: (1e-6, 0.0051)})
    assert "fairness 3, kept against its folds" in kept_against_folds and "0.11%" in kept_against_folds
    resolution = _distance_words("m", 257, 0.1, 0.0093, {0.1: (1e-3, 0.0093)})
    assert "detail finer than the image resolves" in resolution

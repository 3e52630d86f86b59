"""Input checks of smooth geometry images: every synthetic genus-0 shape passes with its exact counts, every bad
input fails the one check it is built to fail, and the message says where."""

import numpy as np
import pytest

from datasets_synthetic.closed_meshes import (ellipsoid_mesh, nonmanifold_edge, open_cup, sphere_mesh, star_blob,
                                              star_blob_normals, stretched_blob, torus_mesh, two_spheres)
from splinevis.errors import MeshTopologyError
from splinevis.geometry_image.validate import check_genus0


@pytest.mark.parametrize("make", [sphere_mesh, ellipsoid_mesh, star_blob, stretched_blob])
@pytest.mark.parametrize("level", [1, 3])
def test_genus0_shapes_pass_with_their_counts(make, level):
    info = check_genus0(make(level=level))
    F = 20 * 4 ** level
    assert info == {**info, "triangles": F, "edges": 3 * F // 2, "vertices": 10 * 4 ** level + 2, "genus": 0}
    assert info["volume"] > 0


def test_the_sphere_volume_converges_to_4_pi_over_3():
    # an inscribed polyhedron: its volume is below the ball's and the gap shrinks ~4x a level
    gaps = [4 * np.pi / 3 - check_genus0(sphere_mesh(level=k))["volume"] for k in (2, 3, 4)]
    assert all(g > 0 for g in gaps) and 3.5 < gaps[0] / gaps[1] < 4.5 and 3.5 < gaps[1] / gaps[2] < 4.5


def test_star_blob_normals_are_the_surface_normals():
    """The exact normals against the gradient of the implicit form G(x) = |x| - rho(x / |x|), by central
    differences (step 1e-5: truncation ~1e-10, rounding ~1e-11), normalized: they agree to 1e-8."""
    from datasets_synthetic.closed_meshes import star_blob_radius

    X = star_blob(level=2).points

    def G(Y):
        r = np.linalg.norm(Y, axis=1)
        return r - star_blob_radius(Y / r[:, None], 0.25)

    h = 1e-5
    grad = np.column_stack([(G(X + h * e) - G(X - h * e)) / (2 * h) for e in np.eye(3)])
    grad /= np.linalg.norm(grad, axis=1, keepdims=True)
    assert np.abs(star_blob_normals(X) - grad).max() < 1e-8
    assert np.abs(G(X)).max() < 1e-14  # the points lie on the surface


@pytest.mark.parametrize("make, check, words", [
    (torus_mesh, "genus 0", "genus 1"),
    (open_cup, "manifold edges", "border edge"),
    (two_spheres, "one component", "2 separate pieces"),
    (nonmanifold_edge, "manifold edges", "non-manifold edge (in 4 triangles)"),
])
def test_bad_inputs_fail_the_check_they_are_built_to_fail(make, check, words):
    with pytest.raises(MeshTopologyError) as err:
        check_genus0(make(), "input")
    assert err.value.check == check and words in str(err.value) and "input" in str(err.value)


def test_inward_and_flipped_meshes_are_refused():
    m = sphere_mesh(level=1)
    with pytest.raises(MeshTopologyError, match="face inward"):
        check_genus0(m.flip_faces())
    faces = m.faces.reshape(-1, 4).copy()
    faces[0, 1:] = faces[0, [2, 1, 3]]  # one triangle turned
    bad = m.copy()
    bad.faces = faces.ravel()
    with pytest.raises(MeshTopologyError, match="orientation flips"):
        check_genus0(bad)


def test_quads_and_degenerate_triangles_are_refused():
    import pyvista as pv

    with pytest.raises(MeshTopologyError, match="triangulate"):
        check_genus0(pv.Cube())
    m = sphere_mesh(level=1)
    faces = m.faces.reshape(-1, 4).copy()
    faces[0, 2] = faces[0, 1]
    bad = m.copy()
    bad.faces = faces.ravel()
    with pytest.raises(MeshTopologyError, match="no area"):
        check_genus0(bad)

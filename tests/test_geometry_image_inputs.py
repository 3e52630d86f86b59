"""Meshes as users bring them to a geometry image: OBJ-style triangle soups are welded, polygons triangulated
(each repair reported and warned), a pinched vertex is named with its position, tiny meshes (a tetrahedron, an
octahedron) build, and n="auto" picks a size whose measured distance meets its goal."""

import warnings

import numpy as np
import pytest
import pyvista as pv

from datasets_synthetic.closed_meshes import sphere_mesh
from splinevis.errors import MeshTopologyError
from splinevis.geometry_image.build import AUTO_HAUSDORFF, AUTO_SIZES, geometry_image_from_mesh
from splinevis.geometry_image.validate import check_genus0


def _soup(mesh):
    """Every triangle with its own three points, as VTK reads an OBJ with texture coordinates."""
    F = mesh.faces.reshape(-1, 4)[:, 1:]
    P = np.asarray(mesh.points)[F.ravel()]
    return pv.PolyData(P, np.column_stack([np.full(len(F), 3), np.arange(3 * len(F)).reshape(-1, 3)]).ravel())


def test_a_triangle_soup_is_welded_and_the_weld_reported():
    m = sphere_mesh(level=2)
    soup = _soup(m)
    with pytest.raises(MeshTopologyError, match="border edge"):
        check_genus0(soup)  # what a user got before the repair
    with pytest.warns(UserWarning, match=f"welded {soup.n_points:,} points into {m.n_points:,} vertices"):
        _, report = geometry_image_from_mesh(soup, n=17, name="soup")
    assert report.vertices == m.n_points and report.triangles == m.n_cells and len(report.repairs) == 1


def test_positions_written_twice_with_float32_rounding_are_welded_within_the_tolerance():
    from splinevis.geometry_image.repair import prepare_mesh

    m = sphere_mesh(level=2)
    soup = _soup(m)
    # each corner written from float32 by an exporter that moved the mesh first: positions of one vertex differ
    # in their last float32 bits: two copies differ by <= 2 x 2^-23 per coordinate (coordinates of size 1, the
    # unit sphere's), sqrt(3) x 2^-22 = 4.1e-7 in all, far below WELD_TOLERANCE x diagonal (2 sqrt(3) = 3.5e-6)
    # and far above 0 (exact welding keeps them apart)
    jitter = np.random.default_rng(0).integers(-1, 2, size=soup.points.shape) * 2.0 ** -23
    soup.points = (np.asarray(soup.points, dtype=np.float64) + jitter).astype(np.float32).astype(np.float64)
    welded, repairs = prepare_mesh(soup, "float32 soup")
    assert welded.n_points == m.n_points and welded.n_cells == m.n_cells
    assert "of the bounding box's diagonal; the largest distance merged is" in repairs[0]
    check_genus0(welded)  # closed again
    exact, _ = prepare_mesh(soup, "float32 soup", weld_tolerance=0)
    assert exact.n_points > m.n_points


def test_a_face_whose_corners_weld_together_is_removed_and_counted():
    from splinevis.geometry_image.repair import prepare_mesh

    m = sphere_mesh(level=2)
    P = np.asarray(m.points, dtype=np.float64)
    F = m.faces.reshape(-1, 4)[:, 1:]
    # a sliver: a new point 1e-9 from vertex F[0, 0], replacing it in face 0 only; a triangle between it and
    # the two corners would have an edge of 1e-9 (below the tolerance): that face welds into a segment
    sliver = np.array([[F[0, 0], len(P), F[0, 1]]])
    P2 = np.vstack([P, P[F[0, 0]] + 1e-9])
    faces = np.vstack([F, sliver])
    mesh = pv.PolyData(P2, np.column_stack([np.full(len(faces), 3), faces]).ravel())
    welded, repairs = prepare_mesh(mesh, "sliver")
    assert welded.n_points == m.n_points and welded.n_cells == m.n_cells
    assert any(r.startswith("removed 1 faces whose corners welded") for r in repairs)


def test_quads_are_triangulated_without_repeating_an_edge():
    cube = pv.Cube().clean()  # 6 quads
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _, report = geometry_image_from_mesh(cube, n=17, name="cube")
    assert report.triangles == 12 and any("triangulated 6 polygons (6 quads)" in r for r in report.repairs)
    assert any("triangulated 6 polygons" in str(w.message) for w in caught)


def test_a_pinched_vertex_is_named_with_its_position():
    # two octahedra sharing one vertex: every edge in two triangles, one vertex where two fans meet
    up = np.vstack([np.eye(3), -np.eye(3)]) + [0, 0, 1]
    down = np.vstack([np.eye(3), -np.eye(3)]) - [0, 0, 1]
    faces = np.array([[0, 1, 2], [1, 3, 2], [3, 4, 2], [4, 0, 2], [1, 0, 5], [3, 1, 5], [4, 3, 5], [0, 4, 5]])
    P = np.vstack([up, np.delete(down, 2, axis=0)])  # down's vertex 2 (0, 0, 0) is up's vertex 5
    lower = faces.copy()
    lower = np.where(lower == 2, 5 - 6, lower)  # marks the shared vertex
    lower = np.where(lower > 2, lower - 1, lower) + 6
    lower = np.where(lower == 5, 5, lower)
    F = np.vstack([faces, lower])
    mesh = pv.PolyData(P, np.column_stack([np.full(len(F), 3), F]).ravel())
    with pytest.raises(MeshTopologyError, match=r"manifold vertices: .* vertex 5 \[0.0, 0.0, 0.0\], where 2 separate fans"):
        check_genus0(mesh, "two octahedra")


@pytest.mark.parametrize("which", ["tetrahedron", "octahedron"])
def test_tiny_meshes_build(which):
    if which == "tetrahedron":
        P = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1.0]])
        F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    else:
        P = np.vstack([np.eye(3), -np.eye(3)])
        F = np.array([[0, 1, 2], [1, 3, 2], [3, 4, 2], [4, 0, 2], [1, 0, 5], [3, 1, 5], [4, 3, 5], [0, 4, 5]])
    mesh = pv.PolyData(P, np.column_stack([np.full(len(F), 3), F]).ravel())
    image, report = geometry_image_from_mesh(mesh, n=17, name=which)
    assert report.stretch["flipped"] == 0 and np.isfinite(image.control).all()
    # measured and reported (a smooth surface cannot follow a tetrahedron's corners closely; no goal here)
    assert np.isfinite(report.distance["hausdorff"]) and report.distance["hausdorff"] > 0


def test_auto_size_stops_at_the_first_size_within_the_goal():
    _, report = geometry_image_from_mesh(sphere_mesh(level=3), name="sphere")
    tried = report.distance["sizes_tried"]
    assert list(tried) == list(AUTO_SIZES[: len(tried)]) and report.n == list(tried)[-1]
    assert tried[report.n] <= AUTO_HAUSDORFF and all(d > AUTO_HAUSDORFF for d in list(tried.values())[:-1])

"""The check's accuracy figures of a geometry image (splinevis.geometry_image.judge.surface_measures), measured
tile by tile, against the same figures of the whole limit level computed directly (surface_distance, fold_counts,
folded_fraction, reversed_normals on the whole arrays): equal, the RMS up to the order of its sum (relative
1e-12: a sum of ~1e5 squares in float64 reordered moves by at most n u of the sum)."""

import numpy as np
import pytest

from datasets_synthetic.closed_meshes import star_blob
from splinevis.geometry_image.build import fold_counts, folded_fraction, limit_mesh_arrays
from splinevis.geometry_image.image import cut_vertices, symmetrize
from splinevis.geometry_image.judge import BUILD_FOLD_LEVEL, REVERSED_LEVEL, surface_measures
from splinevis.geometry_image.measure import reversed_normals, surface_distance
from splinevis.geometry_image.model import GeometryImage
from splinevis.geometry_image.program import model_from
from splinevis.geometry_image.subdivision import grid_faces


def _whole(model, mesh, L, drawn):
    import igl

    V = np.asarray(mesh.points, dtype=np.float64)
    F = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
    P, N, T = limit_mesh_arrays(model, L)
    M = int(round(np.sqrt(len(P))))
    out = dict(surface_distance(P, T, V, F))
    folded, at_cut = fold_counts(P.reshape(M, M, 3), N.reshape(M, M, 3))
    out.update(folded_triangles=folded, cut_vertex_folded=at_cut, limit_triangles=len(T))
    s = 1 << (L - drawn)
    out["drawn_folded"] = fold_counts(P.reshape(M, M, 3)[::s, ::s], N.reshape(M, M, 3)[::s, ::s])[0]
    s = 1 << (L - min(BUILD_FOLD_LEVEL, L))
    Mb = (M - 1) // s + 1
    out["build_folded_fraction"] = folded_fraction(P.reshape(M, M, 3)[::s, ::s].reshape(-1, 3),
                                                   N.reshape(M, M, 3)[::s, ::s].reshape(-1, 3), grid_faces(Mb))
    s = 1 << max(L - REVERSED_LEVEL, 0)
    grid = np.zeros((M, M), bool)
    grid[::s, ::s] = True
    for vr, vc in cut_vertices(M):
        grid[vr, vc] = False
    idx = np.flatnonzero(grid.ravel())
    closest = igl.point_mesh_squared_distance(np.ascontiguousarray(P[idx]), V, F)[1]
    out.update(reversed_normals(N[idx], closest, V, F))
    return out


@pytest.mark.parametrize("crumple, cells", [(0.0, 4), (0.2, 4), (0.3, 3)])
def test_tiled_measures_equal_the_whole_levels(crumple, cells):
    blob = star_blob(level=2)
    model = model_from(blob, 17, fairness=0.1)
    if crumple:  # folds and inside-out points, so the counts are not all zero
        rng = np.random.default_rng(5)
        model = GeometryImage(symmetrize(model.control + crumple * rng.normal(size=model.control.shape)), constrain=True)
    L, drawn = 3, 2
    got = surface_measures(model, blob, L, drawn, cells=cells)
    want = _whole(model, blob, L, drawn)
    for key in ("hausdorff", "to_reference", "from_reference", "diagonal", "folded_triangles", "cut_vertex_folded",
                "limit_triangles", "drawn_folded", "build_folded_fraction", "reversed_points", "reversed_grid_points",
                "reversed_fraction", "input_folded_faces"):
        assert got[key] == want[key], key
    assert got["rms"] == pytest.approx(want["rms"], rel=1e-12)
    if crumple:
        assert got["folded_triangles"] > 0 and got["reversed_points"] > 0 and got["cut_vertex_folded"] > 0


@pytest.mark.parametrize("reach", [0.05, 1e-4])
def test_pruned_distances_from_the_mesh_equal_those_to_the_whole_level(reach):
    """Every input sample's distance to the limit triangles (the check's 'from the reference' direction), searched
    tile by tile among the blocks that can hold the nearest triangle (judge._from_reference), equals libigl's over
    all the level's triangles at once; with a reach of 1e-4 of the diagonal most samples take the fallback (every
    triangle of every tile) and still agree."""
    import igl

    from splinevis.geometry_image import judge

    blob = star_blob(level=2)
    rng = np.random.default_rng(5)
    model = model_from(blob, 17, fairness=0.1)
    model = GeometryImage(symmetrize(model.control + 0.3 * rng.normal(size=model.control.shape)), constrain=True)
    V = np.asarray(blob.points, dtype=np.float64)
    F = np.asarray(blob.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
    samples = np.vstack([V, V[F].mean(axis=1)])
    L, cells = 3, 3
    P, _, T = limit_mesh_arrays(model, L)
    M = int(round(np.sqrt(len(P))))
    want = igl.point_mesh_squared_distance(samples, P, T)[0]
    diagonal = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    reach2 = (reach * diagonal) ** 2
    corners = P.reshape(M, M, 3)[::2, ::2].reshape(-1, 3)
    got = judge._from_reference(samples, corners, model.control, L, cells, reach2)
    np.testing.assert_array_equal(got, want)
    if reach < 1e-3:
        assert (want > reach2).mean() > 0.5  # the fallback measured most of them

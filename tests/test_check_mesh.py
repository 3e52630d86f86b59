"""``splinevis check`` on closed triangle meshes (the ``mesh`` judge, :mod:`splinevis.geometry_image.judge`): a
mesh with a hole or a handle fails with the check that names it, a geometry image of another shape and one
folded over fail on their accuracy findings, a correct closed mesh passes, and the reader's repairs (welding the
per-corner points of an OBJ with texture coordinates, triangulating polygons without repeating an edge, OFF
through libigl) are done and reported."""

from __future__ import annotations

import numpy as np
import pytest

from datasets_synthetic.closed_meshes import ellipsoid_mesh, open_cup, star_blob, torus_mesh
from splinevis.check.run import judge_file
from splinevis.errors import MeshTopologyError
from splinevis.geometry_image.judge import JUDGE, THRESHOLDS, MeshData
from splinevis.geometry_image.model import GeometryImage
from splinevis.geometry_image.program import model_from
from splinevis.geometry_image.validate import check_genus0


def _faces(mesh):
    return np.asarray(mesh.faces).reshape(-1, 4)[:, 1:]


def _write_obj(path, points, polygons, *, texture=False):
    """An OBJ file; ``texture=True`` gives every face corner its own ``vt`` (as a UV atlas does), so that VTK's
    reader splits the mesh into one point per corner."""
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(points, dtype=np.float64).tolist()]
    k = 0
    for poly in polygons:
        if texture:
            lines += [f"vt {0.001 * (k + i)!r} 0.5" for i in range(len(poly))]
            lines.append("f " + " ".join(f"{v + 1}/{k + i + 1}" for i, v in enumerate(poly)))
            k += len(poly)
        else:
            lines.append("f " + " ".join(str(v + 1) for v in poly))
    path.write_text("\n".join(lines) + "\n")
    return path


def _accuracy_findings(data, model, options=None):
    findings = []
    m = JUDGE.accuracy("mesh.obj", data, model, data.mesh, options or {}, findings)
    return m, findings


# ---- wrong files fail, with the reason ------------------------------------------------------------------------

@pytest.mark.parametrize("make, check, words", [
    (lambda: open_cup(level=2), "manifold edges", "like a border edge (in one triangle)"),
    (lambda: torus_mesh(n=12), "genus 0", "has genus 1"),
], ids=["open cup", "torus"])
def test_a_mesh_with_a_hole_or_a_handle_fails_with_the_reason(tmp_path, make, check, words):
    mesh = make()
    path = _write_obj(tmp_path / "bad.obj", mesh.points, _faces(mesh).tolist())
    r = judge_file(path, "mesh", tmp_path / "out", options={"n": 17})
    assert r["verdict"] == "FAIL"
    reason = r["findings"][-1]["reason"]
    assert reason.startswith(f"build failed: MeshTopologyError: {check}: bad.obj"), reason
    assert words in reason
    if check == "manifold edges":  # the message counts the border edges: the cup's rim
        edges, count = np.unique(np.sort(np.concatenate([_faces(mesh)[:, [0, 1]], _faces(mesh)[:, [1, 2]],
                                                         _faces(mesh)[:, [2, 0]]]), axis=1), axis=0, return_counts=True)
        assert f"{int((count == 1).sum())} edges like a border edge" in reason
    assert r["accuracy"] == {} and "thumbnail" not in r  # nothing drawn


def test_a_surface_of_another_shape_fails():
    blob = star_blob(level=3)
    data = MeshData(blob, "blob")
    m, findings = _accuracy_findings(data, model_from(ellipsoid_mesh(level=3), 17))
    # the ellipsoid (2 x 1 x 0.5) against the blob (radius 0.75 .. 1.25): a quarter of the blob's diagonal apart
    assert 0.2 < m["hausdorff"] < 0.3, m
    assert m["hausdorff"] > THRESHOLDS["hausdorff_fail"]
    assert findings[0].level == "FAIL" and "a different shape" in findings[0].reason
    assert f"{100 * m['hausdorff']:.2f} %" in findings[0].reason


def test_a_folded_surface_fails():
    blob = star_blob(level=3)
    data = MeshData(blob, "blob")
    good = model_from(blob, 17)
    G = good.control.copy()
    G[5:10, 5:10] = G[5:10, 5:10][:, ::-1]  # a 5 x 5 block of the image turned over: the surface folds there
    m, findings = _accuracy_findings(data, GeometryImage(G, constrain=True))
    # its middle sheet faces backwards: 6 % of the limit points have normals against the blob's
    assert 0.03 < m["reversed_fraction"] < 0.1, m
    assert m["reversed_fraction"] > THRESHOLDS["reversed_fail"]
    assert [f.level for f in findings] == ["FAIL", "FAIL"]  # moved by 8 % of the diagonal, and inside out
    assert "inside out over more than 0.1 %" in findings[1].reason
    # the same blob's own geometry image: no fold anywhere
    m_good, good_findings = _accuracy_findings(data, good)
    assert (m_good["folded_triangles"], m_good["reversed_points"], m_good["drawn_folded"]) == (0, 0, 0)
    assert good_findings[1].level == "PASS"


# ---- a right file passes ------------------------------------------------------------------------------------

def test_a_correct_closed_mesh_passes(tmp_path):
    blob = star_blob(level=3)  # 642 vertices, 1,280 triangles
    path = _write_obj(tmp_path / "blob.obj", blob.points, _faces(blob).tolist())
    r = judge_file(path, "mesh", tmp_path / "out", options={"n": 33})
    assert r["verdict"] == "PASS", r["findings"]
    acc = r["accuracy"]
    assert (acc["n"], acc["measure_level"], acc["drawn_level"], acc["limit_triangles"]) == (33, 4, 3, 2 * 512 ** 2)
    assert (acc["input_vertices"], acc["input_triangles"]) == (642, 1280)
    # the smooth surface against the faceted blob: within a quarter of the WARN threshold's 0.5 % of the diagonal
    assert acc["hausdorff"] < 0.004 and acc["rms"] < 0.001, acc
    assert (acc["folded_triangles"], acc["reversed_points"], acc["drawn_folded"]) == (0, 0, 0)
    assert [f["level"] for f in r["findings"]] == ["PASS", "PASS"]
    assert r["findings"][1]["reason"].startswith("no folds: 0 of the 524,288 limit triangles at level 4")
    assert min(v["iou"] for v in r["views"].values()) > 0.97
    assert (tmp_path / "out" / r["thumbnail"]).stat().st_size > 1000


# ---- the reader's repairs -----------------------------------------------------------------------------------

def test_an_obj_with_texture_coordinates_is_welded_and_reported(tmp_path):
    blob = star_blob(level=2)  # 162 vertices, 320 triangles
    plain, textured = [], []
    a = JUDGE.read(_write_obj(tmp_path / "plain.obj", blob.points, _faces(blob).tolist()), {}, plain)
    b = JUDGE.read(_write_obj(tmp_path / "uv.obj", blob.points, _faces(blob).tolist(), texture=True), {}, textured)
    assert plain == []  # nothing to repair: the file's vertices, in the file's order
    assert np.array_equal(a.mesh.points, blob.points) and np.array_equal(_faces(a.mesh), _faces(blob))
    assert [(f.level, f.reason.split(" (")[0]) for f in textured] == [("WARN", "welded 960 points into 162 vertices")]
    # the same triangles, corner by corner (the welded vertices are numbered as the corners come)
    assert b.mesh.n_points == 162 and np.array_equal(b.mesh.points[_faces(b.mesh)], a.mesh.points[_faces(a.mesh)])
    assert check_genus0(b.mesh)["genus"] == 0


def test_polygons_are_triangulated_without_repeating_an_edge(tmp_path):
    """Two quads sharing two sides (a vertex of valence 2, as in beast.obj): cut from their first corners, both
    take the diagonal a-b and make that edge a non-manifold one; the reader cuts the second along its other
    diagonal."""
    blob = star_blob(level=2)
    P, F = np.asarray(blob.points), _faces(blob)
    a, b, e1 = (int(v) for v in F[0])
    (t2,) = [t for t in range(len(F)) if t != 0 and {a, b} <= set(F[t].tolist())]
    e2 = int(next(v for v in F[t2] if v not in (a, b)))
    x = len(P)
    normal = P[a] + P[b]
    normal /= np.linalg.norm(normal)
    # x stands off the edge a-b by its length, so a-b is each quad's shorter diagonal
    P = np.vstack([P, 0.5 * (P[a] + P[b]) + np.linalg.norm(P[a] - P[b]) * normal])
    polygons = [[a, x, b, e1], [b, x, a, e2]] + [f.tolist() for t, f in enumerate(F) if t not in (0, t2)]
    findings = []
    data = JUDGE.read(_write_obj(tmp_path / "pocket.obj", P, polygons), {}, findings)
    assert [(f.level, f.reason.split(" (fans")[0]) for f in findings] == [
        ("WARN", "triangulated 2 polygons (2 quads) into 322 triangles in all")]
    info = check_genus0(data.mesh, "pocket")
    assert (info["vertices"], info["triangles"], info["genus"]) == (163, 322, 0)
    # the fixed fan from each polygon's first corner
    naive = [[p[0], p[j], p[j + 1]] for p in polygons for j in range(1, len(p) - 1)]
    fixed = np.column_stack([np.full(len(naive), 3), naive]).ravel()
    with pytest.raises(MeshTopologyError, match="non-manifold edge \\(in 4 triangles\\)"):
        check_genus0(type(data.mesh)(P, fixed), "pocket")


def test_off_is_read_with_libigl_and_n_is_an_option(tmp_path):
    blob = star_blob(level=2)
    F = _faces(blob)
    lines = ["OFF", f"{blob.n_points} {len(F)} 0"] + [f"{x!r} {y!r} {z!r}" for x, y, z in blob.points.tolist()]
    lines += [f"3 {i} {j} {k}" for i, j, k in F]
    (tmp_path / "blob.off").write_text("\n".join(lines) + "\n")
    findings = []
    data = JUDGE.read(tmp_path / "blob.off", {}, findings)
    assert findings == [] and data.name == "blob.off"
    assert np.allclose(data.mesh.points, blob.points) and np.array_equal(_faces(data.mesh), F)
    assert JUDGE.build(data, {"n": 17}, findings).n == 17
    assert JUDGE.baseline(data, None, {}, findings) is data.mesh

"""splinevis check, NURBS family (splinevis/nurbs/judge.py): faces drawn against the faces a second reader counts
in the file (a dropped face FAILs, naming it), the OpenCASCADE baseline in the model's world frame, and its
measured deviation from the exact surfaces judged against the deflection asked for."""

import numpy as np
import pytest
import rhino3dm

import splinevis.io.nurbs_files as nurbs_files
from splinevis.check.judge import worst_level
from splinevis.nurbs import NurbsModel
from splinevis.nurbs.judge import DEFLECTION, FAIL_FACTOR, JUDGE, WARN_FACTOR, NurbsFile, count_faces

# box [0, 2] x [0, 1] x [0, 1] (6 faces), unit ball about (4, 0, 0), disc of radius 0.75 about (0, 3, 0) (trimmed)
BOUNDS = (-0.75, 5.0, -1.0, 3.75, -1.0, 1.0)
NAMES = [f"box face {k}" for k in range(6)] + ["ball", "disc"]


def _attributes(name):
    a = rhino3dm.ObjectAttributes()
    a.Name = name
    return a


@pytest.fixture(scope="module")
def small_3dm(tmp_path_factory):
    f3 = rhino3dm.File3dm()
    f3.Objects.AddBrep(rhino3dm.Brep.CreateFromBoundingBox(rhino3dm.BoundingBox(0, 0, 0, 2, 1, 1)), _attributes("box"))
    f3.Objects.AddBrep(rhino3dm.Brep.CreateFromSphere(rhino3dm.Sphere(rhino3dm.Point3d(4, 0, 0), 1.0)),
                       _attributes("ball"))
    circle = rhino3dm.Circle(rhino3dm.Point3d(0, 3, 0), 0.75).ToNurbsCurve()
    f3.Objects.AddBrep(rhino3dm.Brep.CreateTrimmedPlane(rhino3dm.Plane.WorldXY(), circle), _attributes("disc"))
    path = tmp_path_factory.mktemp("nurbs") / "small.3dm"
    assert f3.Write(str(path), 8)
    return path


def _judge(path, options=None):
    """read, build, baseline, accuracy of the judge (no rendering): (data, model, baseline, accuracy, findings)."""
    options, findings = dict(options or {}), []
    data = JUDGE.read(path, options, findings)
    model = JUDGE.build(data, options, findings)
    base = JUDGE.baseline(data, model, options, findings)
    acc = JUDGE.accuracy(path, data, model, base, options, findings)
    return data, model, base, acc, findings


@pytest.fixture(scope="module")
def judged(small_3dm):
    return _judge(small_3dm)


def test_correct_3dm_passes(judged):
    data, model, base, acc, findings = judged
    assert model.names == tuple(NAMES) and data.face_names == NAMES
    assert (acc["faces_in_file"], acc["faces_drawn"]) == (8, 8)
    assert acc["counted_by"].startswith("rhino3dm") and acc["not_nurbs_objects"] == 0
    assert [f.level for f in findings] == ["PASS", "PASS"]
    assert "all 8 faces in the file are drawn" in findings[0].reason
    assert acc["deflection"] == DEFLECTION
    assert 0.5 * DEFLECTION < acc["tessellation_deviation"] <= WARN_FACTOR * DEFLECTION  # curved faces use delta
    # the baseline is in the model's world frame: the trimmed disc's edge, not its plane's square, bounds it
    delta = acc["deflection"] * acc["diagonal"]
    assert np.allclose(base.bounds, BOUNDS, atol=2 * delta)
    assert set(np.unique(base.cell_data["face_id"]).tolist()) == set(range(8))


def test_dropped_face_fails(small_3dm, monkeypatch):
    real = nurbs_files.read_nurbs

    def lossy(path):  # a reader that loses the box's last face, as a reader bug would
        m = real(path)
        keep = [k for k, n in enumerate(m.names) if n != "box face 5"]
        return NurbsModel([m.surfaces[k] for k in keep], [m.trims[k] for k in keep], source=m.source)

    monkeypatch.setattr(nurbs_files, "read_nurbs", lossy)
    _, model, _, acc, findings = _judge(small_3dm)
    assert (acc["faces_in_file"], acc["faces_drawn"]) == (8, 7)
    fails = [f.reason for f in findings if f.level == "FAIL"]
    assert len(fails) == 1 and worst_level(findings) == "FAIL"
    assert fails[0].startswith("1 of the 8 faces in the file are not drawn (7 drawn;")
    assert "lost: 'box face 5'" in fails[0]


def test_file_without_nurbs_fails_with_reason(tmp_path):
    f3 = rhino3dm.File3dm()
    mesh = rhino3dm.Mesh()
    for x, y in ((0, 0), (1, 0), (1, 1)):
        mesh.Vertices.Add(x, y, 0)
    mesh.Faces.AddFace(0, 1, 2)
    f3.Objects.AddMesh(mesh)
    path = tmp_path / "mesh_only.3dm"
    assert f3.Write(str(path), 8)
    counted = count_faces(path)
    assert (counted["faces"], counted["not_nurbs"]) == (0, {"Mesh": 1})
    findings = []
    with pytest.raises(ValueError, match="holds no supported NURBS surface"):
        JUDGE.read(path, {}, findings)
    assert [f.level for f in findings] == ["FAIL"]
    assert "no NURBS face in the file" in findings[0].reason
    assert "1 Mesh object(s), which are not NURBS" in findings[0].reason


def test_deviation_of_a_wrong_baseline_is_judged(judged):
    data, model, base, acc, _ = judged
    delta = acc["deflection"] * acc["diagonal"]
    for shift, level in ((5.0, "WARN"), (20.0, "FAIL")):
        moved = base.copy()
        moved.points = base.points + [0.0, 0.0, shift * delta]  # a mesh off its surfaces by shift * delta
        findings = []
        got = JUDGE.accuracy("small.3dm", data, model, moved, {}, findings)
        # the flat faces are off by the shift exactly; elsewhere the chord error of the right mesh may add to it
        ratio = got["tessellation_deviation"] / DEFLECTION
        assert shift * (1 - 1e-9) <= ratio <= shift + acc["tessellation_deviation"] / DEFLECTION + 1e-9
        assert [f.level for f in findings] == ["PASS", level]
        assert f"{ratio:.2f} x the deflection" in findings[1].reason
    assert WARN_FACTOR < 5.0 < FAIL_FACTOR < 20.0


def _nurbs_box():
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox

    return BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), True).Shape()


def test_step_counted_and_meshed_by_opencascade(tmp_path):
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    path = tmp_path / "box.step"
    w = STEPControl_Writer()
    w.Transfer(_nurbs_box(), STEPControl_AsIs)
    w.Write(str(path))
    data, model, base, acc, findings = _judge(path)
    assert data.shape is not None  # the baseline meshes the file's own shape, not our reading of it
    assert (acc["faces_in_file"], acc["faces_drawn"], acc["counted_by"]) == (6, 6, "OpenCASCADE STEPControl_Reader")
    assert [f.level for f in findings] == ["PASS", "PASS"]
    assert acc["tessellation_deviation"] < 1e-12  # planes
    assert np.allclose(base.bounds, (0, 1, 0, 2, 0, 3), atol=1e-12)


def test_baseline_applies_the_faces_placement():
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.gp import gp_Trsf, gp_Vec

    t = gp_Trsf()
    t.SetTranslation(gp_Vec(10.0, -5.0, 2.0))
    moved = BRepBuilderAPI_Transform(_nurbs_box(), t, False).Shape()  # a location on the shape, nodes unmoved
    assert not moved.Location().IsIdentity()
    findings = []
    base = JUDGE.baseline(NurbsFile(None, 6, "test", shape=moved), None, {}, findings)
    assert findings == []
    assert np.allclose(base.bounds, (10, 11, -5, -3, 2, 5), atol=1e-12)


def test_bpt_patch_count(tmp_path):
    path = tmp_path / "two.bpt"
    quad = "1 1\n0 0 0\n0 1 0\n1 0 0\n1 1 1\n"
    path.write_text("2\n" + quad + quad)
    assert count_faces(path)["faces"] == 2
    assert count_faces(tmp_path / "model.g2") is None


def test_judge_file_end_to_end(small_3dm, tmp_path):
    from splinevis.check.run import judge_file

    r = judge_file(small_3dm, "nurbs", tmp_path)
    assert r["verdict"] == "PASS", r["findings"]
    assert (r["accuracy"]["faces_in_file"], r["accuracy"]["faces_drawn"]) == (8, 8)
    assert r["baseline"] == JUDGE.baseline_name
    assert min(v["iou"] for v in r["views"].values()) > 0.97
    assert (tmp_path / r["thumbnail"]).is_file()

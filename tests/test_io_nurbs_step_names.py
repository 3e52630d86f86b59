"""splinevis.io.read_step reads the names a STEP file stores (through OpenCASCADE's XCAF document): each
``ADVANCED_FACE('name', ...)``, else the owning part's (product's) name, else ``"face <k>"``; the geometry,
face order and trims are what the plain STEPControl_Reader path reads, which is also the fallback.

Every file is written with OCP into a temporary folder and its text checked for the names first, so the
names come back from the file, not from memory."""

import sys
import warnings

import numpy as np
import pytest

from _occ import occ_bspline_surface
from splinevis.io.nurbs_files import read_nurbs
from splinevis.io.nurbs_step import read_step

SUBSHAPE_NAMES = "write.stepcaf.subshapes.name"


def bspline_face(dz: float, reverse: bool = False):
    """A rational bicubic x quadratic B-spline face (OCP), lifted by ``dz``; its surface for reference."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace

    surf = occ_bspline_surface(dz)
    face = BRepBuilderAPI_MakeFace(surf, 1e-9).Face()
    return (face.Reversed() if reverse else face), surf


def compound(shapes):
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    comp = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(comp)
    for s in shapes:
        builder.Add(comp, s)
    return comp


def new_document():
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    doc = TDocStd_Document(TCollection_ExtendedString("MDTV-XCAF"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    return doc, XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())


def set_name(label, name: str):
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name

    TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))


def add_part(tool, faces, part_name, face_names):
    """A part (compound of the faces) on a new free label, named ``part_name``; face k named
    ``face_names[k]`` on a sub-shape label (None: no label)."""
    label = tool.AddShape(compound(faces), False)
    if part_name:
        set_name(label, part_name)
    for face, name in zip(faces, face_names):
        if name is not None:
            sub = tool.AddSubShape(label, face)
            assert not sub.IsNull()
            set_name(sub, name)
    return label


def write_document(doc, path, face_names: bool = True):
    """STEPCAFControl_Writer with names; face names (ADVANCED_FACE('...')) only with the sub-shape static."""
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs

    from splinevis.io.nurbs_step import _quiet_occ

    _quiet_occ()
    writer = STEPCAFControl_Writer()  # defines the static (first use of the STEP-CAF controller)
    writer.SetNameMode(True)
    before = Interface_Static.IVal_s(SUBSHAPE_NAMES)
    assert Interface_Static.SetIVal_s(SUBSHAPE_NAMES, int(face_names))
    try:
        assert writer.Transfer(doc, STEPControl_AsIs)
        assert str(writer.Write(str(path))).endswith("RetDone")
    finally:
        Interface_Static.SetIVal_s(SUBSHAPE_NAMES, before)
    return path.read_text(encoding="latin-1")


def check_geometry(model, surfs, reversed_=()):
    """Each patch k evaluates to surface k (v mirrored for the reversed faces), at random parameters."""
    rng = np.random.default_rng(3)
    assert len(model) == len(surfs)
    for k, (s, ref) in enumerate(zip(model.surfaces, surfs)):
        (u0, u1), (v0, v1) = s.domain
        u, v = rng.uniform(u0, u1, 20), rng.uniform(v0, v1, 20)
        vr = (v0 + v1) - v if k in reversed_ else v
        want = [[(p := ref.Value(a, b)).X(), p.Y(), p.Z()] for a, b in zip(u, vr)]
        assert np.abs(s.evaluate(u, v) - want).max() < 1e-12, k


def same_models(a, b):
    """Identical geometry and trims (names aside)."""
    assert len(a) == len(b)
    for s, t in zip(a.surfaces, b.surfaces):
        assert s.degree == t.degree and np.array_equal(s.control_points, t.control_points)
        assert all(np.array_equal(x, y) for x, y in zip(s.knots, t.knots))
        assert (s.weights is None) == (t.weights is None)
        assert s.weights is None or np.array_equal(s.weights, t.weights)
    for la, lb in zip(a.trims, b.trims):
        assert (la is None) == (lb is None)
        assert len(la or ()) == len(lb or ())
        for loop_a, loop_b in zip(la or (), lb or ()):
            assert len(loop_a) == len(loop_b)
            for c, d in zip(loop_a, loop_b):
                assert np.array_equal(c.control_points, d.control_points) and np.array_equal(c.knots, d.knots)


def read_without_warnings(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return read_nurbs(path)


def test_advanced_face_names_in_order_and_part_name_for_the_unnamed(tmp_path, monkeypatch):
    from OCP.Interface import Interface_Static

    made = [bspline_face(3.0 * k, reverse=(k == 2)) for k in range(4)]
    doc, tool = new_document()
    add_part(tool, [f for f, _ in made], "bracket", ["top skin", None, "rib 2", "fillet"])
    f = tmp_path / "bracket.step"
    text = write_document(doc, f)
    # the names are in the file (ADVANCED_FACE('name', ...)), the unnamed face has '' and the part a PRODUCT
    assert [text.count(f"ADVANCED_FACE('{n}',") for n in ("top skin", "rib 2", "fillet", "")] == [1, 1, 1, 1]
    assert "PRODUCT('bracket'" in text

    before = Interface_Static.IVal_s("read.stepcaf.subshapes.name")
    m = read_without_warnings(f)
    assert m.names == ("top skin", "bracket / face 1", "rib 2", "fillet")
    assert m.source == f"{f} (STEP (OCP))" and m.skipped == {}
    assert Interface_Static.IVal_s("read.stepcaf.subshapes.name") == before  # the reader's static is restored
    check_geometry(m, [s for _, s in made], reversed_=(2,))  # names sit on their faces; the reversed one flipped
    assert all(t is not None and len(t) == 1 and len(t[0]) == 4 for t in m.trims)

    # names in STEP's escaped form come through decoded
    g = tmp_path / "escaped.step"
    g.write_text(text.replace("ADVANCED_FACE('fillet',", "ADVANCED_FACE('fillet \\X2\\00E9\\X0\\',"),
                 encoding="latin-1")
    assert read_step(g).names[3] == "fillet \u00e9"

    # without XCAF: the plain reader, the same geometry and trims, "face <k>", and a warning saying so
    monkeypatch.setitem(sys.modules, "OCP.STEPCAFControl", None)
    with pytest.warns(UserWarning, match="face names not read.*XCAF.*plain STEPControl_Reader"):
        plain = read_step(f)
    assert plain.names == ("face 0", "face 1", "face 2", "face 3")
    assert "names not read" in plain.source and "plain reader" in plain.source
    same_models(m, plain)


def test_file_without_names_keeps_face_k(tmp_path):
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    made = [bspline_face(3.0 * k) for k in range(3)]
    f = tmp_path / "plain.step"
    w = STEPControl_Writer()
    w.Transfer(compound([face for face, _ in made]), STEPControl_AsIs)
    w.Write(str(f))
    text = f.read_text(encoding="latin-1")
    assert text.count("ADVANCED_FACE('',") == 3 and "PRODUCT('Open CASCADE STEP translator" in text
    m = read_without_warnings(f)
    assert m.names == ("face 0", "face 1", "face 2")  # the writer's placeholder product name is no name
    check_geometry(m, [s for _, s in made])

    # an XCAF document without any name: the same
    doc, tool = new_document()
    add_part(tool, [face for face, _ in made], None, [None] * 3)
    g = tmp_path / "unnamed.step"
    assert "PRODUCT('COMPOUND'" in write_document(doc, g)  # XCAF's auto-name: the shape type
    assert read_without_warnings(g).names == ("face 0", "face 1", "face 2")


def test_product_names_as_fallback_in_an_assembly(tmp_path):
    from OCP.gp import gp_Trsf, gp_Vec
    from OCP.TopLoc import TopLoc_Location

    bracket = [bspline_face(0.0), bspline_face(3.0)]
    plate = [bspline_face(10.0)]
    loose = [bspline_face(20.0)]
    doc, tool = new_document()
    part = add_part(tool, [f for f, _ in bracket], "bracket", [None, "flange"])
    other = add_part(tool, [f for f, _ in plate], None, [None])  # unnamed part: its assembly's name
    assembly = tool.NewShape()
    set_name(assembly, "robot arm")
    shift = gp_Trsf()
    shift.SetTranslation(gp_Vec(0.0, 0.0, 100.0))
    tool.AddComponent(assembly, part, TopLoc_Location())
    tool.AddComponent(assembly, part, TopLoc_Location(shift))  # a second instance: the same names
    tool.AddComponent(assembly, other, TopLoc_Location())
    free_part = add_part(tool, [f for f, _ in loose], "lid", [None])  # a free part of its own
    tool.UpdateAssemblies()
    assert not free_part.IsNull()
    f = tmp_path / "arm.step"
    text = write_document(doc, f, face_names=True)
    for name in ("PRODUCT('bracket'", "PRODUCT('robot arm'", "PRODUCT('lid'", "ADVANCED_FACE('flange',"):
        assert name in text, name
    m = read_without_warnings(f)
    assert m.names == ("bracket / face 0", "flange", "bracket / face 2", "flange", "robot arm / face 4",
                       "lid / face 5")
    zs = [float(np.mean(s.control_points[..., 2])) for s in m.surfaces]
    ref = [float(np.mean([s.Pole(i, j).Z() for i in range(1, 6) for j in range(1, 4)])) for _, s in
           bracket + bracket + plate + loose]
    np.testing.assert_allclose(zs, np.array(ref) + [0, 0, 100, 100, 0, 0], atol=1e-9)

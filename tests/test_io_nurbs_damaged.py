"""Damaged IGES and STEP files are errors that name the file, what it promised and what was found; with
``read_nurbs(path, partial=True)`` the intact faces are read and the loss is reported (warning, ``skipped``,
``source``).

Every file is written by OpenCASCADE into a temporary folder (five faces: four B-spline faces and a plate with
a hole), then damaged as files get damaged: lines overwritten with garbage, numbers garbled in place, cut off,
a ``#n`` pointing nowhere. The expected line numbers, directory entries and instance numbers are read from the
intact file's own structure by the small parsers below, not written into the tests."""

import random
import re
import warnings

import numpy as np
import pytest

from _occ import occ_bspline_surface
from splinevis.io.nurbs_common import DamagedFileError
from splinevis.io.nurbs_files import read_nurbs
from splinevis.io.nurbs_iges import check_iges, read_iges
from splinevis.io.nurbs_step import check_step

FACES = 5


def parts():
    """A compound of four B-spline faces (lifted apart) and a 4 x 2 plate with a hole (converted to NURBS)."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pln, gp_Pnt
    from OCP.TopoDS import TopoDS_Compound

    from splinevis.io.nurbs_step import _quiet_occ

    _quiet_occ()
    plate = BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 4.0, 0.0, 2.0).Face()
    cyl = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1, 1, -1), gp_Dir(0, 0, 1)), 0.5, 2.0).Shape()
    comp = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(comp)
    for dz in (0.0, 3.0, 6.0, 9.0):
        builder.Add(comp, BRepBuilderAPI_MakeFace(occ_bspline_surface(dz), 1e-9).Face())
    builder.Add(comp, BRepBuilderAPI_NurbsConvert(BRepAlgoAPI_Cut(plate, cyl).Shape(), True).Shape())
    return comp


@pytest.fixture(scope="module")
def iges_text(tmp_path_factory):
    from OCP.IGESControl import IGESControl_Writer

    f = tmp_path_factory.mktemp("iges") / "parts.igs"
    w = IGESControl_Writer("MM", 0)
    assert w.AddShape(parts())
    w.ComputeModel()
    assert w.Write(str(f))
    return f.read_text(encoding="latin-1")


@pytest.fixture(scope="module")
def step_text(tmp_path_factory):
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    f = tmp_path_factory.mktemp("step") / "parts.step"
    w = STEPControl_Writer()
    w.Transfer(parts(), STEPControl_AsIs)
    assert str(w.Write(str(f))).endswith("RetDone")
    return f.read_text(encoding="latin-1")


def quiet(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return read_nurbs(path, orient=False, **kw)  # the faces as the file has them (orientation: test_nurbs_orient)


def partial(path, **kw):
    """``read_nurbs(path, partial=True)`` and the text of its damage warning."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = read_nurbs(path, partial=True, orient=False, **kw)
    damaged = [str(w.message) for w in caught if "damaged" in str(w.message)]
    assert len(damaged) == 1, [str(w.message) for w in caught]
    return m, damaged[0]


def same_faces(part, whole):
    """Every face read from the damaged file is one of the intact file's faces, exactly."""
    for s in part.surfaces:
        assert any(s.degree == t.degree and s.shape == t.shape and np.array_equal(s.control_points, t.control_points)
                   for t in whole.surfaces), s.name


# ---- IGES --------------------------------------------------------------------------------------------------
def iges_directory(text):
    """(file line of parameter line 1, {DE: (type, first P line, P line count)}, file line of each P line)."""
    lines = text.splitlines()
    d = [ln for ln in lines if ln[72:73] == "D"]
    entries = {2 * k + 1: (int(d[2 * k][:8]), int(d[2 * k][8:16]), int(d[2 * k + 1][24:32]))
               for k in range(len(d) // 2)}
    first_p = next(i for i, ln in enumerate(lines, 1) if ln[72:73] == "P")
    return lines, entries, first_p


def test_intact_iges_has_no_problems(iges_text, tmp_path):
    f = tmp_path / "parts.igs"
    f.write_text(iges_text, encoding="latin-1")
    damage, lost, repaired = check_iges(f)
    assert not damage and damage.problems == [] and lost == set() and repaired is None
    assert damage.expected == FACES
    assert len(quiet(f)) == FACES


def test_iges_lines_overwritten_with_garbage(iges_text, tmp_path):
    lines, entries, first_p = iges_directory(iges_text)
    # overwrite the parameter lines of the first 128 surface (whole lines, as a disk or editor would)
    de, (t, ptr, count) = next((de, e) for de, e in entries.items() if e[0] == 128 and e[2] >= 2)
    a, b = first_p + ptr - 1, first_p + ptr + count - 2  # file lines, 1-based
    rng = random.Random(5)
    damaged = list(lines)
    for i in range(a - 1, b):
        damaged[i] = "".join(rng.choice("abcXYZ0123456789,;# ") for _ in range(80))
    f = tmp_path / "garbage.igs"
    f.write_text("\n".join(damaged) + "\n", encoding="latin-1")
    with pytest.raises(DamagedFileError) as err:
        read_nurbs(f)
    msg = str(err.value)
    assert msg.startswith(f"{f}: damaged IGES file, 1 of {FACES} faces cannot be read (1 x 144 (trimmed surface))")
    span = f"{a}-{b}" if b > a else f"{a}"
    assert f"{count} lines are not IGES records" in msg and f"columns 73-80): {span}" in msg
    pspan = f"{ptr}-{ptr + count - 1}" if count > 1 else f"{ptr}"
    assert f"directory entry {de} (type 128): its parameter lines {pspan} are missing or garbled" in msg
    assert "read_nurbs(path, partial=True)" in msg
    intact = tmp_path / "intact.igs"
    intact.write_text(iges_text, encoding="latin-1")
    whole = quiet(intact)
    for backend in ("ocp", "pyiges"):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            m = read_iges(f, backend=backend, partial=True)
        assert len(m) == FACES - 1
        assert m.skipped == {"damaged 144 (trimmed surface)": 1}
        assert "DAMAGED, read in part: 1 of 5 faces cannot be read" in m.source
        assert any(f"damaged IGES file read in part: {FACES - 1} faces read" in str(w.message) for w in caught)
        same_faces(m, whole)


@pytest.mark.parametrize("line", [0, 1])
def test_iges_numbers_garbled_in_place(iges_text, tmp_path, line):
    """Columns 1-64 of a parameter line overwritten, its section letter and sequence number intact: the first
    line of a record (its entity type is gone) or a later one (a number is gone)."""
    lines, entries, first_p = iges_directory(iges_text)
    de, (t, ptr, count) = next((de, e) for de, e in entries.items() if e[0] in (126, 128) and e[2] >= 3)
    damaged = list(lines)
    damaged[first_p + ptr - 2 + line] = "X" * 64 + lines[first_p + ptr - 2 + line][64:]
    f = tmp_path / "garbled.igs"
    f.write_text("\n".join(damaged) + "\n", encoding="latin-1")
    with pytest.raises(DamagedFileError) as err:
        read_nurbs(f)
    if line == 0:
        assert (f"directory entry {de} (type {t}): its parameter record (line {ptr}) starts with "
                f"'XXXXXXXXXXXXXXXXXXXX', not {t}") in str(err.value)
    else:  # a middle line: the record still ends
        assert re.search(rf"directory entry {de} \(type {t}\): parameter \d+ of its record \(lines {ptr}-"
                         rf"{ptr + count - 1}\) is 'X{{20}}', not a number", str(err.value)), str(err.value)
    m, warning = partial(f)
    assert m.skipped == {"damaged 144 (trimmed surface)": 1} and len(m) == FACES - 1


@pytest.mark.parametrize("fraction", [0.5, 0.9])
def test_iges_cut_off(iges_text, tmp_path, fraction):
    lines, entries, first_p = iges_directory(iges_text)
    keep = int(len(lines) * fraction)
    assert keep > first_p  # the cut is in the parameter section
    f = tmp_path / "cut.igs"
    f.write_text("\n".join(lines[:keep]) + "\n", encoding="latin-1")
    last_p = keep - first_p + 1
    beyond = sorted(de for de, (t, ptr, count) in entries.items() if ptr + count - 1 > last_p)
    with pytest.raises(DamagedFileError) as err:
        read_nurbs(f)
    msg = str(err.value)
    t, ptr, count = entries[beyond[0]]
    assert f"the file ends at line {keep} (parameter line {last_p}) without the terminate (T) record" in msg
    assert (f"directory entry {beyond[0]} (type {t}) points to parameter lines {ptr}-{ptr + count - 1}, the "
            f"parameter section ends at line {last_p} (file line {keep}), and so do {len(beyond) - 1} more") in msg
    damage, lost, _ = check_iges(f)
    assert damage.expected == FACES and damage.lost_total >= 1  # the directory is whole: it lists every face
    if damage.lost_total == FACES:
        assert "no face is intact" in msg
        with pytest.raises(DamagedFileError):
            read_nurbs(f, partial=True)
        return
    m, warning = partial(f)
    assert len(m) == FACES - damage.lost_total
    assert f"{len(m)} faces read, {damage.lost_total} of {FACES} faces cannot be read" in warning
    intact = tmp_path / "intact.igs"
    intact.write_text(iges_text, encoding="latin-1")
    same_faces(m, quiet(intact))


def test_iges_directory_lines_garbled(iges_text, tmp_path):
    """Garbage over directory lines: the entries after them keep their numbers (placeholders in a repaired copy)."""
    lines, entries, first_p = iges_directory(iges_text)
    first_d = next(i for i, ln in enumerate(lines) if ln[72:73] == "D")
    # the directory entry of the last 144 (both lines) overwritten
    de = max(d for d, e in entries.items() if e[0] == 144)
    damaged = list(lines)
    damaged[first_d + de - 1] = damaged[first_d + de] = "#" * 80
    f = tmp_path / "directory.igs"
    f.write_text("\n".join(damaged) + "\n", encoding="latin-1")
    with pytest.raises(DamagedFileError) as err:
        read_nurbs(f)
    msg = str(err.value)
    assert "1 directory entries are unreadable (what they held is lost)" in msg
    assert f"directory entries {de} are incomplete" in msg
    assert "2 lines are not IGES records" in msg and f"{first_d + de}-{first_d + de + 1}" in msg
    m, warning = partial(f)
    assert len(m) == FACES - 1 and m.skipped == {"unreadable directory entries": 1}
    intact = tmp_path / "intact.igs"
    intact.write_text(iges_text, encoding="latin-1")
    same_faces(m, quiet(intact))


# ---- STEP --------------------------------------------------------------------------------------------------
def instances(text):
    """{#n: (type, file line)} of the data section."""
    out = {}
    for m in re.finditer(r"^#(\d+)\s*=\s*\(?\s*([A-Z_0-9]+)", text, re.M):
        out[int(m.group(1))] = (m.group(2), text.count("\n", 0, m.start()) + 1)
    return out


def test_intact_step_has_no_problems(step_text, tmp_path):
    f = tmp_path / "parts.step"
    f.write_text(step_text, encoding="latin-1")
    damage, repaired = check_step(f)
    assert not damage and repaired is None and damage.expected == FACES
    assert len(quiet(f)) == FACES


def test_step_reference_pointing_nowhere(step_text, tmp_path):
    """The surface reference of the third ADVANCED_FACE replaced by a number the file does not define (this
    crashed OpenCASCADE's reader before the check)."""
    faces = [m for m in re.finditer(r"^#(\d+)\s*=\s*ADVANCED_FACE\('[^']*',\([^)]*\),#(\d+),", step_text, re.M)]
    assert len(faces) == FACES
    face = faces[2]
    nowhere = max(instances(step_text)) + 1000
    text = step_text[:face.start(2)] + str(nowhere) + step_text[face.end(2):]
    f = tmp_path / "dangling.step"
    f.write_text(text, encoding="latin-1")
    with pytest.raises(DamagedFileError) as err:
        read_nurbs(f)
    line = text.count("\n", 0, face.start()) + 1
    assert str(err.value) == (
        f"{f}: damaged STEP file, 1 of {FACES} faces cannot be read (1 x ADVANCED_FACE): 1 reference in 1 instance "
        f"to 1 instance the file does not define: #{face.group(1)} (ADVANCED_FACE, line {line}) refers to "
        f"#{nowhere}. Get an intact copy of the file, or read the intact faces with read_nurbs(path, partial=True).")
    m, warning = partial(f)
    assert len(m) == FACES - 1 and m.skipped == {"damaged ADVANCED_FACE": 1}
    assert warning.startswith(f"{f}: damaged STEP file read in part: 4 faces read, 1 of 5 faces cannot be read")
    intact = tmp_path / "intact.step"
    intact.write_text(step_text, encoding="latin-1")
    same_faces(m, quiet(intact))


def test_step_garbled_instance(step_text, tmp_path):
    m = re.search(r"^#(\d+)\s*=\s*B_SPLINE_CURVE_WITH_KNOTS\(", step_text, re.M)
    close = step_text.index(";", m.end())
    text = step_text[:close - 1] + step_text[close:]  # its last ")" lost
    f = tmp_path / "garbled.step"
    f.write_text(text, encoding="latin-1")
    with pytest.raises(DamagedFileError) as err:
        read_nurbs(f)
    line = text.count("\n", 0, m.start()) + 1
    assert (f"#{m.group(1)} (B_SPLINE_CURVE_WITH_KNOTS, line {line}) is garbled (unbalanced parentheses or no "
            "entity name)") in str(err.value)
    damage, _ = check_step(f)
    got, _ = partial(f)
    assert len(got) == FACES - damage.lost_total >= 1


@pytest.mark.parametrize("fraction", [0.5, 0.8])
def test_step_cut_off(step_text, tmp_path, fraction):
    cut = int(len(step_text) * fraction)
    text = step_text[:cut]
    f = tmp_path / "cut.step"
    f.write_text(text, encoding="latin-1")
    inside = re.findall(r"#(\d+)\s*=\s*\(?\s*([A-Z_0-9]*)", text)[-1]
    with pytest.raises(DamagedFileError) as err:
        read_nurbs(f)
    msg = str(err.value)
    assert msg.startswith(f"{f}: damaged STEP file, ")
    assert (f"the file ends at line {text.count(chr(10)) + 1} inside #{inside[0]} ({inside[1]}) without ENDSEC; and "
            "END-ISO-10303-21;: it was cut off") in msg
    damage, _ = check_step(f)
    defined = sum(1 for t, _ in instances(text).values() if t == "ADVANCED_FACE")
    assert damage.cut and damage.expected >= defined and "and the faces after the cut are lost" in msg
    if damage.lost_total == damage.expected:
        assert "no face is intact" in msg
        with pytest.raises(DamagedFileError):
            read_nurbs(f, partial=True)
        return
    m, warning = partial(f)
    assert len(m) == damage.expected - damage.lost_total
    intact = tmp_path / "intact.step"
    intact.write_text(step_text, encoding="latin-1")
    same_faces(m, quiet(intact))


def test_partial_read_of_an_intact_file_is_the_whole_read(step_text, iges_text, tmp_path):
    for name, text in (("a.step", step_text), ("a.igs", iges_text)):
        f = tmp_path / name
        f.write_text(text, encoding="latin-1")
        a, b = quiet(f), quiet(f, partial=True)
        assert a.names == b.names and a.source == b.source and a.skipped == b.skipped == {}

"""NURBS faces from STEP files through OpenCASCADE (``OCP``), and the OCP shape conversion IGES shares.

OCP comes from the optional extra ``cad`` (``pip install cadquery-ocp-novtk``, ~380 MB); without it
:func:`read_step` raises an ImportError saying so. Nothing from OCP is imported at module import time.

What is read
------------
Every face of the transferred shape whose surface is a ``Geom_BSplineSurface`` (also under a
``Geom_RectangularTrimmedSurface``) becomes one patch, in the shape's face order. Periodic surfaces are
unrolled to their non-periodic form (same points). The face's wires become its trim loops: each edge's
curve on the surface (its "pcurve", trimmed to the edge's range) converted to a 2-D B-spline with
``Geom2dConvert``, in the surface's own ``(u, v)`` domain. A reversed face (its outside the surface's back)
is mirrored in v (trims with it) so that ``S_u x S_v`` points out. Faces on other surfaces (planes,
cylinders, cones, spheres, tori, extrusions, revolutions, offsets: not converted to NURBS by the writer) are
converted exactly and counted in ``source``: those whose edges run along parameter lines by OpenCASCADE's
surface conversion with trims mapped by :func:`.nurbs_iso_faces.iso_face` (checked; some 40 times faster),
the others by ``BRepBuilderAPI_NurbsConvert``; a face it cannot convert is counted in ``skipped`` as
``"face on <surface type>"``. Degrees up to OpenCASCADE's 25 are read
(:data:`splinevis.nurbs.basis.MAX_DEGREE`); pcurves above degree 3 are approximated by cubics within 1e-9 of
the domain (:func:`_cubic_pcurve`).

Names
-----
The file is read into an XCAF document (``STEPCAFControl_Reader`` with name mode on and the static
``read.stepcaf.subshapes.name`` set to 1 for the call, so named representation items get sub-shape
labels). The free shapes of ``XCAFDoc_ShapeTool`` are walked (assembly components to the parts they refer
to, each part to its sub-shape labels), and each face takes the ``TDataStd_Name`` of its own label: the
name of its ``ADVANCED_FACE('name', ...)``. A face without one is named after the nearest named owner, a
named solid or shell sub-shape, else its part (product) or assembly: ``"bracket / face 3"``; without any,
``"face <k>"``. ``k`` counts the faces in the shape's order either way. Empty names, and the placeholders
OpenCASCADE gives unnamed shapes (product names ``"Open CASCADE STEP translator ..."`` from its STEP
writer, the shape type, ``"SOLID"``, ``"COMPOUND"``, ..., from XCAF's auto-naming), count as no name.
Faces are matched to labels by their underlying ``TopoDS_TShape`` (locations and orientation aside), so
every instance of a part carries the part's names. The shape itself is the XCAF reader's own
``STEPControl_Reader`` result, so faces, order, trims and orientation are what the plain reader gives. If
the XCAF document cannot be built (its modules missing, the transfer failing), the file is read with the
plain ``STEPControl_Reader``: faces are named ``"face <k>"``, a UserWarning says why and ``source`` says
``"names not read"``.

Damaged files
-------------
OpenCASCADE's STEP reader does not say when a file is damaged: a cut file loads the faces before the cut,
and a ``#123`` that points nowhere can crash the Python process. :func:`check_step` therefore scans the
data section first (strings and comments masked, so no ``;`` or ``#`` inside them counts): every instance
``#n = ...;`` with its references, instances defined twice, garbled instances (unbalanced parentheses),
references to instances the file does not define, and a file that ends without ``ENDSEC;`` /
``END-ISO-10303-21;`` (cut off). A face (``ADVANCED_FACE``, ``FACE_SURFACE``) is lost when anything it
reaches is broken; the faces a shell lists but the file never defines are counted too. ``read_step`` raises
a :class:`~.nurbs_common.DamagedFileError` naming them ("#48 (ADVANCED_FACE, line 69) refers to #9999999"),
or with ``partial=True`` reads a copy without the lost instances: containers (shells, representations,
layers) keep their lists without the lost members, any other instance that refers to a lost one is dropped
with it (a face is read whole or not at all), and intact solids and surface models whose representation or
product was lost are given a new one (in millimetres when the units were lost too, which the damage report
says). The copy is checked again before OpenCASCADE sees it. When no face is intact, the error is raised
even with ``partial=True``.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface, TrimCurve
from .nurbs_common import DamagedFileError, build_model, checked, flip_v
from .nurbs_iso_faces import iso_face
from .nurbs_step_check import check_step

__all__ = ["read_step", "check_step", "ocp_available", "shape_to_model", "shape_faces", "bspline_surface", "OCP_HINT"]

#: What to install for OCP.
OCP_HINT = "pip install cadquery-ocp-novtk (or: pip install 'splinevis[cad]')"


def ocp_available() -> bool:
    """True when OpenCASCADE's Python bindings (``OCP``) can be imported.

    >>> isinstance(ocp_available(), bool)
    True
    """
    try:
        import OCP.STEPControl  # noqa: F401
    except ImportError:
        return False
    return True


def _quiet_occ() -> None:
    """Keep OpenCASCADE's transfer statistics off stdout (only failures are printed)."""
    from OCP.Message import Message, Message_Gravity

    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)


def read_step(path, partial: bool = False) -> NurbsModel:
    """Read the faces of a STEP file (with their trim loops and stored names) through OCP.

    Names come from the file's XCAF document: a face's own name, else ``"<part> / face <k>"``, else
    ``"face <k>"`` (see the module notes); without XCAF the plain reader is used, with a warning.

    Parameters
    ----------
    path : str or path-like
    partial : bool
        A damaged file (module notes, "Damaged files"): False raises
        :class:`~.nurbs_common.DamagedFileError` naming what is broken; True reads the intact faces (from a
        copy without the lost instances) and reports the lost ones (warning, ``skipped``, ``source``).

    Raises
    ------
    ImportError
        OCP is not installed (``pip install cadquery-ocp-novtk``).
    DamagedFileError
        The file is damaged (and ``partial`` is False): cut off, a ``#n`` that points nowhere, a garbled
        instance.
    ValueError
        The file cannot be read, or holds no face.

    Examples
    --------
    >>> import tempfile
    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    >>> from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
    >>> box = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), True).Shape()
    >>> _quiet_occ()
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = str(Path(folder) / "box.step")
    ...     w = STEPControl_Writer(); _ = w.Transfer(box, STEPControl_AsIs); _ = w.Write(f)
    ...     m = read_step(f)
    >>> len(m), m.bounds(), m.names[:2]  # the file names no face: "face <k>"
    (6, (0.0, 1.0, 0.0, 2.0, 0.0, 3.0), ('face 0', 'face 1'))
    """
    path = Path(path)
    try:
        import OCP.STEPControl  # noqa: F401
    except ImportError:
        raise ImportError(f"{path}: reading STEP files needs OpenCASCADE's Python bindings (OCP): {OCP_HINT}.") from None
    damage, repaired = check_step(path)
    if damage and (not partial or damage.lost_total == damage.expected):
        # OpenCASCADE may crash on a dangling reference: it never sees a damaged file
        raise DamagedFileError(path, damage)
    if repaired is None:
        return _read_step(path, path, damage)
    import tempfile

    with tempfile.TemporaryDirectory(prefix="splinevis-step-") as folder:
        fixed = Path(folder) / "repaired.stp"
        fixed.write_text(repaired(), encoding="latin-1")
        return _read_step(fixed, path, damage)


def _read_step(file: Path, path: Path, damage) -> NurbsModel:
    """Read ``file`` (``path`` itself or its repaired copy; ``path`` for names and messages)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    _quiet_occ()
    try:
        shape, names = _read_xcaf(file, path)
    except _Unreadable:
        raise
    except Exception as err:  # noqa: BLE001 -- any XCAF failure: read the geometry without names, and say so
        why = f"{type(err).__name__}: {err}"
        warnings.warn(f"{path}: face names not read, OpenCASCADE's XCAF document could not be built ({why}); "
                      "read with the plain STEPControl_Reader.", UserWarning, stacklevel=2)
        reader = STEPControl_Reader()
        if reader.ReadFile(str(file)) != IFSelect_RetDone:
            raise _Unreadable(_unreadable(path)) from None
        reader.TransferRoots()
        return shape_to_model(reader.OneShape(), path, f"STEP (OCP, plain reader; names not read: {why})", {},
                              damage)
    skipped, converted = {}, {}
    surfaces, trims = shape_faces(shape, path, skipped, names=names.name, converted=converted)
    return build_model(path, "STEP (OCP)" + converted_note(converted), surfaces, trims, skipped, damage=damage)


class _Unreadable(ValueError):
    """The file is not STEP (no point in a second reader)."""


def _unreadable(path) -> str:
    return f"{path}: OpenCASCADE could not read this file as STEP; is it a valid ISO 10303-21 file?"


def _read_xcaf(file: Path, path: Path):
    """``(shape, FaceNames)``: ``file`` through ``STEPCAFControl_Reader`` into an XCAF document; the shape is
    the reader's own ``STEPControl_Reader`` result (what the plain path reads); ``path`` for messages."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    reader = STEPCAFControl_Reader()  # defines the static below (its controller's first use)
    reader.SetNameMode(True)
    key = "read.stepcaf.subshapes.name"
    before = Interface_Static.IVal_s(key)
    Interface_Static.SetIVal_s(key, 1)
    try:
        if reader.ReadFile(str(file)) != IFSelect_RetDone:
            raise _Unreadable(_unreadable(path))
        app = XCAFApp_Application.GetApplication_s()
        doc = TDocStd_Document(TCollection_ExtendedString("MDTV-XCAF"))
        app.InitDocument(doc)
        if not reader.Transfer(doc):
            raise RuntimeError("STEPCAFControl_Reader.Transfer failed")
    finally:
        Interface_Static.SetIVal_s(key, before)
    names = _FaceNames()
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    free = _label_sequence()
    tool.GetFreeShapes(free)
    for i in range(1, free.Length() + 1):
        _walk(free.Value(i), "", names)
    return reader.ChangeReader().OneShape(), names


def _label_sequence():
    try:  # OCP 8
        from OCP.OCP.collections import Sequence_TDF_Label
    except ImportError:
        try:
            from OCP.collections import Sequence_TDF_Label
        except ImportError:  # OCP 7.7 and earlier
            from OCP.TDF import TDF_LabelSequence as Sequence_TDF_Label
    return Sequence_TDF_Label()


#: Product names OpenCASCADE's STEP writer makes up for unnamed shapes: no name.
_PLACEHOLDER = "Open CASCADE STEP translator"
#: The names XCAF's auto-naming gives unnamed shapes (their type), e.g. written as PRODUCT('SOLID'): no name.
_AUTO_NAMES = {"ASSEMBLY", "COMPOUND", "COMPSOLID", "SOLID", "SHELL", "FACE", "WIRE", "EDGE", "VERTEX", "SHAPE"}


def _label_name(label) -> str:
    """The label's ``TDataStd_Name`` ("" without one, or for a writer's placeholder)."""
    from OCP.TDataStd import TDataStd_Name

    attr = TDataStd_Name()
    if not label.FindAttribute(TDataStd_Name.GetID_s(), attr):
        return ""
    name = attr.Get().ToExtString().strip()
    return "" if name.startswith(_PLACEHOLDER) or name in _AUTO_NAMES else name


def _walk(label, owner: str, names) -> None:
    """Record the names of the faces under an XCAF shape label (see the module notes)."""
    from OCP.TDF import TDF_Label
    from OCP.TopAbs import TopAbs_FACE
    from OCP.XCAFDoc import XCAFDoc_ShapeTool as Tool

    if Tool.IsReference_s(label):
        referred = TDF_Label()
        if not Tool.GetReferredShape_s(label, referred):
            return
        label = referred
    owner = _label_name(label) or owner
    if Tool.IsAssembly_s(label):
        components = _label_sequence()
        Tool.GetComponents_s(label, components, False)
        for i in range(1, components.Length() + 1):
            _walk(components.Value(i), owner, names)
        return
    if owner:
        for face in _faces(Tool.GetShape_s(label)):
            names.add(face, owner=owner)
    subs = _label_sequence()
    Tool.GetSubShapes_s(label, subs)
    for i in range(1, subs.Length() + 1):
        name = _label_name(subs.Value(i))
        shape = Tool.GetShape_s(subs.Value(i))
        if not name or shape.IsNull():
            continue
        if shape.ShapeType() == TopAbs_FACE:  # the face's own name
            names.add(shape, own=name)
        else:  # a named solid, shell, ...: the closest owner of its faces
            for face in _faces(shape):
                names.add(face, owner=name, inner=True)


class _FaceNames:
    """Names of OCP faces, matched by their underlying ``TopoDS_TShape`` (location and orientation aside):
    each face's own name, and the name of the (innermost named) shape that owns it.

    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> from OCP.gp import gp_Trsf, gp_Vec
    >>> from OCP.TopLoc import TopLoc_Location
    >>> box = BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape()
    >>> names = _FaceNames()
    >>> for face in _faces(box):
    ...     names.add(face, owner="box")
    >>> names.add(_faces(box)[2], own="lid")
    >>> shift = gp_Trsf(); shift.SetTranslation(gp_Vec(5.0, 0.0, 0.0))
    >>> moved = box.Moved(TopLoc_Location(shift))  # another instance: the same faces, elsewhere
    >>> [names.name(face, k) for k, face in enumerate(_faces(moved))][1:3]
    ['box / face 1', 'lid']
    """

    def __init__(self):
        self._table = {}  # hash of the unlocated forward face -> [[face, own, owner], ...]

    def _entry(self, face, create: bool):
        from OCP.TopAbs import TopAbs_FORWARD
        from OCP.TopLoc import TopLoc_Location

        key = face.Located(TopLoc_Location()).Oriented(TopAbs_FORWARD)
        bucket = self._table.setdefault(hash(key), []) if create else self._table.get(hash(key), [])
        for entry in bucket:
            if entry[0].IsSame(key):
                return entry
        if not create:
            return None
        bucket.append([key, "", ""])
        return bucket[-1]

    def add(self, face, own: str = "", owner: str = "", inner: bool = False) -> None:
        """Record a face's own name, or its owner's (kept if one is known, unless ``inner``: a closer owner)."""
        entry = self._entry(face, True)
        if own:
            entry[1] = own
        if owner and (inner or not entry[2]):
            entry[2] = owner

    def name(self, face, k: int):
        """The face's own name, else ``"<owner> / face <k>"``, else None."""
        entry = self._entry(face, False)
        if entry is None:
            return None
        return entry[1] or (f"{entry[2]} / face {k}" if entry[2] else None)


def _faces(shape) -> list:
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    faces = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        faces.append(explorer.Current())
        explorer.Next()
    return faces


def shape_to_model(shape, path, kind: str, skipped: dict, damage=None) -> NurbsModel:
    """Turn an OCP shape's faces into a NurbsModel (analytic faces converted, :func:`shape_faces`; see the
    module notes).

    Parameters
    ----------
    shape : OCP.TopoDS.TopoDS_Shape
    path : path-like
        For names and messages.
    kind : str
        The format and library, for ``source``.
    skipped : dict
        What the caller already skipped (entity type -> count); faces on other surfaces are added.
    damage : Damage, optional
        What a partial read of a damaged file lost (:func:`.nurbs_common.build_model`).

    Examples
    --------
    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> m = shape_to_model(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(), "box", "OCP shape", {})
    >>> len(m), m.bounds(), "6 analytic faces converted to NURBS by OpenCASCADE (6 x Geom_Plane)" in m.source
    (6, (0.0, 1.0, 0.0, 1.0, 0.0, 1.0), True)
    """
    skipped, converted = dict(skipped), {}
    surfaces, trims = shape_faces(shape, path, skipped, converted=converted)
    return build_model(path, kind + converted_note(converted), surfaces, trims, skipped, damage=damage)


def shape_faces(shape, path, skipped: dict, prefix: str = "", names=None, converted=None) -> tuple:
    """``(surfaces, trims)`` of an OCP shape's faces. A face on an analytic surface (plane, cylinder, cone,
    sphere, torus, extrusion, revolution, offset) is converted to a B-spline face exactly (these surfaces are
    rational): with edges along parameter lines by :func:`.nurbs_iso_faces.iso_face`, else by OpenCASCADE's
    ``BRepBuilderAPI_NurbsConvert``; it is counted in ``converted`` (surface type -> count) when a dict is
    given; a face OpenCASCADE cannot convert is counted in ``skipped``.

    Faces are named ``names(face, k)`` when that gives a name (``names``: a function of the
    ``TopoDS_Face`` and its index ``k`` in the shape, returning a str or None), else
    ``"<prefix> face <k>"`` (``"face <k>"`` without a prefix); a shape with a single face names it
    ``prefix`` itself when one is given.

    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    >>> box = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(), True).Shape()
    >>> surfaces, trims = shape_faces(box, "box", {}, prefix="box")
    >>> [s.name for s in surfaces][:2], len(trims[0]), len(trims[0][0])  # one wire of four edges
    (['box face 0', 'box face 1'], 1, 4)
    >>> surfaces, _ = shape_faces(box, "box", {}, names=lambda face, k: "lid" if k == 5 else None)
    >>> [s.name for s in surfaces][4:]
    ['face 4', 'lid']
    """
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    faces = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        faces.append(TopoDS.Face(explorer.Current()))
        explorer.Next()
    surfaces, trims = [], []
    for k, face in enumerate(faces):
        name = (names(face, k) if names is not None else None) or (
            prefix if (prefix and len(faces) == 1) else (f"{prefix} face {k}" if prefix else f"face {k}"))
        surf = _face_surface(face)
        kind_name = "no surface" if surf is None else surf.DynamicType().Name()
        fast = None
        if kind_name != "Geom_BSplineSurface" and surf is not None:
            fast = iso_face(face, path, name)  # edges along parameter lines: exact and fast
            face, surf = (face, fast[0]) if fast is not None else _nurbs_face(face)
            if surf is not None and converted is not None:
                converted[kind_name] = converted.get(kind_name, 0) + 1
        if surf is None or surf.DynamicType().Name() != "Geom_BSplineSurface":
            key = f"face on {kind_name}"
            skipped[key] = skipped.get(key, 0) + 1
            continue
        surface = checked(path, name, lambda: bspline_surface(surf, name))
        loops = (fast[1] if fast is not None else [_loop(wire, face, path, name) for wire in _wires(face)]) or None
        if face.Orientation() == TopAbs_REVERSED:  # the face's outside is the surface's back: mirror v
            surface, loops = flip_v(surface, loops)
        surfaces.append(surface)
        trims.append(loops)
    return surfaces, trims


def _face_surface(face):
    """The face's surface (the basis of a rectangular trimmed one), or None."""
    from OCP.BRep import BRep_Tool

    surf = BRep_Tool.Surface_s(face)
    if surf is not None and surf.DynamicType().Name() == "Geom_RectangularTrimmedSurface":
        surf = surf.BasisSurface()
    return surf


def _nurbs_face(face):
    """The face converted to a B-spline face by OpenCASCADE and its surface, or ``(face, None)``."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.TopoDS import TopoDS

    try:
        new = TopoDS.Face(BRepBuilderAPI_NurbsConvert(face, True).Shape())
    except Exception:  # noqa: BLE001 -- OpenCASCADE refuses: the face is skipped and counted
        return face, None
    return new, _face_surface(new)


def converted_note(converted: dict) -> str:
    """The ``source`` note of faces converted to NURBS.

    >>> converted_note({"Geom_Plane": 6, "Geom_CylindricalSurface": 1})
    '; 7 analytic faces converted to NURBS by OpenCASCADE (1 x Geom_CylindricalSurface, 6 x Geom_Plane)'
    >>> converted_note({})
    ''
    """
    if not converted:
        return ""
    parts = ", ".join(f"{n} x {k}" for k, n in sorted(converted.items()))
    return f"; {sum(converted.values())} analytic faces converted to NURBS by OpenCASCADE ({parts})"


def bspline_surface(surf, name: str = "") -> NurbsSurface:
    """A ``Geom_BSplineSurface`` as a NurbsSurface (periodic directions unrolled).

    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    >>> from OCP.BRep import BRep_Tool
    >>> from OCP.TopExp import TopExp_Explorer
    >>> from OCP.TopAbs import TopAbs_FACE
    >>> from OCP.TopoDS import TopoDS
    >>> box = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(), True).Shape()
    >>> s = bspline_surface(BRep_Tool.Surface_s(TopoDS.Face(TopExp_Explorer(box, TopAbs_FACE).Current())))
    >>> s.degree, s.shape
    ((1, 1), (2, 2))
    """
    if surf.IsUPeriodic() or surf.IsVPeriodic():
        surf = surf.Copy()
        if surf.IsUPeriodic():
            surf.SetUNotPeriodic()
        if surf.IsVPeriodic():
            surf.SetVNotPeriodic()
    nu, nv = surf.NbUPoles(), surf.NbVPoles()
    U = [surf.UKnot(i) for i in range(1, surf.NbUKnots() + 1) for _ in range(surf.UMultiplicity(i))]
    V = [surf.VKnot(i) for i in range(1, surf.NbVKnots() + 1) for _ in range(surf.VMultiplicity(i))]
    P = np.empty((nu, nv, 3))
    W = np.empty((nu, nv))
    for i in range(nu):
        for j in range(nv):
            p = surf.Pole(i + 1, j + 1)
            P[i, j] = p.X(), p.Y(), p.Z()
            W[i, j] = surf.Weight(i + 1, j + 1)
    rational = surf.IsURational() or surf.IsVRational()
    return NurbsSurface((surf.UDegree(), surf.VDegree()), (U, V), P, W if rational else None, name=name)


def _wires(face):
    from OCP.TopAbs import TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    explorer = TopExp_Explorer(face, TopAbs_WIRE)
    while explorer.More():
        yield TopoDS.Wire(explorer.Current())
        explorer.Next()


def _loop(wire, face, path, name: str) -> list:
    """The wire's edges as TrimCurves in the face's surface parameters (reversed edges reversed)."""
    from OCP.BRep import BRep_Tool
    from OCP.Geom2d import Geom2d_TrimmedCurve
    from OCP.Geom2dConvert import Geom2dConvert
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    loop = []
    explorer = TopExp_Explorer(wire, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge(explorer.Current())
        explorer.Next()
        curve = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)
        if curve is None:
            raise ValueError(f"{path}: {name}: an edge of the face has no curve on the surface (pcurve); "
                             "the file's topology is incomplete, trims cannot be read.")
        a, b = BRep_Tool.Range_s(edge, face)
        bs = Geom2dConvert.CurveToBSplineCurve_s(Geom2d_TrimmedCurve(curve, a, b))
        if bs.IsPeriodic():
            bs.SetNotPeriodic()
        if bs.Degree() > 3:  # intersection pcurves come as degree 8 and more: a cubic within 1e-9 of the domain
            bs = _cubic_pcurve(bs, path, name)
        if edge.Orientation() == TopAbs_REVERSED:
            bs.Reverse()
        n = bs.NbPoles()
        knots = [bs.Knot(i) for i in range(1, bs.NbKnots() + 1) for _ in range(bs.Multiplicity(i))]
        pts = [(bs.Pole(i).X(), bs.Pole(i).Y()) for i in range(1, n + 1)]
        w = [bs.Weight(i) for i in range(1, n + 1)] if bs.IsRational() else None
        loop.append(checked(path, f"{name} trim curve", lambda: TrimCurve(bs.Degree(), knots, pts, w)))
    return loop


def _cubic_pcurve(bs, path, name):
    """A C1 cubic B-spline within ``1e-9`` of the domain's size of the pcurve ``bs`` (OpenCASCADE's
    ``Geom2dConvert_ApproxCurve``): the trims of the per-fragment program are cubic at most, and the files'
    intersection curves come as degree 8 and more."""
    from OCP.Geom2dConvert import Geom2dConvert_ApproxCurve
    from OCP.GeomAbs import GeomAbs_C1

    box = [bs.Pole(i) for i in range(1, bs.NbPoles() + 1)]
    size = max(max(p.X() for p in box) - min(p.X() for p in box), max(p.Y() for p in box) - min(p.Y() for p in box))
    tol = 1e-9 * max(size, 1e-300)
    approx = Geom2dConvert_ApproxCurve(bs, tol, GeomAbs_C1, 1000, 3)  # C2 would need degree 5 here
    if not (approx.IsDone() and approx.HasResult()) or approx.MaxError() > tol:
        raise ValueError(f"{path}: {name}: a trim curve of degree {bs.Degree()} could not be brought to a cubic "
                         f"within {tol:.3g} (OpenCASCADE's approximation reached {approx.MaxError():.3g}).")
    return approx.Curve()


# --------------------------------------------------------------------------------------------------

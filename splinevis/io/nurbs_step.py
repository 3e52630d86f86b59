"""NURBS faces from STEP files through OpenCASCADE (``OCP``), and the OCP shape conversion IGES shares.

OCP comes from the optional extra ``cad`` (``pip install cadquery-ocp-novtk``, ~380 MB); without it
:func:`read_step` raises an ImportError saying so. Nothing from OCP is imported at module import time.

What is read
------------
Every face of the transferred shape whose surface is a ``Geom_BSplineSurface`` (also under a
``Geom_RectangularTrimmedSurface``) becomes one patch named ``"face <k>"`` (k counts the faces in the
shape's order). Periodic surfaces are unrolled to their non-periodic form (same points). The face's
wires become its trim loops: each edge's curve on the surface (its "pcurve", trimmed to the edge's
range) converted to a 2-D B-spline with ``Geom2dConvert``, in the surface's own ``(u, v)`` domain. Faces
on other surfaces (planes, cylinders, ... not converted to NURBS by the writer) are counted in
``skipped`` as ``"face on Geom_Plane"`` etc. The face orientation (a reversed face flips the normal) is
not applied: the patch keeps the surface's parametrization.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface, TrimCurve
from .nurbs_common import build_model, checked, flip_v

__all__ = ["read_step", "ocp_available", "shape_to_model", "shape_faces", "bspline_surface", "OCP_HINT"]

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


def read_step(path) -> NurbsModel:
    """Read the B-spline faces of a STEP file (with their trim loops) through OCP.

    Raises
    ------
    ImportError
        OCP is not installed (``pip install cadquery-ocp-novtk``).
    ValueError
        The file cannot be read, or holds no B-spline face.

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
    >>> len(m), m.bounds()
    (6, (0.0, 1.0, 0.0, 2.0, 0.0, 3.0))
    """
    path = Path(path)
    try:
        from OCP.IFSelect import IFSelect_RetDone
        from OCP.STEPControl import STEPControl_Reader
    except ImportError:
        raise ImportError(f"{path}: reading STEP files needs OpenCASCADE's Python bindings (OCP): {OCP_HINT}.") from None
    _quiet_occ()
    reader = STEPControl_Reader()
    if reader.ReadFile(str(path)) != IFSelect_RetDone:
        raise ValueError(f"{path}: OpenCASCADE could not read this file as STEP; is it a valid ISO 10303-21 file?")
    reader.TransferRoots()
    return shape_to_model(reader.OneShape(), path, "STEP (OCP)", {})


def shape_to_model(shape, path, kind: str, skipped: dict) -> NurbsModel:
    """Turn an OCP shape's B-spline faces into a NurbsModel (see the module notes).

    Parameters
    ----------
    shape : OCP.TopoDS.TopoDS_Shape
    path : path-like
        For names and messages.
    kind : str
        The format and library, for ``source``.
    skipped : dict
        What the caller already skipped (entity type -> count); faces on other surfaces are added.

    Examples
    --------
    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> import warnings
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     shape_to_model(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(), "box", "OCP shape", {})
    Traceback (most recent call last):
    ValueError: box holds no supported NURBS surface (OCP shape); it contains: 6 x face on Geom_Plane.
    """
    skipped = dict(skipped)
    surfaces, trims = shape_faces(shape, path, skipped)
    return build_model(path, kind, surfaces, trims, skipped)


def shape_faces(shape, path, skipped: dict, prefix: str = "") -> tuple:
    """``(surfaces, trims)`` of an OCP shape's B-spline faces; other faces are counted in ``skipped``.

    Faces are named ``"<prefix> face <k>"`` (``"face <k>"`` without a prefix); a shape with a single
    face names it ``prefix`` itself when one is given.

    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    >>> box = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(), True).Shape()
    >>> surfaces, trims = shape_faces(box, "box", {}, prefix="box")
    >>> [s.name for s in surfaces][:2], len(trims[0]), len(trims[0][0])  # one wire of four edges
    (['box face 0', 'box face 1'], 1, 4)
    """
    from OCP.BRep import BRep_Tool
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
        name = prefix if (prefix and len(faces) == 1) else (f"{prefix} face {k}" if prefix else f"face {k}")
        surf = BRep_Tool.Surface_s(face)
        if surf is not None and surf.DynamicType().Name() == "Geom_RectangularTrimmedSurface":
            surf = surf.BasisSurface()
        kind_name = "no surface" if surf is None else surf.DynamicType().Name()
        if kind_name != "Geom_BSplineSurface":
            key = f"face on {kind_name}"
            skipped[key] = skipped.get(key, 0) + 1
            continue
        surface = checked(path, name, lambda: bspline_surface(surf, name))
        loops = [_loop(wire, face, path, name) for wire in _wires(face)] or None
        if face.Orientation() == TopAbs_REVERSED:  # the face's outside is the surface's back: mirror v
            surface, loops = flip_v(surface, loops)
        surfaces.append(surface)
        trims.append(loops)
    return surfaces, trims


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
        if edge.Orientation() == TopAbs_REVERSED:
            bs.Reverse()
        n = bs.NbPoles()
        knots = [bs.Knot(i) for i in range(1, bs.NbKnots() + 1) for _ in range(bs.Multiplicity(i))]
        pts = [(bs.Pole(i).X(), bs.Pole(i).Y()) for i in range(1, n + 1)]
        w = [bs.Weight(i) for i in range(1, n + 1)] if bs.IsRational() else None
        loop.append(checked(path, f"{name} trim curve", lambda: TrimCurve(bs.Degree(), knots, pts, w)))
    return loop

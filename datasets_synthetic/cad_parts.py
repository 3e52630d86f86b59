"""Trimmed CAD solids written to STEP as CAD systems write them (planes, cylinders, spheres, with trims), for the
walkthrough of real B-rep models through the readers: a plate with every edge filleted and a grid of holes,
repeated on a grid as one assembly. Built with OpenCASCADE (the optional ``cad`` extra, OCP); read back with
:func:`splinevis.io.read_nurbs`, which converts the analytic faces to NURBS.

>>> import tempfile, pathlib
>>> with tempfile.TemporaryDirectory() as d:
...     m = plates(pathlib.Path(d) / "plates.step", copies=2)
>>> len(m), sum(1 for t in m.trims if t)  # 32 faces a plate, every one trimmed
(64, 64)
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["plate_shape", "plates"]


def plate_shape(size=(6.0, 4.0, 1.0), fillet: float = 0.3, holes=(3, 2), radius: float = 0.4):
    """An OCP solid: a box of ``size`` with every edge filleted (cylinders along the edges, sphere octants at the
    corners) and ``holes[0] x holes[1]`` cylindrical holes of ``radius`` through it on a regular grid.

    >>> from OCP.TopAbs import TopAbs_FACE
    >>> from OCP.TopExp import TopExp_Explorer
    >>> ex, n = TopExp_Explorer(plate_shape(), TopAbs_FACE), 0
    >>> while ex.More():
    ...     n += 1; ex.Next()
    >>> n  # 6 planes, 12 edge cylinders, 8 corner spheres, 6 holes
    32
    """
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    a, b, c = (float(x) for x in size)
    shape = BRepPrimAPI_MakeBox(gp_Pnt(0.0, 0.0, 0.0), a, b, c).Shape()
    rounded = BRepFilletAPI_MakeFillet(shape)
    edges = TopExp_Explorer(shape, TopAbs_EDGE)
    while edges.More():
        rounded.Add(float(fillet), TopoDS.Edge(edges.Current()))
        edges.Next()
    shape = rounded.Shape()
    nx, ny = holes
    for i in range(nx):
        for j in range(ny):
            axis = gp_Ax2(gp_Pnt(a * (i + 0.5) / nx, b * (j + 0.5) / ny, -c), gp_Dir(0.0, 0.0, 1.0))
            shape = BRepAlgoAPI_Cut(shape, BRepPrimAPI_MakeCylinder(axis, float(radius), 3.0 * c).Shape()).Shape()
    return shape


def plates(path, copies: int = 16, spacing: float = 8.0, **options):
    """``copies`` plates (:func:`plate_shape`) on a square grid ``spacing`` apart, written to ``path`` and read
    back (:func:`splinevis.io.read_nurbs`): 32 trimmed faces a plate. A ``.step``/``.stp`` path gets one STEP
    assembly of solids; an ``.igs``/``.iges`` path IGES faces mode (entity 144 trimmed surfaces, no topology and
    no outside: what many CAD exports hold)."""
    import math

    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.gp import gp_Trsf, gp_Vec
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    from splinevis.io import read_nurbs
    from splinevis.io.nurbs_step import _quiet_occ

    _quiet_occ()
    one = plate_shape(**options)
    side = math.ceil(math.sqrt(int(copies)))
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    for k in range(int(copies)):
        move = gp_Trsf()
        move.SetTranslation(gp_Vec(spacing * (k % side), spacing * (k // side), 0.0))
        builder.Add(compound, BRepBuilderAPI_Transform(one, move, True).Shape())
    if Path(path).suffix.lower() in (".igs", ".iges"):
        from OCP.IGESControl import IGESControl_Writer

        writer = IGESControl_Writer("MM", 0)  # faces mode: 144 trimmed surfaces
        writer.AddShape(compound)
        writer.ComputeModel()
    else:
        writer = STEPControl_Writer()
        writer.Transfer(compound, STEPControl_AsIs)
    writer.Write(str(Path(path)))
    return read_nurbs(path)

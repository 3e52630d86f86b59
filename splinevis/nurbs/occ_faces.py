"""Our NURBS patches as OpenCASCADE faces (``OCP``, the ``cad`` extra): the same points, weights and knots
(``Geom_BSplineSurface``), trimmed by our loops as 2-D B-spline curves on the surface, for the CAD baseline of
``splinevis check`` (:mod:`.judge`) and for OpenCASCADE's own orientation of a model's shells
(:func:`occ_outward`, the independent check of :mod:`.orient`). OCP is imported only when called.
"""

from __future__ import annotations

import numpy as np

from .model import NurbsModel

__all__ = ["occ_outward"]


def _occ_arrays():
    try:  # OCP 8: NCollection arrays in OCP.collections
        from OCP.OCP.collections import Array1_double, Array1_gp_Pnt2d, Array1_int, Array2_double, Array2_gp_Pnt
    except ImportError:  # OCP 7.x
        from OCP.TColgp import TColgp_Array1OfPnt2d as Array1_gp_Pnt2d, TColgp_Array2OfPnt as Array2_gp_Pnt
        from OCP.TColStd import TColStd_Array1OfInteger as Array1_int, TColStd_Array1OfReal as Array1_double
        from OCP.TColStd import TColStd_Array2OfReal as Array2_double
    return Array1_double, Array1_int, Array2_double, Array2_gp_Pnt, Array1_gp_Pnt2d


def _knots(K):
    Real1, Int1 = _occ_arrays()[:2]
    values, mults = np.unique(np.asarray(K, dtype=np.float64), return_counts=True)
    kv, km = Real1(1, len(values)), Int1(1, len(values))
    for i, (a, m) in enumerate(zip(values, mults)):
        kv.SetValue(i + 1, float(a))
        km.SetValue(i + 1, int(m))
    return kv, km


def _occ_surface(s):
    """A NurbsSurface as a ``Geom_BSplineSurface`` (same points, weights, knots: the same parametrization)."""
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt

    _, _, Real2, Pnt2, _ = _occ_arrays()
    nu, nv = s.shape
    poles, weights = Pnt2(1, nu, 1, nv), Real2(1, nu, 1, nv)
    w = np.ones((nu, nv)) if s.weights is None else s.weights
    for i in range(nu):
        for j in range(nv):
            poles.SetValue(i + 1, j + 1, gp_Pnt(*map(float, s.control_points[i, j])))
            weights.SetValue(i + 1, j + 1, float(w[i, j]))
    (p, q), (U, V) = s.degree, s.knots
    (ku, mu), (kv, mv) = _knots(U), _knots(V)
    return Geom_BSplineSurface(poles, weights, ku, kv, mu, mv, p, q, False, False)


def _occ_curve2d(c):
    """A TrimCurve as a ``Geom2d_BSplineCurve``."""
    from OCP.Geom2d import Geom2d_BSplineCurve
    from OCP.gp import gp_Pnt2d

    Real1, _, _, _, Pnt1 = _occ_arrays()
    n = c.control_points.shape[0]
    poles, weights = Pnt1(1, n), Real1(1, n)
    w = np.ones(n) if c.weights is None else c.weights
    for i in range(n):
        poles.SetValue(i + 1, gp_Pnt2d(*map(float, c.control_points[i])))
        weights.SetValue(i + 1, float(w[i]))
    k, m = _knots(c.knots)
    return Geom2d_BSplineCurve(poles, weights, k, m, c.degree, False)


def _loop_area(loop) -> float:
    """Area enclosed by a trim loop in (u, v) (shoelace over sampled points; its sign is the orientation)."""
    pts = np.concatenate([c.evaluate(np.linspace(*c.domain, 33)) for c in loop])
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _occ_face(s, loops, tol: float):
    """One patch as an OpenCASCADE face: the surface bounded by its trim loops (the largest one the outer
    boundary, the others holes, each oriented as OpenCASCADE wants), or its natural boundary."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
    from OCP.BRepLib import BRepLib
    from OCP.TopoDS import TopoDS

    surf = _occ_surface(s)
    if not loops:
        return BRepBuilderAPI_MakeFace(surf, tol).Face()
    wires = []
    for loop in loops:
        make = BRepBuilderAPI_MakeWire()
        for c in loop:
            make.Add(BRepBuilderAPI_MakeEdge(_occ_curve2d(c), surf).Edge())
        wires.append((_loop_area(loop), make.Wire()))
    wires.sort(key=lambda aw: -abs(aw[0]))
    # OpenCASCADE keeps the material left of each wire in (u, v): the outer one counter-clockwise, holes clockwise
    oriented = [w if (a > 0) == (k == 0) else TopoDS.Wire(w.Reversed()) for k, (a, w) in enumerate(wires)]
    make = BRepBuilderAPI_MakeFace(surf, oriented[0], True)
    for w in oriented[1:]:
        make.Add(w)
    face = make.Face()
    BRepLib.BuildCurves3d_s(face)
    return face


def _model_shape(model: NurbsModel, tol: float):
    """The model's patches as a compound of OpenCASCADE faces; ``(compound, [names it could not build])``."""
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    builder, compound, failed = BRep_Builder(), TopoDS_Compound(), []
    builder.MakeCompound(compound)
    for s, loops in zip(model.surfaces, model.trims):
        try:
            builder.Add(compound, _occ_face(s, loops, tol))
        except Exception as err:  # noqa: BLE001 -- OpenCASCADE refuses a face: the baseline lacks it, and says so
            failed.append(f"{s.name} ({type(err).__name__})")
    return compound, failed


def _diagonal(shape) -> float:
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    if box.IsVoid():
        return 0.0
    lo, hi = box.CornerMin(), box.CornerMax()
    return float(np.linalg.norm([hi.X() - lo.X(), hi.Y() - lo.Y(), hi.Z() - lo.Z()]))


def occ_outward(model: NurbsModel, tol: float = 1e-6) -> np.ndarray:
    """OpenCASCADE's answer: ``+1`` where a face's normal ``S_u x S_v`` points out of the solid its sewn shell
    bounds, ``-1`` where it points in, ``0`` where the face is not in a closed shell (or not built).

    Needs ``OCP`` (the ``cad`` extra). The faces are built as in the OpenCASCADE judge, sewn
    (``BRepBuilderAPI_Sewing``), each shell oriented (``ShapeFix_Shell``) and made a solid with outward faces
    (``ShapeFix_Solid``); a face REVERSED in that solid has its outside behind its surface normal. ``tol`` is
    the absolute sewing tolerance (gaps of real files need about 1e-4 of the model's size); the independent
    check of :func:`.orient.orient_faces`.

    >>> from splinevis.nurbs.exact import box_faces
    >>> from splinevis.nurbs.orient import flip_u
    >>> faces = box_faces(2.0, 1.0, 1.0)
    >>> occ_outward(NurbsModel(faces[:5] + [flip_u(faces[5])[0]]), 1e-7).tolist()  # the +x face turned in
    [1.0, 1.0, 1.0, 1.0, 1.0, -1.0]
    """
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.ShapeFix import ShapeFix_Shell, ShapeFix_Solid
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED, TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    faces = []
    for s, loops in zip(model.surfaces, model.trims):
        try:
            faces.append(_occ_face(s, loops, tol))
        except Exception:  # noqa: BLE001 -- a face OpenCASCADE cannot build has no answer (0)
            faces.append(None)
    sew = BRepBuilderAPI_Sewing(tol)
    for f in faces:
        if f is not None:
            sew.Add(f)
    sew.Perform()
    sewn = sew.SewedShape()
    out = np.zeros(len(faces))
    images = [None if f is None else (sew.Modified(f) if sew.IsModified(f) else f) for f in faces]
    shells = TopExp_Explorer(sewn, TopAbs_SHELL)
    while shells.More():
        fix = ShapeFix_Shell(TopoDS.Shell(shells.Current()))
        fix.Perform()
        shell = fix.Shell()
        shells.Next()
        if not shell.Closed():
            continue
        solid = ShapeFix_Solid().SolidFromShell(shell)
        ex = TopExp_Explorer(solid, TopAbs_FACE)
        while ex.More():
            f = ex.Current()
            ex.Next()
            for k, img in enumerate(images):
                if img is not None and img.IsSame(f):
                    out[k] = -1.0 if f.Orientation() == TopAbs_REVERSED else 1.0
    return out

"""Faces on analytic surfaces whose edges run along parameter lines, converted without NurbsConvert
(splinevis.io.nurbs_iso_faces): the B-spline lies on the exact analytic surface and the trims' 3-D images on
the face's edges, within the bound the conversion checked its maps against (its rounding analysis); the
surface is NurbsConvert's own; faces that do not qualify (a hole's circle in a plane, a slanted cut, maps that
fail the check) are converted by NurbsConvert as before, and a file reads into the same model either way."""

import warnings

import numpy as np
import pytest

from splinevis.io import nurbs_iso_faces, nurbs_step
from splinevis.io.nurbs_files import read_nurbs
from splinevis.io.nurbs_iso_faces import iso_face
from splinevis.io.nurbs_step import (
    _loop,
    _nurbs_face,
    _quiet_occ,
    _wires,
    bspline_surface,
    shape_faces,
)

U = 2.0 ** -53  # unit roundoff [Higham2002, sec. 2.1]
RNG = np.random.default_rng(11)
TORUS_AXIS = np.array([0.0, 1.0, 1.0]) / np.sqrt(2.0)
CONE_AXIS = np.array([1.0, 0.0, 1.0]) / np.sqrt(2.0)


def _along(P, c, n):
    """Axial coordinate and distance from the axis through ``c`` along unit ``n``."""
    h = (P - c) @ n
    return h, np.linalg.norm(P - c - h[:, None] * n, axis=1)


#: The exact shapes written (cylinder, sphere, torus, cone, 4 apart in x): signed distance to each surface.
SHAPES = {
    0: lambda P: np.hypot(P[:, 0], P[:, 1]) - 1.0,
    4: lambda P: np.linalg.norm(P - [4.0, 0.0, 0.0], axis=1) - 1.0,
    8: lambda P: np.hypot(_along(P, [8.0, 0.0, 0.0], TORUS_AXIS)[1] - 1.5, _along(P, [8.0, 0.0, 0.0], TORUS_AXIS)[0]) - 0.5,
    12: lambda P: ((_along(P, [12.0, 0.0, 0.0], CONE_AXIS)[1] - 1.0) * 2.0
                   - _along(P, [12.0, 0.0, 0.0], CONE_AXIS)[0] * (0.3 - 1.0)) / np.hypot(2.0, 0.7),
}


def _distance(P):
    """Distance of points (of one shape) to that shape's exact surface, and the rounding of computing it: a
    handful of operations on coordinates up to ``|P| + 12`` (16 ulps of that)."""
    shape = SHAPES[min(SHAPES, key=lambda x: abs(x - P[:, 0].mean()))]
    return np.abs(shape(P)), 16 * U * (np.abs(P).max() + 12.0)


def _primitives():
    from OCP.BRep import BRep_Builder
    from OCP.BRepPrimAPI import (
        BRepPrimAPI_MakeCone,
        BRepPrimAPI_MakeCylinder,
        BRepPrimAPI_MakeSphere,
        BRepPrimAPI_MakeTorus,
    )
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.TopoDS import TopoDS_Compound

    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    for shape in (BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 1.0, 2.0),
                  BRepPrimAPI_MakeSphere(gp_Pnt(4, 0, 0), 1.0),
                  BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(8, 0, 0), gp_Dir(*TORUS_AXIS)), 1.5, 0.5),
                  BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(12, 0, 0), gp_Dir(*CONE_AXIS)), 1.0, 0.3, 2.0)):
        builder.Add(compound, shape.Shape())
    return compound


@pytest.fixture(scope="module")
def iges(tmp_path_factory):
    """The primitives written as IGES faces (144 trimmed surfaces on 120 surfaces of revolution, planes), as CAD
    exports hold them."""
    from OCP.IGESControl import IGESControl_Writer

    _quiet_occ()
    path = tmp_path_factory.mktemp("iso") / "primitives.igs"
    writer = IGESControl_Writer("MM", 0)
    writer.AddShape(_primitives())
    writer.ComputeModel()
    writer.Write(str(path))
    return path


def _faces(shape):
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    out, ex = [], TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        out.append(TopoDS.Face(ex.Current()))
        ex.Next()
    return out


def _read_shape(path):
    from OCP.IGESControl import IGESControl_Reader

    reader = IGESControl_Reader()
    reader.ReadFile(str(path))
    reader.TransferRoots()
    return reader.OneShape()


def _revolution_faces(path):
    return [f for f in _faces(_read_shape(path)) if nurbs_step._face_surface(f).DynamicType().Name()
            == "Geom_SurfaceOfRevolution"]


def _edges(face):
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    out = []
    for wire in _wires(face):
        ex = TopExp_Explorer(wire, TopAbs_EDGE)
        while ex.More():
            out.append(TopoDS.Edge(ex.Current()))
            ex.Next()
    return out


def _edge_distance(face, edge, X):
    """Distance of points ``X`` to the edge's curve on the face's own surface: the nearest of 2001 samples, then
    Gauss-Newton on the edge's parameter (the points lie on the curve: quadratic convergence to the foot)."""
    from OCP.BRep import BRep_Tool
    from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec, gp_Vec2d

    surf, curve = BRep_Tool.Surface_s(face), BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)
    a, b = BRep_Tool.Range_s(edge, face)
    ts = np.linspace(a, b, 2001)
    C = np.array([surf.Value(*curve.Value(t).Coord()).Coord() for t in ts])
    out = []
    P, du, dv, q, dq = gp_Pnt(), gp_Vec(), gp_Vec(), gp_Pnt2d(), gp_Vec2d()
    for x in X:
        t = ts[np.argmin(np.linalg.norm(C - x, axis=1))]
        for _ in range(8):
            curve.D1(t, q, dq)
            surf.D1(q.X(), q.Y(), P, du, dv)
            d = np.array(du.Coord()) * dq.X() + np.array(dv.Coord()) * dq.Y()
            if not d @ d > 0:  # a degenerate edge (a pole): one point
                break
            t = min(max(t - (np.array(P.Coord()) - x) @ d / (d @ d), a), b)
        curve.D1(t, q, dq)
        out.append(np.linalg.norm(np.array(surf.Value(q.X(), q.Y()).Coord()) - x))
    return np.array(out)


def _drift(face, edge):
    """How far a pcurve that holds its parameter line only to the file's precision strays from it in 3-D: the
    spread of the held coordinate times the largest speed across it along the edge (module notes, 3); 0 for a
    pcurve on its line exactly."""
    from OCP.BRep import BRep_Tool
    from OCP.gp import gp_Pnt, gp_Vec

    surf, curve = BRep_Tool.Surface_s(face), BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)
    a, b = BRep_Tool.Range_s(edge, face)
    uv = np.array([curve.Value(t).Coord() for t in np.linspace(a, b, 33)])
    spread = np.ptp(uv, axis=0)
    held = int(np.argmin(spread))
    if spread[held] == 0.0:
        return 0.0
    P, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    speed = 0.0
    for x, y in uv:
        surf.D1(x, y, P, du, dv)
        speed = max(speed, (du, dv)[held].Magnitude())
    assert spread[held] * speed <= BRep_Tool.Tolerance_s(edge)  # taken only within the edge's tolerance
    return spread[held] * speed


def test_revolution_faces_lie_on_the_exact_surfaces_and_trims_on_their_edges(iges):
    faces = _revolution_faces(iges)
    assert len(faces) == 4  # the cylinder's, cone's side, the sphere, the torus
    for face in faces:
        bs, loops, tol = iso_face(face)
        s = bspline_surface(bs)
        (u0, u1), (v0, v1) = s.domain
        P = s.evaluate(RNG.uniform(u0, u1, 400), RNG.uniform(v0, v1, 400))
        dist, rounding = _distance(P)
        assert dist.max() <= tol + rounding, (dist.max(), tol)
        curves = [c for loop in loops for c in loop]
        edges = _edges(face)
        assert len(curves) == len(edges) and {c.degree for c in curves} == {1}
        for c, edge in zip(curves, edges):
            uv = c.evaluate(np.linspace(*c.domain, 17))
            X = s.evaluate(np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1))
            d = _edge_distance(face, edge, X)
            assert d.max() <= tol + _drift(face, edge) + _distance(X)[1], (d.max(), tol)


def test_the_surface_is_nurbsconvert_s_and_the_trims_end_where_its_trims_end(iges):
    """NurbsConvert converts the face's rectangle with the same routine; its rectangle may differ from
    OpenCASCADE's UVBounds (which we take) by the pcurves' precision, so knots agree to within the edges'
    tolerance over the surface's speed, control points to within the checked bound plus the edges' tolerance;
    each trim curve starts and ends where NurbsConvert's (re-approximated, to the edge's tolerance) does."""
    from OCP.BRep import BRep_Tool

    for face in _revolution_faces(iges):
        bs, loops, tol = iso_face(face)
        ours = bspline_surface(bs)
        new, surf = _nurbs_face(face)
        theirs = bspline_surface(surf)
        edge_tol = max(BRep_Tool.Tolerance_s(e) for e in _edges(face))
        assert ours.degree == theirs.degree and ours.shape == theirs.shape
        assert (ours.weights is None) == (theirs.weights is None)
        (u0, u1), (v0, v1) = ours.domain
        uu, vv = np.meshgrid(np.linspace(u0, u1, 9), np.linspace(v0, v1, 9))
        D = ours.derivatives(uu.ravel(), vv.ravel(), 1)
        speed = [np.linalg.norm(D[:, 1, 0], axis=1), np.linalg.norm(D[:, 0, 1], axis=1)]
        for a, b, sp in zip(ours.knots, theirs.knots, speed):
            assert np.abs(a - b).max() * sp[sp > 0].min() <= edge_tol
        assert np.abs(ours.control_points - theirs.control_points).max() <= tol + edge_tol
        nc = [c for w in _wires(new) for c in _loop(w, new, "", "")]
        mine = [c for loop in loops for c in loop]
        assert len(nc) == len(mine)
        for a, b, edge in zip(mine, nc, _edges(face)):
            for ta, tb in zip(a.domain, b.domain):
                pa = ours.evaluate(*[[x] for x in np.clip(a.evaluate([ta])[0], *np.array(ours.domain).T)])
                pb = theirs.evaluate(*[[x] for x in np.clip(b.evaluate([tb])[0], *np.array(theirs.domain).T)])
                assert np.linalg.norm(pa - pb) <= 2 * BRep_Tool.Tolerance_s(edge)


def test_faces_off_parameter_lines_go_to_nurbsconvert(iges, monkeypatch):
    """The caps' circles (a plane's pcurve off its parameter lines) and a cylinder cut by a slanted plane (the
    ellipse, a sine in (u, v)) are not taken; shape_faces converts them with NurbsConvert."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf

    planes = [f for f in _faces(_read_shape(iges)) if nurbs_step._face_surface(f).DynamicType().Name() == "Geom_Plane"]
    assert len(planes) == 4 and all(iso_face(f) is None for f in planes)
    tilt = gp_Trsf()
    tilt.SetRotation(gp_Ax1(gp_Pnt(0, 0, 1), gp_Dir(1, 0, 0)), 0.4)
    box = BRepBuilderAPI_Transform(BRepPrimAPI_MakeBox(gp_Pnt(-2, -2, 1), 4.0, 4.0, 3.0).Shape(), tilt, True).Shape()
    cut = BRepAlgoAPI_Cut(BRepPrimAPI_MakeCylinder(1.0, 3.0).Shape(), box).Shape()
    side = [f for f in _faces(cut) if nurbs_step._face_surface(f).DynamicType().Name() == "Geom_CylindricalSurface"]
    assert len(side) == 1 and iso_face(side[0]) is None
    calls = []
    real = nurbs_step._nurbs_face
    monkeypatch.setattr(nurbs_step, "_nurbs_face", lambda face: calls.append(face) or real(face))
    converted = {}
    surfaces, trims = shape_faces(cut, "cut", {}, converted=converted)
    assert len(surfaces) == 3 and converted == {"Geom_CylindricalSurface": 1, "Geom_Plane": 2}
    assert len(calls) == 3  # the side (its slanted edge) and both caps (their circles)
    k = next(i for i, s in enumerate(surfaces) if s.degree != (1, 1))
    n = np.array([0.0, -np.sin(0.4), np.cos(0.4)])  # the cutting plane through (0, 0, 1)
    (u0, u1), (v0, v1) = surfaces[k].domain
    # NurbsConvert's re-approximated pcurves are as exact as the tolerance it gives the converted edges
    approx = max(BRep_Tool.Tolerance_s(e) for e in _edges(real(side[0])[0]))
    slanted = 0
    for c in (c for loop in trims[k] for c in loop):
        uv = c.evaluate(np.linspace(*c.domain, 9))
        X = surfaces[k].evaluate(np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1))
        if np.ptp(X[:, 2]) > 0 and np.ptp(X[:, :2], axis=0).max() > 0.5:  # not the bottom circle, not the seam
            slanted += 1
            assert np.abs((X - [0, 0, 1]) @ n).max() <= approx  # on the plane, to NurbsConvert's approximation
    assert slanted == 1


def test_maps_that_fail_the_check_fall_back_to_nurbsconvert(iges, monkeypatch):
    """Maps off by a millionth of the range (a conversion that would not separate) fail the check on every face:
    the file then reads exactly as with NurbsConvert alone."""
    solve = nurbs_iso_faces._solve

    def off(curve, targets, params, ends, domain, E, work):
        found = solve(curve, targets, params, ends, domain, E, work)
        if found is None:
            return None
        lo, hi = domain
        return {x: min(t + 1e-6 * (hi - lo), hi) for x, t in found[0].items()}, found[1]

    faces = _revolution_faces(iges)
    monkeypatch.setattr(nurbs_iso_faces, "_solve", off)
    assert all(iso_face(f) is None for f in faces)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        failed = read_nurbs(iges, orient=False)
        monkeypatch.setattr(nurbs_step, "iso_face", lambda *a: None)
        plain = read_nurbs(iges, orient=False)
    assert failed.names == plain.names and failed.source == plain.source
    for a, b in zip(failed.surfaces, plain.surfaces):
        assert np.array_equal(a.control_points, b.control_points)
    for ta, tb in zip(failed.trims, plain.trims):
        assert [[np.array_equal(x.control_points, y.control_points) for x, y in zip(la, lb)] for la, lb in zip(ta, tb)] \
            == [[True] * len(la) for la in ta]


def test_iges_revolution_faces_read_fast_into_closed_outward_shells(iges, monkeypatch):
    """The whole reader: names and counts as before, only the caps go to NurbsConvert, and every solid's faces
    close into a shell turned outward (the revolution faces' trims meet the caps' circles)."""
    calls = []
    real = nurbs_step._nurbs_face
    monkeypatch.setattr(nurbs_step, "_nurbs_face", lambda face: calls.append(face) or real(face))
    m = read_nurbs(iges)
    assert len(m) == 8 and len(calls) == 4
    assert "8 analytic faces converted to NURBS by OpenCASCADE (4 x Geom_Plane, 4 x Geom_SurfaceOfRevolution)" in m.source
    report = m.report["orientation"]
    assert report["free_edges"] == [] and report["conflicts"] == []
    assert [c["closed"] for c in report["components"]] == [True] * 4
    assert all(c["signed_volume"] > 0 for c in report["components"])


def test_ends_beyond_the_bounds_move_onto_them_within_the_edge_tolerance():
    """A pcurve's end past the face's bounds by the file's precision moves onto them when its point moves by less
    than the edge's tolerance (the overshoot times the speed: 1 on a unit cylinder), else the face is refused."""
    from OCP.Geom import Geom_CylindricalSurface
    from OCP.gp import gp_Ax3, gp_Pnt, gp_Vec

    surf = Geom_CylindricalSurface(gp_Ax3(), 1.0)
    work = (gp_Pnt(), gp_Vec(), gp_Vec(), gp_Vec())
    bounds = (0.0, 1.0, 0.0, 2.0)
    assert nurbs_iso_faces._onto(surf, (1.0 + 5e-8, 2.0 + 4e-8), bounds, 1e-7, work) == (1.0, 2.0)
    assert nurbs_iso_faces._onto(surf, (0.5, 1.0), bounds, 1e-7, work) == (0.5, 1.0)
    assert nurbs_iso_faces._onto(surf, (1.0 + 2e-7, 1.0), bounds, 1e-7, work) is None

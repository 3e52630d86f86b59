"""splinevis.io.read_nurbs: every reader gives back the surfaces the writing library evaluates (1e-12),
trim loops keep and cut the right parameters, names and counts are kept, unsupported entities counted."""

import json
import sys
import warnings
from math import comb

import numpy as np
import pytest

from _occ import occ_bspline_surface
from splinevis.io.nurbs_files import NURBS_EXTENSIONS, read_nurbs
from splinevis.io.nurbs_iges import read_iges

RNG = np.random.default_rng(7)


def close(a, b, rtol=1e-12):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(np.abs(b).max(), 1.0)
    assert np.abs(a - b).max() <= rtol * scale, np.abs(a - b).max()


def params(surface, n=25):
    (u0, u1), (v0, v1) = surface.domain
    return RNG.uniform(u0, u1, n), RNG.uniform(v0, v1, n)


def inside(loops, uv, samples=2000) -> bool:
    """Even-odd rule over the loops, each sampled densely into a polygon."""
    count = 0
    for loop in loops:
        poly = np.concatenate([c.evaluate(np.linspace(*c.domain, samples)) for c in loop])
        x0, y0 = poly[:-1].T
        x1, y1 = poly[1:].T
        crosses = (y0 > uv[1]) != (y1 > uv[1])
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = x0 + (uv[1] - y0) * (x1 - x0) / (y1 - y0)
        count += int(np.sum(crosses & (xc > uv[0])))
    return count % 2 == 1


def read_quiet(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return (read_iges(path, **kw) if kw else read_nurbs(path))


# ---- text formats ------------------------------------------------------------------------------------
def test_bpt_u_major_bezier_patches(tmp_path):
    nets = [RNG.normal(size=(4, 4, 3)), RNG.normal(size=(3, 2, 3))]  # bicubic and degree (2, 1)
    lines = [str(len(nets))]
    for P in nets:
        lines.append(f"{P.shape[0] - 1} {P.shape[1] - 1}")
        lines += [" ".join(repr(float(x)) for x in P[i, j]) for i in range(P.shape[0]) for j in range(P.shape[1])]
    f = tmp_path / "teapot.bpt"
    f.write_text("\n".join(lines) + "\n")
    m = read_nurbs(f)
    assert m.names == ("patch 0", "patch 1") and m.skipped == {}
    for s, P in zip(m.surfaces, nets):
        n, k = P.shape[0] - 1, P.shape[1] - 1
        u, v = params(s)
        Bu = np.array([[comb(n, i) * t ** i * (1 - t) ** (n - i) for i in range(n + 1)] for t in u])
        Bv = np.array([[comb(k, j) * t ** j * (1 - t) ** (k - j) for j in range(k + 1)] for t in v])
        close(s.evaluate(u, v), np.einsum("mi,mj,ijc->mc", Bu, Bv, P))
    f.write_text("\n".join(lines[:-1]) + "\n")
    with pytest.raises(ValueError, match="ends inside patch 1's control points"):
        read_nurbs(f)


def quarter_cylinder_data(weights=None):
    """A rational quarter cylinder x^2 + y^2 = 1, z = 2 v: u quadratic (3 points), v linear (2 points)."""
    r2 = np.sqrt(0.5)
    pts = [[1, 0, 0], [1, 0, 2], [1, 1, 0], [1, 1, 2], [0, 1, 0], [0, 1, 2]]  # v varies fastest
    w = weights or [1, 1, r2, r2, 1, 1]
    return {"shape": {"type": "surface", "count": 1, "data": [{
        "type": "spline", "rational": True, "name": "quarter", "degree_u": 2, "degree_v": 1,
        "knotvector_u": [0, 0, 0, 1, 1, 1], "knotvector_v": [0, 0, 1, 1], "size_u": 3, "size_v": 2,
        "control_points": {"points": pts, "weights": w}}]}}


def test_geomdl_json_v_fastest_and_exact_cylinder(tmp_path):
    f = tmp_path / "cyl.json"
    f.write_text(json.dumps(quarter_cylinder_data()))
    s = read_nurbs(f).surfaces[0]
    assert s.name == "quarter" and s.degree == (2, 1) and s.shape == (3, 2)
    u, v = params(s)
    p = s.evaluate(u, v)
    close(np.hypot(p[:, 0], p[:, 1]), np.ones_like(u))
    close(p[:, 2], 2 * v)
    close(s.evaluate([0.0, 1.0], [1.0, 0.0]), [[1, 0, 2], [0, 1, 0]])
    d = quarter_cylinder_data()
    d["shape"]["data"][0]["trims"] = {"count": 2, "data": [{"type": "spline"}, {"type": "spline"}]}
    f.write_text(json.dumps(d))
    with pytest.warns(UserWarning, match="2 x trim curves"):
        assert read_nurbs(f).skipped == {"trim curves (geomdl)": 2}
    f.write_text(json.dumps(quarter_cylinder_data([1, 1, 0, 0.7, 1, 1])))
    with pytest.raises(ValueError, match=r"cyl.json: shape.data\[0\]: weights must be positive.*weights\[1, 0\] = 0.0"):
        read_nurbs(f)


def test_g2_against_splipy(tmp_path):
    from splipy import curve_factory, surface_factory, volume_factory
    from splipy.io import G2

    sphere = surface_factory.sphere(2.0)  # rational, periodic in v (the writer splits it)
    bumpy = surface_factory.square(size=(2, 3))
    bumpy.raise_order(2, 1)
    bumpy.refine(2, 1)
    bumpy.set_dimension(3)
    bumpy.controlpoints[..., 2] = RNG.normal(size=bumpy.controlpoints.shape[:2])
    f = tmp_path / "model.g2"
    with G2(str(f)) as g:
        g.write([sphere, bumpy])
        g.write(curve_factory.circle())
        g.write(volume_factory.cube())
    with pytest.warns(UserWarning, match="1 x 100 \\(spline curve\\), 1 x 700 \\(spline volume\\)"):
        m = read_nurbs(f)
    assert m.names == ("surface 0", "surface 1")
    assert m.skipped == {"100 (spline curve)": 1, "700 (spline volume)": 1}
    assert "skipped 1 x 100 (spline curve)" in m.source
    for s, ref in zip(m.surfaces, [sphere, bumpy]):
        u, v = params(s)
        close(s.evaluate(u, v), np.array([ref(a, b) for a, b in zip(u, v)]).reshape(-1, 3))
    circle = "130 1 0 0\n3\n1.5\n0 0 0\n0 0 1\n1 0 0\n0 6.283185307179586\n0\n"
    f.write_text(circle + f.read_text())  # an elementary curve first: skipped through splipy's parser
    with pytest.warns(UserWarning):
        m = read_nurbs(f)
    assert len(m) == 2 and m.skipped == {"130 (circle)": 1, "100 (spline curve)": 1, "700 (spline volume)": 1}
    only_curve = tmp_path / "curve.g2"
    with G2(str(only_curve)) as g:
        g.write(curve_factory.circle())
    with pytest.raises(ValueError, match=r"curve.g2 holds no supported NURBS surface.*1 x 100 \(spline curve\)"):
        read_nurbs(only_curve)


# ---- Rhino -------------------------------------------------------------------------------------------
def rhino_surface(rhino3dm, weights):
    nu, nv = 4, 3
    s = rhino3dm.NurbsSurface.Create(3, True, 3, 3, nu, nv)  # degree 2 x 2
    for i, k in enumerate([0, 0, 0.3, 1, 1]):
        s.KnotsU[i] = k
    for i, k in enumerate([0, 0, 2, 2]):
        s.KnotsV[i] = k
    P = RNG.normal(size=(nu, nv, 3))
    for i in range(nu):
        for j in range(nv):
            w = weights[i, j]
            s.Points[i, j] = rhino3dm.Point4d(*(w * P[i, j]), w)
    return s


def test_3dm_surfaces_breps_trims_names_skipped(tmp_path):
    import rhino3dm

    f3 = rhino3dm.File3dm()

    def add(geometry, name=None, how="AddBrep"):
        attr = rhino3dm.ObjectAttributes()
        if name:
            attr.Name = name
        return getattr(f3.Objects, how)(geometry, attr)

    bump = rhino_surface(rhino3dm, RNG.uniform(0.5, 2.0, (4, 3)))
    add(bump, "bump", "AddSurface")
    disc = rhino3dm.Brep.CreateTrimmedPlane(rhino3dm.Plane.WorldXY(),
                                            rhino3dm.Circle(rhino3dm.Point3d(0.5, 0.5, 0), 0.25).ToNurbsCurve())
    add(disc, "disc")
    box = rhino3dm.Brep.CreateFromBox(rhino3dm.Box(rhino3dm.BoundingBox(0, 0, 0, 1, 2, 3)))
    box_id = add(box)
    add(rhino3dm.Point(rhino3dm.Point3d(1, 2, 3)), "dot", "Add")
    f3.Objects.AddLine(rhino3dm.Point3d(0, 0, 0), rhino3dm.Point3d(1, 1, 1))
    f = tmp_path / "model.3dm"
    assert f3.Write(str(f), 8)
    with pytest.warns(UserWarning, match="skipped"):
        m = read_nurbs(f)
    assert len(m) == 1 + 1 + 6
    assert m.names[:2] == ("bump", "disc") and m.names[2] == f"{box_id} face 0"
    assert m.skipped == {"Point": 1, "LineCurve": 1}
    s = m.surfaces[0]
    u, v = params(s)
    close(s.evaluate(u, v), [[(q := bump.PointAt(a, b)).X, q.Y, q.Z] for a, b in zip(u, v)])
    assert m.trims[0] is None and all(t is None for t in m.trims[2:])  # box faces: untrimmed planes
    loops = m.trims[1]
    assert len(loops) == 1
    assert inside(loops, (0.5, 0.5)) and inside(loops, (0.7, 0.5)) and not inside(loops, (0.27, 0.27))
    close(loops[0][0].evaluate([loops[0][0].domain[0]]), [[0.75, 0.5]])  # the circle starts at angle 0
    face = disc.Faces[0]
    u, v = np.array([0.3, 0.5, 0.7]), np.array([0.6, 0.5, 0.35])
    close(m.surfaces[1].evaluate(u, v), [[(q := face.PointAt(a, b)).X, q.Y, q.Z] for a, b in zip(u, v)])


def uv_on_affine(surface, xyz):
    """Parameters of a point on a planar parallelogram patch (degree 1 x 1)."""
    (u0, u1), (v0, v1) = surface.domain
    P0 = surface.evaluate([u0], [v0])[0]
    A = np.stack([surface.evaluate([u1], [v0])[0] - P0, surface.evaluate([u0], [v1])[0] - P0], axis=1)
    d = np.linalg.lstsq(A, np.asarray(xyz, float) - P0, rcond=None)[0]
    return u0 + d[0] * (u1 - u0), v0 + d[1] * (v1 - v0)


def test_3dm_extrusion_capped_cylinder(tmp_path):
    import rhino3dm

    f3 = rhino3dm.File3dm()
    attr = rhino3dm.ObjectAttributes()
    attr.Name = "can"
    f3.Objects.AddExtrusion(rhino3dm.Extrusion.Create(
        rhino3dm.Circle(rhino3dm.Point3d(0, 0, 0), 1.5).ToNurbsCurve(), 2.0, True), attr)
    f = tmp_path / "can.3dm"
    f3.Write(str(f), 8)
    m = read_nurbs(f)
    assert m.names == ("can face 0", "can face 1", "can face 2") and m.skipped == {}
    side = m.surfaces[0]
    assert m.trims[0] is None
    p = side.evaluate(*params(side))
    close(np.hypot(p[:, 0], p[:, 1]), np.full(len(p), 1.5))
    for cap, loops in zip(m.surfaces[1:], m.trims[1:]):
        z = cap.control_points[0, 0, 2]
        assert inside(loops, uv_on_affine(cap, (0, 0, z))) and inside(loops, uv_on_affine(cap, (1.45, 0, z)))
        assert not inside(loops, uv_on_affine(cap, (1.1, 1.1, z)))


def test_3dm_zero_weight_names_file_and_object(tmp_path):
    import rhino3dm

    f3 = rhino3dm.File3dm()
    w = np.ones((4, 3))
    w[2, 1] = -0.5
    attr = rhino3dm.ObjectAttributes()
    attr.Name = "broken"
    f3.Objects.AddSurface(rhino_surface(rhino3dm, w), attr)
    f = tmp_path / "bad.3dm"
    f3.Write(str(f), 8)
    with pytest.raises(ValueError, match=r"bad.3dm: object 'broken': weights must be positive.*weights\[2, 1\] = -0.5"):
        read_nurbs(f)


# ---- OpenCASCADE: IGES and STEP -------------------------------------------------------------------------
def occ_shapes():
    """(compound, bspline surface, plate): a B-spline face, a 4 x 2 plate with a hole of radius 1/2 about
    (1, 1) (converted to NURBS), and a free line edge."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pln, gp_Pnt
    from OCP.TopoDS import TopoDS_Compound

    surf = occ_bspline_surface()
    face = BRepBuilderAPI_MakeFace(surf, 1e-9).Face()
    plate = BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.0, 4.0, 0.0, 2.0).Face()
    cyl = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1, 1, -1), gp_Dir(0, 0, 1)), 0.5, 2.0).Shape()
    holed = BRepBuilderAPI_NurbsConvert(BRepAlgoAPI_Cut(plate, cyl).Shape(), True).Shape()
    edge = BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 5), gp_Pnt(1, 0, 5)).Edge()
    comp = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(comp)
    for s in (face, holed, edge):
        builder.Add(comp, s)
    return comp, surf


def check_occ_model(m, surf, iges: bool):
    assert len(m) == 2
    s, plate = m.surfaces
    u, v = params(s)
    close(s.evaluate(u, v), [[(p := surf.Value(a, b)).X(), p.Y(), p.Z()] for a, b in zip(u, v)])
    assert s.degree == (3, 2) and s.shape == (5, 3) and s.rational
    (u0, u1), (v0, v1) = plate.domain
    loops = m.trims[1]
    assert len(loops) == 2  # the outer rectangle and the hole

    def uv_of(x, y):  # the plate's NURBS form is affine in (u, v): solve for the parameters of (x, y, 0)
        A = np.stack([plate.evaluate([u1], [v0])[0] - plate.evaluate([u0], [v0])[0],
                      plate.evaluate([u0], [v1])[0] - plate.evaluate([u0], [v0])[0]], axis=1)[:2]
        d = np.linalg.solve(A, np.array([x, y]) - plate.evaluate([u0], [v0])[0][:2])
        return u0 + d[0] * (u1 - u0), v0 + d[1] * (v1 - v0)

    for (x, y), kept in [((1.0, 1.0), False), ((1.3, 1.2), False), ((3.0, 1.0), True), ((1.0, 1.6), True),
                         ((0.1, 0.1), True)]:
        assert inside(loops, uv_of(x, y)) == kept, (x, y)
    close(plate.evaluate(*np.array([uv_of(3.0, 0.5)]).T), [[3.0, 0.5, 0.0]])
    if iges:
        assert m.names[0] != m.names[1] and all("#" in n for n in m.names)
    else:
        assert m.names == ("face 0", "face 1")


@pytest.mark.parametrize("backend", ["ocp", "pyiges"])
def test_iges_bspline_and_trimmed_faces(tmp_path, backend):
    from OCP.IGESControl import IGESControl_Writer

    from splinevis.io.nurbs_step import _quiet_occ

    _quiet_occ()
    comp, surf = occ_shapes()
    f = tmp_path / "parts.igs"
    w = IGESControl_Writer("MM", 0)
    assert w.AddShape(comp)
    w.ComputeModel()
    assert w.Write(str(f))
    with pytest.warns(UserWarning, match="skipped unsupported entities"):
        m = read_iges(f, backend=backend)
    check_occ_model(m, surf, iges=True)
    assert m.skipped == {"110 (line)": 1}  # the free edge
    assert m.names == read_quiet(f, backend="pyiges" if backend == "ocp" else "ocp").names


def test_step_bspline_and_trimmed_faces(tmp_path):
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    comp, surf = occ_shapes()
    f = tmp_path / "parts.step"
    w = STEPControl_Writer()
    w.Transfer(comp, STEPControl_AsIs)
    w.Write(str(f))
    m = read_nurbs(f)
    check_occ_model(m, surf, iges=False)
    assert m.skipped == {}


def test_step_converts_analytic_faces_to_nurbs(tmp_path):
    """Planes and a cylinder as CAD files hold them: converted exactly by OpenCASCADE, trims with them."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    f = tmp_path / "box.stp"
    w = STEPControl_Writer()
    hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0.5, 0.5, -1), gp_Dir(0, 0, 1)), 0.25, 3.0).Shape()
    w.Transfer(BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape(), hole).Shape(), STEPControl_AsIs)
    w.Write(str(f))
    m = read_nurbs(f)
    assert len(m) == 7 and m.skipped == {}
    assert "7 analytic faces converted to NURBS by OpenCASCADE (1 x Geom_CylindricalSurface, 6 x Geom_Plane)" in m.source
    assert m.bounds() == pytest.approx((0.0, 1.0, 0.0, 1.0, 0.0, 1.0), abs=1e-12)
    cyl = next(s for s in m.surfaces if s.degree != (1, 1))
    (u0, u1), (v0, v1) = cyl.domain
    g = np.linspace(0.0, 1.0, 9)
    P = cyl.evaluate(u0 + g * (u1 - u0), v0 + g * (v1 - v0))
    assert np.abs(np.hypot(P[:, 0] - 0.5, P[:, 1] - 0.5) - 0.25).max() < 1e-12  # the exact circle: rational
    assert sum(len(loops) for loops in m.trims if loops) == 9  # 7 outer wires, the top and bottom holes


def test_step_without_ocp_says_what_to_install(tmp_path, monkeypatch):
    f = tmp_path / "part.step"
    f.write_text("ISO-10303-21;\n")
    monkeypatch.setitem(sys.modules, "OCP.STEPControl", None)
    with pytest.raises(ImportError, match="pip install cadquery-ocp-novtk"):
        read_nurbs(f)


def test_iges_falls_back_to_pyiges_without_ocp(tmp_path, monkeypatch):
    from OCP.IGESControl import IGESControl_Writer

    comp, surf = occ_shapes()
    f = tmp_path / "parts.iges"
    w = IGESControl_Writer("MM", 0)
    w.AddShape(comp)
    w.ComputeModel()
    w.Write(str(f))
    monkeypatch.setitem(sys.modules, "OCP.STEPControl", None)
    m = read_quiet(f)
    assert "IGES (pyiges)" in m.source
    check_occ_model(m, surf, iges=True)
    # the plate's outer boundary given as the domain boundary (N1 = 0): the reader adds the rectangle
    text = f.read_text()
    line = next(t for t in text.splitlines() if t.startswith("144,") and t.split(",")[2] == "1")
    pts, n2, pti = line.split(",")[1], line.split(",")[3], line.split(",")[5].split(";")[0]
    new = f"144,{pts},0,{n2},0,{pti};"
    old = line.split(";")[0] + ";"
    f.write_text(text.replace(line, new.ljust(len(old)) + line[len(old):]))
    m = read_quiet(f)
    assert len(m.trims[1]) == 2 and len(m.trims[1][0]) == 1 and m.trims[1][0][0].degree == 1
    check_occ_model(m, surf, iges=True)


# ---- dispatch ----------------------------------------------------------------------------------------
def test_dispatch_errors(tmp_path):
    assert set(NURBS_EXTENSIONS) >= {".3dm", ".igs", ".iges", ".stp", ".step", ".g2", ".json", ".bpt"}
    with pytest.raises(ValueError, match=r"model.obj: extension '.obj' is not supported"):
        read_nurbs(tmp_path / "model.obj")
    with pytest.raises(FileNotFoundError, match="NURBS file not found"):
        read_nurbs(tmp_path / "none.3dm")
    with pytest.raises(TypeError, match="file name"):
        read_nurbs(42)
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    with pytest.raises(ValueError, match="bad.json: not valid JSON"):
        read_nurbs(bad)


def test_step_reversed_faces_are_flipped_so_every_box_normal_points_out(tmp_path):
    # a box's faces come half REVERSED in OpenCASCADE: read back, each face's S_u x S_v must point away from
    # the box centre (known answer), which needs the reversed ones mirrored in v (trims with them)
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    box = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(2.0, 1.0, 1.0).Shape(), True).Shape()
    writer = STEPControl_Writer()
    writer.Transfer(box, STEPControl_AsIs)
    path = tmp_path / "box.stp"
    writer.Write(str(path))
    model = read_nurbs(path)
    assert len(model) == 6
    centre = np.array([1.0, 0.5, 0.5])
    for s, loops in zip(model.surfaces, model.trims):
        (u0, u1), (v0, v1) = s.domain
        u, v = np.array([(u0 + u1) / 2]), np.array([(v0 + v1) / 3])
        n, p = s.normal(u, v)[0], s.evaluate(u, v)[0]
        assert np.dot(n, p - centre) > 0, s.name
        from splinevis.nurbs.trim import inside, trim_pieces

        assert inside(trim_pieces([loops]), 0, u, v).all()  # the mirrored loops still hold the face's inside


def test_3dm_face_orientation_is_kept(tmp_path):
    # a Rhino box's faces point out; Brep.Flip() marks every face reversed (the outside is now inside):
    # read back, S_u x S_v follows the face, not the underlying surface
    import rhino3dm

    for flip, sign in ((False, 1.0), (True, -1.0)):
        box = rhino3dm.Brep.CreateFromBox(rhino3dm.Box(rhino3dm.BoundingBox(0, 0, 0, 2, 1, 1)))
        if flip:
            box.Flip()
            assert all(f.OrientationIsReversed for f in box.Faces)
        f = rhino3dm.File3dm()
        f.Objects.AddBrep(box)
        path = tmp_path / f"box{int(flip)}.3dm"
        f.Write(str(path), 7)
        model = read_nurbs(path)
        assert len(model) == 6
        for s in model.surfaces:
            (u0, u1), (v0, v1) = s.domain
            u, v = np.array([(u0 + u1) / 2]), np.array([(v0 + v1) / 3])
            assert sign * np.dot(s.normal(u, v)[0], s.evaluate(u, v)[0] - [1.0, 0.5, 0.5]) > 0, (flip, s.name)

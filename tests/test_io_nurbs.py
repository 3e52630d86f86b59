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
        m = read_nurbs(f, orient=False)  # the reader against splipy: the faces as written
    assert m.names == ("surface 0", "surface 1")
    assert m.skipped == {"100 (spline curve)": 1, "700 (spline volume)": 1}
    assert "skipped 1 x 100 (spline curve)" in m.source
    for s, ref in zip(m.surfaces, [sphere, bumpy]):
        u, v = params(s)
        close(s.evaluate(u, v), np.array([ref(a, b) for a, b in zip(u, v)]).reshape(-1, 3))
    circle = "130 1 0 0\n3\n1.5\n0 0 0\n0 0 1\n1 0 0\n0 6.283185307179586\n0\n"
    f.write_text(circle + f.read_text())  # an elementary curve first: skipped through splipy's parser
    with pytest.warns(UserWarning):
        m = read_nurbs(f, orient=False)  # the reader against splipy: the faces as written
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
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the point and the line are drawn beside the surfaces, not skipped
        m = read_nurbs(f)
    assert len(m) == 1 + 1 + 6
    assert m.names[:2] == ("bump", "disc") and m.names[2] == f"{box_id} face 0"
    assert m.skipped == {}
    sketch = sorted((T.shape[1], len(P)) for _, P, T in m.companion_meshes())
    assert sketch == [(1, 1), (2, 65)]  # the point; the line sampled at 64 segments
    assert [P.tolist() for _, P, T in m.companion_meshes() if T.shape[1] == 1] == [[[1.0, 2.0, 3.0]]]
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


def high_degree_surface(p: int, q: int):
    """A rational Bezier patch of degree (p, q) over [0, 2] x [-1, 1] (OCP), a bumpy dome."""
    from OCP.collections import Array1_double, Array1_int, Array2_double, Array2_gp_Pnt
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt

    poles, weights = Array2_gp_Pnt(1, p + 1, 1, q + 1), Array2_double(1, p + 1, 1, q + 1)
    for i in range(p + 1):
        for j in range(q + 1):
            x, y = 2.0 * i / p, 2.0 * j / q - 1.0
            poles.SetValue(i + 1, j + 1, gp_Pnt(x, y, 0.6 - 0.3 * (x - 1.0) ** 2 - 0.3 * y ** 2 + 0.05 * ((i + j) % 3)))
            weights.SetValue(i + 1, j + 1, 1.0 + 0.125 * ((i * j) % 3))
    uk, um, vk, vm = Array1_double(1, 2), Array1_int(1, 2), Array1_double(1, 2), Array1_int(1, 2)
    for arr, mult, deg, (a, b) in ((uk, um, p, (0.0, 2.0)), (vk, vm, q, (-1.0, 1.0))):
        arr.SetValue(1, a)
        arr.SetValue(2, b)
        mult.SetValue(1, deg + 1)
        mult.SetValue(2, deg + 1)
    return Geom_BSplineSurface(poles, weights, uk, vk, um, vm, p, q)


def test_step_faces_of_degree_above_7_are_read(tmp_path):
    """STEP from automotive CAD carries degrees 8 and more (ec_turbine-A.stp: up to 11); OpenCASCADE allows 25."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    from splinevis.nurbs.basis import MAX_DEGREE
    from splinevis.nurbs.exact import torus
    from splinevis.nurbs.program import nurbs_program

    assert MAX_DEGREE == 25
    for p, q in ((9, 8), (25, 2)):
        surf = high_degree_surface(p, q)
        w = STEPControl_Writer()
        w.Transfer(BRepBuilderAPI_MakeFace(surf, 1e-9).Face(), STEPControl_AsIs)
        f = tmp_path / f"deg{p}.step"
        w.Write(str(f))
        m = read_nurbs(f)
        s = m.surfaces[0]
        assert s.degree == (p, q) and s.rational
        u, v = params(s)
        close(s.evaluate(u, v), [[(x := surf.Value(a, b)).X(), x.Y(), x.Z()] for a, b in zip(u, v)])
        # the GPU program sizes its basis arrays by the model's degree, only above the default 7
        assert nurbs_program(m, subdivisions=1).defines["SV_NURBS_MAX_DEGREE"] == p
    assert "SV_NURBS_MAX_DEGREE" not in nurbs_program(torus(), subdivisions=1).defines


@pytest.mark.gl
def test_a_degree_9_face_is_drawn_with_the_twins_silhouette():
    import splinevis
    from splinevis.gl.camera import pixel_rays
    from splinevis.nurbs.model import NurbsModel
    from splinevis.nurbs.program import PROGRAM
    from splinevis.nurbs.surface import NurbsSurface

    from splinevis.io.nurbs_step import bspline_surface

    s = bspline_surface(high_degree_surface(9, 8), "deg9")
    assert isinstance(s, NurbsSurface) and s.degree == (9, 8)
    model = NurbsModel([s])
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = pl.add_spline(model, lights=1, color="tan")
    pl.camera_position = [(1.0, -3.5, 3.0), (1.0, 0.0, 0.4), (0, 0, 1)]
    pl.reset_camera_clipping_range()
    img = pl.screenshot()
    depth, matrix = pl.depth_buffer(), pl.camera_matrix()
    pl.close()
    assert "#define SV_NURBS_MAX_DEGREE 9" in actor.program_sources["fragment"]
    gpu_hit = depth < 1.0
    o, d = pixel_rays(matrix, *img.shape[1::-1])
    ref_hit = PROGRAM.raycast(model, o, d).hit
    assert gpu_hit.mean() > 0.2 and img[gpu_hit].std() > 5
    assert (gpu_hit != ref_hit).sum() <= 0.001 * gpu_hit.size


def test_iges_brep_solid_186_faces_and_their_trims(tmp_path):
    """A B-rep solid (186 -> 514 -> 510 faces with 508 loops, no 144), as CAD writes solids: every face is read,
    and the trims are the face's (the two faces z = 0 and z = 1 keep the hole of radius 1/4 about (1, 1/2))."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.IGESControl import IGESControl_Writer

    from splinevis.io.nurbs_iges import check_iges
    from splinevis.io.nurbs_step import _quiet_occ
    from splinevis.nurbs.trim import inside, trim_pieces

    _quiet_occ()
    box = BRepPrimAPI_MakeBox(2.0, 1.0, 1.0).Shape()
    cyl = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1, 0.5, -1), gp_Dir(0, 0, 1)), 0.25, 3.0).Shape()
    solid = BRepBuilderAPI_NurbsConvert(BRepAlgoAPI_Cut(box, cyl).Shape(), True).Shape()
    f = tmp_path / "solid.igs"
    w = IGESControl_Writer("MM", 1)  # B-rep mode: 186 / 514 / 510
    assert w.AddShape(solid)
    w.ComputeModel()
    assert w.Write(str(f))
    types = [int(line[:8]) for line in f.read_text().splitlines()[::1] if line[72:73] == "D"][::2]
    assert 186 in types and 510 in types and 144 not in types
    m = read_quiet(f)
    assert len(m) == 7 == check_iges(f)[0].expected  # 6 box faces and the hole's wall
    assert all(n.startswith("186 #") for n in m.names)
    pieces = trim_pieces(m.trims)
    holed = 0
    for k, s in enumerate(m.surfaces):
        (u0, u1), (v0, v1) = s.domain
        u, v = (g.ravel() for g in np.meshgrid(np.linspace(u0, u1, 41)[1:-1], np.linspace(v0, v1, 41)[1:-1]))
        p = s.evaluate(u, v)
        kept = inside(pieces, k, u, v)
        if np.ptp(p[:, 2]) < 1e-12 and abs(p[0, 2] - 0.5) == 0.5:  # a face z = 0 or z = 1: the hole cut out
            r = np.hypot(p[:, 0] - 1.0, p[:, 1] - 0.5)
            clear = np.abs(r - 0.25) > 0.02  # away from the circle (the loops are exact there, the grid is not)
            assert np.array_equal(kept[clear], r[clear] > 0.25), s.name
            holed += 1
        else:
            assert kept.all(), s.name
    assert holed == 2


def iges_text(entities) -> str:
    """A fixed-format IGES file of ``entities`` ``(type, parameters, form, subordinate)`` (directory entry 2k + 1
    for entity k; parameters as written, pointers as ``"#k"`` for entity k)."""
    glob = "1H,,1H;,4Htest,8Htest.igs,4Htest,4Htest,32,38,6,308,15,4Htest,1.,2,2HMM,1,1.,15H20260101.000000,1E-06,10.,4Htest,4Htest,11,0,15H20260101.000000;"
    g = [glob[i:i + 72] for i in range(0, len(glob), 72)]
    d, p = [], []
    for k, (t, prm, form, sub) in enumerate(entities):
        text = ",".join(str(2 * int(x[1:]) + 1) if isinstance(x, str) and x.startswith("#") else repr(float(x))
                        if isinstance(x, float) else str(x) for x in [t, *prm]) + ";"
        chunks = [text[i:i + 64] for i in range(0, len(text), 64)]
        de = 2 * k + 1
        d.append(f"{t:8d}{len(p) + 1:8d}{0:8d}{0:8d}{0:8d}{0:8d}{0:8d}{0:8d}00{sub:02d}0000")
        d.append(f"{t:8d}{0:8d}{0:8d}{len(chunks):8d}{form:8d}{'':8}{'':8}{'':8}{0:8d}")
        p += [f"{c:64}{de:8d}" for c in chunks]
    lines = [f"{'test':72}S{1:7d}"] + [f"{x:72}G{i:7d}" for i, x in enumerate(g, 1)]
    lines += [f"{x:72}D{i:7d}" for i, x in enumerate(d, 1)] + [f"{x:72}P{i:7d}" for i, x in enumerate(p, 1)]
    lines.append(f"S{1:7d}G{len(g):7d}D{len(d):7d}P{len(p):7d}".ljust(72) + f"T{1:7d}")
    return "\n".join(lines) + "\n"


def test_iges_bounded_surface_143(tmp_path):
    """A 143 bounded surface (a 141 boundary of model-space 126 curves, each with its parameter-space 126) on a
    bilinear 128 square [0, 2]^2: the triangle (0, 0), (2, 0), (0, 2) is what is read."""
    from splinevis.io.nurbs_iges import check_iges
    from splinevis.nurbs.trim import inside, trim_pieces

    corners = [(0.0, 0.0), (2.0, 0.0), (0.0, 2.0)]
    square = (1, 1, 1, 1, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 1, *[1.0] * 4,  # K1 K2 M1 M2, PROP1-5, knots, weights
              0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 2.0, 2.0, 0.0, 0.0, 1.0, 0.0, 1.0)
    entities = [(128, square, 0, 1)]
    for i, (a, b) in enumerate(zip(corners, corners[1:] + corners[:1])):
        for z in (0.0, 0.0):  # the model-space curve, then the parameter-space one (the square is x = u, y = v)
            entities.append((126, (1, 1, 1, 0, 1, 0, 0, 0, 1, 1, 1.0, 1.0, *a, z, *b, z, 0, 1, 0, 0, 1), 0, 1))
    n = len(corners)
    boundary = (1, 1, "#0", n, *[x for i in range(n) for x in (f"#{1 + 2 * i}", 1, 1, f"#{2 + 2 * i}")])
    entities.append((141, boundary, 0, 1))
    entities.append((143, (1, "#0", 1, f"#{len(entities) - 1}"), 0, 0))
    f = tmp_path / "bounded.igs"
    f.write_text(iges_text(entities))
    assert not check_iges(f)[0] and check_iges(f)[0].expected == 1
    m = read_quiet(f, backend="ocp")
    assert len(m) == 1 and m.names == (f"143 #{2 * len(entities) - 1}",) and m.trims[0] is not None
    s = m.surfaces[0]
    u, v = params(s, 400)
    close(s.evaluate(u, v), np.column_stack([u, v, 0 * u]) * (2.0 / np.array([*np.ptp(s.domain, axis=1), 1.0])))
    kept = inside(trim_pieces(m.trims), 0, u, v)
    (u0, u1), (v0, v1) = s.domain
    x, y = 2 * (u - u0) / (u1 - u0), 2 * (v - v0) / (v1 - v0)
    clear = np.abs(x + y - 2.0) > 1e-9
    assert np.array_equal(kept[clear], (x + y < 2.0)[clear])

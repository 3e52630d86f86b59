"""The NURBS family's judge for ``splinevis check`` (:class:`~splinevis.check.judge.FamilyJudge`): does every face
of a CAD file reach the picture, and how close is the mesh it is compared with to the exact surfaces?

What it does with a file
------------------------
* **Faces in the file**, counted by a second reader, before and independently of ours
  (:func:`splinevis.io.read_nurbs`): for ``.3dm`` rhino3dm's objects (each Brep face; each face of an Extrusion
  as Rhino converts it, ``Extrusion.ToBrep``; each Surface object one face; SubD and Mesh objects are counted
  apart as *not NURBS*); for STEP and IGES OpenCASCADE's own transfer of the whole file
  (``STEPControl_Reader`` / ``IGESControl_Reader``, ``TransferRoots``) and its ``TopAbs_FACE`` explorer. A file
  of bare surfaces without topology (STEP ``B_SPLINE_SURFACE_WITH_KNOTS`` without ``ADVANCED_FACE``) comes out
  of that transfer as one face per surface, so it is counted the same way. ``.bpt`` files state their patch
  count in their first line; other text formats are not counted (a WARN says so).
* **Faces drawn**: the patches of the model our reader built, all of which ``Plotter.add_nurbs`` draws per
  fragment [Kanai2007]. Fewer faces drawn than the file holds is a FAIL naming the lost faces (for 3DM by the
  reader's naming rule, ``"<object name or id> face <k>"``; otherwise by the reader's own account of what it
  skipped, ``NurbsModel.skipped``).
* **Baseline**: what CAD users look at, a triangle mesh from OpenCASCADE's ``BRepMesh_IncrementalMesh`` at a
  linear deflection ``delta = DEFLECTION`` x the diagonal of the faces' bounding box (world frame, the same
  coordinates the model has). For STEP and IGES the mesh is of the file's own shape, so it does not depend on
  our reader at all. rhino3dm cannot mesh, so for 3DM the faces *as our reader built them* (the surface and its
  trim loops, each a ``Geom_BSplineSurface`` face bounded by its loops' curves on the surface) are meshed: the
  baseline then checks our drawing of the model, not our reading of the trims. (The error-bounded levels of
  detail, :func:`splinevis.nurbs.lod.levels.build_lod`, would be our own alternative; on these files they take
  up to 15 s and refuse some trimmed faces, past the check's time budget.)
* **Tessellation deviation**: the largest distance between the baseline and the exact surfaces, sampled at
  every triangle's centroid and edge midpoints: the distance to the surface point at the interpolated ``(u, v)``
  [PieglTiller1997, eq. (4.15)] (an upper bound of the distance to the surface), replaced by the distance of the
  point's projection onto the surface where that bound exceeds ``delta``. In units of the diagonal beside the
  ``delta`` asked for: above ``WARN_FACTOR * delta`` the baseline is coarser than asked (its outline can differ
  from the exact one by more than the pixels the silhouette measures forgive), above ``FAIL_FACTOR * delta``
  (an order of magnitude) it misrepresents the surface, usually a face the mesher could not cope with.

``options``: ``deflection`` (relative to the diagonal, default :data:`DEFLECTION`).
"""

from __future__ import annotations

import collections
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..check.judge import FamilyJudge, Finding
from .model import NurbsModel

__all__ = ["JUDGE", "occ_outward"]

#: Linear deflection of the baseline mesh, relative to the diagonal of the faces' bounding box. At the check's
#: close-up (a 300-pixel-high window, zoom 3, pyvista's 30 degree view of the bounding sphere) one pixel is about
#: 1.15e-3 of the diagonal, so the baseline is within about a pixel there.
DEFLECTION = 1e-3
#: Angular deflection (radians) of OpenCASCADE's mesher; the linear deflection is the binding one.
ANGULAR_DEFLECTION = 0.5
#: A measured deviation above ``WARN_FACTOR * delta`` is a WARN, above ``FAIL_FACTOR * delta`` a FAIL.
WARN_FACTOR = 2.0
FAIL_FACTOR = 10.0
#: Sample points of the deviation (4 per triangle) are thinned to at most this many, and at most
#: ``MAX_PROJECTIONS`` of them (the largest parametric distances) are projected onto their surface.
MAX_SAMPLES = 400_000
MAX_PROJECTIONS = 400
#: Names listed in a finding.
MAX_LISTED = 6

_STEP = (".stp", ".step")
_IGES = (".igs", ".iges")
_NOT_NURBS = ("SubD", "Mesh")


@dataclass
class NurbsFile:
    """What :func:`_read` hands on: the model, the faces counted in the file and by what.

    ``face_names``: the faces' names by the reader's naming rule where the counter can give them (3DM), else
    None; ``not_nurbs``: object kind -> count of surfaces that are not NURBS (SubD, Mesh); ``shape``: the
    OpenCASCADE shape of the whole file (STEP, IGES) for the baseline; ``baseline_faces``: filled by the baseline,
    the OpenCASCADE faces it meshed (for the deviation).
    """

    model: NurbsModel
    faces_in_file: int | None
    counted_by: str
    not_nurbs: dict = field(default_factory=dict)
    face_names: list | None = None
    other_kinds: tuple = ()
    shape: object = None
    baseline_faces: list = field(default_factory=list)


# ----------------------------------------------------------------------------------------------- counting
def _quiet_occ() -> None:
    from OCP.Message import Message, Message_Gravity

    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)


def _occ_faces(shape) -> list:
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    faces = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        faces.append(TopoDS.Face(explorer.Current()))
        explorer.Next()
    return faces


def _count_occ(path: Path) -> dict | None:
    """Faces of OpenCASCADE's transfer of the whole file (STEP or IGES); None if it cannot read the file."""
    from OCP.IFSelect import IFSelect_RetDone

    if path.suffix.lower() in _STEP:
        from OCP.STEPControl import STEPControl_Reader as Reader
        tool = "OpenCASCADE STEPControl_Reader"
    else:
        from OCP.IGESControl import IGESControl_Reader as Reader
        tool = "OpenCASCADE IGESControl_Reader"
    _quiet_occ()
    reader = Reader()
    if reader.ReadFile(str(path)) != IFSelect_RetDone:
        return None
    reader.TransferRoots()
    shape = reader.OneShape()
    return {"faces": len(_occ_faces(shape)), "tool": tool, "shape": shape}


def _count_3dm(path: Path) -> dict | None:
    """Faces of the objects rhino3dm reads (module docstring), and their names by the reader's rule."""
    import rhino3dm

    f3 = rhino3dm.File3dm.Read(str(path))
    if f3 is None:
        return None
    names, not_nurbs, other = [], collections.Counter(), collections.Counter()
    for obj in f3.Objects:
        g = obj.Geometry
        kind = type(g).__name__
        name = obj.Attributes.Name or str(obj.Attributes.Id)
        if isinstance(g, rhino3dm.Extrusion):
            brep = g.ToBrep(False)
            n = len(brep.Faces) if brep is not None else 1
        elif isinstance(g, rhino3dm.Brep):
            n = len(g.Faces)
        elif isinstance(g, rhino3dm.Surface):
            names.append(name)
            continue
        else:
            (not_nurbs if kind in _NOT_NURBS else other)[kind] += 1
            continue
        names += [name] if n == 1 else [f"{name} face {k}" for k in range(n)]
    return {"faces": len(names), "tool": f"rhino3dm {getattr(rhino3dm, '__version__', '')}".strip(),
            "names": names, "not_nurbs": dict(not_nurbs), "other": tuple(other)}


def _count_bpt(path: Path) -> dict | None:
    """The patch count a Bezier-patch (teapot format) file states in its first line."""
    try:
        first = path.read_text().split(None, 1)[0]
        return {"faces": int(first), "tool": "the file's patch count (first line)"}
    except (ValueError, IndexError, OSError, UnicodeDecodeError):
        return None


def count_faces(path) -> dict | None:
    """Faces in a file by a reader other than ours (module docstring): a dict with ``faces`` and ``tool`` (and
    ``names``, ``not_nurbs``, ``other``, ``shape`` where known), or None when the format has no second reader
    here or it cannot read the file.

    >>> count_faces("model.g2") is None
    True
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext == ".3dm":
        return _count_3dm(path)
    if ext in _STEP + _IGES:
        return _count_occ(path)
    if ext == ".bpt":
        return _count_bpt(path)
    return None


def _listing(counts: dict) -> str:
    return ", ".join(f"{n} {k}" for k, n in counts.items())


def _read(path, options, findings) -> NurbsFile:
    from ..io.nurbs_files import read_nurbs

    path = Path(path)
    counted = count_faces(path)
    if counted is not None and counted["faces"] == 0:
        extra = counted.get("not_nurbs") or {}
        why = (f"; it holds {_listing(extra)} object(s), which are not NURBS (convert them to NURBS in the CAD "
               "program, e.g. Rhino's ToNURBS)" if extra else "")
        findings.append(Finding("FAIL", f"no NURBS face in the file ({counted['tool']} counts 0 faces{why})"))
    model = read_nurbs(path)  # raises on files it cannot read or without any surface; warns about what it skips
    if counted is None:
        return NurbsFile(model, None, "not counted")
    return NurbsFile(model, counted["faces"], counted["tool"], counted.get("not_nurbs", {}), counted.get("names"),
                     counted.get("other", ()), counted.get("shape"))


def _build(data: NurbsFile, options, findings) -> NurbsModel:
    return data.model


def _add(plotter, model, options):
    return plotter.add_nurbs(model)


# ----------------------------------------------------------------------------------------------- baseline
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


def _baseline(data: NurbsFile, model, options, findings):
    """OpenCASCADE's mesh of the file's faces (module docstring) as a pyvista PolyData in world coordinates; point
    data ``uv`` (each node's surface parameters), cell data ``face_id``; field data ``deflection`` and
    ``diagonal``."""
    import pyvista as pv
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopAbs import TopAbs_REVERSED
    from OCP.TopLoc import TopLoc_Location

    _quiet_occ()
    shape = data.shape
    if shape is None:
        lo, hi = np.asarray(model.bounds()[0::2]), np.asarray(model.bounds()[1::2])
        shape, failed = _model_shape(model, 1e-7 * max(float(np.linalg.norm(hi - lo)), 1e-300))
        if failed:
            more = f", {len(failed) - MAX_LISTED} more" if len(failed) > MAX_LISTED else ""
            findings.append(Finding("WARN", f"baseline: OpenCASCADE could not build {len(failed)} face(s) from the "
                                            f"trims as read ({', '.join(failed[:MAX_LISTED])}{more}); the picture "
                                            "is compared without them"))
    diagonal = _diagonal(shape)
    if not diagonal > 0:
        raise ValueError("the faces have an empty or degenerate bounding box: nothing to mesh")
    relative = float(options.get("deflection", DEFLECTION))
    if not 0.0 < relative < 1.0:
        raise ValueError(f"option deflection must be a fraction of the diagonal in (0, 1), got {relative!r}.")
    delta = relative * diagonal
    # one thread: the check already runs files side by side, and OpenCASCADE's thread pool would outlive the mesh
    # in the process that called it (a pytest worker, a notebook)
    BRepMesh_IncrementalMesh(shape, delta, False, ANGULAR_DEFLECTION, False)
    pts, uvs, tris, ids, faces = [], [], [], [], []
    offset, unmeshed = 0, 0
    for face in _occ_faces(shape):
        loc = TopLoc_Location()
        tri = BRep_Tool.Triangulation_s(face, loc)
        if tri is None or tri.NbTriangles() == 0:
            unmeshed += 1
            continue
        trsf = loc.Transformation()
        M = np.array([[trsf.Value(r, c) for c in range(1, 5)] for r in range(1, 4)])  # the face's placement
        n = tri.NbNodes()
        P = np.array([tri.Node(i).Coord() for i in range(1, n + 1)]) @ M[:, :3].T + M[:, 3]
        has_uv = tri.HasUVNodes()
        UV = (np.array([tri.UVNode(i).Coord() for i in range(1, n + 1)]) if has_uv else np.zeros((n, 2)))
        T = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)], dtype=np.int64) - 1
        if face.Orientation() == TopAbs_REVERSED:
            T = T[:, ::-1]
        pts.append(P)
        uvs.append(UV)
        tris.append(T + offset)
        ids.append(np.full(len(T), len(faces)))
        faces.append((face, has_uv))
        offset += n
    if not tris:
        raise ValueError(f"OpenCASCADE meshed none of the {unmeshed} face(s)")
    if unmeshed:
        findings.append(Finding("WARN", f"baseline: OpenCASCADE did not mesh {unmeshed} face(s); the picture is "
                                        "compared without them"))
    data.baseline_faces = faces
    mesh = pv.PolyData(np.concatenate(pts), faces=pv.CellArray.from_regular_cells(np.concatenate(tris)))
    mesh.point_data["uv"] = np.concatenate(uvs)
    mesh.cell_data["face_id"] = np.concatenate(ids)
    mesh.field_data["deflection"] = np.array([delta])
    mesh.field_data["diagonal"] = np.array([diagonal])
    return mesh


# ----------------------------------------------------------------------------------------------- accuracy
def baseline_deviation(baseline, faces, delta: float) -> tuple:
    """Largest distance between the baseline's triangles and their exact surfaces, sampled at centroids and edge
    midpoints (module docstring); ``(deviation, samples)``.

    ``faces``: per ``face_id``, ``(TopoDS_Face, has_uv)``; faces without (u, v) nodes are not sampled.
    """
    from OCP.BRep import BRep_Tool
    from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
    from OCP.gp import gp_Pnt

    tri = baseline.faces.reshape(-1, 4)[:, 1:]
    P, UV = np.asarray(baseline.points), np.asarray(baseline.point_data["uv"])
    fid = np.asarray(baseline.cell_data["face_id"])
    weights = np.array([[1 / 3, 1 / 3, 1 / 3], [0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])
    step = max(1, -(-4 * len(tri) // MAX_SAMPLES))
    sel = np.arange(0, len(tri), step)
    X = np.einsum("wk,tkc->twc", weights, P[tri[sel]]).reshape(-1, 3)
    W = np.einsum("wk,tkc->twc", weights, UV[tri[sel]]).reshape(-1, 2)
    F = np.repeat(fid[sel], len(weights))
    dist = np.zeros(len(X))
    surfaces = {}
    for k in np.unique(F):
        face, has_uv = faces[int(k)]
        if not has_uv:
            continue
        S = surfaces[int(k)] = BRep_Tool.Surface_s(face)  # with the face's location applied
        idx = np.flatnonzero(F == k)
        Y = np.array([S.Value(u, v).Coord() for u, v in W[idx].tolist()]).reshape(-1, 3)
        dist[idx] = np.linalg.norm(Y - X[idx], axis=1)
    worst = np.argsort(dist)[::-1][:MAX_PROJECTIONS]
    for j in worst[dist[worst] > delta]:  # the interpolated (u, v) overestimates: project onto the surface
        proj = GeomAPI_ProjectPointOnSurf(gp_Pnt(*map(float, X[j])), surfaces[int(F[j])])
        if proj.NbPoints() > 0:
            dist[j] = min(dist[j], float(proj.LowerDistance()))
    # beyond MAX_PROJECTIONS points above delta, the maximum may stay a parametric distance: an upper bound
    return float(dist.max(initial=0.0)), int(len(X))


def _which(data: NurbsFile, model: NurbsModel) -> str:
    """The faces lost between the file and the model, by name (3DM) or by the reader's account."""
    parts = []
    if data.face_names is not None:
        lost = collections.Counter(data.face_names) - collections.Counter(model.names)
        names = sorted(lost.elements())
        if names:
            more = f", {len(names) - MAX_LISTED} more" if len(names) > MAX_LISTED else ""
            parts.append(", ".join(repr(n) for n in names[:MAX_LISTED]) + more)
    skipped = {k: n for k, n in model.skipped.items() if k not in data.other_kinds and k not in data.not_nurbs}
    if skipped:
        parts.append("the reader skipped " + ", ".join(f"{n} x {k}" for k, n in skipped.items()))
    return "; ".join(parts) if parts else "the reader does not say which"


def _accuracy(path, data: NurbsFile, model, baseline, options, findings) -> dict:
    drawn, in_file = len(model), data.faces_in_file
    delta = float(baseline.field_data["deflection"][0])
    diagonal = float(baseline.field_data["diagonal"][0])
    deviation, samples = baseline_deviation(baseline, data.baseline_faces, delta)
    out = {"faces_in_file": in_file, "faces_drawn": drawn, "counted_by": data.counted_by,
           "not_nurbs_objects": int(sum(data.not_nurbs.values())),
           "deflection": delta / diagonal, "tessellation_deviation": deviation / diagonal,
           "deviation_samples": samples, "baseline_triangles": int(baseline.n_cells), "diagonal": diagonal}
    if in_file is None:
        findings.append(Finding("WARN", f"faces in the file not counted: no second reader for "
                                        f"'{Path(path).suffix}' files here ({drawn} faces drawn)"))
    elif drawn < in_file:
        findings.append(Finding("FAIL", f"{in_file - drawn} of the {in_file} faces in the file are not drawn "
                                        f"({drawn} drawn; counted by {data.counted_by}); lost: {_which(data, model)}"))
    elif drawn > in_file:
        findings.append(Finding("WARN", f"{drawn} faces drawn but the file holds {in_file} "
                                        f"(counted by {data.counted_by}): a face read twice, or split"))
    else:
        findings.append(Finding("PASS", f"all {in_file} faces in the file are drawn (counted by {data.counted_by})"))
    if data.not_nurbs and in_file:
        findings.append(Finding("WARN", f"the file also holds {_listing(data.not_nurbs)} object(s): not NURBS, not "
                                        "drawn"))
    ratio = deviation / delta
    what = (f"baseline tessellation deviates up to {deviation / diagonal:.2e} of the diagonal from the exact "
            f"surfaces ({ratio:.2f} x the deflection {delta / diagonal:.0e} asked for; {samples} samples)")
    if ratio > FAIL_FACTOR:
        findings.append(Finding("FAIL", what + f": over {FAIL_FACTOR:g} x, the baseline misrepresents a surface"))
    elif ratio > WARN_FACTOR:
        findings.append(Finding("WARN", what + f": over {WARN_FACTOR:g} x, the baseline is coarser than asked"))
    else:
        findings.append(Finding("PASS", what))
    return out


JUDGE = FamilyJudge(
    family="nurbs",
    baseline_name="OpenCASCADE mesh",
    read=_read, build=_build, baseline=_baseline, accuracy=_accuracy, add=_add,
    description="faces drawn against faces in the file (rhino3dm / OpenCASCADE), and OpenCASCADE's "
                "BRepMesh at 1e-3 of the diagonal as the baseline, its deviation from the exact surfaces measured")


# ------------------------------------------------------------------------- OpenCASCADE's orientation
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

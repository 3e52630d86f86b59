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
  ``delta`` asked for (OpenCASCADE checks the deflection inside each triangle, ``ControlSurfaceDeflection``): above
  ``WARN_FACTOR * delta`` the baseline is coarser than asked (its outline can differ
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
from ..io.nurbs_3dm import ANNOTATIONS
from .model import NurbsModel
from .occ_faces import _diagonal, _model_shape

__all__ = ["JUDGE"]

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
#: SubD patches whose corners lie farther than this share of the diagonal from Rhino's limit points: WARN
#: (the exact patches' corners are limit points to rounding; approximate ones keep their corners on them too).
SUBD_WARN = 1e-6


@dataclass
class NurbsFile:
    """What :func:`_read` hands on: the model, the faces counted in the file and by what.

    ``face_names``: the faces' names by the reader's naming rule where the counter can give them (3DM), else
    None; ``not_nurbs``: object kind -> count of surfaces that are not NURBS (SubD, Mesh); ``subd_names``,
    ``mesh_names``: the SubD objects (converted to bicubic patches by the reader) and the mesh, curve and point
    objects on visible layers (drawn beside the surfaces), by name; ``hidden``: kind -> count of objects on hidden
    layers; ``annotations``: kind -> count of text, hatches, dimensions (not drawn); ``shape``: the
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
    subd_names: tuple = ()
    mesh_names: tuple = ()
    hidden: dict = field(default_factory=dict)
    annotations: dict = field(default_factory=dict)


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
    subd, meshes, hidden, annotations = [], [], collections.Counter(), collections.Counter()
    hidden_layers = {layer.Index for layer in f3.Layers if not layer.Visible}
    for obj in f3.Objects:
        g = obj.Geometry
        kind = type(g).__name__
        name = obj.Attributes.Name or str(obj.Attributes.Id)
        if isinstance(g, rhino3dm.SubD):
            subd.append(name)
            not_nurbs[kind] += 1
            continue
        if kind in ANNOTATIONS:
            annotations[kind] += 1
            continue
        if isinstance(g, (rhino3dm.Mesh, rhino3dm.Curve, rhino3dm.Point, rhino3dm.PointCloud)):
            if obj.Attributes.Visible and obj.Attributes.LayerIndex not in hidden_layers:
                meshes.append(name)
            else:
                hidden[kind] += 1
            if isinstance(g, rhino3dm.Mesh):
                not_nurbs[kind] += 1
            continue
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
            "names": names, "not_nurbs": dict(not_nurbs), "other": tuple(other), "subd": tuple(subd),
            "meshes": tuple(meshes), "hidden": dict(hidden), "annotations": dict(annotations)}


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
    if counted is not None and counted["faces"] == 0 and not counted.get("subd"):
        extra = counted.get("not_nurbs") or {}
        why = (f"; it holds {_listing(extra)} object(s), which are not NURBS (convert them to NURBS in the CAD "
               "program, e.g. Rhino's ToNURBS)" if extra else "")
        findings.append(Finding("FAIL", f"no NURBS face in the file ({counted['tool']} counts 0 faces{why})"))
    model = read_nurbs(path)  # raises on files it cannot read or without any surface; warns about what it skips
    if counted is None:
        return NurbsFile(model, None, "not counted")
    return NurbsFile(model, counted["faces"], counted["tool"], counted.get("not_nurbs", {}), counted.get("names"),
                     counted.get("other", ()), counted.get("shape"), subd_names=counted.get("subd", ()),
                     mesh_names=counted.get("meshes", ()), hidden=counted.get("hidden", {}),
                     annotations=counted.get("annotations", {}))


def _build(data: NurbsFile, options, findings) -> NurbsModel:
    return data.model


def _add(plotter, model, options):
    return plotter.add_nurbs(model, **options.get("style", {}))


# ----------------------------------------------------------------------------------------------- baseline
def _baseline(data: NurbsFile, model, options, findings):
    """OpenCASCADE's mesh of the file's faces (module docstring) as a pyvista PolyData in world coordinates; point
    data ``uv`` (each node's surface parameters), cell data ``face_id``; field data ``deflection`` and
    ``diagonal``."""
    import pyvista as pv
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.IMeshTools import IMeshTools_Parameters
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
    # one thread (InParallel off): the check already runs files side by side, and OpenCASCADE's thread pool would
    # outlive the mesh in the process that called it (a pytest worker, a notebook). The surface deflection is
    # checked inside each triangle, never traded for speed: with the defaults, faces of dense knot vectors
    # (v5_ring) kept triangles 0.7 units off a surface meshed at 0.18
    params = IMeshTools_Parameters()
    params.Deflection = params.DeflectionInterior = delta
    params.Angle = params.AngleInterior = ANGULAR_DEFLECTION
    params.Relative, params.InParallel = False, False
    params.ControlSurfaceDeflection, params.AllowQualityDecrease = True, False
    params.InternalVerticesMode, params.AdjustMinSize = True, True
    BRepMesh_IncrementalMesh(shape, params)
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
    data.baseline_faces = faces
    cells = {2: [], 1: []}
    for _, P, T in (model.companion_meshes() if model is not None else ()):  # the file's mesh objects, drawn as they are in both pictures
        pts.append(P)
        uvs.append(np.zeros((len(P), 2)))
        if T.shape[1] == 3:
            tris.append(T + offset)
            ids.append(np.full(len(T), -1))  # no surface: not part of the deviation
        else:  # curves and points: beside the baseline as beside ours (not part of the deviation)
            cells[T.shape[1]].append(T + offset)
        offset += len(P)
    more = {key: pv.CellArray.from_regular_cells(np.concatenate(cells[k]))
            for k, key in ((2, "lines"), (1, "verts")) if cells[k]}
    mesh = pv.PolyData(np.concatenate(pts), faces=pv.CellArray.from_regular_cells(np.concatenate(tris)), **more)
    mesh.point_data["uv"] = np.concatenate(uvs)
    # VTK orders a PolyData's cells verts, lines, polygons: the curves' and points' cells first, no face
    mesh.cell_data["face_id"] = np.concatenate([np.full(mesh.n_verts + mesh.n_lines, -1)] + ids)
    mesh.field_data["deflection"] = np.array([delta])
    mesh.field_data["diagonal"] = np.array([diagonal])
    if unmeshed:
        findings.append(Finding("WARN", f"baseline: OpenCASCADE did not mesh {unmeshed} face(s); the picture is "
                                        "compared without them"))
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
    fid = np.asarray(baseline.cell_data["face_id"])[baseline.n_verts + baseline.n_lines:]  # the triangles' ids
    weights = np.array([[1 / 3, 1 / 3, 1 / 3], [0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])
    step = max(1, -(-4 * len(tri) // MAX_SAMPLES))
    sel = np.arange(0, len(tri), step)
    X = np.einsum("wk,tkc->twc", weights, P[tri[sel]]).reshape(-1, 3)
    W = np.einsum("wk,tkc->twc", weights, UV[tri[sel]]).reshape(-1, 2)
    F = np.repeat(fid[sel], len(weights))
    dist = np.zeros(len(X))
    surfaces = {}
    for k in np.unique(F[F >= 0]):  # face_id -1: a mesh object of the file, no surface to compare with
        face, has_uv = faces[int(k)]
        if not has_uv:
            continue
        S = surfaces[int(k)] = BRep_Tool.Surface_s(face)  # with the face's location applied
        idx = np.flatnonzero(F == k)
        Y = np.array([S.Value(u, v).Coord() for u, v in W[idx].tolist()]).reshape(-1, 3)
        dist[idx] = np.linalg.norm(Y - X[idx], axis=1)
    worst = np.argsort(dist)[::-1][:MAX_PROJECTIONS]
    worst = worst[F[worst] >= 0]
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


def _from_subd(names, subd_names) -> np.ndarray:
    """Which patch names come from a SubD object (``"<object> exact|approx <i>"``, :mod:`splinevis.io.subd`).

    >>> _from_subd(["a face 0", "logo exact 3", "logo approx 0"], ["logo"]).tolist()
    [False, True, True]
    """
    prefixes = tuple(f"{n} exact " for n in subd_names) + tuple(f"{n} approx " for n in subd_names)
    return np.array([bool(prefixes) and n.startswith(prefixes) for n in names], dtype=bool)


def _subd_findings(path, data: NurbsFile, model, diagonal, findings) -> dict:
    """SubD objects: each converted to patches, and the patches' corners against Rhino's own limit points of the
    control vertices (``SubDVertex.SurfacePoint``, openNURBS): a second reader of the same limit surface."""
    import rhino3dm
    from scipy.spatial import cKDTree

    from ..io.subd import _rhino_items  # the one walk over a rhino3dm SubD iterator

    names = np.array(model.names, dtype=object)
    mask = _from_subd(model.names, data.subd_names)
    missing = [n for n in data.subd_names if not any(str(m).startswith((f"{n} exact ", f"{n} approx "))
                                                     for m in names[mask])]
    if missing:
        findings.append(Finding("FAIL", f"{len(missing)} of the {len(data.subd_names)} SubD objects are not drawn: "
                                        + ", ".join(repr(n) for n in missing[:MAX_LISTED])))
    corners = []
    for k in np.flatnonzero(mask):
        s = model.surfaces[k]
        (u0, u1), (v0, v1) = s.domain
        corners.append(s.evaluate([u0, u1, u0, u1], [v0, v0, v1, v1]))
    deviation, limit_points = None, 0
    if corners:
        tree = cKDTree(np.concatenate(corners))
        f3 = rhino3dm.File3dm.Read(str(path))
        L = np.array([[p.X, p.Y, p.Z] for obj in f3.Objects if isinstance(obj.Geometry, rhino3dm.SubD)
                      for p in (v.SurfacePoint for v in _rhino_items(obj.Geometry.Vertices))]).reshape(-1, 3)
        if len(L):
            deviation, limit_points = float(tree.query(L)[0].max() / diagonal), len(L)
    if not missing:
        what = (f"all {len(data.subd_names)} SubD objects drawn as {int(mask.sum())} bicubic patches (Catmull-Clark "
                f"limit surface)")
        if deviation is not None:
            what += f"; Rhino's limit points of the {limit_points} control vertices lie within {deviation:.1e} of " \
                    "the diagonal of a patch corner"
        findings.append(Finding("WARN" if deviation is not None and deviation > SUBD_WARN else "PASS", what))
    return {"subd_objects": len(data.subd_names), "subd_patches": int(mask.sum()), "subd_limit_deviation": deviation}


def _accuracy(path, data: NurbsFile, model, baseline, options, findings) -> dict:
    subd = _from_subd(model.names, data.subd_names)
    drawn, in_file = int((~subd).sum()), data.faces_in_file
    delta = float(baseline.field_data["deflection"][0])
    diagonal = float(baseline.field_data["diagonal"][0])
    deviation, samples = baseline_deviation(baseline, data.baseline_faces, delta)
    out = {"faces_in_file": in_file, "faces_drawn": drawn, "counted_by": data.counted_by,
           "not_nurbs_objects": int(sum(data.not_nurbs.values())),
           "deflection": delta / diagonal, "tessellation_deviation": deviation / diagonal,
           "deviation_samples": samples, "baseline_triangles": int(baseline.GetNumberOfPolys()), "diagonal": diagonal}
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
    if data.subd_names:
        out.update(_subd_findings(path, data, model, diagonal, findings))
    if data.mesh_names:
        shown = len(model.companion_meshes())
        out["mesh_objects"] = len(data.mesh_names)
        findings.append(Finding("FAIL" if shown < len(data.mesh_names) else "PASS",
                                f"{shown} of the {len(data.mesh_names)} mesh, curve and point objects on visible "
                                "layers drawn beside the surfaces"))
    fit = (model.report or {}).get("trim_fit")
    if fit and fit["beyond_tolerance"]:
        worst = max(fit["faces"].values(), key=lambda f: f["deviation"])
        short = fit["short_of_edges"]
        findings.append(Finding("WARN" if short else "PASS",
                                f"{len(fit['beyond_tolerance'])} face(s) have edges beyond the file's tolerance "
                                f"{fit['tolerance']:.3g} from their surfaces (up to {worst['edge_distance']:.3g}, "
                                f"{worst['edge_distance'] / diagonal:.1e} of the diagonal); drawn with the best loop "
                                f"(deviation up to {worst['deviation']:.3g})"
                                + (f"; {len(short)} fit(s) farther from the edges than that allows" if short else "")))
    if data.annotations:
        findings.append(Finding("PASS", f"not drawn, annotations (drafting objects, not geometry): "
                                        f"{_listing(data.annotations)}"))
    if data.hidden:
        findings.append(Finding("PASS", f"not drawn, hidden in the file (layer or object off): {_listing(data.hidden)}"))
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

"""NURBS surfaces from Rhino ``.3dm`` files through ``rhino3dm`` (imported only when a file is read).

What is read
------------
* ``NurbsSurface`` objects, and other surfaces (``PlaneSurface``, ``RevSurface``, ``SumSurface``) in
  their NURBS form (``ToNurbsSurface``).
* ``Brep`` and ``Extrusion`` objects (the latter through ``ToBrep``): each face's underlying surface in NURBS form, one patch per face. An untrimmed face
  (its duplicate is a plain surface) gets no loops. rhino3dm does not expose the faces' 2-D trim curves,
  so they are rebuilt from the 3-D edges of each loop's trims, in loop order:

  - on **planar faces whose NURBS form is an affine parallelogram** (degree 1 x 1, 2 x 2 points), each
    edge's NURBS curve maps into ``(u, v)`` by the inverse affine map (exact: affine maps commute with
    rational B-splines);
  - on **any other surface** (curved, or a plane in rational form) all edges of the face are pulled back
    onto the surface in one batch (:func:`splinevis.nurbs.pullback.pull_back_many`: point inversion, a
    cubic fit refined until it maps within the tolerance of the edge), each run backwards where its trim
    is reversed. On a closed surface each curve is shifted by the period into the domain: a curve that
    fits the domain at one shift only (a full circle) is placed there, one that fits at several (a seam
    edge: at ``u0`` or ``u1``) next to its placed neighbours, so a loop closes whichever trim it starts
    with and a seam edge's two uses land on the two sides; a singular trim (no edge: a pole) becomes the
    segment joining its neighbours' ends. The tolerance is the file's model absolute tolerance
    (``Settings.ModelAbsoluteTolerance``), else ``1e-6`` of the model's bounding-box diagonal.
  - **Every face is drawn.** Edges of real files lie farther than the model tolerance from their
    surfaces (each Brep edge has its own tolerance, which rhino3dm does not expose; v4_MechPartA.3dm has
    edges 0.009 off at tolerance 0.001, running past the surface's side); such a face gets the best loop
    found (fitted within the tolerance plus the edge's measured distance); ``source`` and
    ``report["trim_fit"]`` give its deviation and the edges' distance (a warning only where the fit stays
    farther from the edges than their distance from the surface plus the tolerance: the reader's shortfall). The ``source`` lists each pulled-back face's
    measured deviation (max distance of the pulled-back curves, mapped through the surface, from the
    edges) and how far its edges are from the surface. Only an edge more than 100 tolerances from its
    surface (not the face's edge: a damaged Brep), or a loop that does not close, drops the face, with a
    warning saying what to do, counted as ``"trimmed Brep face whose trim loops cannot be rebuilt ..."``.

  Why not the exact 2-D trims: rhino3dm 8.35 does not expose them (``BrepTrim`` has only ``EdgeIndex``,
  ``IsReversed`` and vertex indices). ``Brep.Encode()`` holds them in its openNURBS archive, but they are
  in the parameters of the face's own surface (a ``RevSurface`` in angle, not in those of its NURBS form,
  ``GetNurbsFormParameterFromSurfaceParameter``), so they would still need a fit; the pull-back reaches
  the file's tolerance wherever its edges do.
* Names: the object's name (``Attributes.Name``), else its id (a UUID); faces of a Brep with several
  faces are ``"<name> face <k>"``.

Beside the surfaces (``NurbsModel.meshes``, drawn as they are): mesh objects, curves (sampled, as line
segments) and points and point clouds, when their object and layer are visible (hidden ones are named in
``source``). Annotations (:data:`ANNOTATIONS`: text, dimensions, hatches, leaders; drafting objects, not the
model's geometry) are counted in ``report["annotations"]`` and ``source``. Anything else is counted in
``skipped`` by its rhino3dm type, with a warning.
Rhino stores knot vectors without the two superfluous end knots and control points homogeneous
``(w x, w y, w z, w)``; both are converted here.
"""

from __future__ import annotations

import collections
import dataclasses
import itertools
import warnings
from pathlib import Path

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface, TrimCurve
from ..nurbs.pullback import _Inverter, curve_evaluator, pull_back_many, reverse_curve
from .nurbs_common import build_model, checked, flip_v

__all__ = ["read_3dm", "ANNOTATIONS"]

#: rhino3dm types of drafting objects (text, dimensions, hatch fills, leaders, text dots): not drawn.
ANNOTATIONS = frozenset({"Text", "TextDot", "Hatch", "Leader", "AnnotationBase", "Dimension", "LinearDimension",
                         "AngularDimension", "RadialDimension", "OrdinateDimension", "Centermark"})

_CURVED_TRIMMED = "trimmed Brep face whose trim loops cannot be rebuilt from its edges (see the warning)"
#: An edge farther than this many model tolerances from its face's surface (and farther than rounding,
#: ``_ROUNDING`` of the surface's size) is not the face's edge: an error.
_EDGE_SLACK = 100.0
_ROUNDING = 1e-10
#: Without a model tolerance in the file: this fraction of the model's size (Rhino's default 0.001 units
#: on a model of 1000 units).
_RELATIVE_TOLERANCE = 1e-6
_MAX_LISTED = 12  # faces listed by name in the source


def read_3dm(path) -> NurbsModel:
    """Read the NURBS surfaces and Brep faces of a Rhino file (see the module notes).

    Examples
    --------
    >>> import tempfile, rhino3dm
    >>> f3 = rhino3dm.File3dm()
    >>> attr = rhino3dm.ObjectAttributes(); attr.Name = "ball"
    >>> _ = f3.Objects.AddBrep(rhino3dm.Brep.CreateFromSphere(rhino3dm.Sphere(rhino3dm.Point3d(0, 0, 0), 2.0)), attr)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = str(Path(folder) / "ball.3dm")
    ...     _ = f3.Write(f, 8)
    ...     m = read_3dm(f)
    >>> m.names, m.trims, [round(v, 9) for v in m.bounds()]
    (('ball',), (None,), [-2.0, 2.0, -2.0, 2.0, -2.0, 2.0])
    """
    import rhino3dm

    path = Path(path)
    model = rhino3dm.File3dm.Read(str(path))
    if model is None:
        raise ValueError(f"{path}: rhino3dm could not read this file; is it a Rhino .3dm file (version <= 8)?")
    surfaces, trims, skipped, contents, pulled, stopped = [], [], {}, {}, [], []
    meshes, hidden, annotations = [], {}, {}
    hidden_layers = {layer.Index for layer in model.Layers if not layer.Visible}  # no layer table: all shown
    tol, told = _tolerance(model)
    for obj in model.Objects:
        g, attr = obj.Geometry, obj.Attributes
        kind = type(g).__name__
        contents[kind] = contents.get(kind, 0) + 1
        name = attr.Name or str(attr.Id)
        if isinstance(g, rhino3dm.Mesh):  # drawn as it is beside the surfaces, unless the file hides it
            if attr.Visible and attr.LayerIndex not in hidden_layers:
                meshes.append(_mesh(g, name))
            else:
                hidden[kind] = hidden.get(kind, 0) + 1
            continue
        if isinstance(g, (rhino3dm.Curve, rhino3dm.Point, rhino3dm.PointCloud)):  # drawn as lines and points
            if attr.Visible and attr.LayerIndex not in hidden_layers:
                meshes.append(_sketch(g, name, rhino3dm))
            else:
                hidden[kind] = hidden.get(kind, 0) + 1
            continue
        if kind in ANNOTATIONS:  # drafting objects, not geometry of the model
            annotations[kind] = annotations.get(kind, 0) + 1
            continue
        if isinstance(g, rhino3dm.SubD):  # the Catmull-Clark limit surface as bicubic patches
            from .subd import subd_object_surfaces

            subs = checked(path, f"object {name!r}", lambda: subd_object_surfaces(g, name))
            surfaces += subs
            trims += [None] * len(subs)
            continue
        if isinstance(g, rhino3dm.Extrusion):
            g = g.ToBrep(False)
        if isinstance(g, rhino3dm.Brep):
            faces = list(g.Faces)
            for k, face in enumerate(faces):
                fname = name if len(faces) == 1 else f"{name} face {k}"
                ns = face.UnderlyingSurface().ToNurbsSurface()
                surf = checked(path, f"object {fname!r}", lambda: _surface(ns, fname))
                if face.DuplicateFace(False).IsSurface:
                    loops = None
                else:
                    loops = _planar_loops(g, face, surf, path, fname)
                    if loops is None:
                        try:
                            loops, dev, dist, notes = _pulled_loops(g, face, surf, tol, fname)
                        except ValueError as err:
                            warnings.warn(f"{path}: object {fname!r} skipped: {err}", UserWarning, stacklevel=2)
                            skipped[_CURVED_TRIMMED] = skipped.get(_CURVED_TRIMMED, 0) + 1
                            continue
                        pulled.append((dev, dist, fname))
                        stopped += notes
                if face.OrientationIsReversed:  # the face's outside is the surface's back
                    surf, loops = flip_v(surf, loops)
                surfaces.append(surf)
                trims.append(loops)
        elif isinstance(g, rhino3dm.Surface):
            ns = g if isinstance(g, rhino3dm.NurbsSurface) else g.ToNurbsSurface()
            if ns is None:
                skipped[kind] = skipped.get(kind, 0) + 1
                continue
            surfaces.append(checked(path, f"object {name!r}", lambda: _surface(ns, name)))
            trims.append(None)
        else:
            skipped[kind] = skipped.get(kind, 0) + 1
    result = build_model(path, "Rhino 3DM (rhino3dm)", surfaces, trims, skipped, contents)
    drawn = collections.Counter({3: "mesh", 2: "curve", 1: "point"}[np.shape(c)[1]] for _, _, c in meshes)
    extra = "".join(["; drawn beside the surfaces: " + ", ".join(f"{n} {k} object(s)" for k, n in drawn.items())
                     if meshes else "",
                     "; not drawn, hidden in the file: " + ", ".join(f"{n} x {k}" for k, n in hidden.items())
                     if hidden else "",
                     "; annotations (not geometry) not drawn: " + ", ".join(f"{n} x {k}" for k, n in annotations.items())
                     if annotations else ""])
    report = dict(result.report, annotations=dict(annotations)) if annotations else result.report
    result = dataclasses.replace(result, meshes=tuple(meshes), source=result.source + extra, report=report)
    if not pulled:
        return result
    worst = sorted(pulled, reverse=True)
    listing = ", ".join(f"{n!r} {d:.3g} (edges {e:.3g} off)" for d, e, n in worst[:_MAX_LISTED])
    more = f", {len(worst) - _MAX_LISTED} more" if len(worst) > _MAX_LISTED else ""
    over = [(d, e, n) for d, e, n in worst if d > tol]
    within = f"within {tol:.3g}" if not over else f"{len(over)} of them beyond the tolerance {tol:.3g}"
    note = (f"; trim curves pulled back onto {len(pulled)} face(s) {within} ({told}), max deviation per face: "
            f"{listing}{more}")
    fit = {"tolerance": tol, "faces": {n: {"deviation": d, "edge_distance": e} for d, e, n in worst},
           "beyond_tolerance": [n for _, _, n in over], "short_of_edges": []}
    if over:
        names = ", ".join(f"{n!r} {d:.3g} (edges {e:.3g} off)" for d, e, n in over[:_MAX_LISTED])
        more = f", {len(over) - _MAX_LISTED} more" if len(over) > _MAX_LISTED else ""
        note += (f"; {len(over)} face(s) drawn with trim loops beyond the model tolerance {tol:.3g}, the best fit of "
                 f"edges that lie farther than that from their surfaces (the Brep's own edge tolerances): {names}"
                 f"{more}")
    # the fit can come no nearer to an edge than the edge is to the surface; a warning only where it stayed
    # farther than that plus the tolerance (the reader's shortfall, not the file's)
    short = [(d, e, n) for d, e, n in over if d > e + tol]
    if short:
        fit["short_of_edges"] = [n for _, _, n in short]
        names = ", ".join(f"{n!r} {d:.3g} (edges {e:.3g} off)" for d, e, n in short[:_MAX_LISTED])
        more = f", {len(short) - _MAX_LISTED} more" if len(short) > _MAX_LISTED else ""
        text = (f"{len(short)} face(s) drawn with trim loops farther from their edges than the edges are from the "
                f"surface plus the tolerance {tol:.3g}: {names}{more}")
        if stopped:
            text += f"; refinement stopped: {stopped[0]}" + (f" ({len(stopped) - 1} more)" if len(stopped) > 1 else "")
        warnings.warn(f"{path}: {text}", UserWarning, stacklevel=2)
        note += f"; {text}"
    return dataclasses.replace(result, source=result.source + note, report=dict(result.report, trim_fit=fit))


def _mesh(g, name: str) -> tuple:
    """A rhino3dm Mesh as ``(name, points, triangles)``: quads ``(a, b, c, d)`` split along ``a-c``, triangles
    stored as quads with ``c == d`` kept."""
    P = np.array([[v.X, v.Y, v.Z] for v in g.Vertices], dtype=np.float64).reshape(-1, 3)
    F = np.array([tuple(g.Faces[i]) for i in range(len(g.Faces))], dtype=np.int64).reshape(-1, 4)
    quad = F[:, 2] != F[:, 3]
    T = np.concatenate([F[:, :3], F[quad][:, [0, 2, 3]]])
    return name, P, T


def _sketch(g, name: str, rhino3dm) -> tuple:
    """A curve as ``(name, points, segments (m, 2))`` (sampled at 64 points per span of its NURBS form, at
    most 4096: a circle's chords then lie within 1.2e-3 of its radius, under a pixel at any whole-model
    view), a point or point cloud as ``(name, points, vertices (m, 1))``."""
    if isinstance(g, rhino3dm.Point):
        P = np.array([[g.Location.X, g.Location.Y, g.Location.Z]])
    elif isinstance(g, rhino3dm.PointCloud):
        P = np.array([[q.X, q.Y, q.Z] for q in g.GetPoints()], dtype=np.float64).reshape(-1, 3)
    else:
        dom = g.Domain
        n = int(min(4096, 64 * max(1, g.SpanCount)))
        t = dom.T0 + (dom.T1 - dom.T0) * np.linspace(0.0, 1.0, n + 1)
        t[-1] = dom.T1
        P = np.array([[q.X, q.Y, q.Z] for q in map(g.PointAt, t)], dtype=np.float64)
        return name, P, np.column_stack([np.arange(n), np.arange(1, n + 1)])
    return name, P, np.arange(len(P)).reshape(-1, 1)


def _tolerance(model):
    """The file's model absolute tolerance, else a fraction of the size of everything in it."""
    settings = getattr(model, "Settings", None)
    tol = getattr(settings, "ModelAbsoluteTolerance", None) if settings is not None else None
    if tol is not None and np.isfinite(tol) and tol > 0:
        return float(tol), "the file's model tolerance"
    corners = []
    for obj in model.Objects:
        box = obj.Geometry.GetBoundingBox()
        corners += [[box.Min.X, box.Min.Y, box.Min.Z], [box.Max.X, box.Max.Y, box.Max.Z]]
    size = float(np.linalg.norm(np.ptp(np.array(corners), axis=0))) if corners else 0.0
    return _RELATIVE_TOLERANCE * max(size, 1e-300), f"{_RELATIVE_TOLERANCE:g} of the model's bounding-box diagonal"


def _full_knots(knots) -> list:
    """Rhino's knots (n + p - 1 of them) with the superfluous end knots added."""
    k = list(knots.ToList())
    return [k[0]] + k + [k[-1]]


def _surface(ns, name: str) -> NurbsSurface:
    pts = ns.Points
    nu, nv = pts.CountU, pts.CountV
    P = np.empty((nu, nv, 3))
    W = np.empty((nu, nv))
    for i in range(nu):
        for j in range(nv):
            p = pts.GetPoint(i, j)
            P[i, j] = p.X, p.Y, p.Z
            W[i, j] = pts.GetControlPoint(i, j).W if ns.IsRational else 1.0
    return NurbsSurface((ns.Degree(0), ns.Degree(1)), (_full_knots(ns.KnotsU), _full_knots(ns.KnotsV)), P,
                        W if ns.IsRational else None, name=name)


def _planar_loops(brep, face, surf: NurbsSurface, path, name: str):
    """Trim loops of a face on an affine parallelogram, from its 3-D edges; None for any other surface."""
    P = surf.control_points
    if surf.degree != (1, 1) or surf.shape != (2, 2) or surf.rational:
        return None
    scale = max(float(np.ptp(P.reshape(-1, 3), axis=0).max()), 1e-300)
    if np.abs(P[1, 1] - P[1, 0] - P[0, 1] + P[0, 0]).max() > 1e-12 * scale:
        return None
    (u0, u1), (v0, v1) = surf.domain
    A = np.stack([(P[1, 0] - P[0, 0]) / (u1 - u0), (P[0, 1] - P[0, 0]) / (v1 - v0)], axis=1)  # (3, 2)
    pinv = np.linalg.pinv(A)
    loops = []
    for loop in face.Loops:
        curves = []
        for trim in loop.Trims:
            if trim.EdgeIndex < 0:  # a singular trim (no edge): a point in (u, v)
                continue
            c = brep.Edges[trim.EdgeIndex].ToNurbsCurve()
            n = len(c.Points)
            H = np.array([[c.Points[i].X, c.Points[i].Y, c.Points[i].Z, c.Points[i].W] for i in range(n)])
            w = H[:, 3]
            xyz = H[:, :3] / w[:, None]
            uv = (xyz - P[0, 0]) @ pinv.T + [u0, v0]
            curves.append(checked(path, f"object {name!r} trim curve", lambda: TrimCurve(
                c.Degree, _full_knots(c.Knots), uv, w if c.IsRational else None)))
        if curves:
            loops.append(curves)
    return loops


def _curve_arrays(c):
    """(degree, knots, points, weights) of a rhino3dm NurbsCurve."""
    n = len(c.Points)
    H = np.array([[c.Points[i].X, c.Points[i].Y, c.Points[i].Z, c.Points[i].W] for i in range(n)])
    w = H[:, 3] if c.IsRational else np.ones(n)
    return c.Degree, _full_knots(c.Knots), H[:, :3] / w[:, None], w


def _pulled_loops(brep, face, surf: NurbsSurface, tol: float, name: str):
    """Trim loops of a face on any surface, its edges pulled back; (loops, max deviation, max distance,
    notes). Lenient: an edge up to ``_EDGE_SLACK`` tolerances off its surface is fitted as closely as its
    distance allows (the caller reports a deviation beyond the tolerance); farther, ValueError."""
    loops, dev, dist, notes = [], 0.0, 0.0, []
    inv = _Inverter(surf)
    closed = tuple(bool(c) for c in inv.closed)
    trims = [[(t.EdgeIndex, t.IsReversed) for t in loop.Trims] for loop in face.Loops]
    edges = sorted({e for loop in trims for e, _ in loop if e >= 0})
    specs = [(*curve_evaluator(*_curve_arrays(brep.Edges[e].ToNurbsCurve())), e) for e in edges]
    try:  # every edge of the face once, their first feet in one batch
        results = pull_back_many(surf, [(f, dom, breaks, f"{name} edge {e}", None) for f, dom, breaks, e in specs],
                                 tol, strict=False, max_distance=max(_EDGE_SLACK * tol, _ROUNDING * inv.scale),
                                 inverter=inv)
    except ValueError as err:
        raise ValueError(f"{err} The edge is more than {_EDGE_SLACK:g} x the model tolerance off its face: "
                         "the Brep is damaged (Rhino: Check, then RebuildEdges or ExtractSrf and re-trim) "
                         "or the file's model tolerance is too small for it.") from None
    pulled = dict(zip(edges, results))
    for r in results:
        dev, dist = max(dev, r.deviation), max(dist, r.distance)
        notes += [r.note] if r.note else []
    for loop in trims:
        items = []  # per trim: (curves or None for a singular trim, edge index)
        for e, reverse in loop:
            if e < 0:
                items.append((None, -1))
                continue
            r = pulled[e]
            items.append(([reverse_curve(c) for c in r.curves[::-1]] if reverse else list(r.curves), e))
        if all(c is None for c, _ in items):
            continue
        curves = _placed(items, surf, closed, name)
        if curves:
            loops.append(curves)
    return loops, dev, dist, notes


def _placed(items, surf: NurbsSurface, closed, name: str) -> list:
    """One loop's curves shifted by periods into the domain (closed directions), singular trims joined.

    A curve that fits the domain at one shift only (e.g. a full circle across it) is placed there; one that
    fits at several (a seam edge: at ``u0`` or at ``u1``) is placed next to its placed neighbours, so the
    loop closes whichever trim it starts with, and a seam edge's two uses land on the two sides."""
    dom = np.array(surf.domain)
    period = dom[:, 1] - dom[:, 0]
    choices = [np.array(s) * period for s in itertools.product(*[(-1, 0, 1) if c else (0,) for c in closed])]
    n = len(items)
    ties, starts, ends = [None] * n, [None] * n, [None] * n
    for k, (curves, _) in enumerate(items):
        if curves is None:
            continue
        P = np.concatenate([c.control_points for c in curves])
        out = [np.maximum(np.maximum(dom[:, 0] - (P + s), (P + s) - dom[:, 1]), 0).max() for s in choices]
        ties[k] = [s for s, o in zip(choices, out) if o <= min(out) + 1e-9 * period.max()]
        starts[k] = curves[0].evaluate([curves[0].domain[0]])[0]
        ends[k] = curves[-1].evaluate([curves[-1].domain[1]])[0]
    shift = [t[0] if t is not None and len(t) == 1 else None for t in ties]
    pending = [k for k in range(n) if ties[k] is not None and shift[k] is None]
    while pending:
        chosen = {}
        for k in pending:
            p, q = (k - 1) % n, (k + 1) % n
            links = []  # (my point, the placed neighbour's point)
            if n > 1 and shift[p] is not None:
                links.append((starts[k], ends[p] + shift[p]))
            if n > 1 and shift[q] is not None:
                links.append((ends[k], starts[q] + shift[q]))
            if links:
                chosen[k] = min(ties[k], key=lambda s: sum(np.abs(a + s - b).sum() for a, b in links))
        if not chosen:  # nothing placed next to any of them (e.g. between poles): a seam edge's second use on
            k = pending[0]  # the side away from its first, else the first at no shift (or its first fit)
            twin = [j for j in range(n) if j != k and items[j][1] == items[k][1] and shift[j] is not None]
            if twin:
                j = twin[0]
                chosen[k] = max(ties[k], key=lambda s: np.abs(starts[k] + s - starts[j] - shift[j]).sum())
            else:
                chosen[k] = next((x for x in ties[k] if not x.any()), ties[k][0])
        for k, s in chosen.items():
            shift[k] = s
        pending = [k for k in pending if k not in chosen]
    placed = [None if items[k][0] is None else
              [TrimCurve(c.degree, c.knots, c.control_points + shift[k], c.weights) for c in items[k][0]]
              for k in range(n)]
    n = len(placed)
    for k, curves in enumerate(placed):  # one vertex: one point in (u, v), bit for bit (the even-odd joints)
        nxt = placed[(k + 1) % n]
        if curves is not None and nxt is not None and not (n == 1 and len(curves) == 1):
            a, b = curves[-1].control_points[-1], nxt[0].control_points[0]
            if np.any(np.abs(a - b) > 0.25 * period):
                raise ValueError(f"{name}: the pulled-back loop does not close in (u, v): {a} to {b} (consecutive "
                                 "edges whose ends do not meet on the surface, or a seam the reader could not place; "
                                 "Rhino's Check names a bad loop, else report the file).")
            c = nxt[0]
            nxt[0] = TrimCurve(c.degree, c.knots, np.concatenate([a[None], c.control_points[1:]]), c.weights)
    loop = []
    for k, curves in enumerate(placed):
        if curves is not None:
            loop += curves
            continue
        if k > 0 and placed[k - 1] is None:  # a run of singular trims: one segment
            continue
        before = next(placed[(k - j) % n] for j in range(1, n + 1) if placed[(k - j) % n] is not None)
        after = next(placed[(k + j) % n] for j in range(1, n + 1) if placed[(k + j) % n] is not None)
        a, b = before[-1].control_points[-1], after[0].control_points[0]
        if np.abs(a - b).max() > 1e-12 * period.max():  # a pole's segment along the collapsed side
            loop.append(TrimCurve(1, [0, 0, 1, 1], [a, b]))
    return loop

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
  - on **any other surface** (curved, or a plane in rational form) each edge is pulled back onto the
    surface (:func:`splinevis.nurbs.pullback.pull_back`: point inversion, a cubic fit refined until it
    maps within the tolerance of the edge), run backwards where the trim is reversed; on a closed surface
    each curve is shifted by the period into the domain, a seam edge's two uses to the two sides of the
    domain, and a singular trim (no edge: a pole) becomes the segment joining its neighbours' ends. The
    tolerance is the file's model absolute tolerance (``Settings.ModelAbsoluteTolerance``), else
    ``1e-6`` of the model's bounding-box diagonal. The model's ``source`` lists each such face's measured
    deviation (max distance of the pulled-back curves, mapped through the surface, from the edges) and
    how far its edges are from the surface. A face whose edges do not pull back within the tolerance is
    skipped, with a warning giving the reason, and counted as ``"trimmed Brep face on a curved surface
    ..."``.
* Names: the object's name (``Attributes.Name``), else its id (a UUID); faces of a Brep with several
  faces are ``"<name> face <k>"``.

Anything else (curves, meshes, points, ...) is counted in ``skipped`` by its rhino3dm type.
Rhino stores knot vectors without the two superfluous end knots and control points homogeneous
``(w x, w y, w z, w)``; both are converted here.
"""

from __future__ import annotations

import dataclasses
import itertools
import warnings
from pathlib import Path

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface, TrimCurve
from ..nurbs.pullback import curve_evaluator, pull_back, reverse_curve
from .nurbs_common import build_model, checked, flip_v

__all__ = ["read_3dm"]

_CURVED_TRIMMED = "trimmed Brep face on a curved surface whose edges do not pull back within the model tolerance"
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
    surfaces, trims, skipped, contents, pulled = [], [], {}, {}, []
    tol, told = _tolerance(model)
    for obj in model.Objects:
        g, attr = obj.Geometry, obj.Attributes
        kind = type(g).__name__
        contents[kind] = contents.get(kind, 0) + 1
        name = attr.Name or str(attr.Id)
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
                            loops, dev, dist = _pulled_loops(g, face, surf, tol, fname)
                        except ValueError as err:
                            warnings.warn(f"{path}: object {fname!r} skipped: {err}", UserWarning, stacklevel=2)
                            skipped[_CURVED_TRIMMED] = skipped.get(_CURVED_TRIMMED, 0) + 1
                            continue
                        pulled.append((dev, dist, fname))
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
    if not pulled:
        return result
    worst = sorted(pulled, reverse=True)
    listing = ", ".join(f"{n!r} {d:.3g} (edges {e:.3g} off)" for d, e, n in worst[:_MAX_LISTED])
    more = f", {len(worst) - _MAX_LISTED} more" if len(worst) > _MAX_LISTED else ""
    note = (f"; trim curves pulled back onto {len(pulled)} face(s) within {tol:.3g} ({told}), max deviation per "
            f"face: {listing}{more}")
    return dataclasses.replace(result, source=result.source + note)


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
    """Trim loops of a face on any surface, its edges pulled back; (loops, max deviation, max distance)."""
    loops, dev, dist = [], 0.0, 0.0
    for loop in face.Loops:
        items = []  # per trim: (curves or None for a singular trim, edge index)
        for trim in loop.Trims:
            if trim.EdgeIndex < 0:
                items.append((None, -1))
                continue
            f, dom, breaks = curve_evaluator(*_curve_arrays(brep.Edges[trim.EdgeIndex].ToNurbsCurve()))
            r = pull_back(surf, f, dom, tol, name=f"{name} edge {trim.EdgeIndex}", breaks=breaks)
            curves = [reverse_curve(c) for c in r.curves[::-1]] if trim.IsReversed else list(r.curves)
            items.append((curves, trim.EdgeIndex))
            dev, dist, closed = max(dev, r.deviation), max(dist, r.distance), r.closed
        if all(c is None for c, _ in items):
            continue
        curves = _placed(items, surf, closed, name)
        if curves:
            loops.append(curves)
    return loops, dev, dist


def _placed(items, surf: NurbsSurface, closed, name: str) -> list:
    """One loop's curves shifted by periods into the domain (closed directions), singular trims joined."""
    dom = np.array(surf.domain)
    period = dom[:, 1] - dom[:, 0]
    choices = [np.array(s) * period for s in itertools.product(*[(-1, 0, 1) if c else (0,) for c in closed])]
    placed, ends = [], {}  # ends: edge index -> start of its first placed use
    for k, (curves, edge) in enumerate(items):
        if curves is None:
            placed.append(None)
            continue
        P = np.concatenate([c.control_points for c in curves])
        out = [np.maximum(np.maximum(dom[:, 0] - (P + s), (P + s) - dom[:, 1]), 0).max() for s in choices]
        ties = [s for s, o in zip(choices, out) if o <= min(out) + 1e-9 * period.max()]
        start = curves[0].evaluate([curves[0].domain[0]])[0]
        prev = placed[k - 1] if k > 0 else None
        if len(ties) > 1 and prev is not None:  # continue from the previous curve's end
            end = prev[-1].evaluate([prev[-1].domain[1]])[0]
            ties = [min(ties, key=lambda s: np.abs(start + s - end).sum())]
        elif len(ties) > 1 and edge in ends:  # a seam edge's second use: the other side
            ties = [max(ties, key=lambda s: np.abs(start + s - ends[edge]).sum())]
        s = next((x for x in ties if not x.any()), ties[0])
        ends.setdefault(edge, start + s)
        placed.append([TrimCurve(c.degree, c.knots, c.control_points + s, c.weights) for c in curves])
    n = len(placed)
    for k, curves in enumerate(placed):  # one vertex: one point in (u, v), bit for bit (the even-odd joints)
        nxt = placed[(k + 1) % n]
        if curves is not None and nxt is not None and not (n == 1 and len(curves) == 1):
            a, b = curves[-1].control_points[-1], nxt[0].control_points[0]
            if np.any(np.abs(a - b) > 0.25 * period):
                raise ValueError(f"{name}: the pulled-back loop does not close in (u, v): {a} to {b}.")
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

"""NURBS surfaces from Rhino ``.3dm`` files through ``rhino3dm`` (imported only when a file is read).

What is read
------------
* ``NurbsSurface`` objects, and other surfaces (``PlaneSurface``, ``RevSurface``, ``SumSurface``) in
  their NURBS form (``ToNurbsSurface``).
* ``Brep`` and ``Extrusion`` objects (the latter through ``ToBrep``): each face's underlying surface in NURBS form, one patch per face. An untrimmed face
  (its duplicate is a plain surface) gets no loops. rhino3dm does not expose the faces' 2-D trim curves,
  so trim loops are built only where they follow exactly from the 3-D edges: on **planar faces whose
  NURBS form is an affine parallelogram** (degree 1 x 1, 2 x 2 points), each edge's NURBS curve maps into
  ``(u, v)`` by the inverse affine map (exact: affine maps commute with rational B-splines). A trimmed
  face on any other surface is skipped and counted as ``"trimmed Brep face on a curved surface"``.
* Names: the object's name (``Attributes.Name``), else its id (a UUID); faces of a Brep with several
  faces are ``"<name> face <k>"``.

Anything else (curves, meshes, points, ...) is counted in ``skipped`` by its rhino3dm type.
Rhino stores knot vectors without the two superfluous end knots and control points homogeneous
``(w x, w y, w z, w)``; both are converted here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface, TrimCurve
from .nurbs_common import build_model, checked, flip_v

__all__ = ["read_3dm"]

_CURVED_TRIMMED = "trimmed Brep face on a curved surface (rhino3dm exposes no 2-D trim curves)"


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
    surfaces, trims, skipped, contents = [], [], {}, {}
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
                        skipped[_CURVED_TRIMMED] = skipped.get(_CURVED_TRIMMED, 0) + 1
                        continue
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
    return build_model(path, "Rhino 3DM (rhino3dm)", surfaces, trims, skipped, contents)


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

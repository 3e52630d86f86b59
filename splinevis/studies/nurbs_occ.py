"""OpenCASCADE's tessellation of our NURBS patches (``BRepMesh_IncrementalMesh``), the CAD baseline of the NURBS
study; needs the optional package ``cadquery-ocp-novtk`` (``pip install splinevis[cad]``).

Each patch becomes a ``Geom_BSplineSurface`` face; the mesher places nodes so the chord deviation stays
below the given deflection; every node keeps its (u, v), where our float64 model gives the exact normal (as
CAD viewers do), interpolated across the triangles when drawn.
"""

from __future__ import annotations

import numpy as np

from ..io.nurbs_step import ocp_available as occ_available

__all__ = ["occ_available", "occ_tessellate"]


def _face(s):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt

    try:  # OCP 8: NCollection arrays in OCP.collections
        from OCP.OCP.collections import Array1_double as Real1, Array1_int as Int1, Array2_double as Real2
        from OCP.OCP.collections import Array2_gp_Pnt as Pnt2
    except ImportError:  # OCP 7.x
        from OCP.TColgp import TColgp_Array2OfPnt as Pnt2
        from OCP.TColStd import TColStd_Array1OfInteger as Int1, TColStd_Array1OfReal as Real1
        from OCP.TColStd import TColStd_Array2OfReal as Real2

    (p, q), (U, V) = s.degree, s.knots
    nu, nv = s.shape
    poles = Pnt2(1, nu, 1, nv)
    weights = Real2(1, nu, 1, nv)
    w = np.ones((nu, nv)) if s.weights is None else s.weights
    for i in range(nu):
        for j in range(nv):
            poles.SetValue(i + 1, j + 1, gp_Pnt(*map(float, s.control_points[i, j])))
            weights.SetValue(i + 1, j + 1, float(w[i, j]))

    def knots(K):
        vals, mults = np.unique(K, return_counts=True)
        kv, km = Real1(1, len(vals)), Int1(1, len(vals))
        for k, (a, m) in enumerate(zip(vals, mults)):
            kv.SetValue(k + 1, float(a))
            km.SetValue(k + 1, int(m))
        return kv, km

    (ku, mu), (kv, mv) = knots(U), knots(V)
    surf = Geom_BSplineSurface(poles, weights, ku, kv, mu, mv, p, q, False, False)
    return BRepBuilderAPI_MakeFace(surf, 1e-9).Face()


def occ_tessellate(model, deflection: float):
    """A pyvista PolyData of every patch meshed by OpenCASCADE with linear ``deflection`` (model units),
    point arrays ``Normals`` (exact, from the model at each node's (u, v)) and ``patch_id``.

    >>> from splinevis.nurbs.exact import sphere
    >>> mesh = occ_tessellate(sphere(), 1e-2) if occ_available() else None
    >>> mesh is None or mesh.n_cells > 50
    True
    """
    import pyvista as pv
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopLoc import TopLoc_Location

    surfaces = getattr(model, "surfaces", (model,))
    pts, nrm, ids, faces = [], [], [], []
    offset = 0
    for k, s in enumerate(surfaces):
        face = _face(s)
        BRepMesh_IncrementalMesh(face, float(deflection), False, 0.5, False)
        tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
        if tri is None:
            raise RuntimeError(f"OpenCASCADE did not mesh patch {k} ({s.name or 'unnamed'}).")
        n = tri.NbNodes()
        uv = np.array([[tri.UVNode(i).X(), tri.UVNode(i).Y()] for i in range(1, n + 1)])
        (u0, u1), (v0, v1) = s.domain
        uv[:, 0] = np.clip(uv[:, 0], u0, u1)
        uv[:, 1] = np.clip(uv[:, 1], v0, v1)
        pts.append(s.evaluate(uv[:, 0], uv[:, 1]))
        nrm.append(s.normal(uv[:, 0], uv[:, 1]))
        ids.append(np.full(n, k))
        t = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)]) - 1 + offset
        faces.append(np.column_stack([np.full(len(t), 3), t]).ravel())
        offset += n
    mesh = pv.PolyData(np.concatenate(pts), faces=np.concatenate(faces))
    mesh.point_data["Normals"] = np.concatenate(nrm)
    mesh.point_data["patch_id"] = np.concatenate(ids)
    return mesh

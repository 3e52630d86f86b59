"""The baseline CAD users look at today: a NURBS model tessellated into triangles whose vertices carry the
exact surface normal, shaded with normals interpolated across each triangle [Kanai2007, sec. 4, Fig. 3 left].

Each patch is cut along its knot spans, each span into ``per_span x per_span`` quads (two triangles each),
evaluated in float64 by the model. Point arrays: ``Normals`` (exact unit normals), ``uv`` and
``patch_id``. The chord deviation of the mesh (largest distance from a triangle to the surface) is
measured by :func:`chord_deviation` at the triangles' centroids and edge midpoints.
"""

from __future__ import annotations

import numpy as np

from .basis import at_fraction
from .model import NurbsModel
from .surface import NurbsSurface

__all__ = ["span_grid", "tessellate", "chord_deviation"]


def span_grid(surface: NurbsSurface, per_span: int) -> tuple:
    """Parameter lines ``(us, vs)``: every distinct knot of the domain, each span cut ``per_span`` times.

    >>> from splinevis.nurbs.exact import cylinder
    >>> us, vs = span_grid(cylinder(), 2)
    >>> us.tolist(), vs.tolist()
    ([0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0], [0.0, 0.5, 1.0])
    """
    if isinstance(per_span, bool) or not isinstance(per_span, (int, np.integer)) or per_span < 1:
        raise ValueError(f"per_span must be a positive integer, got {per_span!r}.")
    out = []
    for knots, (lo, hi) in zip(surface.knots, surface.domain):
        k = np.unique(knots[(knots >= lo) & (knots <= hi)])
        t = np.linspace(0.0, 1.0, per_span + 1)[:-1]
        out.append(np.concatenate([at_fraction(a, b, t) for a, b in zip(k[:-1], k[1:])] + [[hi]]))
    return tuple(out)


def tessellate(model, per_span: int = 8):
    """A pyvista PolyData of the model's patches (see module docstring).

    >>> from splinevis.nurbs.exact import sphere
    >>> mesh = tessellate(sphere(), 4)
    >>> mesh.n_points, sorted(mesh.point_data.keys())
    (153, ['Normals', 'patch_id', 'uv'])
    """
    import pyvista as pv

    surfaces = model.surfaces if isinstance(model, NurbsModel) else (model,)
    pts, nrm, uvs, ids, faces = [], [], [], [], []
    offset = 0
    for k, s in enumerate(surfaces):
        us, vs = span_grid(s, per_span)
        U, V = np.meshgrid(us, vs, indexing="ij")
        u, v = U.ravel(), V.ravel()
        pts.append(s.evaluate(u, v))
        nrm.append(s.normal(u, v))
        uvs.append(np.column_stack([u, v]))
        ids.append(np.full(u.size, k))
        nu, nv = U.shape
        i, j = np.meshgrid(np.arange(nu - 1), np.arange(nv - 1), indexing="ij")
        a = (i * nv + j).ravel() + offset
        b, c, d = a + nv, a + nv + 1, a + 1
        tri = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
        faces.append(np.column_stack([np.full(len(tri), 3), tri]).ravel())
        offset += u.size
    mesh = pv.PolyData(np.concatenate(pts), faces=np.concatenate(faces))
    mesh.point_data["Normals"] = np.concatenate(nrm)
    mesh.point_data["uv"] = np.concatenate(uvs)
    mesh.point_data["patch_id"] = np.concatenate(ids)
    return mesh


def chord_deviation(model, per_span: int = 8) -> float:
    """Largest distance between the tessellation and the surface, at the triangles' centroids and edge
    midpoints (the surface point at the interpolated (u, v); a lower estimate of the true maximum).

    >>> from splinevis.nurbs.exact import cylinder
    >>> d = chord_deviation(cylinder(1.0), 4)  # 16 segments per turn, 1 - cos(pi/16) = 0.0192 if equal
    >>> round(d, 4)  # the rational parameter makes the segments unequal: the widest one deviates more
    0.0209
    """
    mesh = tessellate(model, per_span)
    surfaces = model.surfaces if isinstance(model, NurbsModel) else (model,)
    tri = mesh.faces.reshape(-1, 4)[:, 1:]
    P, UV, ID = mesh.points, mesh.point_data["uv"], mesh.point_data["patch_id"]
    worst = 0.0
    for w in ([1 / 3, 1 / 3, 1 / 3], [0.5, 0.5, 0], [0, 0.5, 0.5], [0.5, 0, 0.5]):
        w = np.asarray(w)
        x = np.einsum("k,tkc->tc", w, P[tri])
        uv = np.einsum("k,tkc->tc", w, UV[tri])
        pid = ID[tri[:, 0]]
        for k, s in enumerate(surfaces):
            sel = pid == k
            if sel.any():
                worst = max(worst, float(np.linalg.norm(s.evaluate(uv[sel, 0], uv[sel, 1]) - x[sel], axis=1).max()))
    return worst

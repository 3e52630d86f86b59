"""Simplified levels of a super-surface: fewer triangles than its patches' tessellations, across patch edges,
held to a measured bound ``delta + eps`` [Kumar1997, sec. 4].

The paper simplifies each super-surface with simplification envelopes, keeping its border. Here the kept
library is VTK's ``vtkDecimatePro`` (already a dependency): vertices are removed where the retriangulated hole
stays within ``eps`` of the old surface (absolute error, accumulated over removals), border vertices are never
removed (``BoundaryVertexDeletionOff``: the super-surface's border chains, which its neighbours share, stay
exactly as they are) and the topology is kept. VTK gives no guarantee for the accumulated distance, so the
result is *measured* and held to the bound: the distance from dense samples of the true surface to the new
mesh, and from dense samples of the new mesh to the old one (which is within its proven ``delta`` of the
surface, so that distance plus ``delta`` bounds the new mesh's distance to the surface). If either exceeds
``delta + eps`` the decimation is repeated with half the error, at most three times; then the level is kept
unsimplified. Vertices are only removed, never moved, so every kept vertex is a surface point.
"""

from __future__ import annotations

import numpy as np

from .bezier import evaluate

__all__ = ["Simplifier", "surface_distance"]


def _poly(points, tri):
    import pyvista as pv

    return pv.PolyData(points, np.column_stack([np.full(len(tri), 3), tri]).ravel())


def surface_distance(points, tri, samples) -> float:
    """Largest distance from the points ``samples (n, 3)`` to the triangle mesh ``(points, tri)``.

    >>> pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> surface_distance(pts, np.array([[0, 1, 2]]), np.array([[0.2, 0.2, 0.5]]))
    0.5
    """
    import pyvista as pv

    d = pv.PolyData(np.asarray(samples, dtype=np.float64)).compute_implicit_distance(_poly(points, tri))
    return float(np.abs(d["implicit_distance"]).max())


def _triangle_samples(points, tri, n=4):
    """Points of a barycentric grid (``n`` steps, interior and edges) on every triangle."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    ok = i + j <= n
    b = np.stack([i[ok], j[ok], n - i[ok] - j[ok]], axis=1) / n
    P = points[tri]  # (T, 3, 3)
    return np.einsum("kb,tbd->tkd", b, P).reshape(-1, 3)


class Simplifier:
    """Decimate the levels of :func:`splinevis.nurbs.lod.levels.build_lod` (its ``simplify=`` argument): level
    ``l > 0`` of a super-surface (proven within ``delta_l``) may lose vertices while it stays within
    ``delta_l + eps_l`` of the surface, ``eps_l = share * delta_l``, as measured on ``samples x samples``
    points of each of its patches (module docstring).

    >>> from splinevis.nurbs.exact import torus
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> plain = build_lod(torus(), 0.01, levels=3, progress=False)
    >>> lod = build_lod(torus(), 0.01, levels=3, simplify=Simplifier(), progress=False)
    >>> bool(lod.triangles[:, 1:].sum() < plain.triangles[:, 1:].sum()), bool(lod.tolerance[1] == 0.04 * 1.5)
    (True, True)
    """

    def __init__(self, share: float = 0.5, samples: int = 9, target: float = 0.95, attempts: int = 3):
        if not share > 0:
            raise ValueError(f"share must be positive (eps = share * delta), got {share!r}.")
        self.share, self.samples, self.target, self.attempts = float(share), int(samples), float(target), int(attempts)

    def eps(self, delta: float) -> float:
        """The simplification's share of a level's bound.

        >>> Simplifier(0.5).eps(0.04)
        0.02
        """
        return self.share * float(delta)

    def __call__(self, bezier, vertices, tri, members, delta):
        """``(new triangles, measured distance to the surface)`` for one level of one super-surface (its
        patches ``members``); the measured distance is at most ``delta + eps``, or the triangles are returned
        unchanged with ``delta``."""
        import pyvista as pv
        import vtk

        bound = float(delta) + self.eps(delta)
        ids = np.unique(tri)
        local = np.searchsorted(ids, tri)
        poly = _poly(vertices[ids], local)
        poly.point_data["gid"] = ids
        t = np.linspace(0.0, 1.0, self.samples)
        U, V = (x.ravel() for x in np.meshgrid(t, t))
        members = np.asarray(members)
        surface = evaluate(bezier, np.repeat(members, U.size), np.tile(U, members.size), np.tile(V, members.size))
        err = self.eps(delta)
        for _ in range(self.attempts):
            dec = vtk.vtkDecimatePro()
            dec.SetInputData(poly)
            dec.SetTargetReduction(self.target)
            dec.PreserveTopologyOn()
            dec.BoundaryVertexDeletionOff()
            dec.SplittingOff()
            dec.SetErrorIsAbsolute(1)
            dec.SetAbsoluteError(err)
            dec.AccumulateErrorOn()
            dec.Update()
            out = pv.wrap(dec.GetOutput())
            if out.n_cells == 0:
                err *= 0.5
                continue
            new = np.asarray(out.point_data["gid"])[out.faces.reshape(-1, 4)[:, 1:]]
            to_surface = surface_distance(vertices, new, surface)
            to_old = surface_distance(vertices, tri, _triangle_samples(vertices, new)) + float(delta)
            measured = max(to_surface, to_old)
            if measured <= bound:
                return new.astype(np.int64), measured
            err *= 0.5
        return tri, float(delta)

"""Closed triangle meshes with exact answers for smooth geometry images [Losasso2003], and bad inputs.

Genus-0 shapes (each a ``pyvista.PolyData`` of triangles, outward oriented) built on an icosphere subdivided
``level`` times, so each vertex is a point of a known surface:

* :func:`sphere_mesh` (radius ``r``), :func:`ellipsoid_mesh` (semi-axes ``a, b, c``);
* :func:`star_blob`: the star-shaped surface ``x = rho(d) d`` over unit directions ``d`` with
  ``rho(d) = 1 + eps * Y(d)`` (a smooth bump function), whose exact unit normal :func:`star_blob_normals` gives;
* :func:`stretched_blob`: the star blob scaled 4 x 1 x 1 (long thin features: a parametrization's stretch test).
* :func:`bent_blob`: a long ellipsoid bent into a "C", not star-shaped: projecting it from its centroid onto
  a sphere folds it (a parametrization must not start that way).

Bad inputs, each failing one check: :func:`torus_mesh` (genus 1), :func:`open_cup` (a border),
:func:`two_spheres` (two components), :func:`nonmanifold_edge` (an edge in four triangles).

>>> m = sphere_mesh(level=2)
>>> m.n_points, m.n_cells, m.n_points - (m.n_cells * 3 // 2) + m.n_cells  # V - E + F = 2
(162, 320, 2)
"""

from __future__ import annotations

import numpy as np

__all__ = ["sphere_mesh", "ellipsoid_mesh", "star_blob", "star_blob_radius", "star_blob_normals", "stretched_blob",
           "bent_blob", "legged_blob", "torus_mesh", "open_cup", "two_spheres", "nonmanifold_edge"]


def _poly(points, tri):
    import pyvista as pv

    return pv.PolyData(np.asarray(points, dtype=np.float64), np.column_stack([np.full(len(tri), 3), tri]).ravel())


def _icosphere(level: int):
    """Unit icosphere: points on the unit sphere, outward triangles."""
    t = (1.0 + 5 ** 0.5) / 2.0
    P = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=np.float64)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    for _ in range(int(level)):
        edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(edges, axis=0, return_inverse=True)
        mid = P[uniq[:, 0]] + P[uniq[:, 1]]
        mid /= np.linalg.norm(mid, axis=1, keepdims=True)
        m = len(P) + inv.reshape(3, -1).T  # (F, 3): midpoints of edges 01, 12, 20
        P = np.concatenate([P, mid])
        a, b, c = F.T
        F = np.concatenate([np.column_stack([a, m[:, 0], m[:, 2]]), np.column_stack([b, m[:, 1], m[:, 0]]),
                            np.column_stack([c, m[:, 2], m[:, 1]]), m])
    return P, F


def sphere_mesh(r: float = 1.0, level: int = 3):
    """A sphere of radius ``r`` (an icosphere subdivided ``level`` times: ``10 * 4**level + 2`` vertices).

    >>> m = sphere_mesh(2.0, level=1)
    >>> bool(np.allclose(np.linalg.norm(m.points, axis=1), 2.0)), m.n_cells
    (True, 80)
    """
    P, F = _icosphere(level)
    return _poly(float(r) * P, F)


def ellipsoid_mesh(a: float = 2.0, b: float = 1.0, c: float = 0.5, level: int = 3):
    """The ellipsoid ``(x/a)^2 + (y/b)^2 + (z/c)^2 = 1`` (the icosphere's points scaled).

    >>> m = ellipsoid_mesh(level=1)
    >>> x, y, z = m.points.T
    >>> bool(np.allclose((x / 2) ** 2 + y ** 2 + (z / 0.5) ** 2, 1.0))
    True
    """
    P, F = _icosphere(level)
    return _poly(P * [a, b, c], F)


def star_blob_radius(d, eps: float = 0.25):
    """The radius ``rho(d)`` of :func:`star_blob` in the unit directions ``d`` (``(n, 3)``): the exact surface
    ``rho(d) d`` the tests and studies measure distances to.

    >>> star_blob_radius(np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), eps=0.2).tolist()
    [1.1, 1.0]
    """
    x, y, z = np.asarray(d, dtype=np.float64).T
    return 1.0 + eps * (x * y * z * 5.0 + 0.5 * (x * x - y * y))


def _bump_gradient(d, eps):
    x, y, z = d.T
    return eps * np.column_stack([5.0 * y * z + x, 5.0 * x * z - y, 5.0 * x * y])


def star_blob(eps: float = 0.25, level: int = 3):
    """The star-shaped surface ``rho(d) d`` over unit directions ``d``, ``rho = 1 + eps (5 xyz + (x^2 - y^2)/2)``
    (positive for ``eps < 0.4``).

    >>> m = star_blob(level=1)
    >>> r = np.linalg.norm(m.points, axis=1)
    >>> bool(r.min() > 0.6 and r.max() < 1.4)
    True
    """
    P, F = _icosphere(level)
    return _poly(P * star_blob_radius(P, eps)[:, None], F)


def star_blob_normals(points, eps: float = 0.25):
    """Exact unit outward normals of :func:`star_blob` at its ``points``: for ``x = rho(d) d`` the normal is along
    ``d - (grad_s rho) / rho``, ``grad_s`` the gradient on the unit sphere (the radial part of the gradient of the
    bump's extension removed).

    >>> n = star_blob_normals(star_blob(eps=0.0, level=1).points, eps=0.0)  # the sphere: the radial direction
    >>> bool(np.allclose(n, star_blob(eps=0.0, level=1).points))
    True
    """
    X = np.asarray(points, dtype=np.float64)
    d = X / np.linalg.norm(X, axis=1, keepdims=True)
    g = _bump_gradient(d, eps)
    gs = g - np.einsum("ij,ij->i", g, d)[:, None] * d
    n = d - gs / star_blob_radius(d, eps)[:, None]
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def stretched_blob(level: int = 3):
    """:func:`star_blob` scaled by 4 x 1 x 1: long and thin (a test of a parametrization's stretch).

    >>> b = stretched_blob(level=1).bounds
    >>> bool((b[1] - b[0]) > 3 * (b[3] - b[2]))
    True
    """
    P, F = _icosphere(level)
    return _poly(P * star_blob_radius(P, 0.25)[:, None] * [4.0, 1.0, 1.0], F)


def legged_blob(level: int = 4, length: float = 15.0, width: float = 0.2):
    """A unit sphere with six thin legs (along +-x, +-y, +-z) ``length`` long, each over a cap of angular
    radius ``width``: radius ``1 + length sqrt(max(0, 1 - angle / width))`` (a radial graph, so closed and
    embedded). A harmonic (Tutte) embedding shrinks such legs below double precision (the scans with legs and
    ears of real files), which a spherical parametrization must survive.

    >>> m = legged_blob(level=2)
    >>> m.n_points, round(float(m.bounds[1]), 6)
    (162, 16.0)
    """
    P, F = _icosphere(level)
    X = P / np.linalg.norm(P, axis=1, keepdims=True)
    axes = np.vstack([np.eye(3), -np.eye(3)])
    angle = np.arccos(np.clip(X @ axes.T, -1.0, 1.0)).min(axis=1)
    return _poly(X * (1.0 + length * np.sqrt(np.clip(1.0 - angle / width, 0.0, 1.0)))[:, None], F)


def bent_blob(level: int = 3, half_length: float = 2.4, r: float = 0.45):
    """The ellipsoid with semi-axes ``half_length, r, r`` bent into a "C": its point ``(x, y, z)`` goes to
    ``((1 - y) cos x, (1 - y) sin x, z)``, the long axis wrapped on the unit circle over the angles
    ``[-half_length, half_length]`` (a Jacobian determinant ``1 - y > 0``: still outward). With the defaults the
    "C" spans 275 degrees and its centroid lies in the C's hollow, outside the surface, so projecting the
    surface from it onto a sphere folds it: the test of a parametrization that does not rely on a star shape.

    >>> m = bent_blob(level=2)
    >>> d = m.points - m.points.mean(axis=0)
    >>> tri = m.faces.reshape(-1, 4)[:, 1:]
    >>> det = np.einsum("ij,ij->i", d[tri[:, 0]], np.cross(d[tri[:, 1]], d[tri[:, 2]]))
    >>> bool((det < 0).sum() > 0.1 * len(tri))  # central projection flips many triangles
    True
    """
    P, F = _icosphere(level)
    x, y, z = (P * [half_length, r, r]).T
    return _poly(np.column_stack([(1.0 - y) * np.cos(x), (1.0 - y) * np.sin(x), z]), F)


def torus_mesh(R: float = 1.0, r: float = 0.35, n: int = 24):
    """A torus (genus 1), ``n x n/2`` quads split in triangles, outward.

    >>> m = torus_mesh(n=8)
    >>> m.n_points - (m.n_cells * 3 // 2) + m.n_cells  # V - E + F = 0
    0
    """
    nu, nv = int(n), max(3, int(n) // 2)
    u, v = np.meshgrid(np.arange(nu) * 2 * np.pi / nu, np.arange(nv) * 2 * np.pi / nv, indexing="ij")
    P = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a, b = (i * nv + j).ravel(), (((i + 1) % nu) * nv + j).ravel()
    c, d = (((i + 1) % nu) * nv + (j + 1) % nv).ravel(), (i * nv + (j + 1) % nv).ravel()
    return _poly(P, np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]))


def open_cup(level: int = 3):
    """The sphere without the triangles above ``z = 0.6``: one border loop.

    >>> m = open_cup(level=1)
    >>> m.n_cells < sphere_mesh(level=1).n_cells
    True
    """
    P, F = _icosphere(level)
    keep = P[F][:, :, 2].max(axis=1) <= 0.6
    return _poly(P, F[keep]).clean()


def two_spheres(level: int = 2):
    """Two disjoint spheres, 3 apart: two components.

    >>> two_spheres(level=1).n_cells
    160
    """
    P, F = _icosphere(level)
    return _poly(np.concatenate([P, P + [3.0, 0.0, 0.0]]), np.concatenate([F, F + len(P)]))


def nonmanifold_edge(level: int = 2):
    """A sphere with two extra triangles (a fin and its back) on one of its edges: that edge is in four triangles.

    >>> nonmanifold_edge(level=1).n_cells
    82
    """
    P, F = _icosphere(level)
    a, b = F[0, 0], F[0, 1]
    tip = len(P)
    P = np.concatenate([P, [1.5 * (P[a] + P[b])]])
    return _poly(P, np.concatenate([F, [[a, b, tip], [b, a, tip]]]))

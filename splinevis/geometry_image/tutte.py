"""The Tutte start of the spherical parametrization (stage 1 of :mod:`.sphere`): the mesh minus one vertex's
star embedded in the plane with Floater's mean-value weights [Floater2003] (one-to-one by [Tutte1963;
Floater2003b]), then put on the sphere by the inverse stereographic projection.

Why our own code: a few sparse solves (scipy) on the mesh; no library embeds a closed mesh on the sphere.
"""

from __future__ import annotations

import numpy as np

from .relax import _unit

__all__ = []

def _mean_value_weights(P, F):
    """Sparse ``(V, V)`` mean-value weights ``w_ij = (tan(a/2) + tan(b/2)) / |p_i - p_j|`` (a, b the angles at
    ``i`` beside edge ``ij``); ``tan(t/2) = |u x w| / (|u||w| + u.w)`` is positive for every proper triangle."""
    from scipy.sparse import coo_matrix

    rows, cols, vals = [], [], []
    for k in range(3):
        i, j, l = F[:, k], F[:, (k + 1) % 3], F[:, (k + 2) % 3]
        u, w = P[j] - P[i], P[l] - P[i]
        nu, nw = np.linalg.norm(u, axis=1), np.linalg.norm(w, axis=1)
        half = np.linalg.norm(np.cross(u, w), axis=1) / (nu * nw + np.einsum("ij,ij->i", u, w))
        rows += [i, i]
        cols += [j, l]
        vals += [half / nu, half / nw]
    n = len(P)
    return coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)).tocsr()


def _ring(F, v):
    """The ring of vertex ``v`` as an ordered cycle (each star triangle ``(v, a, b)`` gives ``a -> b``)."""
    star = F[(F == v).any(axis=1)]
    star = np.array([np.roll(t, -int(np.flatnonzero(t == v)[0])) for t in star])
    nxt = dict(zip(star[:, 1].tolist(), star[:, 2].tolist()))
    ring = [int(star[0, 1])]
    while len(ring) < len(star):
        ring.append(nxt[ring[-1]])
    return np.array(ring, dtype=np.int64)


def _start_vertices(F, mass, count=5, search=500):
    """Up to ``count`` vertices to cut out (of the ``search`` of largest area, largest first), each with a
    chordless ring: no edge joins two ring vertices that are not ring neighbours. A chord ``ac`` of the ring
    would make triangles like ``abc`` with all three vertices on the circle, whose flat triangles on a small
    circle of the sphere face the wrong way."""
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    found = 0
    for v in np.argsort(-mass, kind="stable")[:search]:
        ring = _ring(F, int(v))
        if np.isin(edges, ring).all(axis=1).sum() == 2 * len(ring):  # each edge is in two triangles
            yield int(v)
            found += 1
            if found == count:
                return


def _solve_nonsymmetric(A, b, refinements: int = 6):
    """``A^-1 b`` for the sparse non-symmetric Tutte system, the same bits on every machine: the normal
    equations ``A^T A x = A^T b`` by Eigen's sparse Cholesky (:func:`splinevis._reproducible.spd_factor`; SciPy's
    SuperLU follows the machine's BLAS kernels), then iterative refinement on the residual ``b - A x`` of the
    original system, which recovers the accuracy the squared condition number costs (each step multiplies the
    error by about ``cond(A)^2 u``), until the residual stops shrinking."""
    from .._reproducible import spd_factor

    if A.shape[0] == 0:  # a tetrahedron: its disk has no inner vertex
        return np.zeros_like(b)
    solve = spd_factor((A.T @ A).tocsc())
    x = solve(A.T @ b)
    r = b - A @ x
    size = float(np.abs(r).max())
    for _ in range(refinements):
        x_new = x + solve(A.T @ r)
        r_new = b - A @ x_new
        size_new = float(np.abs(r_new).max())
        if not size_new < size:
            break
        x, r, size = x_new, r_new, size_new
    return x


def _tutte_sphere(P, F, mass, v):
    """Stage 1: the Tutte embedding of the mesh minus the star of ``v``, then the inverse stereographic
    projection (``v`` at the north pole)."""
    from scipy.sparse import diags

    n = len(P)
    ring = _ring(F, v)
    arc = np.linalg.norm(P[np.roll(ring, -1)] - P[ring], axis=1)
    angle = 2 * np.pi * np.concatenate([[0.0], np.cumsum(arc)[:-1]]) / arc.sum()
    W = _mean_value_weights(P, F)
    L = (diags(np.asarray(W.sum(axis=1)).ravel()) - W).tocsr()
    inner = np.ones(n, dtype=bool)
    inner[ring] = False
    inner[v] = False
    I = np.flatnonzero(inner)
    u = np.zeros((n, 2))
    u[ring] = np.column_stack([np.cos(angle), np.sin(angle)])
    rhs = -(L[I][:, ring] @ u[ring])
    u[I] = _solve_nonsymmetric(L[I][:, I].tocsr(), rhs)
    disk = ~(F == v).any(axis=1)
    e1, e2 = u[F[disk, 1]] - u[F[disk, 0]], u[F[disk, 2]] - u[F[disk, 0]]
    if (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum() < 0:
        u[:, 1] = -u[:, 1]
    # scale so that half the surface lies inside the unit circle: the southern hemisphere
    r = np.linalg.norm(u, axis=1)
    order = np.argsort(r[inner])
    if order.size:  # (a tetrahedron has no inner vertex: its disk is one triangle, left as it is)
        half = np.searchsorted(np.cumsum(mass[inner][order]), 0.5 * mass[inner].sum())
        u /= max(r[inner][order][min(half, order.size - 1)], 1e-300)
    r2 = (u * u).sum(axis=1)
    # inverse stereographic projection from the north pole, mirrored in y: counter-clockwise in the plane is
    # outward on the sphere
    X = np.column_stack([2 * u[:, 0], -2 * u[:, 1], r2 - 1.0]) / (r2 + 1.0)[:, None]
    X[v] = [0.0, 0.0, 1.0]
    return _unit(X)

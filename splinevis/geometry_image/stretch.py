"""The L2 stretch of a map of a triangle mesh onto the unit sphere, as the energy the spherical
parametrization descends (:mod:`.sphere`), with its gradient and a preconditioner.

The stretch is that of the map from the sphere to the mesh [Sander2001], the energy Praun and Hoppe minimize for spherical
parametrizations [PraunHoppe2003]: over the mesh triangles ``P_t``,
``E = sum_t area(P_t) |J_t|_F^2 / 2``, ``J_t`` the linear map from the triangle on the sphere to ``P_t``: that
of the flat triangle ``Q_t`` on the three unit vectors, scaled to the spherical triangle's area,
``|J_t|^2 = |J_flat|^2 area(Q_t) / area_sphere(Q_t)``. Sander et al.'s per-triangle stretch is
``sqrt(|J_t|^2 / 2)`` and over the mesh ``sqrt(E / area(P))``; times ``sqrt(4 pi / area(P))`` it is at least 1
(Cauchy-Schwarz), equal only for a conformal map with every ``area(P_t) / area_sphere(Q_t)`` the same: the
normalized stretch reported. (So even the identity of an inscribed polyhedron, whose flat-to-spherical area
ratios vary, scores ``1 + O(h^4)`` for edges ``h``: 1.3e-6 above 1 on ``sphere_mesh(level=2)``.)

Why the spherical area: with the flat one alone, three points near one great circle make a sliver of no
spherical area but of some flat area, and a descent learns to make such slivers. The spherical area,
``2 atan2(det[a, b, c], 1 + a.b + b.c + c.a)`` [VanOosterom1983], goes to 0 as a triangle degenerates, so ``E`` grows without bound, and sums to ``4 pi`` over
a one-to-one map whatever the triangles do.

The preconditioner: at a similarity of scale ``s`` the energy's Hessian is the mesh's cotangent stiffness times
``s^4``; weighting each triangle by its area ratio ``area(P_t) / area_sphere(Q_t)`` (the first power, not the
second, converged fastest on our shapes) and adding those weights as a lumped mass gives a symmetric positive
definite proxy.

Why our own code: the energy is the spherical parametrization's; libigl gives the cotangent entries.
"""

from __future__ import annotations

import numpy as np

__all__ = ["StretchEnergy"]


class StretchEnergy:
    """The L2 stretch of maps of the mesh ``(P, F)`` (``(V, 3)`` points, ``(F, 3)`` outward triangles) onto the
    unit sphere, as a function of the vertices' images ``X``: energy, gradient, preconditioner and report
    (module docstring).

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> m = sphere_mesh(level=2)
    >>> S = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:])
    >>> bool(1.0 <= S.report(m.points)["l2"] < 1.0 + 1e-5)  # the identity (optimal up to flat / spherical)
    True
    """

    def __init__(self, P, F):
        import igl
        from scipy.sparse import coo_matrix

        P = np.asarray(P, dtype=np.float64)
        F = np.asarray(F, dtype=np.int64)
        self.F = F
        self.n = len(P)
        DP = np.stack([P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]], axis=2)  # (F, 3, 2)
        self.M = np.einsum("fki,fkj->fij", DP, DP)  # Gram matrices of the mesh triangles
        self.area = 0.5 * np.sqrt(np.maximum(np.linalg.det(self.M), 0.0))
        self.total = float(self.area.sum())
        # the mesh's cotangent stiffness per triangle: cot(angle at corner k) / 2 on the edge opposite corner k
        self.cot = np.asarray(igl.cotmatrix_entries(P, F), dtype=np.float64)
        a, b = F[:, [1, 2, 0]], F[:, [2, 0, 1]]  # the edge opposite each corner
        self.rows = np.concatenate([a.ravel(), b.ravel(), a.ravel(), b.ravel()])
        self.cols = np.concatenate([b.ravel(), a.ravel(), a.ravel(), b.ravel()])
        # corner gradients (F, 3) -> vertices
        self.gather = coo_matrix((np.ones(3 * len(F)), (F.ravel(), np.arange(3 * len(F)))),
                                 shape=(self.n, 3 * len(F))).tocsr()

    def _terms(self, X):
        """Per triangle: ``|J|_F^2`` of the flat triangle's map, its area, the spherical triangle's area, the
        numerator and denominator of that area's half-angle tangent, the Gram matrix's inverse and edge vectors."""
        F = self.F
        a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
        DQ = np.stack([b - a, c - a], axis=2)
        G = np.swapaxes(DQ, 1, 2) @ DQ
        det = G[:, 0, 0] * G[:, 1, 1] - G[:, 0, 1] ** 2
        Ginv = np.empty_like(G)
        Ginv[:, 0, 0], Ginv[:, 1, 1] = G[:, 1, 1] / det, G[:, 0, 0] / det
        Ginv[:, 0, 1] = Ginv[:, 1, 0] = -G[:, 0, 1] / det
        M = self.M
        J2 = M[:, 0, 0] * Ginv[:, 0, 0] + 2.0 * M[:, 0, 1] * Ginv[:, 0, 1] + M[:, 1, 1] * Ginv[:, 1, 1]
        num = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = 1.0 + np.einsum("ij,ij->i", a, b) + np.einsum("ij,ij->i", b, c) + np.einsum("ij,ij->i", c, a)
        return J2, 0.5 * np.sqrt(np.maximum(det, 0.0)), 2.0 * np.arctan2(num, den), num, den, Ginv, DQ

    def energy(self, X) -> float:
        """``E = sum_t area(P_t) |J_t|^2 / 2`` with ``J_t`` the flat triangle's map scaled to the spherical
        triangle's area: ``|J_t|^2 = |J_flat|^2 area(Q_flat) / area(Q_sphere)``.

        >>> from datasets_synthetic.closed_meshes import sphere_mesh
        >>> m = sphere_mesh(level=2)
        >>> S = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:])
        >>> E = S.energy(m.points)  # the identity: |J_flat|^2 = 2, E = sum area(P_t)^2 / area_sphere(Q_t)
        >>> bool(0.98 * S.total < E < S.total)  # S.total: the mesh's area; flat areas < spherical ones
        True
        """
        J2, flat, sph = self._terms(X)[:3]
        return 0.5 * float(self.area @ (J2 * flat / sph))

    def gradient(self, X) -> tuple:
        """``(E, dE/dX, spherical areas)``, by the product rule: ``d(area(P) |J_flat|^2 / 2) / dD_Q =
        -area(P) D_Q G^-1 M G^-1`` (``D_Q`` the flat triangle's edge vectors, ``G = D_Q^T D_Q``, ``M`` the mesh
        triangle's Gram matrix), the flat area's derivative ``n x (c - b) / 2`` at ``a`` (``n`` its unit normal)
        and the spherical area's, ``2 atan2(num, den)`` with ``num = det[a, b, c]``, ``den = 1 + a.b + b.c +
        c.a``.

        >>> from datasets_synthetic.closed_meshes import ellipsoid_mesh
        >>> m = ellipsoid_mesh(level=2)
        >>> S = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:])
        >>> X = m.points / np.linalg.norm(m.points, axis=1, keepdims=True)
        >>> E, g, areas = S.gradient(X)
        >>> dX = 1e-7 * np.random.default_rng(0).normal(size=X.shape)
        >>> bool(np.isclose(S.energy(X + dX) - S.energy(X - dX), 2 * np.vdot(g, dX), rtol=1e-5))
        True
        """
        J2, flat, sph, num, den, Ginv, DQ = self._terms(X)
        F = self.F
        dD = -self.area[:, None, None] * (DQ @ (Ginv @ (self.M @ Ginv)))  # (F, 3, 2)
        dJ = np.stack([-dD[:, :, 0] - dD[:, :, 1], dD[:, :, 0], dD[:, :, 1]], axis=1)  # (F, 3 corners, 3)
        a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        d_flat = 0.5 * np.stack([np.cross(n, c - b), np.cross(n, a - c), np.cross(n, b - a)], axis=1)
        d_num = np.stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)], axis=1)
        d_den = np.stack([b + c, c + a, a + b], axis=1)
        d_sph = 2.0 * (den[:, None, None] * d_num - num[:, None, None] * d_den) / (num * num + den * den)[:, None, None]
        e = 0.5 * self.area * J2  # the flat energy per triangle
        r = flat / sph
        corner = dJ * r[:, None, None] + (e / sph)[:, None, None] * d_flat - (e * r / sph)[:, None, None] * d_sph
        g = self.gather @ corner.reshape(-1, 3)
        return float(e @ r), g, sph

    def preconditioner(self, sph):
        """The relaxation's preconditioner (sparse ``(V, V)``, symmetric positive definite) for the spherical
        triangle areas ``sph``: the mesh's cotangent stiffness, triangle ``t`` weighted by
        ``area(P_t) / sph_t``, plus the same weights as a lumped mass (for the Möbius directions, which the
        stiffness does not see).

        >>> from datasets_synthetic.closed_meshes import sphere_mesh
        >>> m = sphere_mesh(level=1)
        >>> S = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:])
        >>> K = S.preconditioner(S.gradient(m.points)[2]).toarray()
        >>> bool(np.allclose(K, K.T) and np.linalg.eigvalsh(K).min() > 0)
        True
        """
        from scipy.sparse import coo_matrix, diags

        w = self.area / sph
        w /= np.median(w)
        c = (w[:, None] * self.cot).ravel()
        K = coo_matrix((np.concatenate([-c, -c, c, c]), (self.rows, self.cols)), shape=(self.n, self.n)).tocsr()
        mass = np.bincount(self.F.ravel(), weights=np.repeat(w * sph / 3.0, 3), minlength=self.n)
        return (K + diags(mass)).tocsc()

    def report(self, X) -> dict:
        """The stretch of the map to ``X``: ``"l2"`` (normalized: 1 is optimal), ``"l2_max"``, ``"l2_p95"``,
        ``"area_ratio_max"`` and ``"area_ratio_p95"`` (:func:`.sphere.spherical_parametrization`).

        >>> from datasets_synthetic.closed_meshes import stretched_blob
        >>> m = stretched_blob(level=2)
        >>> S = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:])
        >>> X = m.points / np.linalg.norm(m.points, axis=1, keepdims=True)  # central projection
        >>> r = S.report(X)
        >>> bool(r["l2"] > 1.5 and r["l2_max"] >= r["l2_p95"] and r["area_ratio_max"] >= 1.0)
        True
        """
        J2, flat, sph = self._terms(X)[:3]
        tot = float(sph.sum())
        per = np.sqrt(0.5 * J2 * flat / sph * tot / self.total)
        ratio = (self.area / self.total) / (sph / tot)
        ratio = np.maximum(ratio, 1.0 / ratio)
        return {"l2": float(np.sqrt(self.energy(X) * tot) / self.total),
                "l2_max": float(per.max()), "l2_p95": float(np.percentile(per, 95)),
                "area_ratio_max": float(ratio.max()), "area_ratio_p95": float(np.percentile(ratio, 95))}

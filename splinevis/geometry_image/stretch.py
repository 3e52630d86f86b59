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

The inverse term (``inverse`` > 0): ``inverse s0^4 sum_t area(P_t) |J_t^-1|^2 / 2`` with ``s0^2 = area(P) / (4 pi)``,
the L2 stretch of the map from the mesh to the sphere, normalized like the first term so that at a map of uniform
scale both are equal: the symmetric Dirichlet energy [SmithSchaefer2015] of the map scaled to the sphere's area.
For a 2 x 2 map ``|J^-1|_F^2 = |J|_F^2 / det(J)^2`` and ``det J_t = area(P_t) / area_sphere(Q_t)`` after the
scaling, so the term is ``|J_flat|^2 area(Q_t) area_sphere(Q_t) / area(P_t)`` per triangle, made of the factors
the first term has: its gradient is theirs with other coefficients. The L2 stretch alone never penalizes a
direction in which the sphere oversamples the mesh (a small singular value of ``J``); the inverse term does, so
it keeps the map nearer conformal where the stretch alone would draw the sphere out into bands
(:data:`.hierarchy.LEVEL_INVERSE`). With ``inverse = 0`` every operation is the first term's alone (the same bits
as without the option).

Why our own code: the energy is the spherical parametrization's; libigl gives the cotangent entries.
"""

from __future__ import annotations

import numpy as np

from .._reproducible import dot, weighted_quantile

__all__ = ["StretchEnergy"]


def _dot(u, v):
    """Column-wise dot products of ``(3, N)`` rows."""
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def _cross(u, v):
    """Column-wise cross products of ``(3, N)`` rows (numpy's ``cross`` moves axes and copies)."""
    return np.stack([u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]])


class StretchEnergy:
    """The L2 stretch of maps of the mesh ``(P, F)`` (``(V, 3)`` points, ``(F, 3)`` outward triangles) onto the
    unit sphere, as a function of the vertices' images ``X``: energy, gradient, preconditioner and report
    (module docstring); ``inverse`` weighs the inverse map's stretch added to the energy (0: the L2 stretch alone;
    the report is the L2 stretch's either way).

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> m = sphere_mesh(level=2)
    >>> S = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:])
    >>> bool(1.0 <= S.report(m.points)["l2"] < 1.0 + 1e-5)  # the identity (optimal up to flat / spherical)
    True
    """

    def __init__(self, P, F, inverse: float = 0.0):
        import igl
        from scipy.sparse import coo_matrix

        P = np.asarray(P, dtype=np.float64)
        F = np.asarray(F, dtype=np.int64)
        self.F = F
        self.n = len(P)
        DP = np.stack([P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]], axis=2)  # (F, 3, 2)
        self.M = np.einsum("fki,fkj->fij", DP, DP)  # Gram matrices of the mesh triangles
        det = self.M[:, 0, 0] * self.M[:, 1, 1] - self.M[:, 0, 1] * self.M[:, 1, 0]  # not np.linalg (machine bits)
        self.area = 0.5 * np.sqrt(np.maximum(det, 0.0))
        self.total = float(np.add.reduce(self.area))
        # the inverse map's stretch, weighted (:attr:`inverse`): lambda s0^4 with s0^2 = area(P) / (4 pi), so that
        # the two terms are equal for a map of uniform scale
        self.inverse = float(inverse)
        self._w = self.inverse * (self.total / (4.0 * np.pi)) ** 2
        # the mesh's cotangent stiffness per triangle: cot(angle at corner k) / 2 on the edge opposite corner k
        self.cot = np.asarray(igl.cotmatrix_entries(P, F), dtype=np.float64)
        a, b = F[:, [1, 2, 0]], F[:, [2, 0, 1]]  # the edge opposite each corner
        self.rows = np.concatenate([a.ravel(), b.ravel(), a.ravel(), b.ravel()])
        self.cols = np.concatenate([b.ravel(), a.ravel(), a.ravel(), b.ravel()])
        # corner gradients (F, 3) -> vertices
        self.gather = coo_matrix((np.ones(3 * len(F)), (F.ravel(), np.arange(3 * len(F)))),
                                 shape=(self.n, 3 * len(F))).tocsr()
        # the same per component: rows (3, F) of coordinates, corner k of triangle t at k F + t
        self._m = (self.M[:, 0, 0].copy(), self.M[:, 0, 1].copy(), self.M[:, 1, 1].copy())
        self._corners = np.ascontiguousarray(F.T).ravel()
        self._F = [np.ascontiguousarray(F[:, k]) for k in range(3)]

    def _terms(self, X):
        """Per triangle, as rows ``(3, F)`` of coordinates: ``|J|_F^2`` of the flat triangle's map, its area, the
        spherical triangle's area, the numerator and denominator of that area's half-angle tangent, the Gram
        matrix's inverse ``(i00, i01, i11)`` and the corners and edge vectors ``(a, b, c, b - a, c - a)``."""
        XT = np.ascontiguousarray(X.T)
        a, b, c = XT[:, self._F[0]], XT[:, self._F[1]], XT[:, self._F[2]]
        e1, e2 = b - a, c - a
        g00, g01, g11 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
        det = g00 * g11 - g01 * g01
        i00, i01, i11 = g11 / det, -g01 / det, g00 / det
        m00, m01, m11 = self._m
        J2 = m00 * i00 + 2.0 * m01 * i01 + m11 * i11
        num = _dot(a, _cross(b, c))
        den = 1.0 + _dot(a, b) + _dot(b, c) + _dot(c, a)
        return (J2, 0.5 * np.sqrt(np.maximum(det, 0.0)), 2.0 * np.arctan2(num, den), num, den, (i00, i01, i11),
                (a, b, c, e1, e2))

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
        return self.energy_and_area(X)[0]

    def energy_and_area(self, X) -> tuple:
        """``(E, A)``: the energy (:meth:`energy`) and the sum ``A`` of the spherical triangles' areas, ``4 pi``
        times the map's degree when no triangle is flipped (a step that keeps every triangle outward can still
        jump to a map that covers the sphere twice: :mod:`.relax` refuses it by ``A``).

        >>> from datasets_synthetic.closed_meshes import sphere_mesh
        >>> m = sphere_mesh(level=2)
        >>> S = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:])
        >>> round(S.energy_and_area(m.points)[1] / np.pi, 12)
        4.0
        """
        J2, flat, sph = self._terms(X)[:3]
        if self._w:
            return (0.5 * dot(self.area, J2 * flat / sph + (self._w / (self.area * self.area)) * J2 * flat * sph),
                    float(np.add.reduce(sph)))
        return 0.5 * dot(self.area, J2 * flat / sph), float(np.add.reduce(sph))

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
        >>> Si = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:], inverse=2.0)  # with the inverse term
        >>> Ei, gi, _ = Si.gradient(X)
        >>> bool(Ei > E and np.isclose(Si.energy(X + dX) - Si.energy(X - dX), 2 * np.vdot(gi, dX), rtol=1e-5))
        True
        """
        J2, flat, sph, num, den, (i00, i01, i11), (a, b, c, e1, e2) = self._terms(X)
        m00, m01, m11 = self._m
        # A = G^-1 M G^-1 (symmetric), from T = M G^-1
        t00, t01 = m00 * i00 + m01 * i01, m00 * i01 + m01 * i11
        t10, t11 = m01 * i00 + m11 * i01, m01 * i01 + m11 * i11
        A00, A01, A11 = i00 * t00 + i01 * t10, i00 * t01 + i01 * t11, i01 * t01 + i11 * t11
        e = 0.5 * self.area * J2  # the flat energy per triangle
        r = flat / sph
        # corner k: r dJ_k + (e / sph) d_flat_k - (e r / sph) d_sph_k, d_sph_k = w (den d_num_k - num d_den_k)
        if self._w:  # the inverse term e q flat sph, q = w / area^2: its factors' coefficients added
            q = self._w / (self.area * self.area)
            kJ, kf, ks = r + q * flat * sph, e / sph + q * e * sph, e * r / sph - q * e * flat
        else:  # (the stretch alone, in the operations it always had: the same bits)
            kJ, kf, ks = r, e / sph, e * r / sph
        dD0 = (-kJ * self.area) * (e1 * A00 + e2 * A01)
        dD1 = (-kJ * self.area) * (e1 * A01 + e2 * A11)
        n = _cross(e1, e2)
        n *= (0.5 * kf) / np.sqrt(_dot(n, n))  # (e / sph) n / 2
        beta = (2.0 * ks) / (num * num + den * den)
        bd, bn = beta * den, beta * num
        ca = -dD0 - dD1 + _cross(n, e2 - e1) - bd * _cross(b, c) + bn * (b + c)
        cb = dD0 - _cross(n, e2) - bd * _cross(c, a) + bn * (c + a)
        cc = dD1 + _cross(n, e1) - bd * _cross(a, b) + bn * (a + b)
        g = np.empty((self.n, 3))
        for j in range(3):
            g[:, j] = np.bincount(self._corners, weights=np.concatenate([ca[j], cb[j], cc[j]]), minlength=self.n)
        if self._w:
            return dot(e, r + q * flat * sph), g, sph
        return dot(e, r), g, sph

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
        aniso = self._anisotropy(J2, flat)
        return {"l2": float(np.sqrt(self.energy(X) * tot) / self.total),
                "l2_max": float(per.max()), "l2_p95": float(np.percentile(per, 95)),
                "area_ratio_max": float(ratio.max()), "area_ratio_p95": float(np.percentile(ratio, 95)),
                "anisotropy_median": weighted_quantile(aniso, self.area, 0.5),
                "anisotropy_p95": weighted_quantile(aniso, self.area, 0.95)}

    def anisotropy(self, X) -> np.ndarray:
        """Per triangle, ``sigma_1 / sigma_2`` of the linear map ``J_t`` from the flat triangle on the sphere to the
        mesh triangle (its singular values): how much longer one way than the other a square of the sphere comes
        out on the mesh, so how unevenly a grid of samples on the sphere covers it there (1: conformal). From the
        2 x 2 invariants: ``sigma_1^2 + sigma_2^2 = |J|_F^2`` and ``sigma_1 sigma_2 = area(P_t) / area(Q_t)``,
        ``sigma_1 / sigma_2 = (f + sqrt(f^2 - 4)) / 2`` with ``f = |J|_F^2 / det J`` (at least 2).

        >>> from datasets_synthetic.closed_meshes import sphere_mesh
        >>> m = sphere_mesh(level=2)
        >>> S = StretchEnergy(m.points, m.faces.reshape(-1, 4)[:, 1:])
        >>> bool(np.allclose(S.anisotropy(m.points), 1.0, atol=1e-6))  # the identity: conformal
        True
        >>> stretched = m.points * [4.0, 1.0, 1.0]  # the sphere's images squeezed 4 : 1 along x
        >>> S4 = StretchEnergy(stretched, m.faces.reshape(-1, 4)[:, 1:])
        >>> bool(S4.anisotropy(m.points).max() > 3.9)  # near the equator x: 4 : 1
        True
        """
        return self._anisotropy(*self._terms(X)[:2])

    def _anisotropy(self, J2, flat):
        """:meth:`anisotropy` from ``|J_flat|^2`` and the flat triangles' areas (:meth:`_terms`)."""
        f = np.maximum(J2 * flat / self.area, 2.0)  # |J|^2 / det J, scale-free (2 for a similarity)
        return 0.5 * (f + np.sqrt(f * f - 4.0))


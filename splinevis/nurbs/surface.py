"""Non-uniform rational B-spline surfaces in float64: points, derivatives, normals, curvature.

``S(u, v) = sum_k sum_l N_k,p(u) N_l,q(v) w_kl P_kl / sum_k sum_l N_k,p(u) N_l,q(v) w_kl``
[PieglTiller1997, eq. (4.15)]. Derivatives of the homogeneous surface ``A^(k,l)`` come from the basis
derivatives (A3.6), the rational ones by the quotient rule (A4.4, eq. (4.20)). Normals and curvatures
follow from the first and second fundamental forms [DoCarmo1976, sec. 3-3]. Everything is vectorized over
the parameters; this is the float64 twin of the fragment program (``glsl/programs/nurbs.glsl``).
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

from .basis import check_knots, ders_basis_funs, find_span

__all__ = ["NurbsSurface"]


@dataclass(frozen=True, eq=False)
class NurbsSurface:
    """A (rational) B-spline surface patch.

    Parameters
    ----------
    degree : (p, q)
        Degrees in u and v, each 1..7.
    knots : (U, V)
        Knot vectors, ``len(U) == nu + p + 1``, ``len(V) == nv + q + 1``; clamped or not, interior
        knots repeated up to the degree (a crease at multiplicity p).
    control_points : (nu, nv, 3) array
        ``P[k, l]``: k along u, l along v.
    weights : (nu, nv) array or None
        Positive weights; None for a polynomial (non-rational) surface.
    name : str
        The patch's identity (a file's entity or object name).

    Examples
    --------
    >>> s = NurbsSurface.bilinear([[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 1]])
    >>> s.evaluate([0.5], [0.5])
    array([[0.5 , 0.5 , 0.25]])
    >>> NurbsSurface((1, 1), ([0, 0, 1, 1], [0, 0, 1, 1]), np.zeros((2, 2, 3)), weights=[[1, 1], [1, 0]])
    Traceback (most recent call last):
    ValueError: weights must be positive and finite; weights[1, 1] = 0.0 (a zero or negative weight puts the surface at infinity or flips it; fix the model).
    """

    degree: tuple
    knots: tuple
    control_points: np.ndarray
    weights: np.ndarray | None = None
    name: str = ""

    def __post_init__(self):
        P = np.array(self.control_points, dtype=np.float64)
        if P.ndim != 3 or P.shape[2] != 3:
            raise ValueError(f"control_points must have shape (nu, nv, 3), got {P.shape}.")
        if not np.isfinite(P).all():
            idx = tuple(int(i) for i in np.argwhere(~np.isfinite(P))[0])
            raise ValueError(f"control_points must be finite; control_points{list(idx)} = {float(P[idx])!r}.")
        p, q = (int(d) for d in self.degree)
        U = check_knots(self.knots[0], p, P.shape[0], "knots[0] (u)")
        V = check_knots(self.knots[1], q, P.shape[1], "knots[1] (v)")
        W = None
        if self.weights is not None:
            W = np.array(self.weights, dtype=np.float64)
            if W.shape != P.shape[:2]:
                raise ValueError(f"weights must have shape {P.shape[:2]} (one per control point), got {W.shape}.")
            bad = ~(np.isfinite(W) & (W > 0))
            if bad.any():
                i, j = (int(v) for v in np.argwhere(bad)[0])
                raise ValueError(f"weights must be positive and finite; weights[{i}, {j}] = {float(W[i, j])!r} (a zero or "
                                 "negative weight puts the surface at infinity or flips it; fix the model).")
            W.setflags(write=False)
        for a in (P, U, V):
            a.setflags(write=False)
        object.__setattr__(self, "degree", (p, q))
        object.__setattr__(self, "knots", (U, V))
        object.__setattr__(self, "control_points", P)
        object.__setattr__(self, "weights", W)

    # ---------------------------------------------------------------------------------------------
    @classmethod
    def bilinear(cls, p00, p10, p01=None, p11=None, name: str = "") -> "NurbsSurface":
        """The bilinear patch through four corners (``bilinear([p00, p10], [p01, p11])`` also works).

        >>> NurbsSurface.bilinear([[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]).shape
        (2, 2)
        """
        if p01 is None:
            (p00, p10), (p01, p11) = p00, p10
        P = np.array([[p00, p01], [p10, p11]], dtype=np.float64)
        return cls((1, 1), ([0.0, 0.0, 1.0, 1.0], [0.0, 0.0, 1.0, 1.0]), P, name=name)

    @property
    def shape(self) -> tuple:
        """Control net size ``(nu, nv)``.

        >>> from splinevis.nurbs.exact import torus
        >>> torus().shape
        (9, 9)
        """
        return self.control_points.shape[:2]

    @property
    def rational(self) -> bool:
        """True when some weights differ (a surface with all weights equal is polynomial).

        >>> NurbsSurface.bilinear([[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]).rational
        False
        """
        return self.weights is not None and bool(np.ptp(self.weights) > 0)

    @property
    def domain(self) -> tuple:
        """``((u0, u1), (v0, v1))``, the parameter rectangle.

        >>> NurbsSurface.bilinear([[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]).domain
        ((0.0, 1.0), (0.0, 1.0))
        """
        (p, q), (U, V) = self.degree, self.knots
        nu, nv = self.shape
        return (float(U[p]), float(U[nu])), (float(V[q]), float(V[nv]))

    def homogeneous(self) -> np.ndarray:
        """``(nu, nv, 4)`` control points ``(w P, w)``.

        >>> NurbsSurface.bilinear([[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]).homogeneous()[1, 1]
        array([1., 1., 0., 1.])
        """
        w = np.ones(self.shape) if self.weights is None else self.weights
        return np.concatenate([self.control_points * w[..., None], w[..., None]], axis=-1)

    # ---------------------------------------------------------------------------------------------
    def derivatives(self, u, v, order: int = 2) -> np.ndarray:
        """``SKL[..., k, l, :]`` = the derivative d^(k+l) S / du^k dv^l, for ``k + l <= order``
        [PieglTiller1997, A3.6 and A4.4]; entries with ``k + l > order`` are zero.

        Returns ``(len(u), order + 1, order + 1, 3)``.

        Examples
        --------
        >>> s = NurbsSurface.bilinear([[0, 0, 0], [2, 0, 0]], [[0, 1, 0], [2, 1, 2]])
        >>> d = s.derivatives([0.5], [0.5], 1)[0]
        >>> d[1, 0], d[0, 1]  # S_u, S_v
        (array([2., 0., 1.]), array([0., 1., 1.]))
        """
        u, v = self._params(u, v)
        return _rational(self._homogeneous_derivatives(u, v, order), order)

    def evaluate(self, u, v) -> np.ndarray:
        """Points ``S(u, v)``, shape ``(len(u), 3)``.

        >>> NurbsSurface.bilinear([[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 1]]).evaluate([1.0], [1.0])
        array([[1., 1., 1.]])
        """
        return self.derivatives(u, v, 0)[:, 0, 0]

    def normal(self, u, v) -> np.ndarray:
        """Unit normals ``S_u x S_v / |S_u x S_v|``; where that vanishes (a pole, a collapsed row) the limit
        from the second derivatives, ``S_u x S_uv + S_uv x S_v`` (or ``S_u x S_vv``, ``S_uu x S_v``).

        >>> NurbsSurface.bilinear([[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]).normal([0.3], [0.6])
        array([[0., 0., 1.]])
        """
        u, v = self._params(u, v)
        return self._normal(u, v, self.derivatives(u, v, 2))

    def _normal(self, u, v, SKL) -> np.ndarray:
        """:meth:`normal` from the derivatives ``SKL`` (order 2) at ``(u, v)`` already evaluated."""
        n, degenerate = _unit_normal(SKL, with_mask=True)
        if degenerate.any():  # orient the limit normal like the regular normal just inside the domain
            (u0, u1), (v0, v1) = self.domain
            h = 1e-7
            ui = u[degenerate] + h * (u1 - u0) * np.sign(0.5 * (u0 + u1) - u[degenerate])
            vi = v[degenerate] + h * (v1 - v0) * np.sign(0.5 * (v0 + v1) - v[degenerate])
            near = _unit_normal(self.derivatives(ui, vi, 2))
            flip = np.einsum("ij,ij->i", n[degenerate], near) < 0
            n[np.flatnonzero(degenerate)[flip]] *= -1
        return n

    def curvature(self, u, v) -> dict:
        """Gaussian ``K``, mean ``H`` and principal curvatures ``k1 >= k2`` with respect to :meth:`normal`.

        ``K = (LN - M^2) / (EG - F^2)``, ``H = (EN - 2FM + GL) / (2 (EG - F^2))``, ``k = H +- sqrt(H^2 - K)``
        [DoCarmo1976, sec. 3-3]. Returns a dict of ``(len(u),)`` arrays ``K, H, k1, k2``; NaN where the
        parametrization degenerates (``EG - F^2`` at rounding level: poles, collapsed rows).

        Examples
        --------
        >>> from splinevis.nurbs.exact import cylinder
        >>> c = cylinder(radius=2.0).curvature([0.3], [0.4])
        >>> round(float(c["K"][0]), 12) + 0.0, round(abs(float(c["H"][0])), 12)  # K = 0, |H| = 1/(2r)
        (0.0, 0.25)
        """
        return fundamental_curvature(self.derivatives(u, v, 2))

    # ---------------------------------------------------------------------------------------------
    def _params(self, u, v):
        u = np.atleast_1d(np.asarray(u, dtype=np.float64)).ravel()
        v = np.atleast_1d(np.asarray(v, dtype=np.float64)).ravel()
        if u.shape != v.shape:
            raise ValueError(f"u and v must have the same number of parameters, got {u.size} and {v.size}.")
        return u, v

    def _homogeneous_derivatives(self, u, v, order):
        (p, q), (U, V) = self.degree, self.knots
        Pw = self.homogeneous()
        su, sv = find_span(p, U, u), find_span(q, V, v)
        Nu = ders_basis_funs(su, u, p, order, U)  # (m, d+1, p+1)
        Nv = ders_basis_funs(sv, v, q, order, V)
        iu = su[:, None] - p + np.arange(p + 1)  # (m, p+1)
        iv = sv[:, None] - q + np.arange(q + 1)
        net = Pw[iu[:, :, None], iv[:, None, :]]  # (m, p+1, q+1, 4)
        # A^(k,l) = sum_a N_u^(k)[a] (sum_b N_v^(l)[b] Pw[a, b]): two contractions (a third of the products of
        # the one three-operand sum; numpy's own loops, not BLAS, so the bits do not follow the BLAS kernels)
        rows = np.einsum("mlb,mabc->malc", Nv, net)
        return np.einsum("mka,malc->mklc", Nu, rows)


def _rational(Aw: np.ndarray, order: int) -> np.ndarray:
    """The surface's derivatives ``SKL`` (m, d+1, d+1, 3) from the homogeneous ones ``Aw`` (m, d+1, d+1, 4) by
    the quotient rule [PieglTiller1997, A4.4]."""
    A, w = Aw[..., :3], Aw[..., 3]
    SKL = np.zeros_like(A)
    for k in range(order + 1):
        for l in range(order - k + 1):
            val = A[:, k, l].copy()
            for j in range(1, l + 1):
                val -= comb(l, j) * w[:, 0, j, None] * SKL[:, k, l - j]
            for i in range(1, k + 1):
                val -= comb(k, i) * w[:, i, 0, None] * SKL[:, k - i, l]
                v2 = np.zeros_like(val)
                for j in range(1, l + 1):
                    v2 += comb(l, j) * w[:, i, j, None] * SKL[:, k - i, l - j]
                val -= comb(k, i) * v2
            SKL[:, k, l] = val / w[:, 0, 0, None]
    return SKL


def _unit_normal(SKL: np.ndarray, with_mask: bool = False):
    Su, Sv = SKL[:, 1, 0], SKL[:, 0, 1]
    n = np.cross(Su, Sv)
    size = np.linalg.norm(n, axis=-1)
    # degenerate when |S_u x S_v| is negligible against the larger tangent squared: a vanishing tangent
    # (a pole) is rounding noise of the size eps |P| in float64, whose direction is arbitrary, so a
    # test relative to |S_u| |S_v| would take that noise for a tangent
    scale = np.maximum(np.linalg.norm(Su, axis=-1), np.linalg.norm(Sv, axis=-1)) ** 2
    degenerate = size <= 1e-12 * scale + (scale == 0)
    if degenerate.any():
        Suu, Suv, Svv = SKL[degenerate, 2, 0], SKL[degenerate, 1, 1], SKL[degenerate, 0, 2]
        a, b = Su[degenerate], Sv[degenerate]
        # first non-vanishing term of the expansion of S_u(u+h) x S_v(v+k) about the singular point
        cand = [np.cross(a, Suv) + np.cross(Suv, b), np.cross(a, Svv), np.cross(Suu, b), np.cross(Suu, Svv)]
        alt = cand[0]
        for c in cand[1:]:
            small = np.linalg.norm(alt, axis=-1) <= 1e-12
            alt = np.where(small[:, None], c, alt)
        n = n.copy()
        n[degenerate] = alt
        size = np.linalg.norm(n, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = n / size[:, None]
    return (unit, degenerate) if with_mask else unit


def fundamental_curvature(SKL: np.ndarray) -> dict:
    """Curvatures from derivatives ``SKL`` (as :meth:`NurbsSurface.derivatives` with order 2).

    >>> SKL = np.zeros((1, 3, 3, 3)); SKL[0, 1, 0] = [1, 0, 0]; SKL[0, 0, 1] = [0, 1, 0]
    >>> SKL[0, 2, 0] = [0, 0, 2.0]  # z = u^2 at the origin: k1 = 2, k2 = 0
    >>> {k: float(v[0]) for k, v in fundamental_curvature(SKL).items()}
    {'K': 0.0, 'H': 1.0, 'k1': 2.0, 'k2': 0.0}
    """
    Su, Sv, Suu, Suv, Svv = SKL[:, 1, 0], SKL[:, 0, 1], SKL[:, 2, 0], SKL[:, 1, 1], SKL[:, 0, 2]
    n = _unit_normal(SKL)
    E, F, G = (np.einsum("ij,ij->i", a, b) for a, b in ((Su, Su), (Su, Sv), (Sv, Sv)))
    L, M, N = (np.einsum("ij,ij->i", a, n) for a in (Suu, Suv, Svv))
    det = E * G - F * F
    # where the parametrization degenerates (a pole, a collapsed row: S_u x S_v = 0 up to rounding) the
    # formulas are 0/0; the curvature there is a limit they cannot give: NaN, not a rounding-sized quotient
    # (a collapsed row leaves |S_u| at rounding level, ~1e-16 |S_v|: a ratio no regular point comes near)
    eps = np.finfo(float).eps
    regular = (det > 64.0 * eps * E * G) & (np.minimum(E, G) > (1e4 * eps) ** 2 * np.maximum(E, G))
    det = np.where(regular, det, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        K = (L * N - M * M) / det
        H = (E * N - 2 * F * M + G * L) / (2 * det)
    disc = np.sqrt(np.maximum(H * H - K, 0.0))
    return {"K": K, "H": H, "k1": H + disc, "k2": H - disc}

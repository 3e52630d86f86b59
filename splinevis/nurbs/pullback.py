"""Pull a 3-D curve back onto a NURBS surface: the 2-D trim curve in ``(u, v)`` of an edge that lies on it.

Why our own: rhino3dm exposes a Brep's 3-D edges but not its 2-D trim curves, and none of the libraries
the project keeps pulls a NURBS curve back onto a NURBS surface in numpy (OpenCASCADE does, in C++, for
IGES and STEP files only). The method is the textbook one:

* **Point inversion** [PieglTiller1997, sec. 6.1]: the foot ``(u, v)`` of a point ``P`` is a root of
  ``f = S_u . (S - P)``, ``g = S_v . (S - P)``, found by Newton's method (eq. 6.6) with the full Jacobian
  ``[[|S_u|^2 + r . S_uu, S_u . S_v + r . S_uv], [.., |S_v|^2 + r . S_vv]]``, ``r = S - P``, or the first
  fundamental form alone where that matrix is not positive definite. **Vectorized**: all samples of all
  curves handed over together (:func:`pull_back_many`: every edge of a face) are one batch; each Newton
  round evaluates the surface once for the whole batch, and a point leaves the batch after a step below
  ``1e-13`` of the domain (quadratic convergence: its error is then of the order of that step squared).
  Every sample starts from the nearest point of a coarse grid (4 points per knot span, in a k-d tree);
  then, where a foot is off the surface and farther than a neighbour's (a wrong sheet or side of a seam),
  from the neighbours' feet as well, keeping the closer (continuation, in batch). The cost is in the
  number of rounds, not in the batch size: one face's edges cost about what one edge alone does.
* **Closed surfaces**: a direction is closed when ``S(u0, v) = S(u1, v)``. There Newton runs on the
  unwrapped parameter (evaluated modulo the period), so the 2-D curve stays continuous across the seam
  instead of jumping by a period (consecutive feet unwrapped by whole periods, ``numpy.unwrap``); a run
  without a given start is shifted so that its median point lies in the domain; a caller may shift a whole
  curve by the period afterwards.
* **Poles** (``S_u = 0``, a collapsed row of control points): ``u`` is undefined at the pole; it is
  taken from the regular neighbours along the curve (linear interpolation inside, the nearest value at
  the ends: the limit along the curve, exact for meridians).
* **Fit and check**: a cubic interpolating B-spline (``scipy.interpolate.make_interp_spline`` on the
  curve parameter) through the feet, refined by adding the midpoints of the intervals where the fitted
  curve mapped through ``S`` strays more than the tolerance from the 3-D curve at 7 test points between
  neighbouring samples. The reported ``deviation`` is the largest such distance on the final test points.
  The **edge-to-surface distance** (``|C(t) - S(foot)|`` at the samples) is a floor on any pull-back: a
  file's edges lie within its model tolerance of their surfaces, so that tolerance is what can be asked
  (``strict``, the default: a curve farther than ``max_distance``, or a fit that does not reach the
  tolerance, is an error). Real files hold edges farther than the model tolerance from their surfaces
  (a Brep edge carries its own tolerance, often larger; the Rhino 4 sample v4_MechPartA.3dm holds edges 9
  model tolerances off, ending past the surface's side). **Lenient** pull-backs (``strict=False``) fit such a
  curve within ``tolerance`` plus its measured distance and return the best fit found at
  ``max_samples`` with the reason in ``note``; the caller reports the deviation.

A curve with corners is pulled back piece by piece between its break parameters (e.g. knots of a
B-spline of multiplicity >= its degree), one :class:`~splinevis.nurbs.model.TrimCurve` per piece.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .basis import at_fraction, check_knots, into_domain, ders_basis_funs, find_span
from .model import TrimCurve
from .surface import NurbsSurface

__all__ = ["Pullback", "curve_evaluator", "pull_back", "pull_back_many", "reverse_curve"]

_TEST_FRACTIONS = np.arange(1, 8) / 8.0  # test points between neighbouring samples
_POLE = 1e-7  # |S_u| below this times |S_v|: u is undefined (a pole)
_STOP = 1e-13  # Newton stops after a step below this fraction of the domain
_FIRST_SAMPLES = 9  # samples of a piece before any refinement
_ROUNDING = 1e-12  # lenient pull-backs: no fit is asked to be closer than this fraction of the surface's size


@dataclass(frozen=True)
class Pullback:
    """A pulled-back curve: its 2-D pieces, in the curve's order and direction, and what was measured.

    ``deviation``: max ``|S(c(t)) - C(t)|`` over ``checked_at`` (7 parameters between neighbouring samples);
    ``distance``: max distance of the 3-D curve from the surface at the samples; ``samples``: how many;
    ``closed``: whether the surface is closed in u and in v (where a curve may be shifted by the period);
    ``note``: why the fit stopped short of the tolerance (lenient pull-backs only), else empty.

    >>> from splinevis.nurbs.exact import cylinder
    >>> line = lambda t: np.column_stack([np.ones_like(t), np.zeros_like(t), t])  # the cylinder's seam
    >>> r = pull_back(cylinder(), line, (0.0, 1.0), 1e-9)
    >>> len(r.curves), r.deviation < 1e-9, r.samples, r.closed
    (1, True, 9, (True, False))
    """

    curves: tuple
    deviation: float
    distance: float
    samples: int
    checked_at: np.ndarray
    closed: tuple = (False, False)
    note: str = ""


def curve_evaluator(degree: int, knots, control_points, weights=None):
    """``(evaluate, (t0, t1), breaks)`` of a (rational) B-spline curve in any dimension: ``evaluate(t)``
    gives ``(len(t), d)`` points [PieglTiller1997, A4.1]; ``breaks`` are the interior knots of multiplicity
    >= the degree (where the curve may have a corner).

    >>> from splinevis.nurbs.exact import CIRCLE_KNOTS, circle_net
    >>> xy, w = circle_net()
    >>> f, dom, breaks = curve_evaluator(2, CIRCLE_KNOTS, np.column_stack([xy, np.ones(9)]), w)
    >>> np.round(f([0.125, 0.25]), 12).tolist(), dom, breaks
    ([[0.707106781187, 0.707106781187, 1.0], [0.0, 1.0, 1.0]], (0.0, 1.0), (0.25, 0.5, 0.75))
    """
    P = np.asarray(control_points, dtype=np.float64)
    p = int(degree)
    U = check_knots(knots, p, P.shape[0], "curve knots")
    w = np.ones(P.shape[0]) if weights is None else np.asarray(weights, dtype=np.float64)
    if w.shape != (P.shape[0],) or not (np.isfinite(w) & (w > 0)).all():
        raise ValueError(f"curve weights must be {P.shape[0]} positive numbers.")
    lo, hi = float(U[p]), float(U[P.shape[0]])
    values, counts = np.unique(U, return_counts=True)
    breaks = tuple(float(k) for k, c in zip(values, counts) if lo < k < hi and c >= p)

    def evaluate(t):
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=np.float64)), lo, hi)
        span = find_span(p, U, t)
        N = ders_basis_funs(span, t, p, 0, U)[:, 0, :]
        idx = span[:, None] - p + np.arange(p + 1)
        num = np.einsum("ma,mac->mc", N, P[idx] * w[idx][..., None])
        return num / np.einsum("ma,ma->m", N, w[idx])[:, None]

    return evaluate, (lo, hi), breaks


def reverse_curve(curve: TrimCurve) -> TrimCurve:
    """The same 2-D curve run backwards over the same domain.

    >>> c = reverse_curve(TrimCurve(1, [0, 0, 2, 2], [[0, 0], [1, 1]]))
    >>> c.evaluate([0.5]).tolist()
    [[0.75, 0.75]]
    """
    a, b = curve.domain
    return TrimCurve(curve.degree, (a + b) - curve.knots[::-1], curve.control_points[::-1],
                     None if curve.weights is None else curve.weights[::-1])


class _Inverter:
    """Point inversion on one surface: domain, closed directions, a coarse grid for first guesses (in a k-d
    tree). Build it once per surface and pass it to :func:`pull_back` for every curve on that surface."""

    def __init__(self, surface: NurbsSurface):
        from scipy.spatial import cKDTree

        self.s = surface
        self.dom = np.array(surface.domain)  # ((u0, u1), (v0, v1))
        self.period = self.dom[:, 1] - self.dom[:, 0]
        P = surface.control_points.reshape(-1, 3)
        self.scale = max(float(np.ptp(P, axis=0).max()), float(np.abs(P).max()), 1e-300)
        self.closed = np.zeros(2, dtype=bool)
        a = np.linspace(0, 1, 9)
        (u0, u1), (v0, v1) = self.dom
        u, v = at_fraction(u0, u1, a), at_fraction(v0, v1, a)
        for d, (A, B) in enumerate(((surface.evaluate(np.full(9, u0), v), surface.evaluate(np.full(9, u1), v)),
                                    (surface.evaluate(u, np.full(9, v0)), surface.evaluate(u, np.full(9, v1))))):
            self.closed[d] = np.abs(A - B).max() <= 1e-10 * self.scale
        axes = []
        for d in range(2):
            k = np.unique(surface.knots[d])
            k = k[(k >= self.dom[d, 0]) & (k <= self.dom[d, 1])]
            g = np.unique(np.concatenate([np.linspace(x, y, 5) for x, y in zip(k[:-1], k[1:])]))
            axes.append(g if g.size <= 65 else np.linspace(*self.dom[d], 65))
        G = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
        self.grid_uv, self.grid_xyz = G, surface.evaluate(G[:, 0], G[:, 1])
        self.tree = cKDTree(self.grid_xyz)
        self.stop = _STOP * self.period  # a Newton step below this (per direction) is the last one

    def wrap(self, uv):
        """Parameters inside the domain: modulo the period where closed, clamped where open."""
        out = np.empty_like(uv)
        for d in range(2):
            a, b = self.dom[d]
            out[:, d] = into_domain(a + np.mod(uv[:, d] - a, b - a) if self.closed[d] else uv[:, d], a, b)
        return out

    def newton(self, X, uv, iterations: int = 40):
        """Feet of points ``X`` (m, 3) from starts ``uv`` (m, 2), unwrapped in closed directions; all points
        at once, each dropped from the batch after a step below ``stop`` (quadratic convergence: the step
        taken then leaves an error of the order of its square)."""
        uv = np.array(uv, dtype=np.float64)
        X = np.asarray(X, dtype=np.float64)
        active = np.arange(len(uv))
        dot = lambda a, b: np.einsum("ij,ij->i", a, b)  # noqa: E731
        for _ in range(iterations):
            if active.size == 0:
                break
            cur = uv[active]
            w = self.wrap(cur)
            D = self.s.derivatives(w[:, 0], w[:, 1], 2)
            r = D[:, 0, 0] - X[active]
            Su, Sv, Suu, Suv, Svv = D[:, 1, 0], D[:, 0, 1], D[:, 2, 0], D[:, 1, 1], D[:, 0, 2]
            E, F, G = dot(Su, Su), dot(Su, Sv), dot(Sv, Sv)
            J11, J12, J22 = E + dot(r, Suu), F + dot(r, Suv), G + dot(r, Svv)
            bad = (J11 <= 0) | (J11 * J22 - J12 * J12 <= 0)  # not a minimum's Hessian: Gauss-Newton
            J11, J12, J22 = np.where(bad, E, J11), np.where(bad, F, J12), np.where(bad, G, J22)
            damp = 1e-14 * (E + G) + 1e-300  # keeps the step finite at a pole (E = 0)
            J11, J22 = J11 + damp, J22 + damp
            f, g = dot(Su, r), dot(Sv, r)
            det = J11 * J22 - J12 * J12
            step = np.column_stack([-(J22 * f - J12 * g) / det, -(J11 * g - J12 * f) / det])
            step = np.clip(step, -0.25 * self.period, 0.25 * self.period)
            new = cur + step
            for d in range(2):
                if not self.closed[d]:
                    new[:, d] = np.clip(new[:, d], *self.dom[d])
            moved = (np.abs(new - cur) > self.stop).any(axis=1)
            uv[active] = new
            active = active[moved]
        return uv

    def distance(self, X, uv):
        w = self.wrap(uv)
        return np.linalg.norm(self.s.evaluate(w[:, 0], w[:, 1]) - X, axis=1)

    def near(self, uv, ref):
        """``uv`` shifted by whole periods (closed directions) to lie nearest ``ref``."""
        uv = np.array(uv, dtype=np.float64)
        for d in range(2):
            if self.closed[d]:
                uv[..., d] += self.period[d] * np.round((ref[..., d] - uv[..., d]) / self.period[d])
        return uv

    def unwrap(self, uv, start=None):
        """Consecutive feet made continuous in closed directions (each shifted by whole periods to lie
        nearest the one before; the first nearest ``start`` when given, else the run's median point in the
        domain)."""
        uv = np.array(uv, dtype=np.float64)
        if start is not None:
            uv[0] = self.near(uv[0], np.asarray(start, dtype=np.float64))
        for d in range(2):
            if self.closed[d] and len(uv) > 1:
                uv[:, d] = np.unwrap(uv[:, d], period=self.period[d])
        if start is None:  # the whole run by whole periods: its median point inside the domain
            mid = np.median(uv, axis=0)
            uv += self.near(mid, self.dom.mean(axis=1)) - mid
        return uv

    def invert_along(self, X, start=None, rounds: int = 3):
        """Feet of consecutive curve points ``X`` (one run of :meth:`invert_runs`)."""
        return self.invert_runs([X], [start], rounds)[0]

    def invert_runs(self, runs, starts, rounds: int = 3):
        """Feet of the consecutive points of each run (a list of ``(m_k, 3)`` arrays), all runs at once:
        Newton from the nearest grid point, then (``rounds`` times at most) from the neighbours' feet in the
        run where a foot is off the surface and farther than a neighbour's, keeping the closer foot (at
        equal distance the one found first); each run continuous in closed directions (:meth:`unwrap`,
        from its ``start``)."""
        sizes = np.array([len(r) for r in runs])
        X = np.concatenate([np.asarray(r, dtype=np.float64).reshape(-1, 3) for r in runs])
        first = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        last = first + sizes - 1
        i = np.arange(len(X))
        run = np.repeat(np.arange(len(runs)), sizes)
        prev_i, next_i = np.where(np.isin(i, first), i, i - 1), np.where(np.isin(i, last), i, i + 1)
        # neighbours for the distance comparison: inside the run (an end compares with its one neighbour)
        cmp_prev, cmp_next = np.where(prev_i == i, next_i, prev_i), np.where(next_i == i, prev_i, next_i)
        uv = self.newton(X, self.grid_uv[self.tree.query(X)[1]])
        dist = self.distance(X, uv)
        tie = 1e-9 * self.scale  # a foot this close is on the surface: no other can be closer
        has_start = np.array([s is not None for s in starts])
        start_uv = np.array([np.asarray(s, dtype=np.float64) if s is not None else (0.0, 0.0) for s in starts])
        for _ in range(rounds):
            # suspects: off the surface and farther than a neighbour (a foot on the wrong sheet or side of a
            # seam; a curve uniformly off its surface has none)
            near = np.minimum(dist[cmp_prev], dist[cmp_next])
            idx = np.flatnonzero((dist > tie) & (dist > 1.25 * near + tie) & (sizes[run] > 1))
            if idx.size == 0:
                break
            prev = uv[prev_i[idx]]
            at_start = (prev_i[idx] == idx) & has_start[run[idx]]
            prev[at_start] = start_uv[run[idx][at_start]]
            nxt = uv[next_i[idx]]
            m = idx.size
            cand = self.newton(np.concatenate([X[idx], X[idx]]), np.concatenate([prev, nxt]))
            cd = self.distance(np.concatenate([X[idx], X[idx]]), cand).reshape(2, m)
            k = np.argmin(cd, axis=0)
            best = np.where(k[:, None] == 0, cand[:m], cand[m:])
            better = cd.min(axis=0) < dist[idx] - tie
            if not better.any():
                break
            uv[idx[better]], dist[idx[better]] = best[better], cd.min(axis=0)[better]
        return [self.unwrap(uv[f:f + n], st) for f, n, st in zip(first, sizes, starts)]

    def fix_poles(self, t, uv):
        """At a pole (a vanishing S_u or S_v) the parameter along it comes from the regular neighbours."""
        w = self.wrap(uv)
        D = self.s.derivatives(w[:, 0], w[:, 1], 1)
        su, sv = np.linalg.norm(D[:, 1, 0], axis=1), np.linalg.norm(D[:, 0, 1], axis=1)
        for d, (a, b) in enumerate(((su, sv), (sv, su))):
            pole = a <= _POLE * b
            if pole.any() and not pole.all():
                uv[pole, d] = np.interp(t[pole], t[~pole], uv[~pole, d])
        return uv


def _fit(t, uv):
    from scipy.interpolate import make_interp_spline

    return make_interp_spline(t, uv, k=min(3, len(t) - 1))


def _pull_piece(inv: _Inverter, curve, t, X, uv, tol: float, name: str, first, max_samples: int, strict: bool,
                max_distance: float):
    """One piece from its first samples ``t``, points ``X`` and feet ``uv``: fit, check, refine."""

    def settle(t, uv):
        uv = inv.fix_poles(t, uv)
        if first is not None:  # the previous piece's end: the joint is one point in (u, v), bit for bit
            uv[0] = first
        return uv

    uv = settle(t, uv)
    while True:
        dist = inv.distance(X, uv)
        if dist.max() > max_distance:
            k = int(np.argmax(dist > max_distance))
            u, v = np.round(inv.wrap(uv[k:k + 1])[0], 9) + 0.0
            what = "the tolerance" if max_distance == tol else "the largest distance allowed"
            raise ValueError(f"{name}: the curve is {dist[k]:.3g} from surface {inv.s.name!r} at t = {t[k]:.6g} "
                             f"(nearest (u, v) = ({u:.6g}, {v:.6g})), more than {what} {max_distance:.3g}: it does "
                             "not lie on the surface.")
        # what can be asked: the fit within tol, or (lenient) within tol of what the curve's own distance
        # from the surface allows
        target = tol if strict else max(tol, float(dist.max()) + 0.25 * tol, _ROUNDING * inv.scale)
        spl = _fit(t, uv)
        tt = (t[:-1, None] + _TEST_FRACTIONS * np.diff(t)[:, None])  # (intervals, 7)
        w = inv.wrap(spl(tt.ravel()))
        dev = np.linalg.norm(inv.s.evaluate(w[:, 0], w[:, 1]) - curve(tt.ravel()), axis=1).reshape(tt.shape)
        bad = dev.max(axis=1) > target
        if not bad.any():
            return spl, float(dev.max()), float(dist.max()), len(t), tt.ravel(), ""
        if len(t) + bad.sum() > max_samples:
            msg = (f"{name}: the pulled-back curve on surface {inv.s.name!r} still strays {dev.max():.3g} "
                   f"from the 3-D curve (tolerance {tol:.3g}, the curve is {dist.max():.3g} from the "
                   f"surface) with {len(t)} samples; not refined further (max_samples = {max_samples}).")
            if strict:
                raise ValueError(msg)
            return spl, float(dev.max()), float(dist.max()), len(t), tt.ravel(), msg
        tn = 0.5 * (t[:-1] + t[1:])[bad]
        un = inv.newton(curve(tn), spl(tn))
        order = np.argsort(np.concatenate([t, tn]), kind="stable")
        t, X = np.concatenate([t, tn])[order], np.concatenate([X, curve(tn)])[order]
        uv = settle(t, np.concatenate([uv, un])[order])


def pull_back(surface: NurbsSurface, curve, domain, tolerance: float, name: str = "curve", breaks=(),
              start=None, max_samples: int = 4097, strict: bool = True, max_distance: float | None = None,
              inverter: _Inverter | None = None) -> Pullback:
    """Pull the 3-D curve ``curve(t) -> (len(t), 3)`` on ``domain = (t0, t1)`` back onto ``surface``: one
    cubic :class:`TrimCurve` per piece between ``breaks``, each refined until ``S(c(t))`` lies within
    ``tolerance`` of ``curve(t)`` at the test points (see the module notes). ``start``: a ``(u, v)`` near
    the first foot (continuity with a previous curve on a closed surface). Raises ValueError naming
    ``name`` when the curve is farther than ``max_distance`` (default: ``tolerance``) from the surface or
    (``strict``) the fit does not reach the tolerance within ``max_samples``. Lenient (``strict=False``):
    a curve up to ``max_distance`` off the surface is fitted within ``tolerance`` plus that distance (and
    never asked for less than ``1e-12`` of the surface's size, a rounding floor), and
    the best fit found is returned with the reason in ``note`` when ``max_samples`` would be exceeded; the
    caller compares ``deviation`` with the tolerance. ``inverter``: the prepared ``_Inverter(surface)``
    (built here when not given; a caller pulling many curves back onto one surface passes one).

    Examples
    --------
    >>> from splinevis.nurbs.exact import sphere
    >>> z = -np.sqrt(0.5)  # the latitude at v = 1/4 (the middle of the south quarter arc)
    >>> ring = lambda t: np.column_stack([-z * np.cos(t), -z * np.sin(t), np.full_like(t, z)])
    >>> r = pull_back(sphere(), ring, (0.0, 2 * np.pi), 1e-8, name="ring")
    >>> c = r.curves[0]
    >>> r.deviation <= 1e-8, float(np.abs(c.control_points[:, 1] - 0.25).max()) < 1e-14
    (True, True)
    >>> pull_back(sphere(), lambda t: ring(t) * 1.01, (0.0, 1.0), 1e-3, name="halo")
    Traceback (most recent call last):
    ValueError: halo: the curve is 0.01 from surface 'sphere' at t = 0 (nearest (u, v) = (0, 0.25)), more than the tolerance 0.001: it does not lie on the surface.
    >>> r = pull_back(sphere(), lambda t: ring(t) * 1.01, (0.0, 1.0), 1e-3, strict=False, max_distance=0.1)
    >>> round(r.distance, 12), r.deviation <= r.distance + 0.25e-3
    (0.01, True)
    """
    return pull_back_many(surface, [(curve, domain, breaks, name, start)], tolerance, max_samples=max_samples,
                          strict=strict, max_distance=max_distance, inverter=inverter)[0]


def pull_back_many(surface: NurbsSurface, curves, tolerance: float, max_samples: int = 4097, strict: bool = True,
                   max_distance: float | None = None, inverter: _Inverter | None = None) -> list:
    """:func:`pull_back` of several curves ``(curve, domain, breaks, name, start)`` onto one surface, their
    first feet found in one batch (:meth:`_Inverter.invert_runs`: the cost of point inversion is in the
    number of Newton rounds over the batch, not in its size); one :class:`Pullback` per curve.

    >>> from splinevis.nurbs.exact import cylinder
    >>> seam = lambda t: np.column_stack([np.ones_like(t), np.zeros_like(t), t])  # x = 1, y = 0: the seam
    >>> rim = lambda t: np.column_stack([np.cos(2 * np.pi * t), np.sin(2 * np.pi * t), np.ones_like(t)])
    >>> rs = pull_back_many(cylinder(), [(seam, (0.0, 1.0), (), "seam", None), (rim, (0.0, 1.0), (), "rim", None)], 1e-6)
    >>> [bool(r.deviation < 1e-6) for r in rs]
    [True, True]
    """
    tol = float(tolerance)
    if not tol > 0:
        raise ValueError(f"{curves[0][3] if curves else 'curve'}: the tolerance must be positive, got {tolerance!r}.")
    inv = _Inverter(surface) if inverter is None else inverter
    maxd = tol if max_distance is None else float(max_distance)

    def checked_curve(curve, name):
        def C(t):
            X = np.asarray(curve(np.asarray(t, dtype=np.float64)), dtype=np.float64)
            if X.shape != (np.size(t), 3) or not np.isfinite(X).all():
                raise ValueError(f"{name}: the curve must give finite points of shape ({np.size(t)}, 3), "
                                 f"got {X.shape}.")
            return X
        return C

    plans, runs, starts = [], [], []
    for curve, domain, breaks, name, start in curves:
        t0, t1 = (float(x) for x in domain)
        cuts = [t0] + sorted(float(b) for b in breaks if t0 < b < t1) + [t1]
        C = checked_curve(curve, name)
        ts = [np.linspace(a, b, _FIRST_SAMPLES) for a, b in zip(cuts[:-1], cuts[1:])]
        Xs = [C(t) for t in ts]
        plans.append((C, name, ts, Xs))
        runs.append(np.concatenate(Xs))  # the pieces of one curve: one run (continuous across the breaks)
        starts.append(start)
    feet = inv.invert_runs(runs, starts)
    out = []
    for (C, name, ts, Xs), uv_all in zip(plans, feet):
        pieces, devs, dists, count, checked, first, notes = [], [], [], 0, [], None, []
        for k, (t, X) in enumerate(zip(ts, Xs)):
            uv = uv_all[k * _FIRST_SAMPLES:(k + 1) * _FIRST_SAMPLES]
            if first is not None:  # the run's copy of the joint by whole periods onto the previous piece's end
                uv = uv + (inv.near(uv[0], first) - uv[0])
            spl, dev, dist, n, tt, note = _pull_piece(inv, C, t, X, uv, tol, name, first, max_samples, strict, maxd)
            P = np.array(spl.c)
            if first is not None:
                P[0] = first  # the interpolant's end control points are its end samples (up to rounding)
            pieces.append(TrimCurve(spl.k, spl.t, P))
            first = P[-1]
            devs.append(dev)
            dists.append(dist)
            count += n
            checked.append(tt)
            notes += [note] if note else []
        out.append(Pullback(tuple(pieces), max(devs), max(dists), count, np.concatenate(checked),
                            tuple(bool(c) for c in inv.closed), "; ".join(notes)))
    return out

"""Points and derivatives of many NURBS patches, and points of many trim curves, in one pass each (float64), for
the passes over a whole model (:mod:`.orient`, :mod:`.shell_volume`).

Why own code: :meth:`.NurbsSurface.derivatives` and :meth:`.TrimCurve.evaluate` take one patch or one curve
at a time, and a model's orientation evaluates a few dozen points on each of hundreds of faces and curves,
where numpy's fixed cost per call (a dozen calls an evaluation) outweighs the arithmetic many times over. Here
the points of all patches (curves) of one degree go through the same steps together:

* each point's knot span is found in its own knot vector (``find_span`` [PieglTiller1997, A2.1] for every
  patch at once: one sort of all knots and parameters keyed by patch, counting the patch's knots ``<= u``);
* the knot vectors lie end to end, so that :func:`.basis.ders_basis_funs` (A2.3) reads each point's knots at
  its own offset; the control nets likewise;
* the products and the quotient rule (A3.6, A4.4) are those of :meth:`.NurbsSurface.derivatives` and
  :meth:`.TrimCurve.evaluate`: points are theirs bit for bit; derivatives contract the control points by
  stacked matrix products (a third of the time of the two ``einsum`` of a patch's own evaluation; the sums
  associate differently, so they differ from :meth:`.NurbsSurface.derivatives` by rounding, relative to the
  size of the terms summed).
"""

from __future__ import annotations

import numpy as np

from .basis import MAX_DEGREE, ders_basis_funs
from .surface import _rational

__all__ = ["CurveBatch", "SurfaceBatch"]


class _Knots:
    """Knot vectors laid end to end, with each one's offset, degree and last span."""

    def __init__(self, vectors, degrees):
        lens = np.array([len(U) for U in vectors], dtype=np.int64)
        self.cat = np.concatenate(vectors) if vectors else np.zeros(0)
        self.off = np.cumsum(lens) - lens
        self.owner = np.repeat(np.arange(len(vectors)), lens)
        self.p = np.asarray(degrees, dtype=np.int64)
        self.n = lens - self.p - 2
        self.lo, self.hi = self.cat[self.off + self.p], self.cat[self.off + self.n + 1]

    def spans(self, idx, t):
        """Global index (into ``cat``) of the span ``U[i] <= t < U[i + 1]`` of each parameter in its own knot
        vector ``idx``, as :func:`.basis.find_span`: the last non-empty span at the domain's right end."""
        if t.size and (np.isnan(t).any() or (t < self.lo[idx]).any() or (t > self.hi[idx]).any()):
            bad = int(np.flatnonzero(np.isnan(t) | (t < self.lo[idx]) | (t > self.hi[idx]))[0])
            raise ValueError(f"parameter {float(t[bad])!r} is outside the knot domain [{float(self.lo[idx[bad]])!r}, "
                             f"{float(self.hi[idx[bad]])!r}]; clamp or rescale the parameters into the domain.")
        K = self.cat.size
        # by owner, then value, knots before parameters on a tie: a parameter's position counts the knots <= it
        order = np.lexsort((np.r_[np.zeros(K, dtype=bool), np.ones(t.size, dtype=bool)], np.r_[self.cat, t],
                            np.r_[self.owner, idx]))
        is_t = order >= K
        before = np.cumsum(~is_t) - 1  # knots up to each position, less one: the span of a parameter
        span = np.empty(t.size, dtype=np.int64)
        span[order[is_t] - K] = before[is_t]
        return np.clip(span - self.off[idx], self.p[idx], self.n[idx]) + self.off[idx]


class SurfaceBatch:
    """Many patches, evaluated together (module notes).

    >>> from splinevis.nurbs.exact import sphere, torus
    >>> b = SurfaceBatch([sphere(), torus()])
    >>> P = b.evaluate([0, 1, 1], [0.3, 0.3, 0.7], [0.6, 0.6, 0.2])
    >>> bool(np.array_equal(P[1:], torus().evaluate([0.3, 0.7], [0.6, 0.2])))
    True
    """

    def __init__(self, surfaces):
        self.surfaces = list(surfaces)
        deg = np.array([s.degree for s in self.surfaces], dtype=np.int64).reshape(-1, 2)
        self.degree = deg
        self.U = _Knots([s.knots[0] for s in self.surfaces], deg[:, 0])
        self.V = _Knots([s.knots[1] for s in self.surfaces], deg[:, 1])
        nets = [s.homogeneous().reshape(-1, 4) for s in self.surfaces]
        sizes = np.array([len(n) for n in nets], dtype=np.int64)
        self.Pw = np.concatenate(nets) if nets else np.zeros((0, 4))
        self.poff = np.cumsum(sizes, dtype=np.int64) - sizes
        self.nv = np.array([s.shape[1] for s in self.surfaces], dtype=np.int64)

    def derivatives(self, face, u, v, order: int = 0, chunk: int = 1 << 15) -> np.ndarray:
        """``SKL`` ``(len(u), order + 1, order + 1, 3)`` of patch ``face[i]`` at ``(u[i], v[i])``, as
        :meth:`.NurbsSurface.derivatives` (``chunk`` points at a time: the control nets gathered per point
        stay in the cache).

        >>> from splinevis.nurbs.exact import sphere, torus
        >>> D = SurfaceBatch([sphere(), torus()]).derivatives([1], [0.3], [0.6], 2)
        >>> D.shape, bool(np.allclose(D, torus().derivatives([0.3], [0.6], 2), rtol=0, atol=1e-12))
        ((1, 3, 3, 3), True)
        """
        face = np.asarray(face, dtype=np.int64).ravel()
        u = np.asarray(u, dtype=np.float64).ravel()
        v = np.asarray(v, dtype=np.float64).ravel()
        if u.size > chunk:
            return np.concatenate([self.derivatives(face[a:a + chunk], u[a:a + chunk], v[a:a + chunk], order, chunk)
                                   for a in range(0, u.size, chunk)])
        su, sv = self.U.spans(face, u), self.V.spans(face, v)
        out = np.empty((u.size, order + 1, order + 1, 3))
        key = self.degree[face, 0] * (MAX_DEGREE + 1) + self.degree[face, 1]
        keys = np.unique(key)
        for kk in keys:
            sel = slice(None) if keys.size == 1 else np.flatnonzero(key == kk)
            p, q = divmod(int(kk), MAX_DEGREE + 1)
            f = face[sel]
            Nu = ders_basis_funs(su[sel], u[sel], p, order, self.U.cat)  # (m, d+1, p+1)
            Nv = ders_basis_funs(sv[sel], v[sel], q, order, self.V.cat)
            iu = (su[sel] - self.U.off[f] - p)[:, None] + np.arange(p + 1)
            iv = (sv[sel] - self.V.off[f] - q)[:, None] + np.arange(q + 1)
            net = self.Pw[self.poff[f][:, None, None] + iu[:, :, None] * self.nv[f][:, None, None] + iv[:, None, :]]
            if order == 0:  # NurbsSurface's own contractions: the points bit for bit
                Aw = np.einsum("mka,malc->mklc", Nu, np.einsum("mlb,mabc->malc", Nv, net))
            else:  # a third of the time; the sums associate differently (rounding-level differences)
                m, d = net.shape[0], order + 1
                rows = np.matmul(Nv[:, None], net)  # (m, p+1, d, 4): sum_b Nv[l, b] Pw[a, b]
                Aw = np.matmul(Nu, rows.reshape(m, p + 1, d * 4)).reshape(m, d, d, 4)  # sum_a Nu[k, a] rows[a]
            out[sel] = _rational(Aw, order)
        return out

    def evaluate(self, face, u, v) -> np.ndarray:
        """Points ``(len(u), 3)`` of patch ``face[i]`` at ``(u[i], v[i])``.

        >>> from splinevis.nurbs.exact import sphere
        >>> SurfaceBatch([sphere()]).evaluate([0], [0.0], [0.0]).round(12).tolist()  # the south pole
        [[0.0, 0.0, -1.0]]
        """
        return self.derivatives(face, u, v, 0)[:, 0, 0]

    def grid_derivatives(self, face, us, vs, keep, order: int = 1, chunk: int = 1 << 15) -> np.ndarray:
        """``SKL`` ``(keep.sum(), order + 1, order + 1, 3)`` of patch ``face[k]`` on its tensor grid
        ``(us[k, i], vs[k, j])`` where ``keep[k, i, j]``, in that order (``us`` (F, g), ``vs`` (F, h), ``keep``
        (F, g, h)). The grid's rows share their u: the basis functions are found once per ``us`` and ``vs``
        value, and the control net is contracted in u once per grid row (every column of the net), then in v
        per point; stacked matrix products as :meth:`derivatives` (about half its work per point).

        >>> from splinevis.nurbs.exact import torus
        >>> b = SurfaceBatch([torus()])
        >>> us, vs = np.array([[0.1, 0.4]]), np.array([[0.2, 0.7, 0.9]])
        >>> keep = np.array([[[True, False, True], [False, True, False]]])
        >>> D = b.grid_derivatives([0], us, vs, keep)  # (0.1, 0.2), (0.1, 0.9), (0.4, 0.7)
        >>> bool(np.allclose(D, b.derivatives([0, 0, 0], [0.1, 0.1, 0.4], [0.2, 0.9, 0.7], 1), rtol=0, atol=1e-12))
        True
        """
        face = np.asarray(face, dtype=np.int64).ravel()
        us, vs = np.asarray(us, dtype=np.float64), np.asarray(vs, dtype=np.float64)
        keep = np.asarray(keep, dtype=bool)
        g, h, d = us.shape[1], vs.shape[1], order + 1
        rank = np.cumsum(keep.ravel()) - 1  # each kept point's place in the output
        out = np.empty((int(keep.sum()), d, d, 3))
        key = self.degree[face, 0] * (MAX_DEGREE + 1) + self.degree[face, 1]
        per = max(1, chunk // max(g * h, 1))  # faces at a time
        for kk in np.unique(key):
            p, q = divmod(int(kk), MAX_DEGREE + 1)
            group = np.flatnonzero(key == kk)
            for c0 in range(0, group.size, per):
                sel = group[c0:c0 + per]
                f, G = face[sel], sel.size
                fu, fv = np.repeat(f, g), np.repeat(f, h)
                uu, vv = us[sel].ravel(), vs[sel].ravel()
                su, sv = self.U.spans(fu, uu), self.V.spans(fv, vv)
                Nu = ders_basis_funs(su, uu, p, order, self.U.cat)  # (G g, d, p+1)
                Nv = ders_basis_funs(sv, vv, q, order, self.V.cat)  # (G h, d, q+1)
                # u first: Q[row (k, i), column b] = sum_a Nu[k, i][., a] Pw[span - p + a, b]
                cols = self.nv[fu]
                row = np.repeat(np.arange(G * g), cols)
                b = np.arange(row.size) - np.repeat(np.cumsum(cols) - cols, cols)
                first = su - self.U.off[fu] - p
                net = self.Pw[self.poff[fu][row, None] + (first[row, None] + np.arange(p + 1)) * cols[row, None]
                              + b[:, None]]  # (rows x columns, p+1, 4)
                Q = np.matmul(Nu[row], net)  # (rows x columns, d, 4)
                start = np.cumsum(cols) - cols
                # then v at each kept point: sum_b Nv[k, j][., b] Q[(k, i), span - q + b]
                gk, gi, gj = np.nonzero(keep[sel])
                ri, rj = gk * g + gi, gk * h + gj
                at = start[ri, None] + (sv[rj] - self.V.off[fv[rj]] - q)[:, None] + np.arange(q + 1)
                m = ri.size
                A = np.matmul(Nv[rj], Q[at].reshape(m, q + 1, d * 4)).reshape(m, d, d, 4)  # [l, k, c]
                out[rank[((sel[gk] * g + gi) * h + gj)]] = _rational(A.transpose(0, 2, 1, 3), order)
        return out


class CurveBatch:
    """Many trim curves, evaluated together (module notes).

    >>> from splinevis.nurbs.model import TrimCurve
    >>> a, b = TrimCurve(1, [0, 0, 1, 1], [[0, 0], [1, 0]]), TrimCurve(2, [0, 0, 0, 2, 2, 2], [[0, 0], [1, 2], [2, 0]])
    >>> CurveBatch([a, b]).evaluate([0, 1], [0.25, 1.0]).tolist()
    [[0.25, 0.0], [1.0, 1.0]]
    """

    def __init__(self, curves):
        self.curves = list(curves)
        self.K = _Knots([c.knots for c in self.curves], [c.degree for c in self.curves])
        weights = [np.ones(len(c.control_points)) if c.weights is None else c.weights for c in self.curves]
        sizes = np.array([len(w) for w in weights], dtype=np.int64)
        self.P = np.concatenate([c.control_points * w[:, None] for c, w in zip(self.curves, weights)]) if weights \
            else np.zeros((0, 2))
        self.w = np.concatenate(weights) if weights else np.zeros(0)
        self.poff = np.cumsum(sizes, dtype=np.int64) - sizes
        self.degree = self.K.p

    def evaluate(self, curve, t) -> np.ndarray:
        """Points ``(len(t), 2)`` of curve ``curve[i]`` at ``t[i]``, as :meth:`.TrimCurve.evaluate`.

        >>> from splinevis.nurbs.model import TrimCurve
        >>> CurveBatch([TrimCurve(1, [0, 0, 2, 2], [[0, 0], [1, 1]])]).evaluate([0, 0], [0.5, 2.0]).tolist()
        [[0.25, 0.25], [1.0, 1.0]]
        """
        curve = np.asarray(curve, dtype=np.int64).ravel()
        t = np.asarray(t, dtype=np.float64).ravel()
        span = self.K.spans(curve, t)
        out = np.empty((t.size, 2))
        deg = self.degree[curve]
        degs = np.unique(deg)
        for p in degs:
            sel = slice(None) if degs.size == 1 else np.flatnonzero(deg == p)
            c = curve[sel]
            N = ders_basis_funs(span[sel], t[sel], int(p), 0, self.K.cat)[:, 0, :]
            idx = self.poff[c][:, None] + (span[sel] - self.K.off[c] - p)[:, None] + np.arange(p + 1)
            out[sel] = np.einsum("ma,mac->mc", N, self.P[idx]) / np.einsum("ma,ma->m", N, self.w[idx])[:, None]
        return out

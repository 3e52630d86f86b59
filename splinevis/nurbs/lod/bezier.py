"""Every surface of a NURBS model cut into rational Bezier patches, stored by degree for vectorized work.

[Kumar1997, sec. 2] works on Bezier patches: each NURBS surface is decomposed by knot insertion
(every interior knot raised to multiplicity ``p``, the ends clamped; [PieglTiller1997, A5.7], done here
with :func:`splinevis.nurbs.operations.bezier_segments` one direction at a time, vectorized over the rows
of the other direction). A patch of degree ``p x q`` is the tensor-product rational Bezier patch

    ``F(s, t) = sum_ij B_i^p(s) B_j^q(t) w_ij P_ij / sum_ij B_i^p(s) B_j^q(t) w_ij``,  ``(s, t) in [0, 1]^2``,

stored as homogeneous control points ``(w P, w)`` (``w = 1`` exactly for a polynomial surface). The local
parameters map to the parent's by ``u = u0 + s (u1 - u0)``, ``v = v0 + t (v1 - v0)`` with the patch's
rectangle ``[u0, u1] x [v0, v1]`` of its knot span.

Patches are numbered flat across the model (surface by surface, each surface's patches u-major as in
:func:`splinevis.nurbs.operations.bezier_patches`) and grouped by degree ``(p, q)``: a group's control
points are one ``(N, p + 1, q + 1, 4)`` array, so that bounds, evaluation and tessellation run as array
operations over tens of thousands of patches.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import NurbsModel
from ..operations import bezier_segments
from ..surface import NurbsSurface

__all__ = ["BezierGroup", "BezierSet", "bezier_set", "evaluate", "bernstein", "locate", "patch_trims"]


@dataclass(frozen=True, eq=False)
class BezierGroup:
    """The patches of one degree ``(p, q)``: homogeneous control points and their flat patch ids.

    Examples
    --------
    >>> from splinevis.nurbs.exact import torus
    >>> g = bezier_set(torus()).groups[0]
    >>> g.degree, g.control.shape, g.ids[:3].tolist()
    ((2, 2), (16, 3, 3, 4), [0, 1, 2])
    """

    degree: tuple
    control: np.ndarray  # (N, p + 1, q + 1, 4) homogeneous (w x, w y, w z, w)
    ids: np.ndarray  # (N,) flat patch ids, increasing

    def __len__(self) -> int:
        return int(self.ids.size)

    @property
    def points(self) -> np.ndarray:
        """Cartesian control points ``(N, p + 1, q + 1, 3)``.

        >>> from splinevis.nurbs.exact import sphere
        >>> g = bezier_set(sphere()).groups[0]
        >>> g.points[0, :, 0].tolist()  # v = 0 is the south pole: a collapsed row
        [[0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [0.0, 0.0, -1.0]]
        """
        return self.control[..., :3] / self.control[..., 3:]


@dataclass(frozen=True, eq=False)
class BezierSet:
    """A model's rational Bezier patches (build it with :func:`bezier_set`).

    Attributes
    ----------
    groups : tuple of BezierGroup
        One per degree ``(p, q)``, sorted by degree.
    group, row : (P,) int arrays
        Patch ``i`` is ``groups[group[i]].control[row[i]]``.
    parent : (P,) int array
        The index of the patch's surface in the model.
    rect : (P, 4) float array
        ``(u0, u1, v0, v1)``: the patch's rectangle of its parent's parameter domain.
    trimmed : (P,) bool array
        The parent has trim loops (``model.trims[parent] is not None``); the patch itself may lie wholly
        inside or outside them.
    bbox : (P, 6) float array
        ``(xmin, xmax, ymin, ymax, zmin, zmax)`` of the patch's Cartesian control points, which contain the
        patch (convex hull property; weights are positive).
    size : float
        The diagonal of the model's control-point box: the length scale of tolerances.
    names : tuple of str
        The surfaces' names (index with ``parent``).

    Examples
    --------
    >>> from splinevis.nurbs.exact import sphere, torus
    >>> from splinevis.nurbs.model import NurbsModel
    >>> b = bezier_set(NurbsModel([sphere(), torus()]))
    >>> len(b), [g.degree for g in b.groups], b.parent[[0, 7, 8]].tolist()
    (24, [(2, 2)], [0, 0, 1])
    >>> b.rect[1].tolist(), b.bbox[0].tolist()  # sphere patch u in [0, 1/4], v in [1/2, 1]
    ([0.0, 0.25, 0.5, 1.0], [0.0, 1.0, 0.0, 1.0, -1.0, 0.0])
    """

    groups: tuple
    group: np.ndarray
    row: np.ndarray
    parent: np.ndarray
    rect: np.ndarray
    trimmed: np.ndarray
    bbox: np.ndarray
    size: float
    names: tuple = ()
    source: str = ""

    def __len__(self) -> int:
        return int(self.parent.size)

    @property
    def degrees(self) -> np.ndarray:
        """``(P, 2)`` degrees ``(p, q)`` per patch.

        >>> from splinevis.nurbs.hard_cases import bumpy
        >>> bezier_set(bumpy(3, 1, 6, 2)).degrees.tolist()
        [[3, 1], [3, 1], [3, 1]]
        """
        table = np.array([g.degree for g in self.groups], dtype=np.int64).reshape(-1, 2)
        return table[self.group]

    def control(self, i: int) -> np.ndarray:
        """The homogeneous control points ``(p + 1, q + 1, 4)`` of patch ``i``.

        >>> from splinevis.nurbs.exact import saddle
        >>> bezier_set(saddle()).control(0)[2, 0].tolist()
        [1.0, -1.0, 0.0, 1.0]
        """
        return self.groups[self.group[i]].control[self.row[i]]

    def surface(self, i: int) -> NurbsSurface:
        """Patch ``i`` as a :class:`NurbsSurface` on the local domain ``[0, 1]^2`` (polynomial when all its
        weights are 1), named ``"<parent name>[k]"`` with ``k`` its index within the parent.

        >>> from splinevis.nurbs.exact import torus
        >>> s = bezier_set(torus()).surface(5)
        >>> s.name, s.domain, bool(np.allclose(s.evaluate([0.0], [0.0]), torus().evaluate([0.25], [0.25])))
        ('torus[5]', ((0.0, 1.0), (0.0, 1.0)), True)
        """
        i = int(i)
        C = self.control(i)
        p, q = C.shape[0] - 1, C.shape[1] - 1
        w = C[..., 3]
        k = i - int(np.searchsorted(self.parent, self.parent[i]))
        knots = ([0.0] * (p + 1) + [1.0] * (p + 1), [0.0] * (q + 1) + [1.0] * (q + 1))
        name = f"{self.names[self.parent[i]] if self.names else ''}[{k}]"
        return NurbsSurface((p, q), knots, C[..., :3] / w[..., None], None if (w == 1.0).all() else w, name)


def _single_span(s: NurbsSurface) -> bool:
    """The surface is already one clamped Bezier patch (no knot insertion needed)."""
    for p, U in zip(s.degree, s.knots):
        if U.size != 2 * p + 2 or U[0] != U[p] or U[p + 1] != U[-1]:
            return False
    return True


def _spans(p: int, U: np.ndarray, n: int) -> np.ndarray:
    """``(k, 2)`` non-empty knot spans of the domain ``[U[p], U[n]]`` (n control points), in order: the
    segments :func:`bezier_segments` returns, one per span."""
    vals = np.unique(U[p:n + 1])
    return np.column_stack([vals[:-1], vals[1:]])


def _decompose(s: NurbsSurface):
    """``(control (k, p+1, q+1, 4), rect (k, 4))`` of one surface's Bezier patches, u-major."""
    (p, q), (U, V) = s.degree, s.knots
    nu, nv = s.shape
    net = s.control_points if s.weights is None else s.homogeneous()  # polynomial: keep w = 1 exact
    c = net.shape[2]
    A = np.stack(bezier_segments(p, U, net.reshape(nu, nv * c), "knots[0] (u)"))  # (ku, p+1, nv*c)
    ku = A.shape[0]
    A = A.reshape(ku, p + 1, nv, c).transpose(2, 0, 1, 3).reshape(nv, ku * (p + 1) * c)
    B = np.stack(bezier_segments(q, V, A, "knots[1] (v)"))  # (kv, q+1, ku*(p+1)*c)
    kv = B.shape[0]
    C = B.reshape(kv, q + 1, ku, p + 1, c).transpose(2, 0, 3, 1, 4).reshape(ku * kv, p + 1, q + 1, c)
    su, sv = _spans(p, U, nu), _spans(q, V, nv)
    if s.weights is None:
        C = np.concatenate([C, np.ones(C.shape[:3] + (1,))], axis=-1)
    iu, iv = np.divmod(np.arange(su.shape[0] * sv.shape[0]), sv.shape[0])
    return C, np.column_stack([su[iu], sv[iv]])


def bezier_set(model) -> BezierSet:
    """Cut every surface of ``model`` (a :class:`NurbsModel` or one :class:`NurbsSurface`) into rational
    Bezier patches by knot insertion [Kumar1997, sec. 2; PieglTiller1997, A5.7].

    Clamped or unclamped knot vectors, repeated knots and degrees 1..7 are all accepted (an unclamped end is
    clamped at the domain end first; the surface outside its domain is not part of the model). A surface
    that is already a single clamped Bezier patch (the Newell teapot's) is taken as it is.

    Examples
    --------
    >>> from datasets_synthetic.teapot import newell_teapot
    >>> b = bezier_set(newell_teapot())
    >>> len(b), len(b.groups), b.groups[0].control.shape, round(b.size, 6)
    (32, 1, (32, 4, 4, 4), 8.276359)
    >>> from splinevis.nurbs.hard_cases import crease
    >>> bezier_set(crease()).rect.tolist()  # the C0 crease at u = 1/2 splits the roof
    [[0.0, 0.5, 0.0, 1.0], [0.5, 1.0, 0.0, 1.0]]
    """
    if isinstance(model, NurbsSurface):
        model = NurbsModel([model], source=model.name)
    if not isinstance(model, NurbsModel):
        raise TypeError(f"bezier_set needs a NurbsModel or a NurbsSurface, got {type(model).__name__}.")
    by_degree: dict = {}  # degree -> (list of control blocks, list of flat id ranges)
    parents, rects, trimmed = [], [], []
    start = 0
    # single-span surfaces (most patches of large models: the teapot's) skip knot insertion
    for k, s in enumerate(model.surfaces):
        if _single_span(s):
            C = s.control_points[None] if s.weights is None else s.homogeneous()[None]
            (p, q), (U, V) = s.degree, s.knots
            rect = np.array([[U[p], U[p + 1], V[q], V[q + 1]]])
        else:
            C, rect = _decompose(s)
        blocks, ids = by_degree.setdefault(s.degree, ([], []))
        blocks.append(C)
        ids.append(np.arange(start, start + C.shape[0]))
        parents.append(np.full(C.shape[0], k, dtype=np.int64))
        rects.append(rect)
        trimmed.append(np.full(C.shape[0], bool(model.trims[k])))
        start += C.shape[0]
    total = start
    group = np.empty(total, dtype=np.int64)
    row = np.empty(total, dtype=np.int64)
    bbox = np.empty((total, 6))
    groups = []
    for g, degree in enumerate(sorted(by_degree)):
        blocks, ids = by_degree[degree]
        if all(b.shape[-1] == 3 for b in blocks):  # all polynomial: one concatenation, then w = 1
            C = np.concatenate(blocks)
            C = np.concatenate([C, np.ones(C.shape[:3] + (1,))], axis=-1)
        else:
            C = np.concatenate([b if b.shape[-1] == 4 else np.concatenate([b, np.ones(b.shape[:3] + (1,))], axis=-1)
                                for b in blocks])
        idx = np.concatenate(ids)
        group[idx] = g
        row[idx] = np.arange(idx.size)
        P = (C[..., :3] / C[..., 3:]).reshape(idx.size, -1, 3)
        bbox[idx, 0::2] = P.min(axis=1)
        bbox[idx, 1::2] = P.max(axis=1)
        for a in (C, idx):
            a.setflags(write=False)
        groups.append(BezierGroup(degree, C, idx))
    lo, hi = bbox[:, 0::2].min(axis=0), bbox[:, 1::2].max(axis=0)
    out = dict(group=group, row=row, parent=np.concatenate(parents), rect=np.concatenate(rects).astype(np.float64),
               trimmed=np.concatenate(trimmed), bbox=bbox)
    for a in out.values():
        a.setflags(write=False)
    return BezierSet(tuple(groups), size=float(np.linalg.norm(hi - lo)), names=model.names, source=model.source, **out)


# -------------------------------------------------------------------------------------------------
def bernstein(n: int, t, derivative: bool = False):
    """Bernstein polynomials ``B_i^n(t)``, ``(len(t), n + 1)``, by the triangle
    ``B_i^k = (1 - t) B_i^(k-1) + t B_(i-1)^(k-1)`` [Farin2002, ch. 5] (all terms non-negative: each value
    to a few ulps); with ``derivative=True`` also ``dB_i^n/dt = n (B_(i-1)^(n-1) - B_i^(n-1))``.

    >>> bernstein(2, [0.5])
    array([[0.25, 0.5 , 0.25]])
    >>> bernstein(2, [0.5], derivative=True)[1]
    array([[-1.,  0.,  1.]])
    """
    t = np.atleast_1d(np.asarray(t, dtype=np.float64)).ravel()
    s = 1.0 - t
    B = np.ones((t.size, 1))
    prev = B
    for k in range(1, n + 1):
        prev = B
        B = np.zeros((t.size, k + 1))
        B[:, :k] = s[:, None] * prev
        B[:, 1:] += t[:, None] * prev
    if not derivative:
        return B
    if n == 0:
        return B, np.zeros_like(B)
    D = np.zeros((t.size, n + 1))
    D[:, 1:] = prev
    D[:, :n] -= prev
    return B, n * D


def evaluate(bezier, patch_ids, u, v, derivatives: bool = False):
    """Points of Bezier patches at local parameters ``(u, v)`` in ``[0, 1]^2``: ``(M, 3)``.

    ``bezier`` is a :class:`BezierSet` (``patch_ids`` are flat patch ids) or a :class:`BezierGroup`
    (``patch_ids`` are rows of the group). ``patch_ids``, ``u`` and ``v`` broadcast against each other.
    With ``derivatives=True`` returns ``(S, S_u, S_v)``, the first derivatives with respect to the local
    parameters (the parent's are ``S_u / (u1 - u0)``, ``S_v / (v1 - v0)``).

    The homogeneous point is ``sum_ij B_i(u) B_j(v) Pw_ij`` with Bernstein matrices (:func:`bernstein`)
    contracted over the nets of all points at once (in chunks), the derivatives by the quotient rule
    ``S_u = (A_u - w_u S) / w``. Rounding: ``(p + 1)(q + 1)`` products summed with non-negative weights
    that sum to 1, so a few ulps times that count of ``max |Pw|`` [Higham2002, sec. 3.1].

    Examples
    --------
    >>> from splinevis.nurbs.exact import sphere
    >>> b = bezier_set(sphere(2.0))
    >>> P = evaluate(b, np.arange(len(b)), 0.3, 0.6)
    >>> np.linalg.norm(P, axis=1).round(12).tolist() == [2.0] * 8
    True
    >>> S, Su, Sv = evaluate(b, [2], [0.5], [0.5], derivatives=True)
    >>> abs(float(np.dot(S[0], Su[0]))) < 1e-14  # tangents of a sphere are normal to the radius
    True
    """
    ids, u, v = (a.ravel() for a in np.broadcast_arrays(np.asarray(patch_ids, dtype=np.int64),
                                                        np.asarray(u, dtype=np.float64),
                                                        np.asarray(v, dtype=np.float64)))
    if isinstance(bezier, BezierGroup):
        return _evaluate_group(bezier.control, ids, u, v, derivatives)
    if not isinstance(bezier, BezierSet):
        raise TypeError(f"evaluate needs a BezierSet or a BezierGroup, got {type(bezier).__name__}.")
    if ids.size and (ids.min() < 0 or ids.max() >= len(bezier)):
        raise IndexError(f"patch ids must lie in 0..{len(bezier) - 1}, got {int(ids.min())}..{int(ids.max())}.")
    out = [np.empty((ids.size, 3)) for _ in range(3 if derivatives else 1)]
    g = bezier.group[ids]
    for k, grp in enumerate(bezier.groups):
        sel = np.flatnonzero(g == k)
        if sel.size:
            res = _evaluate_group(grp.control, bezier.row[ids[sel]], u[sel], v[sel], derivatives)
            for o, r in zip(out, res if derivatives else (res,)):
                o[sel] = r
    return tuple(out) if derivatives else out[0]


def _evaluate_group(C, rows, u, v, derivatives):
    p, q = C.shape[1] - 1, C.shape[2] - 1
    m = rows.size
    S = np.empty((m, 3))
    if derivatives:
        Su, Sv = np.empty((m, 3)), np.empty((m, 3))
    chunk = max(1, (1 << 22) // ((p + 1) * (q + 1) * 4))  # ~32 MB of gathered nets at a time
    for a in range(0, m, chunk):
        b = min(a + chunk, m)
        net = C[rows[a:b]]
        if derivatives:
            Bu, dBu = bernstein(p, u[a:b], True)
            Bv, dBv = bernstein(q, v[a:b], True)
        else:
            Bu, Bv = bernstein(p, u[a:b]), bernstein(q, v[a:b])
        T = np.einsum("mj,mijc->mic", Bv, net)
        A = np.einsum("mi,mic->mc", Bu, T)
        w = A[:, 3:]
        S[a:b] = A[:, :3] / w
        if derivatives:
            Au = np.einsum("mi,mic->mc", dBu, T)
            Av = np.einsum("mi,mic->mc", Bu, np.einsum("mj,mijc->mic", dBv, net))
            Su[a:b] = (Au[:, :3] - Au[:, 3:] * S[a:b]) / w
            Sv[a:b] = (Av[:, :3] - Av[:, 3:] * S[a:b]) / w
    return (S, Su, Sv) if derivatives else S


def locate(bs, f: int, uv) -> tuple:
    """The patch and local parameters ``(patch (K,), st (K, 2))`` of the points ``uv (K, 2)`` of surface ``f``'s
    domain (a point on a knot line: the first patch whose closed rectangle holds it; outside every one: the
    nearest, clamped).

    >>> from splinevis.nurbs.exact import torus
    >>> p, st = locate(bezier_set(torus()), 0, [[0.3, 0.6]])  # 4 x 4 spans of 1/4
    >>> p.tolist(), st.round(6).tolist()
    ([6], [[0.2, 0.4]])
    """
    ids = np.flatnonzero(bs.parent == f)
    r = bs.rect[ids]
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    inside = ((uv[:, None, 0] >= r[None, :, 0]) & (uv[:, None, 0] <= r[None, :, 1])
              & (uv[:, None, 1] >= r[None, :, 2]) & (uv[:, None, 1] <= r[None, :, 3]))
    # outside every rectangle (rounding at the border): the nearest
    gap = (np.maximum(0, r[None, :, 0] - uv[:, None, 0]) + np.maximum(0, uv[:, None, 0] - r[None, :, 1])
           + np.maximum(0, r[None, :, 2] - uv[:, None, 1]) + np.maximum(0, uv[:, None, 1] - r[None, :, 3]))
    k = np.where(inside.any(axis=1), np.argmax(inside, axis=1), np.argmin(gap, axis=1))
    p, rr = ids[k], r[k]
    s = np.clip((uv[:, 0] - rr[:, 0]) / (rr[:, 1] - rr[:, 0]), 0.0, 1.0)
    t = np.clip((uv[:, 1] - rr[:, 2]) / (rr[:, 3] - rr[:, 2]), 0.0, 1.0)
    return p, np.column_stack([s, t])


def patch_trims(bezier, i: int, trims):
    """The trim loops of patch ``i``'s surface (``trims``: the model's, per surface) in the patch's local domain
    ``[0, 1]^2`` (control points mapped by the patch's rectangle: exact for rational curves), keeping only the
    curves a ray towards ``+u`` from a point of the patch can cross (so the even-odd test inside the patch is
    unchanged); None when the surface has no trims.

    >>> from splinevis.nurbs.exact import saddle
    >>> from splinevis.nurbs.model import TrimCurve
    >>> from splinevis.nurbs.operations import refine_knots
    >>> b = bezier_set(refine_knots(saddle(), 0, [0.5]))  # two patches, u in [0, 1/2] and [1/2, 1]
    >>> line = lambda a, b: TrimCurve(1, [0, 0, 1, 1], [a, b])
    >>> loop = [line([0.1, 0.2], [0.3, 0.2]), line([0.3, 0.2], [0.1, 0.2])]
    >>> patch_trims(b, 0, [[loop]])[0][0].control_points.tolist(), patch_trims(b, 1, [[loop]])
    ([[0.2, 0.2], [0.6, 0.2]], [])
    """
    from ..model import TrimCurve

    loops = trims[int(bezier.parent[i])] if trims is not None else None
    if loops is None:
        return None
    u0, u1, v0, v1 = (float(x) for x in bezier.rect[i])
    out = []
    for loop in loops:
        kept = []
        for c in loop:
            P = np.asarray(c.control_points, dtype=np.float64)
            if P[:, 1].max() < v0 or P[:, 1].min() > v1 or P[:, 0].max() < u0:
                continue  # no ray from the patch towards +u meets it
            Q = np.column_stack([(P[:, 0] - u0) / (u1 - u0), (P[:, 1] - v0) / (v1 - v0)])
            kept.append(TrimCurve(c.degree, c.knots, Q, c.weights))
        if kept:
            out.append(kept)
    return out

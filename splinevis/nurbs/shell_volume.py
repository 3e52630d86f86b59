"""Signed volumes enclosed by NURBS faces, by the divergence theorem: ``V = 1/3 sum_faces integral (S - c) .
(S_u x S_v) du dv`` for the field ``x - c`` [DoCarmo1976, sec. 2-6 for the orientation the normal induces].
A closed shell whose normals point out encloses ``V > 0``; :mod:`.orient` uses the sign to turn shells outward.

Untrimmed faces are integrated by Gauss-Legendre rules on every knot span (exact for polynomial patches up to
the rule's degree); trimmed faces by the midpoint rule on a grid over their loops, masked by the inside test
(:func:`.trim.inside`), with an error of the order of the grid step along the trim.
"""

from __future__ import annotations

import numpy as np

from .basis import at_fraction
from .batch import CurveBatch, SurfaceBatch
from .trim import inside_many, trim_pieces

__all__ = ["signed_volumes"]


def _breaks(knots, lo, hi):
    k = np.unique(knots[(knots >= lo) & (knots <= hi)])
    return k if k.size >= 2 else np.array([lo, hi])


def _piece_params(breaks, n):
    """``n`` parameters per interval of ``breaks`` (at fractions k / n, each interval at once) and the last break."""
    t = np.linspace(0.0, 1.0, n + 1)[:-1]
    breaks = np.asarray(breaks, dtype=np.float64)
    inner = at_fraction(breaks[:-1, None], breaks[1:, None], t[None, :]).ravel()
    return np.concatenate([inner, breaks[-1:]])


def _params_many(breaks, ns):
    """:func:`_piece_params` of every piece (``breaks[i]``, ``ns[i]``) at once, concatenated (the same values),
    and each parameter's piece."""
    nint = np.array([len(b) - 1 for b in breaks], dtype=np.int64)
    ns = np.asarray(ns, dtype=np.int64)
    lo = np.concatenate([b[:-1] for b in breaks]).astype(np.float64)
    hi = np.concatenate([b[1:] for b in breaks]).astype(np.float64)
    per = np.repeat(ns, nint)  # samples per interval
    total = nint * ns + 1
    first = np.concatenate([[0], np.cumsum(total)[:-1]])
    # where each interval's samples start: its piece's start plus the intervals before it in the piece
    rank = np.arange(lo.size) - np.repeat(np.cumsum(nint) - nint, nint)
    at = np.repeat(first, nint) + rank * per
    out = np.empty(int(total.sum()))
    for n in np.unique(per):
        sel = np.flatnonzero(per == n)
        t = np.linspace(0.0, 1.0, n + 1)[:-1]
        out[at[sel, None] + np.arange(n)] = at_fraction(lo[sel, None], hi[sel, None], t[None, :])
    out[first + nint * ns] = np.array([b[-1] for b in breaks], dtype=np.float64)
    return out, np.repeat(np.arange(len(breaks)), total)


def _gauss_nodes(breaks, g, min_intervals):
    """Gauss-Legendre nodes and weights on each interval of ``breaks`` (each split so there are at least
    ``min_intervals``)."""
    per = int(np.ceil(min_intervals / (len(breaks) - 1)))
    x, w = np.polynomial.legendre.leggauss(g)
    nodes, weights = [], []
    for a, b in zip(breaks[:-1], breaks[1:]):
        if b <= a:
            continue
        edges = at_fraction(a, b, np.linspace(0.0, 1.0, per + 1))
        for c, d in zip(edges[:-1], edges[1:]):
            nodes.append(0.5 * (c + d) + 0.5 * (d - c) * x)
            weights.append(0.5 * (d - c) * w)
    return np.concatenate(nodes), np.concatenate(weights)


def signed_volumes(surfaces, trims=None, center=None, gauss: int = 8, grid: int = 32, pieces=None, batch=None,
                   curves=None) -> np.ndarray:
    """Each face's share ``1/3 integral (S - center) . (S_u x S_v) du dv`` of the divergence theorem's volume
    (over the kept region of a trimmed face); a closed, outward-oriented shell's shares sum to its volume.

    Untrimmed faces: ``gauss``-point Gauss-Legendre on every knot span (at least 4 intervals a direction);
    trimmed faces: midpoint rule on ``grid x grid`` cells over the loops' box, masked by the inside test.
    All faces' points are evaluated together (``batch``: a :class:`.batch.SurfaceBatch` of ``surfaces``;
    ``curves``: a :class:`.batch.CurveBatch` of the trim curves, face by face in loop order; ``pieces``: their
    :func:`.trim.trim_pieces`; each made here when not given).

    >>> from splinevis.nurbs.exact import sphere
    >>> round(float(signed_volumes([sphere(2.0)])[0] / (4 / 3 * np.pi * 8)), 10)
    1.0
    """
    surfaces = list(surfaces)
    trims = list(trims) if trims else [None] * len(surfaces)
    if center is None:
        P = np.concatenate([s.control_points.reshape(-1, 3) for s in surfaces])
        center = 0.5 * (P.min(axis=0) + P.max(axis=0))
    center = np.asarray(center, dtype=np.float64)
    if pieces is None and any(trims):
        pieces = trim_pieces(trims)
    batch = SurfaceBatch(surfaces) if batch is None else batch
    faces, us, vs, ws, parts = [], [], [], [], []  # Gauss nodes; (faces, weights, derivatives) to sum
    trimmed = [k for k, loops in enumerate(trims) if loops and any(loops)]  # with a curve at least
    for k, s in enumerate(surfaces):
        if trims[k]:
            continue
        (u0, u1), (v0, v1) = s.domain
        uu, wu = _gauss_nodes(_breaks(s.knots[0], u0, u1), gauss, 4)
        vv, wv = _gauss_nodes(_breaks(s.knots[1], v0, v1), gauss, 4)
        U, V = np.meshgrid(uu, vv, indexing="ij")
        faces.append(np.full(U.size, k))
        us.append(U.ravel())
        vs.append(V.ravel())
        ws.append(np.outer(wu, wv).ravel())
    if trimmed:
        loops_curves = [c for k in trimmed for lp in trims[k] for c in lp]
        curves = CurveBatch(loops_curves) if curves is None else curves
        owner = np.repeat(trimmed, [sum(len(lp) for lp in trims[k]) for k in trimmed])
        t, which = _params_many([_breaks(c.knots, *c.domain) for c in loops_curves], np.full(len(loops_curves), 4))
        pts = curves.evaluate(which, t)
        f_of = owner[which]
        cut = np.flatnonzero(np.diff(f_of)) + 1
        starts = np.r_[0, cut]
        dom = np.array([[*surfaces[k].domain[0], *surfaces[k].domain[1]] for k in trimmed]).reshape(-1, 4)
        a = np.maximum(np.minimum.reduceat(pts, starts, axis=0), dom[:, [0, 2]])
        b = np.minimum(np.maximum.reduceat(pts, starts, axis=0), dom[:, [1, 3]])
        ok = (b > a).all(axis=1)
        frac = (np.arange(grid) + 0.5) / grid
        gu = at_fraction(a[ok, 0, None], b[ok, 0, None], frac[None, :])  # (faces, grid)
        gv = at_fraction(a[ok, 1, None], b[ok, 1, None], frac[None, :])
        kept = np.asarray(trimmed)[ok]
        U = np.repeat(gu, grid, axis=1).ravel()  # u-major, as meshgrid(..., indexing="ij")
        V = np.tile(gv, (1, grid)).ravel()
        F = np.repeat(kept, grid * grid)
        keep = inside_many(pieces, F, U, V, iterations=40)
        area = ((b[ok, 0] - a[ok, 0]) * (b[ok, 1] - a[ok, 1]) / grid**2)
        D = batch.grid_derivatives(kept, gu, gv, keep.reshape(-1, grid, grid), 1)  # the cells' midpoints, u-major
        parts.append((F[keep], np.repeat(area, grid * grid)[keep], D))
    if faces:
        F = np.concatenate(faces)
        parts.append((F, np.concatenate(ws), batch.derivatives(F, np.concatenate(us), np.concatenate(vs), 1)))
    out = np.zeros(len(surfaces))
    for F, W, D in parts:
        f = np.einsum("ij,ij->i", D[:, 0, 0] - center, np.cross(D[:, 1, 0], D[:, 0, 1]))
        out += np.bincount(F, weights=W * f, minlength=len(surfaces))
    return out / 3.0

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
from .trim import inside, trim_pieces

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


def signed_volumes(surfaces, trims=None, center=None, gauss: int = 8, grid: int = 32, pieces=None) -> np.ndarray:
    """Each face's share ``1/3 integral (S - center) . (S_u x S_v) du dv`` of the divergence theorem's volume
    (over the kept region of a trimmed face); a closed, outward-oriented shell's shares sum to its volume.

    Untrimmed faces: ``gauss``-point Gauss-Legendre on every knot span (at least 4 intervals a direction);
    trimmed faces: midpoint rule on ``grid x grid`` cells over the loops' box, masked by the inside test.

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
    out = np.zeros(len(surfaces))
    for k, (s, loops) in enumerate(zip(surfaces, trims)):
        (u0, u1), (v0, v1) = s.domain
        if not loops:
            uu, wu = _gauss_nodes(_breaks(s.knots[0], u0, u1), gauss, 4)
            vv, wv = _gauss_nodes(_breaks(s.knots[1], v0, v1), gauss, 4)
            U, V = np.meshgrid(uu, vv, indexing="ij")
            W = np.outer(wu, wv).ravel()
            u, v = U.ravel(), V.ravel()
        else:
            pts = np.concatenate([c.evaluate(_piece_params(_breaks(c.knots, *c.domain), 4)) for lp in loops
                                  for c in lp])
            a = np.maximum(pts.min(axis=0), [u0, v0])
            b = np.minimum(pts.max(axis=0), [u1, v1])
            if not (b > a).all():
                continue
            t = (np.arange(grid) + 0.5) / grid
            U, V = np.meshgrid(at_fraction(a[0], b[0], t), at_fraction(a[1], b[1], t), indexing="ij")
            u, v = U.ravel(), V.ravel()
            keep = inside(pieces, k, u, v, iterations=40)
            u, v = u[keep], v[keep]
            W = np.full(u.size, (b[0] - a[0]) * (b[1] - a[1]) / grid**2)
        if u.size == 0:
            continue
        D = s.derivatives(u, v, 1)
        f = np.einsum("ij,ij->i", D[:, 0, 0] - center, np.cross(D[:, 1, 0], D[:, 0, 1]))
        out[k] = float(np.dot(W, f)) / 3.0
    return out

"""Large NURBS models for the walkthrough of tens of thousands of Bezier patches: a field of Newell teapots
and a ship hull of a few B-spline surfaces with many knot spans and trimmed portholes. Real ship and
submarine models run to many thousands of patches [Kumar1997, sec. 2.1]; the paper's test model has 38,750
Bezier patches after knot insertion [Kumar1997, sec. 6], the size of ``teapot_field(1250)``.

>>> m = teapot_field(4)
>>> len(m), m.names[33]
(128, 'teapot 1: rim 1')
>>> h = hull(200)
>>> len(h), h.source
(10, 'ship hull, 200 bicubic Bezier patches (nu=11, nv=6, nd=4), 4 portholes a side')
"""

from __future__ import annotations

import numpy as np

__all__ = ["teapot_field", "hull", "hull_spans", "ellipse_loop", "rectangle_loop"]


def teapot_field(n: int, spacing: float = 10.0, seed: int = 0):
    """``n`` copies of the Newell teapot (32 bicubic Bezier patches each) on a square grid, each turned about
    the vertical by a random angle and scaled by a random factor in ``[0.6, 1.4]`` (so neighbours never touch
    at the default ``spacing``: the teapot reaches 3.6 from its axis). One :class:`NurbsModel`; patch
    ``32 i + k`` is part ``k`` of copy ``i``, named ``"teapot i: <part>"``. 1250 copies are 40,000 patches.

    >>> m = teapot_field(3, seed=1)
    >>> len(m), m.names[0], m.names[95]
    (96, 'teapot 0: rim 0', 'teapot 2: bottom 3')
    >>> x0, x1, y0, y1, z0, z1 = m.bounds()
    >>> bool(z0 == 0.0), bool(9.0 < x1 - x0 < 25.0)  # copies stand on z = 0, one grid step apart in x
    (True, True)
    """
    from splinevis.nurbs.model import NurbsModel
    from splinevis.nurbs.surface import NurbsSurface

    from .teapot import TEAPOT_GROUPS, newell_teapot

    n = int(n)
    if n < 1:
        raise ValueError(f"teapot_field needs at least one teapot, got n={n}.")
    base = newell_teapot()
    nets = np.stack([s.control_points for s in base.surfaces])  # (32, 4, 4, 3)
    parts = [f"{g} {k - a}" for g, a, b in TEAPOT_GROUPS for k in range(a, b)]
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    scale = rng.uniform(0.6, 1.4, n)
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros((n, 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1], R[:, 2, 2] = c, -s, s, c, 1.0
    R *= scale[:, None, None]  # rotation and a positive scale: normals keep pointing out
    cols = int(np.ceil(np.sqrt(n)))
    iy, ix = np.divmod(np.arange(n), cols)
    offset = np.column_stack([ix * spacing, iy * spacing, np.zeros(n)])
    P = np.einsum("nij,kabj->nkabi", R, nets) + offset[:, None, None, None, :]  # (n, 32, 4, 4, 3)
    knots = base.surfaces[0].knots
    surfaces = [NurbsSurface((3, 3), knots, P[i, k], name=f"teapot {i}: {parts[k]}")
                for i in range(n) for k in range(len(parts))]
    return NurbsModel(surfaces, source=f"{n} Newell teapots, {32 * n} bicubic Bezier patches")


# -------------------------------------------------------------------------------------------------
LENGTH, BEAM, DEPTH = 100.0, 8.0, 10.0  # the hull's length, half beam and depth amidships


def _shape(s, t):
    """Port-side hull points ``(..., 3)`` at ``s`` in [0, 1] from bow to stern and ``t`` in [0, 1] around the
    section from the keel (y = 0) to the sheer (the deck edge)."""
    s, t = np.broadcast_arrays(np.asarray(s, dtype=np.float64), np.asarray(t, dtype=np.float64))
    b = BEAM * np.sin(0.5 * np.pi * np.minimum(s / 0.3, 1.0)) * (1.0 - 0.25 * np.maximum(s - 0.75, 0.0) ** 2 / 0.0625)
    keel = 2.5 * np.maximum(1.0 - s / 0.15, 0.0) ** 2  # the forefoot rises at the bow
    sheer = DEPTH + 1.5 * (1.0 - s) ** 2  # the deck edge rises toward the bow
    th = 0.5 * np.pi * t
    return np.stack([LENGTH * s, b * np.sin(th), keel + (sheer - keel) * (1.0 - np.cos(th))], axis=-1)


def _knots(a: float, b: float, spans: int):
    """Clamped uniform cubic knots on [a, b] and their Greville abscissae (ends exactly a and b)."""
    inner = a + (b - a) * np.arange(1, spans) / spans
    U = np.concatenate([[a] * 4, inner, [b] * 4])
    g = (U[1:-3] + U[2:-2] + U[3:-1]) / 3.0
    g[0], g[-1] = a, b
    return U, g


def hull_spans(patches: int) -> tuple:
    """``(nu, nv, nd)``: knot spans along the hull, around one side's section and across the deck, so that
    the hull has ``nu (2 nv + nd) + nd nv`` Bezier patches: exactly ``patches`` where such spans exist (every
    count from 630 to 50,000 was checked, and most smaller ones), else the nearest count; among the exact
    ones the closest to the hull's proportions (nv ~ 0.15 nu, nd ~ 0.16 nu: spans of similar size).

    >>> hull_spans(20000), hull_spans(200)
    ((195, 31, 35), (11, 6, 4))
    """
    N = int(patches)
    if N < 10:
        raise ValueError(f"a hull needs at least 10 patches (1 span along, 3 around, 1 across), got {patches}.")
    top = int(np.sqrt(N)) + 2
    nv, nd = np.meshgrid(np.arange(3, top + 3), np.arange(1, top + 1), indexing="ij")
    nu = np.maximum(np.rint((N - nd * nv) / (2 * nv + nd)), 1).astype(np.int64)
    miss = np.abs(nu * (2 * nv + nd) + nd * nv - N)
    shape = np.abs(np.log(nv / (0.15 * nu))) + np.abs(np.log(nd / (0.16 * nu)))
    k = np.lexsort((shape.ravel(), miss.ravel()))[0]
    return int(nu.ravel()[k]), int(nv.ravel()[k]), int(nd.ravel()[k])


def ellipse_loop(cu, cv, ru, rv):
    """A closed trim loop: the exact rational ellipse about ``(cu, cv)`` with radii ``(ru, rv)`` (one quadratic
    TrimCurve).

    >>> c = ellipse_loop(0.5, 0.5, 0.2, 0.1)[0]
    >>> p = c.evaluate([c.domain[0]])[0]
    >>> bool(abs(((p[0] - 0.5) / 0.2) ** 2 + ((p[1] - 0.5) / 0.1) ** 2 - 1) < 1e-12)
    True
    """
    from splinevis.nurbs.exact import CIRCLE_KNOTS, circle_net
    from splinevis.nurbs.model import TrimCurve

    xy, w = circle_net()
    return [TrimCurve(2, CIRCLE_KNOTS, np.array([cu, cv]) + np.array([ru, rv]) * xy, w)]


def rectangle_loop(u0, u1, v0, v1):
    """A closed trim loop: the rectangle ``[u0, u1] x [v0, v1]`` counter-clockwise, four lines.

    >>> [c.control_points.tolist() for c in rectangle_loop(0, 1, 0, 2)][:2]
    [[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [1.0, 2.0]]]
    """
    from splinevis.nurbs.model import TrimCurve

    c = [(u0, v0), (u1, v0), (u1, v1), (u0, v1), (u0, v0)]
    return [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in zip(c[:-1], c[1:])]


def hull(patches: int = 20000, portholes: bool = True):
    """A closed ship hull of bicubic B-spline surfaces whose Bezier decomposition has ``patches`` patches
    (see :func:`hull_spans`): each side as three strakes (bilge, a porthole band one span high, topside),
    the deck, and the transom in three strakes. Length 100 along +x from the bow (x = 0), half beam 8,
    depth 10 (sheer higher toward the bow). All normals point out of the hull.

    Neighbouring surfaces share their boundary control points exactly (keel, stem, strake seams, sheer,
    the transom's edges), so the patch mesh is closed: no open edge. Collapsed sides: the deck narrows to
    a point at the stem and the transom to a point at the keel. The sides are C0 across the strake seams.

    ``portholes=True`` trims circular portholes (ellipses in the parameter domain, about circles on the
    hull) out of every few patches of the porthole band, between 20 % and 85 % of the length: that
    band's surfaces carry trim loops (the domain's border and one hole per porthole; even-odd rule as in
    :class:`splinevis.nurbs.model.NurbsModel`). The holes do not change the patches' edges.

    >>> h = hull(500)
    >>> [s.name for s in h.surfaces][:4], len(h)
    (['port bilge', 'port portholes', 'port topside', 'starboard bilge'], 10)
    >>> len(h.trims[1]), h.trims[0] is None  # the border and 11 holes on the porthole band
    (12, True)
    """
    from splinevis.nurbs.model import NurbsModel
    from splinevis.nurbs.surface import NurbsSurface

    nu, nv, nd = hull_spans(patches)
    U, su = _knots(0.0, 1.0, nu)
    Ud, gd = _knots(0.0, 1.0, nd)  # across the deck and the transom, starboard to port
    jp = nv - 1 - max(1, nv // 8)  # the porthole band: one span of t near the sheer
    cuts = [0.0, jp / nv, (jp + 1) / nv, 1.0]
    spans = [jp, 1, nv - jp - 1]
    names = ["bilge", "portholes", "topside"]
    strakes = []  # (t knots, port net in t order)
    for (a, b), k in zip(zip(cuts[:-1], cuts[1:]), spans):
        V, gv = _knots(a, b, k)
        strakes.append((V, _shape(su[:, None], gv[None, :])))
    mirror = np.array([1.0, -1.0, 1.0])
    surfaces, trims = [], []
    holes = []
    if portholes:  # porthole centres (u, t) and radii: a circle of 0.3 of the smaller span side on the hull
        V, net = strakes[1]
        band = NurbsSurface((3, 3), (U, V), net)
        du, dv = 1.0 / nu, cuts[2] - cuts[1]
        every = max(2, nu // 40)
        cu = (np.arange(nu) + 0.5) * du
        cu = cu[(cu > 0.2) & (cu < 0.85) & (np.arange(nu) % every == 0)]
        ct = np.full(cu.size, 0.5 * (cuts[1] + cuts[2]))
        if cu.size:
            d = band.derivatives(cu, ct, 1)
            speed_u, speed_v = np.linalg.norm(d[:, 1, 0], axis=1), np.linalg.norm(d[:, 0, 1], axis=1)
            r3 = 0.3 * np.minimum(speed_u * du, speed_v * dv)
            holes = list(zip(cu, ct, r3 / speed_u, r3 / speed_v))
    for side in ("port", "starboard"):
        for name, (V, net) in zip(names, strakes):
            if side == "port":  # v from the sheer down to the keel: S_u x S_v points out (+y)
                P, Vs = net[:, ::-1], (V[0] + V[-1]) - V[::-1]
            else:  # the mirror image, v from the keel up
                P, Vs = net * mirror, V
            surfaces.append(NurbsSurface((3, 3), (U, Vs), P, name=f"{side} {name}"))
            loops = None
            if name == "portholes" and holes:
                a, b = Vs[0], Vs[-1]
                flip = side == "port"
                loops = [rectangle_loop(0.0, 1.0, a, b)] + [ellipse_loop(u, (a + b - t) if flip else t, ru, rv)
                                                            for u, t, ru, rv in holes]
            trims.append(loops)
    Sp, Ss = strakes[-1][1][:, -1], strakes[-1][1][:, -1] * mirror  # port and starboard sheer rows
    crown = 0.3 * 4.0 * gd * (1.0 - gd)  # deck camber, scaled down with the beam toward the bow
    width = np.abs(Sp[:, 1]) / BEAM
    deck = (1.0 - gd)[None, :, None] * Ss[:, None, :] + gd[None, :, None] * Sp[:, None, :]
    deck[..., 2] += width[:, None] * crown[None, :]
    surfaces.append(NurbsSurface((3, 3), (U, Ud), deck, name="deck"))
    trims.append(None)
    for name, (V, net) in zip(names, strakes):  # the transom: u starboard to port, v keel up (normal +x)
        T = (1.0 - gd)[:, None, None] * (net[-1] * mirror)[None, :, :] + gd[:, None, None] * net[-1][None, :, :]
        if name == "topside":
            T[:, -1, 2] += width[-1] * crown
        surfaces.append(NurbsSurface((3, 3), (Ud, V), T, name=f"transom {name}"))
        trims.append(None)
    count = nu * (2 * nv + nd) + nd * nv
    return NurbsModel(surfaces, trims=trims, source=f"ship hull, {count} bicubic Bezier patches (nu={nu}, nv={nv}, "
                                                     f"nd={nd}), {len(holes)} portholes a side")

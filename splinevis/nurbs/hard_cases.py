"""Scenes where the float32 NURBS fragment program is most likely to part from its float64 twin
(:class:`splinevis.gl.contract.HardCase`): poles (a collapsed row: S_u = 0), seams at knot values, a C0 crease
(an interior knot of multiplicity p), degree 7, tiny and huge patches, coordinates around 1e6, a grazing
view, a camera inside the bounding box, the Newell teapot's poles (real data), and poles without half-turn symmetry (a Newton step over the pole must
go on along the antipodal meridian, not half a turn on: :mod:`splinevis.nurbs.poles`)."""

from __future__ import annotations

import numpy as np

from ..gl.contract import HardCase
from .exact import saddle, sphere, torus
from .model import NurbsModel
from .surface import NurbsSurface

__all__ = ["crease", "degree7", "bumpy", "trimmed_plate", "unequal_arcs_sphere", "hard_cases"]


def crease() -> NurbsSurface:
    """A roof: biquadratic, the u knot 0.5 repeated twice (multiplicity p: C0 across x = 0).

    >>> s = crease()
    >>> s.evaluate([0.5], [0.5]).round(12).tolist()  # on the ridge (lifted by 0.2 y^2 in the control net)
    [[0.0, 0.0, 1.1]]
    """
    x = np.array([-1.0, -0.5, 0.0, 0.5, 1.0])
    z = np.array([0.0, 0.5, 1.0, 0.5, 0.0])
    y = np.array([-1.0, 0.0, 1.0])
    P = np.empty((5, 3, 3))
    P[..., 0], P[..., 1] = x[:, None], y[None, :]
    P[..., 2] = z[:, None] + 0.2 * y[None, :] ** 2
    U = np.array([0, 0, 0, 0.5, 0.5, 1, 1, 1.0])
    V = np.array([0, 0, 0, 1, 1, 1.0])
    return NurbsSurface((2, 2), (U, V), P, name="crease")


def trimmed_plate() -> NurbsModel:
    """A bicubic plate over [-1, 1]^2 with a circular hole holding a round island (nested loops, exact rational
    circles in the parameter domain; outer loop = the domain's border).

    >>> m = trimmed_plate()
    >>> len(m.trims[0])  # border, hole, island
    3
    """
    from .exact import CIRCLE_KNOTS, circle_net
    from .model import TrimCurve

    k = [0.0] * 4 + [1.0] * 4
    g = np.linspace(-1.0, 1.0, 4)
    X, Y = np.meshgrid(g, g, indexing="ij")
    P = np.stack([X, Y, 0.15 * X**2 - 0.1 * Y], axis=-1)
    xy, w = circle_net()
    border = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in
              [((0, 0), (1, 0)), ((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))]]
    hole = [TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.3 * xy, w)]
    island = [TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.12 * xy, w)]
    return NurbsModel([NurbsSurface((3, 3), (k, k), P, name="plate")], trims=[[border, hole, island]])


def _trim_zoom_camera(model):
    # 1000x zoom onto the hole's edge: the plate is 2 wide, the view ~2e-3 (a pixel ~1e-5 of the plate)
    s = model.surfaces[0]
    p = s.evaluate([0.8], [0.5])[0]
    n = s.normal([0.8], [0.5])[0]
    return [tuple(p + 0.004 * n), tuple(p), (0.0, 1.0, 0.0)]


def degree7() -> NurbsSurface:
    """A bumpy degree-7 x 7 Bezier patch over [-1, 1]^2 with unequal weights.

    >>> degree7().degree, degree7().rational
    ((7, 7), True)
    """
    return bumpy(7, 7, 8, 8)


def bumpy(p: int, q: int, nu: int, nv: int, x0: float = 0.0) -> NurbsSurface:
    """A bumpy rational patch of degrees (p, q) over [x0 - 1, x0 + 1] x [-1, 1], uniform interior knots.

    >>> s = bumpy(3, 1, 6, 2, x0=5.0)
    >>> s.degree, s.shape, s.knots[0].tolist()
    ((3, 1), (6, 2), [0.0, 0.0, 0.0, 0.0, 0.3333333333333333, 0.6666666666666666, 1.0, 1.0, 1.0, 1.0])
    """
    tu, tv = np.linspace(-1.0, 1.0, nu), np.linspace(-1.0, 1.0, nv)
    P = np.empty((nu, nv, 3))
    P[..., 0], P[..., 1] = x0 + tu[:, None], tv[None, :]
    P[..., 2] = 0.4 * np.sin(3.0 * tu[:, None]) * np.cos(2.0 * tv[None, :])
    W = 1.0 + 0.5 * np.outer(np.cos(tu), np.cos(tv))

    def clamped(d, n):
        return np.r_[np.zeros(d + 1), np.linspace(0.0, 1.0, n - d + 1)[1:-1], np.ones(d + 1)]

    return NurbsSurface((p, q), (clamped(p, nu), clamped(q, nv)), P, W, name=f"bumpy{p}{q}")


def unequal_arcs_sphere(arcs=(150.0, 90.0, 60.0, 60.0), radius: float = 1.0) -> NurbsSurface:
    """The unit sphere, exactly, but its u circle made of four arcs of unequal angles (degrees, summing to 360;
    each a rational quadratic: middle point on the tangents' meet, weight cos(angle / 2) [PieglTiller1997,
    sec. 7.5]) over equal knot spans: the meridian half a turn on in u is not the antipodal one (at u = 0, the
    +x meridian, the antipode -x is at u = 0.25 + 0.25 * 30 / 90 in angle, not 0.5), so the old half-turn rule
    over the poles lands up to ~60 degrees off.

    >>> s = unequal_arcs_sphere()
    >>> u, v = np.linspace(0, 1, 7), np.linspace(0, 1, 7)
    >>> bool(np.abs(np.linalg.norm(s.evaluate(u, v), axis=1) - 1).max() < 1e-15), s.shape
    (True, (9, 5))
    """
    base = sphere(radius)
    phi = np.radians(np.concatenate([[0.0], np.cumsum(arcs)]))
    if abs(phi[-1] - 2 * np.pi) > 1e-12 or len(arcs) != 4 or max(arcs) >= 180:
        raise ValueError(f"arcs must be four angles below 180 summing to 360 degrees, got {arcs!r}.")
    xy, wc = [], []
    for a, b in zip(phi[:-1], phi[1:]):
        h, m = 0.5 * (b - a), 0.5 * (a + b)
        xy += [[np.cos(a), np.sin(a)], [np.cos(m) / np.cos(h), np.sin(m) / np.cos(h)]]
        wc += [1.0, np.cos(h)]
    xy, wc = np.array(xy + [[1.0, 0.0]]), np.array(wc + [1.0])
    rho, z = base.control_points[0, :, 0], base.control_points[0, :, 2]
    P = np.stack([xy[:, None, 0] * rho, xy[:, None, 1] * rho, np.broadcast_to(z, (9, len(z)))], axis=-1)
    return NurbsSurface((2, 2), (base.knots[0], base.knots[1]), P, np.outer(wc, base.weights[0]),
                        name="unequal-arcs-sphere")


def _teapot():
    from datasets_synthetic.teapot import newell_teapot  # real data: the Newell teapot's 32 patches

    return newell_teapot()


def _scaled(r, c):
    return lambda: NurbsModel([sphere(r, c)])


def hard_cases() -> list:
    """The NURBS program's hard cases.

    >>> [c.name for c in hard_cases()][:3]
    ['sphere-poles', 'torus', 'saddle']
    """
    far = (1.0e6, -2.0e6, 5.0e5)
    return [
        HardCase("sphere-poles", _scaled(1.0, (0, 0, 0)), [(2.0, -2.0, 3.5), (0, 0, 0), (0, 1, 0)]),
        HardCase("torus", lambda: NurbsModel([torus()]), [(4.0, -5.0, 3.0), (0, 0, 0), (0, 0, 1)]),
        HardCase("saddle", lambda: NurbsModel([saddle()]), [(2.5, -3.0, 3.0), (0, 0, 0), (0, 0, 1)]),
        HardCase("c0-crease", lambda: NurbsModel([crease()]), [(2.0, -3.0, 2.5), (0, 0, 0.4), (0, 0, 1)]),
        HardCase("degree-7", lambda: NurbsModel([degree7()]), [(2.0, -3.0, 2.5), (0, 0, 0), (0, 0, 1)]),
        HardCase("mixed-degrees", lambda: NurbsModel([bumpy(1, 1, 3, 3, -4.4), bumpy(3, 1, 6, 2, -2.2), bumpy(2, 5, 5, 7),
                                                      bumpy(5, 4, 9, 7, 2.2), bumpy(6, 3, 7, 5, 4.4)]),
                 [(0.0, -9.0, 6.0), (0, 0, 0), (0, 0, 1)], (200, 100)),
        HardCase("tiny", _scaled(1e-3, (0, 0, 0)), [(3e-3, -4e-3, 2e-3), (0, 0, 0), (0, 0, 1)]),
        HardCase("huge", _scaled(1e4, (0, 0, 0)), [(3e4, -4e4, 2e4), (0, 0, 0), (0, 0, 1)]),
        HardCase("far-from-origin", lambda: NurbsModel([torus(2.0, 0.5, far)]),
                 [(far[0] + 4.0, far[1] - 5.0, far[2] + 3.0), far, (0, 0, 1)]),
        HardCase("grazing-2-degrees", lambda: NurbsModel([degree7()]),
                 [(0.0, -6.0, 0.21), (0.0, 0.0, 0.0), (0, 0, 1)]),
        HardCase("camera-inside-box", lambda: NurbsModel([torus()]), [(0.0, 0.0, 0.3), (2.0, 0.3, 0.0), (0, 0, 1)],
                 clipping_range=(1e-3, 10.0)),
        HardCase("seams-at-knots", lambda: NurbsModel([torus()]), [(6.0, 0.0, 0.0), (0, 0, 0), (0, 0, 1)]),
        HardCase("trimmed-hole-and-island", trimmed_plate, [(0.3, -2.2, 2.4), (0.0, 0.0, 0.0), (0, 0, 1)]),
        HardCase("trim-edge-1000x-zoom", trimmed_plate, _trim_zoom_camera, clipping_range=(1e-4, 1.0)),
        # close to the south pole of a sphere whose u circle is four unequal arcs: fragments near the pole start on
        # the wrong side of it (the shell is pushed outward), Newton steps over the pole and must go on along the
        # antipodal meridian (the pole table), not half a turn on. 16 steps: a view this close to a pole converges
        # slowly however the pole is crossed (the equal-arc sphere has as many slow pixels here); with the
        # half-turn rule 39 depths leave the bound (99.73%, failing), with the antipode rule 7 (99.95%)
        # real data: the Newell teapot seen from above and from below; four patches, each a quarter turn (open in
        # u), meet at the knob's pole and at the bottom's centre (a step over those poles cannot go on in the same
        # patch: the neighbour's fragments must cover it), seams with only G1, handle and spout through the body
        HardCase("teapot-knob-pole", _teapot, [(0.3, -0.4, 6.0), (0.0, 0.0, 2.5), (0, 1, 0)]),
        HardCase("teapot-bottom-pole", _teapot, [(0.5, -0.4, -4.0), (0.0, 0.0, 0.5), (0, 1, 0)]),
        HardCase("pole-without-half-turn-symmetry", lambda: NurbsModel([unequal_arcs_sphere()]),
                 [(0.25, 0.1, -1.15), (0.0, 0.0, -1.0), (0, 1, 0)], newton_iterations=16),
    ]

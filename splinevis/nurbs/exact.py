"""Surfaces with known geometry, exactly represented as NURBS: the reference cases of the tests.

Circles are rational quadratics with 9 control points on a square (weights 1 and sqrt(2)/2)
[PieglTiller1997, sec. 7.5]; surfaces of revolution take the tensor product of a profile and that circle
[PieglTiller1997, sec. 8.5]. Known values: sphere ``K = 1/r^2``, area ``4 pi r^2``; torus
``K = cos(phi) / (r (R + r cos(phi)))``, area ``4 pi^2 R r``; cylinder ``K = 0``, ``|H| = 1/(2r)``;
saddle ``z = x^2 - y^2`` (polynomial, biquadratic).
"""

from __future__ import annotations

import numpy as np

from .surface import NurbsSurface

__all__ = ["circle_net", "sphere", "torus", "cylinder", "saddle", "box_faces", "CIRCLE_KNOTS"]

_H = np.sqrt(0.5)
#: Knots of the 9-point full circle (quarter arcs joined at double knots).
CIRCLE_KNOTS = np.array([0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1], dtype=np.float64)
_SEMI_KNOTS = np.array([0, 0, 0, 0.5, 0.5, 1, 1, 1], dtype=np.float64)


def circle_net():
    """Unit-circle control points (9, 2) and weights (9,), counter-clockwise from (1, 0).

    >>> xy, w = circle_net()
    >>> xy[:3].tolist(), w[:3].round(4).tolist()
    ([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], [1.0, 0.7071, 1.0])
    """
    xy = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]], dtype=np.float64)
    w = np.array([1, _H, 1, _H, 1, _H, 1, _H, 1], dtype=np.float64)
    return xy, w


def _revolve(profile_rz, profile_w, profile_knots, center, name, degree=2):
    """Revolve a (rho, z) profile about the z axis: u around the axis, v along the profile."""
    xy, wc = circle_net()
    rho, z = profile_rz[:, 0], profile_rz[:, 1]
    P = np.empty((9, len(rho), 3))
    P[..., 0] = xy[:, None, 0] * rho[None, :]
    P[..., 1] = xy[:, None, 1] * rho[None, :]
    P[..., 2] = z[None, :]
    P += np.asarray(center, dtype=np.float64)
    return NurbsSurface((2, degree), (CIRCLE_KNOTS, profile_knots), P, np.outer(wc, profile_w), name=name)


def sphere(radius: float = 1.0, center=(0.0, 0.0, 0.0)) -> NurbsSurface:
    """The sphere: a semicircle from the south to the north pole, revolved (poles are degenerate rows).

    >>> s = sphere(2.0)
    >>> float(np.linalg.norm(s.evaluate([0.3], [0.7])[0])), s.shape
    (2.0, (9, 5))
    """
    r = float(radius)
    prof = np.array([[0, -r], [r, -r], [r, 0], [r, r], [0, r]], dtype=np.float64)
    return _revolve(prof, np.array([1, _H, 1, _H, 1]), _SEMI_KNOTS, center, "sphere")


def torus(R: float = 2.0, r: float = 0.5, center=(0.0, 0.0, 0.0)) -> NurbsSurface:
    """The torus: a circle of radius ``r`` centred at distance ``R`` from the axis, revolved.

    The tube angle is ``phi`` with ``v = 0`` on the outer equator (``cos phi = 1``).

    >>> t = torus(2.0, 0.5)
    >>> t.evaluate([0.0], [0.0]).tolist()  # the outer equator at u = 0
    [[2.5, 0.0, 0.0]]
    """
    xy, w = circle_net()
    prof = np.column_stack([R + r * xy[:, 0], r * xy[:, 1]])
    return _revolve(prof, w, CIRCLE_KNOTS, center, "torus")


def cylinder(radius: float = 1.0, height: float = 1.0, center=(0.0, 0.0, 0.0)) -> NurbsSurface:
    """The cylinder ``x^2 + y^2 = r^2``, ``0 <= z <= height`` (a line revolved).

    >>> c = cylinder(2.0, 3.0)
    >>> c.evaluate([0.25], [1.0]).round(12).tolist()  # a quarter turn, the top
    [[0.0, 2.0, 3.0]]
    """
    prof = np.array([[radius, 0.0], [radius, height]], dtype=np.float64)
    return _revolve(prof, np.ones(2), np.array([0, 0, 1, 1], dtype=np.float64), center, "cylinder", degree=1)


def saddle(size: float = 1.0) -> NurbsSurface:
    """``z = x^2 - y^2`` over ``[-size, size]^2`` as one biquadratic Bezier patch (x = size (2u - 1)).

    >>> s = saddle()
    >>> s.evaluate([0.75], [0.5]).tolist()  # x = 0.5, y = 0
    [[0.5, 0.0, 0.25]]
    """
    a = float(size)
    x = np.array([-a, 0.0, a])
    sq = np.array([a * a, -a * a, a * a])  # Bernstein coefficients of x^2 on [-a, a]
    P = np.empty((3, 3, 3))
    P[..., 0] = x[:, None]
    P[..., 1] = x[None, :]
    P[..., 2] = sq[:, None] - sq[None, :]
    k = np.array([0, 0, 0, 1, 1, 1], dtype=np.float64)
    return NurbsSurface((2, 2), (k, k), P, name="saddle")


def box_faces(a: float = 1.0, b: float = 1.0, c: float = 1.0) -> list:
    """The six faces of the box ``[0, a] x [0, b] x [0, c]``, bilinear patches with ``S_u x S_v`` pointing out.

    >>> faces = box_faces(2.0, 1.0, 1.0)
    >>> [f.name for f in faces[:2]], faces[1].normal([0.5], [0.5]).tolist()
    (['box -z', 'box +z'], [[0.0, 0.0, 1.0]])
    """
    P = [[[x, y, z] for z in (0.0, c)] for x in (0.0, a) for y in (0.0, b)]  # P[2 i + j][k]: x_i, y_j, z_k
    corner = lambda i, j, k: P[2 * i + j][k]  # noqa: E731
    quads = {  # (p00, p10, p01, p11) with (p10 - p00) x (p01 - p00) outward
        "-z": ((0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0)), "+z": ((0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1)),
        "-y": ((0, 0, 0), (1, 0, 0), (0, 0, 1), (1, 0, 1)), "+y": ((0, 1, 0), (0, 1, 1), (1, 1, 0), (1, 1, 1)),
        "-x": ((0, 0, 0), (0, 0, 1), (0, 1, 0), (0, 1, 1)), "+x": ((1, 0, 0), (1, 1, 0), (1, 0, 1), (1, 1, 1)),
    }
    return [NurbsSurface.bilinear(*(corner(*q) for q in qs), name=f"box {side}") for side, qs in quads.items()]

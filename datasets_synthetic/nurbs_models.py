"""Synthetic NURBS test models: a freeform bicubic "hood" with non-uniform knots, tilings of many small patches
and one-patch surfaces of every degree (for the NURBS study and hard cases)."""

from __future__ import annotations

import numpy as np

__all__ = ["hood", "patch_tiling", "degree_patch", "vase"]


def hood(n: int = 8, seed: int = 3):
    """A smooth freeform bicubic B-spline surface over ``[0, 2] x [0, 1]`` (n x n control points, non-uniform
    interior knots, heights of a gentle crown plus small waves), the kind of panel zebra stripes judge.

    >>> s = hood()
    >>> s.degree, s.shape, s.domain
    ((3, 3), (8, 8), ((0.0, 1.0), (0.0, 1.0)))
    """
    from splinevis.nurbs.surface import NurbsSurface

    rng = np.random.default_rng(seed)
    inner = np.sort(rng.uniform(0.15, 0.85, n - 4))
    knots = np.concatenate([[0.0] * 4, inner, [1.0] * 4])
    x = np.linspace(0.0, 2.0, n)
    y = np.linspace(0.0, 1.0, n)
    X, Y = np.meshgrid(x, y, indexing="ij")
    Z = 0.35 * (1 - (X - 1) ** 2) * (1 - (2 * Y - 1) ** 2) + 0.03 * np.sin(3 * X + 2 * Y)
    return NurbsSurface((3, 3), (knots, knots), np.stack([X, Y, Z], axis=-1), name="hood")


def patch_tiling(count: int, size: float = 2.0):
    """``count`` bicubic Bezier patches (a square number is used as given, else the next one's first ``count``)
    tiling a ``size x size`` square: the same picture drawn by more, smaller patches.

    >>> m = patch_tiling(32)
    >>> len(m), m.surfaces[0].degree
    (32, (3, 3))
    """
    from splinevis.nurbs.model import NurbsModel
    from splinevis.nurbs.surface import NurbsSurface

    k = int(np.ceil(np.sqrt(count)))
    h = size / k
    t = np.linspace(0.0, 1.0, 4)
    knots = [0.0] * 4 + [1.0] * 4
    patches = []
    for idx in range(count):
        i, j = divmod(idx, k)
        X, Y = np.meshgrid(i * h + t * h, j * h + t * h, indexing="ij")
        Z = 0.2 * np.sin(2.0 * X) * np.cos(1.5 * Y)  # control net of a smooth graph (not interpolating)
        patches.append(NurbsSurface((3, 3), (knots, knots), np.stack([X, Y, Z], axis=-1), name=f"tile{idx}"))
    return NurbsModel(patches, source=f"{count} bicubic tiles")


def degree_patch(p: int, seed: int = 0):
    """One clamped patch of degree ``p x p`` with ``p + 3`` control points per direction over ``[0, 2] x [0, 2]``.

    >>> degree_patch(5).degree, degree_patch(5).shape
    ((5, 5), (8, 8))
    """
    from splinevis.nurbs.surface import NurbsSurface

    n = p + 3
    knots = np.concatenate([[0.0] * (p + 1), np.linspace(0, 1, n - p + 1)[1:-1], [1.0] * (p + 1)])
    g = np.linspace(0.0, 2.0, n)
    X, Y = np.meshgrid(g, g, indexing="ij")
    Z = 0.25 * np.sin(1.7 * X + 0.3) * np.cos(1.3 * Y) + 0.05 * np.random.default_rng(seed).normal(size=X.shape)
    return NurbsSurface((p, p), (knots, knots), np.stack([X, Y, Z], axis=-1), name=f"degree{p}")


def vase(profile=((0.0, 0.0), (1.0, 0.0), (1.3, 0.6), (0.9, 1.2), (0.6, 1.6), (0.7, 2.1), (0.9, 2.4), (0.85, 2.6)),
         segments: int = 8):
    """A vase of ``4 * segments`` bicubic Bezier patches, built the way the Newell teapot's body is: a profile of
    cubic Bezier segments (a Catmull-Rom spline through the ``profile`` points (radius, height), resampled to
    ``segments`` segments) revolved in four quarter turns, each quarter circle the cubic Bezier approximation
    with handles ``k = 4/3 (sqrt(2) - 1)`` (radial error 2.7e-4 of the radius) [Farin2002, ch. 13].

    >>> m = vase()
    >>> len(m), m.surfaces[0].degree, m.surfaces[0].shape
    (32, (3, 3), (4, 4))
    """
    from splinevis.nurbs.model import NurbsModel
    from splinevis.nurbs.surface import NurbsSurface

    pts = np.asarray(profile, dtype=np.float64)
    # Catmull-Rom through the points, then resampled: Bezier control points of each segment
    ext = np.vstack([2 * pts[0] - pts[1], pts, 2 * pts[-1] - pts[-2]])
    t = np.linspace(0.0, len(pts) - 1.0, segments + 1)

    def cr(s, d=0):
        i = np.clip(np.floor(s).astype(int), 0, len(pts) - 2)
        u = (s - i)[:, None]
        p0, p1, p2, p3 = ext[i], ext[i + 1], ext[i + 2], ext[i + 3]
        if d == 0:
            return 0.5 * (2 * p1 + (-p0 + p2) * u + (2 * p0 - 5 * p1 + 4 * p2 - p3) * u**2 + (-p0 + 3 * p1 - 3 * p2 + p3) * u**3)
        return 0.5 * ((-p0 + p2) + 2 * (2 * p0 - 5 * p1 + 4 * p2 - p3) * u + 3 * (-p0 + 3 * p1 - 3 * p2 + p3) * u**2)

    a, b = cr(t[:-1]), cr(t[1:])
    h = (t[1] - t[0]) / 3.0
    prof = np.stack([a, a + h * cr(t[:-1], 1), b - h * cr(t[1:], 1), b], axis=1)  # (segments, 4, (r, z))
    k = 4.0 / 3.0 * (np.sqrt(2.0) - 1.0)
    knots = [0.0] * 4 + [1.0] * 4
    patches = []
    for q in range(4):
        c0, s0 = np.cos(q * np.pi / 2), np.sin(q * np.pi / 2)
        e0, e1 = np.array([c0, s0]), np.array([-s0, c0])  # start direction and its quarter turn
        arc = np.stack([e0, e0 + k * e1, e1 + k * e0, e1])  # the unit quarter circle's cubic Bezier net
        for sgm in range(segments):
            P = np.empty((4, 4, 3))
            P[..., :2] = arc[:, None, :] * prof[sgm][None, :, 0, None]
            P[..., 2] = prof[sgm][None, :, 1]
            patches.append(NurbsSurface((3, 3), (knots, knots), P, name=f"vase q{q} s{sgm}"))
    return NurbsModel(patches, source=f"vase, {4 * segments} bicubic Bezier patches")

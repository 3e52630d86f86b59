"""Synthetic NURBS test models: a freeform bicubic "hood" with non-uniform knots, tilings of many small patches
and one-patch surfaces of every degree (for the NURBS study and hard cases)."""

from __future__ import annotations

import numpy as np

__all__ = ["hood", "patch_tiling", "degree_patch"]


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

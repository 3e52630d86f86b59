"""Two bicubic patches joined along a seam with a chosen continuity: the golden case of surface interrogation.

Patch A is the graph ``z = a x^2`` over ``x in [-1, 0]``, patch B a graph over ``x in [0, 1]`` that meets it
with G2 (``z = a x^2`` continued), G1 (``z = -a x^2``: same tangent plane, curvature jumps by 4a), G0
(``z = a x``: a crease) or with a gap (B lifted). Both are cubic in x and linear-as-cubic in y over
``y in [0, 1]``; zebra stripes must kink at a G1 seam and run smoothly across a G2 one.
"""

from __future__ import annotations

from math import comb

import numpy as np

__all__ = ["graph_patch", "joined_pair", "JOINS"]

#: The kinds of seam :func:`joined_pair` builds.
JOINS = ("G2", "G1", "G0", "gap")


def graph_patch(x0: float, x1: float, g, y0: float = 0.0, y1: float = 1.0, name: str = ""):
    """The bicubic Bezier patch of the graph ``z = g(x)`` (g a polynomial of degree <= 3) over
    ``[x0, x1] x [y0, y1]`` (u along x, v along y).

    >>> s = graph_patch(0.0, 2.0, lambda x: x**3)
    >>> float(s.evaluate([0.5], [0.3])[0, 2])  # x = 1
    1.0
    """
    from splinevis.nurbs.surface import NurbsSurface

    t = np.linspace(0.0, 1.0, 4)
    bern = np.array([[comb(3, i) * s**i * (1 - s) ** (3 - i) for i in range(4)] for s in t])
    cz = np.linalg.solve(bern, np.asarray(g(x0 + t * (x1 - x0)), dtype=np.float64))
    P = np.zeros((4, 4, 3))
    P[..., 0] = np.linspace(x0, x1, 4)[:, None]
    P[..., 1] = np.linspace(y0, y1, 4)[None, :]
    P[..., 2] = cz[:, None]
    k = [0.0] * 4 + [1.0] * 4
    return NurbsSurface((3, 3), (k, k), P, name=name)


def joined_pair(join: str = "G2", a: float = 0.5):
    """Patches A and B meeting at ``x = 0`` with the continuity ``join`` (one of :data:`JOINS`).

    >>> A, B = joined_pair("G1")
    >>> A.evaluate([1.0], [0.5]).tolist() == B.evaluate([0.0], [0.5]).tolist()  # they meet at x = 0
    True
    """
    if join not in JOINS:
        raise ValueError(f"join must be one of {JOINS}, got {join!r}.")
    A = graph_patch(-1.0, 0.0, lambda x: a * x**2, name="A")
    g = {"G2": lambda x: a * x**2, "G1": lambda x: -a * x**2, "G0": lambda x: a * x,
         "gap": lambda x: a * x**2 + 0.02}[join]
    return A, graph_patch(0.0, 1.0, g, name=f"B-{join}")

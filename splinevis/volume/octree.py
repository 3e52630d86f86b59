"""Min-max octree over the cubes of a volume spline (paper 003, sec. 4, Fig. 5).

Level 0 holds one ``[lo, hi]`` range per cube (a bound of the cube's BB coefficients, so of the spline on
the cube by the convex-hull property); the node ``(k, j, i)`` of level L covers the cubes
``[2^L k, 2^L (k+1)) x ...`` and stores the min of their ``lo`` and max of their ``hi``. Nodes beyond the
grid hold the empty range ``(+inf, -inf)``. Nothing here depends on an isovalue: the tree is built once,
and :meth:`MinMaxOctree.candidates` answers any isovalue by descending only into nodes whose range
contains it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MinMaxOctree"]


def _reduce(a: np.ndarray, fill: float, op) -> np.ndarray:
    """2 x 2 x 2 reduction of a (nz, ny, nx) array, padding odd sizes with ``fill``."""
    nz, ny, nx = a.shape
    pz, py, px = nz % 2, ny % 2, nx % 2
    if pz or py or px:
        a = np.pad(a, ((0, pz), (0, py), (0, px)), constant_values=fill)
    a = op(a[0::2], a[1::2])
    a = op(a[:, 0::2], a[:, 1::2])
    return op(a[:, :, 0::2], a[:, :, 1::2])


class MinMaxOctree:
    """A min-max pyramid of cube ranges.

    Parameters
    ----------
    lo, hi : (nz, ny, nx) arrays
        Per-cube lower and upper bounds of the spline (float32 is enough if rounded outward).

    Attributes
    ----------
    levels : list of (lo, hi) arrays
        ``levels[0]`` is the input, ``levels[-1]`` has a single node.
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray):
        lo = np.asarray(lo)
        hi = np.asarray(hi)
        if lo.shape != hi.shape or lo.ndim != 3:
            raise ValueError(f"lo and hi must be 3-D arrays of one shape, got {lo.shape} and {hi.shape}.")
        self.shape = lo.shape
        self.levels = [(lo, hi)]
        while max(self.levels[-1][0].shape) > 1:
            a, b = self.levels[-1]
            self.levels.append((_reduce(a, np.inf, np.minimum), _reduce(b, -np.inf, np.maximum)))

    @property
    def depth(self) -> int:
        """Number of levels above the cubes."""
        return len(self.levels) - 1

    @property
    def nbytes(self) -> int:
        """Memory of all levels."""
        return int(sum(a.nbytes + b.nbytes for a, b in self.levels))

    @property
    def value_range(self) -> tuple:
        """``(lo, hi)`` over the whole volume."""
        a, b = self.levels[-1]
        return float(a.min()), float(b.max())

    def nodes(self, isovalue: float, level: int) -> np.ndarray:
        """(n, 3) int ``(i, j, k)`` of the nodes of ``level`` whose range contains ``isovalue``, found by
        descending from the root through containing nodes only."""
        if not 0 <= level <= self.depth:
            raise ValueError(f"level must be in 0..{self.depth}, got {level}.")
        iso = float(isovalue)
        a, b = self.levels[-1]
        idx = np.argwhere((a <= iso) & (iso <= b))  # (n, 3) as (k, j, i)
        for L in range(self.depth - 1, level - 1, -1):
            if len(idx) == 0:
                break
            a, b = self.levels[L]
            kids = (2 * idx[:, None, :] + _CHILD[None]).reshape(-1, 3)
            inside = (kids < np.array(a.shape)).all(axis=1)
            kids = kids[inside]
            k, j, i = kids.T
            keep = (a[k, j, i] <= iso) & (iso <= b[k, j, i])
            idx = kids[keep]
        return np.ascontiguousarray(idx[:, ::-1])

    def candidates(self, isovalue: float) -> np.ndarray:
        """(n, 3) int ``(i, j, k)`` of the cubes whose range contains ``isovalue``, in (k, j, i) lexicographic
        order."""
        c = self.nodes(isovalue, 0)
        order = np.lexsort((c[:, 0], c[:, 1], c[:, 2]))
        return c[order]


_CHILD = np.array([(dz, dy, dx) for dz in (0, 1) for dy in (0, 1) for dx in (0, 1)], dtype=np.int64)

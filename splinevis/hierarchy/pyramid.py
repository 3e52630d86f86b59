"""An n-dimensional min-max pyramid: bounds of a function over blocks of 2^L cells per axis.

Level 0 holds one ``[lo, hi]`` range per cell (for a spline: the min and max of the cell's BB coefficients,
so a bound of the spline on the cell by the convex-hull property). A node of level L covers the cells
``[2^L k, 2^L (k + 1))`` along every axis and stores the min of their ``lo`` and the max of their ``hi``;
an odd count is padded with the empty range ``(+inf, -inf)``. The top level is a single node. The terrain
program walks the 2-D pyramid per fragment (a quadtree over the cells [Reis2008]); the volume program
descends the 3-D one for every isovalue (the min-max octree of [Kalbe2008, sec. 4, Fig. 5]).
"""

from __future__ import annotations

import numpy as np

__all__ = ["MinMaxPyramid"]


def _reduce(a: np.ndarray, fill: float, op) -> np.ndarray:
    """2 x ... x 2 reduction of an n-D array by ``op``, padding odd sizes with ``fill``."""
    pad = [(0, s % 2) for s in a.shape]
    if any(p for _, p in pad):
        a = np.pad(a, pad, constant_values=fill)
    for axis in range(a.ndim):
        even = [slice(None)] * a.ndim
        odd = [slice(None)] * a.ndim
        even[axis], odd[axis] = slice(0, None, 2), slice(1, None, 2)
        a = op(a[tuple(even)], a[tuple(odd)])
    return a


class MinMaxPyramid:
    """Min-max bounds of cells and of blocks of 2^L x ... cells.

    Parameters
    ----------
    lo, hi : n-D arrays of one shape
        Per-cell lower and upper bounds (float32 is enough if rounded outward).

    Attributes
    ----------
    levels : list of (lo, hi)
        ``levels[0]`` is the input; ``levels[-1]`` has a single node.
    shape : tuple

    Examples
    --------
    >>> import numpy as np
    >>> lo = np.arange(12.0).reshape(3, 4)
    >>> p = MinMaxPyramid(lo, lo + 1)
    >>> p.depth, p.levels[1][0].tolist(), p.value_range
    (2, [[0.0, 2.0], [8.0, 10.0]], (0.0, 12.0))
    >>> p.nodes(5.5, 0).tolist()   # cells whose range holds 5.5, as array indices
    [[1, 1]]
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray):
        lo = np.asarray(lo)
        hi = np.asarray(hi)
        if lo.shape != hi.shape or lo.ndim < 1 or lo.size == 0:
            raise ValueError(f"lo and hi must be non-empty arrays of one shape, got {lo.shape} and {hi.shape}.")
        self.shape = lo.shape
        self.levels = [(lo, hi)]
        while max(self.levels[-1][0].shape) > 1:
            a, b = self.levels[-1]
            self.levels.append((_reduce(a, np.inf, np.minimum), _reduce(b, -np.inf, np.maximum)))
        self._children = np.array(np.meshgrid(*[(0, 1)] * lo.ndim, indexing="ij")).reshape(lo.ndim, -1).T

    @property
    def depth(self) -> int:
        """Number of levels above the cells.

        >>> MinMaxPyramid(np.zeros((5, 3)), np.ones((5, 3))).depth  # 5 -> 3 -> 2 -> 1 nodes per axis
        3
        """
        return len(self.levels) - 1

    @property
    def nbytes(self) -> int:
        """Memory of all levels.

        >>> MinMaxPyramid(np.zeros((4, 4)), np.ones((4, 4))).nbytes  # (16 + 4 + 1) nodes x 2 x 8 bytes
        336
        """
        return int(sum(a.nbytes + b.nbytes for a, b in self.levels))

    @property
    def value_range(self) -> tuple:
        """``(lo, hi)`` over all cells.

        >>> MinMaxPyramid(np.array([[-1.0, 2.0]]), np.array([[0.0, 5.0]])).value_range
        (-1.0, 5.0)
        """
        a, b = self.levels[-1]
        return float(a.min()), float(b.max())

    def stacked(self, level: int) -> np.ndarray:
        """Level ``level`` as one ``(..., 2)`` array of (lo, hi).

        >>> lo = np.arange(12.0).reshape(3, 4)
        >>> MinMaxPyramid(lo, lo + 1).stacked(2)  # the top node: the range of all cells
        array([[[ 0., 12.]]])
        """
        a, b = self.levels[level]
        return np.stack([a, b], axis=-1)

    def nodes(self, value: float, level: int) -> np.ndarray:
        """(n, ndim) int array indices of the nodes of ``level`` whose range contains ``value``, found by
        descending from the top through containing nodes only (lexicographic order).

        >>> lo = np.arange(12.0).reshape(3, 4)
        >>> p = MinMaxPyramid(lo, lo + 1)
        >>> p.nodes(5.0, 0).tolist()  # the cells (1, 0) = [4, 5] and (1, 1) = [5, 6]
        [[1, 0], [1, 1]]
        >>> p.nodes(5.0, 1).tolist()  # coarser: node (0, 1) = [2, 8] holds 5.0, none of its cells does
        [[0, 0], [0, 1]]
        """
        if not 0 <= level <= self.depth:
            raise ValueError(f"level must be in 0..{self.depth}, got {level}.")
        v = float(value)
        a, b = self.levels[-1]
        idx = np.argwhere((a <= v) & (v <= b))
        for L in range(self.depth - 1, level - 1, -1):
            if len(idx) == 0:
                break
            a, b = self.levels[L]
            kids = (2 * idx[:, None, :] + self._children[None]).reshape(-1, idx.shape[1])
            kids = kids[(kids < np.array(a.shape)).all(axis=1)]
            at = tuple(kids.T)
            idx = kids[(a[at] <= v) & (v <= b[at])]
        if len(idx):
            idx = idx[np.lexsort(idx.T[::-1])]
        return np.ascontiguousarray(idx)

"""Distances to axis-aligned boxes, shared by the families that prune by bounding boxes (the NURBS levels of
detail pick a level by the eye's distance to each super-surface's box; the geometry-image judge searches only
the blocks of limit triangles whose boxes are near a sample). Two lines of numpy; no library has them on arrays
of boxes and points at once."""

from __future__ import annotations

import numpy as np

__all__ = ["box_distance2"]


def box_distance2(q, lo, hi) -> np.ndarray:
    """Squared distances of the points ``q`` ``(K, 3)`` (or one point ``(3,)``) to the axis-aligned boxes
    ``[lo, hi]`` (``(K, 3)`` each, or one box); 0 inside.

    >>> box_distance2(np.array([[2.0, 0.5, 0.5], [0.5, 0.5, 0.5]]), np.zeros(3), np.ones(3)).tolist()
    [1.0, 0.0]
    """
    d = np.maximum(np.maximum(lo - q, q - hi), 0.0)
    return np.einsum("ij,ij->i", d, d)

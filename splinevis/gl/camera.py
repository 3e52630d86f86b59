"""Camera rays and window depths in float64: the reference side of every per-pixel comparison.

A camera is its 4x4 world -> normalized-device matrix (VTK's composite projection at the window's
aspect), so this module needs no VTK. Pixel (row i from the top, column j) is sampled at its centre,
as the rasterizer does.
"""

from __future__ import annotations

import numpy as np

from .._validation import as_float64_array

__all__ = ["pixel_rays", "window_depth"]


def pixel_rays(matrix, width: int, height: int):
    """Rays through the pixel centres of a ``height x width`` window.

    Returns
    -------
    origins : (H, W, 3) ndarray
        Points on the near clipping plane.
    directions : (H, W, 3) ndarray
        From the near to the far plane (not unit): ``t`` in [0, 1] spans the view frustum.

    Examples
    --------
    With the identity matrix world coordinates are normalized device coordinates:

    >>> origins, directions = pixel_rays(np.eye(4), 2, 2)
    >>> origins[0]  # the top row: pixel centres at y = 0.5 on the near plane z = -1
    array([[-0.5,  0.5, -1. ],
           [ 0.5,  0.5, -1. ]])
    >>> directions[1, 1]
    array([0., 0., 2.])
    """
    m = as_float64_array(matrix, "matrix", ndim=2, shape_tail=(4, 4))
    inv = np.linalg.inv(m)
    x = 2.0 * (np.arange(width) + 0.5) / width - 1.0
    y = 1.0 - 2.0 * (np.arange(height) + 0.5) / height
    xx, yy = np.meshgrid(x, y)

    def unproject(z):
        ndc = np.stack([xx, yy, np.full_like(xx, z), np.ones_like(xx)], axis=-1)
        p = ndc @ inv.T
        return p[..., :3] / p[..., 3:4]

    near = unproject(-1.0)
    far = unproject(1.0)
    return near, far - near


def window_depth(matrix, points) -> np.ndarray:
    """Window depth in [0, 1] (default depth range) of world points (..., 3); NaN stays NaN.

    Examples
    --------
    >>> window_depth(np.eye(4), [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [np.nan, np.nan, np.nan]])
    array([0.5, 1. , nan])
    """
    m = as_float64_array(matrix, "matrix", ndim=2, shape_tail=(4, 4))
    p = np.asarray(points, dtype=np.float64)
    h = np.concatenate([p, np.ones(p.shape[:-1] + (1,))], axis=-1) @ m.T
    return 0.5 * (h[..., 2] / h[..., 3] + 1.0)

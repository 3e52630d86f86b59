"""Tensor-product Bezier patches: the float64 twin of ``glsl/lib/tensor/bezier_patch.glsl``.

De Casteljau in u for every row of coefficients, then in v [Farin2002, ch. 16], the same operations in the
same order as the shader; the first tensor-product building block for NURBS segments after knot insertion
[Kumar1997] and geometry-image B-spline patches [Losasso2003].
"""

from __future__ import annotations

import numpy as np

from .roots import eval_deriv

__all__ = ["bezier_patch_eval", "BEZIER_PATCH_BOUND"]


def bezier_patch_eval(c, u, v, *, dtype=np.float64):
    """Value and first partial derivatives of tensor-product Bezier patches.

    Parameters
    ----------
    c : (..., m + 1, n + 1) array_like
        Coefficient ``c[..., i, j]`` multiplies ``B^m_i(u) B^n_j(v)``; m, n <= 4.
    u, v : (...) array_like
        Parameters (broadcast against the leading axes of ``c``).
    dtype : numpy float type
        ``float32`` runs the shader's arithmetic step for step.

    Returns
    -------
    f, f_u, f_v : (...) ndarrays

    Examples
    --------
    >>> import numpy as np
    >>> c = np.add.outer(np.arange(4.0), 10 * np.arange(3.0))   # f = 3 u + 20 v: bilinear data, degree (3, 2)
    >>> [float(x) for x in bezier_patch_eval(c, 0.5, 0.25)]
    [6.5, 3.0, 20.0]
    """
    c = np.asarray(c, dtype=dtype)
    if c.ndim < 2 or not (1 <= c.shape[-2] <= 5 and 1 <= c.shape[-1] <= 5):
        raise ValueError(f"c must have shape (..., m + 1, n + 1) with m, n <= 4; got {c.shape}.")
    u = np.asarray(u, dtype=dtype)
    v = np.asarray(v, dtype=dtype)
    rows = np.moveaxis(c, -1, -2)  # (..., n + 1, m + 1): one polynomial in u per j
    value, slope = eval_deriv(rows, u[..., None], dtype=dtype)
    f, f_v = eval_deriv(value, v, dtype=dtype)
    f_u, _ = eval_deriv(slope, v, dtype=dtype)
    return f, f_u, f_v


def BEZIER_PATCH_BOUND(m: int, n: int) -> float:
    """Bound on |float32 - exact| of the value, in units of u32 * sum_ij |c_ij| B_i(u) B_j(v): m levels of
    3 roundings in u, n in v, and the error of the rows carried through the convex combinations in v:
    ``gamma_{3(m + n)} / u32`` (to first order 3 (m + n) + a margin for the product of (1 + delta) factors).

    >>> round(BEZIER_PATCH_BOUND(3, 3), 3)
    18.0
    """
    k = 3 * (m + n)
    u32 = 2.0 ** -24
    return k / (1.0 - k * u32)

"""Twins of the GPU's univariate Bernstein-Bezier arithmetic: value and derivative by de Casteljau's
algorithm (``sv_bernstein_eval_deriv``) and the closed-form inflection points (``sv_inflection_points``).

Every root finder of :mod:`splinevis.bb.roots` evaluates through these functions, in float64 (the
reference twins) or float32 (operation by operation as on the GPU, without fused multiply-adds).
"""

from __future__ import annotations

import numpy as np

from ..._validation import as_float64_array
from .tolerance import _check_dtype, _check_univariate

__all__ = ["eval_deriv", "inflection_points"]


def _eval_deriv(c, x, dtype):
    """mirrors glsl/lib/core/bernstein.glsl sv_bernstein_eval_deriv(4): value and derivative at x.
    c: (..., n+1), x: broadcasting against c[..., 0] (possibly with an extra trailing axis handled by caller)."""
    n = c.shape[-1] - 1
    one = dtype(1.0)
    if n == 0:
        f = np.broadcast_to(c[..., 0], np.broadcast_shapes(c[..., 0].shape, np.shape(x))).astype(dtype)
        return f, np.zeros_like(f)
    s = one - x                                        # float s = 1.0 - t;
    b = [c[..., k] for k in range(n + 1)]              # float b[5] = c;
    if n == 1 or np.ndim(s) == 0 and np.ndim(b[0]) == 0:
        for level in range(1, n):                      # for level < n
            for k in range(0, n - level + 1):          #   for k <= n - level
                b[k] = s * b[k] + x * b[k + 1]         #     b[k] = s * b[k] + t * b[k + 1];
        f = s * b[0] + x * b[1]                        # f = (1.0 - t) * b0 + t * b1;
        return f, dtype(n) * (b[1] - b[0])             # fp = float(n) * (b1 - b0);
    # the same operations in the same order, into buffers allocated once: the arrays of a terrain walk's scan are
    # millions of values, and a fresh array per operation made this memory-bound (1.75x the time)
    tmp = x * c[..., 1]
    for k in range(n):                                 # level 1, from the coefficients c
        b[k] = s * c[..., k]
        np.multiply(x, c[..., k + 1], out=tmp)
        np.add(b[k], tmp, out=b[k])
    for level in range(2, n):
        for k in range(0, n - level + 1):
            np.multiply(s, b[k], out=b[k])
            np.multiply(x, b[k + 1], out=tmp)
            np.add(b[k], tmp, out=b[k])
    f = s * b[0]
    f += np.multiply(x, b[1], out=tmp)
    fp = np.subtract(b[1], b[0], out=tmp)
    fp *= dtype(n)                                     # n (b1 - b0): the product is the same either way round
    return f, fp


def eval_deriv(c, t, *, dtype=np.float64):
    """Value and derivative of univariate BB polynomials exactly as the GPU computes them.

    Parameters
    ----------
    c : (..., n + 1) array_like
        Coefficients, degree n in 0..4.
    t : array_like
        Parameters, broadcasting against ``c.shape[:-1]``.
    dtype : {numpy.float64, numpy.float32}
        Arithmetic precision. float32 reproduces ``sv_bernstein_eval_deriv`` of
        ``glsl/lib/core/bernstein.glsl`` operation by operation (up to fused multiply-adds on the GPU).

    Returns
    -------
    f, fp : ndarray
        ``f(t)`` after n de Casteljau levels and ``f'(t) = n (b1 - b0)``.

    Examples
    --------
    ``(t - 1/4)(t - 3/4)`` in BB form:

    >>> eval_deriv([3 / 16, -5 / 16, 3 / 16], [0.25, 0.5, 0.75])
    (array([ 0.    , -0.0625,  0.    ]), array([-0.5,  0. ,  0.5]))
    """
    c = _check_univariate(c)
    t = as_float64_array(t, "t")
    dtype = _check_dtype(dtype)
    with np.errstate(all="ignore"):
        return _eval_deriv(c.astype(dtype), t.astype(dtype), dtype)


def _inflection_points(c, dtype):
    """mirrors glsl/lib/core/roots.glsl sv_inflection_points."""
    n = c.shape[-1] - 1
    shape = c.shape[:-1]
    w0 = np.full(shape, -1.0, dtype=dtype)
    w1 = np.full(shape, -1.0, dtype=dtype)
    two = dtype(2.0)
    if n == 4:
        a0 = c[..., 2] - two * c[..., 1] + c[..., 0]
        a1 = c[..., 3] - two * c[..., 2] + c[..., 1]
        a2 = c[..., 4] - two * c[..., 3] + c[..., 2]
        A = a0 - two * a1 + a2
        B = two * (a1 - a0)
        C = a0
        lin = A == 0.0
        # if (A == 0.0) { if (B != 0.0) w0 = -C / B; }
        w0 = np.where(lin & (B != 0.0), -C / np.where(B != 0.0, B, 1.0), w0)
        disc = B * B - dtype(4.0) * A * C
        quad = ~lin & (disc >= 0.0)
        sgn = np.where(B >= 0.0, dtype(1.0), dtype(-1.0))
        q = dtype(-0.5) * (B + sgn * np.sqrt(np.where(quad, disc, 0.0)))
        r0 = q / np.where(lin, 1.0, A)
        r1 = np.where(q != 0.0, C / np.where(q != 0.0, q, 1.0), r0)
        w0 = np.where(quad, np.minimum(r0, r1), w0)
        w1 = np.where(quad, np.maximum(r0, r1), w1)
    elif n == 3:
        a0 = c[..., 2] - two * c[..., 1] + c[..., 0]
        a1 = c[..., 3] - two * c[..., 2] + c[..., 1]
        ok = a0 != a1
        w0 = np.where(ok, a0 / np.where(ok, a0 - a1, 1.0), w0)
    return w0.astype(dtype), w1.astype(dtype)


def inflection_points(c, *, dtype=np.float64):
    """Roots ``w0 <= w1`` of the second derivative (closed form), ``-1`` where there is none.

    Degree 4: the quadratic ``f''`` is solved with the cancellation-free formula; degree 3: the linear
    ``f''``; lower degrees have none. Values are not restricted to (0, 1) here.

    Returns
    -------
    w0, w1 : ndarray, shape ``c.shape[:-1]``

    Examples
    --------
    >>> inflection_points([1.0, -1.0, 1.0, -1.0])  # a cubic: one inflection point
    (array(0.5), array(-1.))
    >>> inflection_points([0.0, 0.0, 1.0])  # a quadratic has none
    (array(-1.), array(-1.))
    """
    c = _check_univariate(c)
    dtype = _check_dtype(dtype)
    with np.errstate(all="ignore"):
        return _inflection_points(c.astype(dtype), dtype)

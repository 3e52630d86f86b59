"""Float32 precision model shared by the root finders: the degree limit, the residual tolerance and the
argument checks.

A root finder running in float32 on the GPU cannot drive ``f(x)`` to zero; it accepts ``x`` when
``|f(x)| <= K_n * EPS32 * sum_k |c_k| B_k(x)`` with the constant ``K_n`` of :func:`root_tolerance_k`,
derived from the rounding bound of de Casteljau's algorithm.
"""

from __future__ import annotations

import numpy as np

from ..._validation import as_float64_array, check_degree

__all__ = ["MAX_ROOT_DEGREE", "EPS32", "root_tolerance_k"]

#: Largest degree the root finders accept (the GPU code uses ``float c[5]``).
MAX_ROOT_DEGREE = 4
#: float32 machine epsilon 2^-23 (= 2u, u the unit roundoff).
EPS32 = 2.0**-23
_U32 = 2.0**-24


def root_tolerance_k(n: int) -> float:
    """Constant ``K_n`` of the residual test ``|f(x)| <= K_n * EPS32 * sum_k |c_k| B_k(x)``.

    Notes
    -----
    With u = 2^-24: the float32 de Casteljau value is within ``gamma_{3n} S`` of the exact value at the
    float32 argument (``S = sum |c_k| B_k``; each level rounds ``1 - t``, two products and one sum), and
    rounding a simple root ``x*`` to float32 adds ``|f'(x*)| ulp/2``, which is bounded by another
    ``gamma_{3n} S`` unless the root is argument-ill-conditioned (those cases are classified in the
    self-test). S itself is computed with relative error ``gamma_{3n}`` and ``K eps S`` costs two more
    roundings, so ``K_n = 2 gamma_{3n} / eps32 / (1 - gamma_{3n}) (1 + u)^2 <= 3n (1 + 2^-16)`` for
    n <= 4. Same expression as ``sv_root_tol_k`` in ``glsl/lib/core/roots.glsl`` ([Higham2002, sec. 3.4]
    for gamma; [MainarPena1999] for the de Casteljau bound).

    Examples
    --------
    >>> root_tolerance_k(4)  # 3 n (1 + 2^-16)
    12.00018310546875
    """
    return 3.0 * float(n) * (1.0 + 2.0**-16)


def _check_univariate(c, name="coefficients", high=MAX_ROOT_DEGREE, finite=True):
    """``c`` as a float64 array of shape ``(..., n + 1)`` with degree n in 0..high, else ValueError."""
    c = as_float64_array(c, name, finite=finite)
    if c.ndim < 1 or c.shape[-1] < 1:
        raise ValueError(f"{name} must have shape (..., n + 1) with degree n in 0..{high}; got shape {c.shape}.")
    check_degree(c.shape[-1] - 1, f"degree n (= {name}.shape[-1] - 1)", low=0, high=high)
    return c


def _check_dtype(dtype):
    """``numpy.float64`` or ``numpy.float32`` for a dtype spelling either, else TypeError."""
    if dtype in (np.float64, np.float32):
        return dtype
    dt = np.dtype(dtype)
    if dt == np.float64:
        return np.float64
    if dt == np.float32:
        return np.float32
    raise TypeError(f"dtype must be numpy.float64 or numpy.float32, got {dtype!r}.")

"""Newton iteration from fixed starting points, the papers' GPU root finders (line-by-line twins).

* :func:`newton_secure` -- the method of [Reis2008, sec. V] (``sv_first_root_newton4``): four starts ``(0, w0, w1, 1)``,
  the end points and the inflection points, for degree <= 4.
* :func:`newton_three_starts` -- the method of [Kalbe2008, sec. 5.3] (``sv_first_root_newton3``): three starts
  ``(0, w, 1)`` for cubics.

Both take the smallest iterate in [0, 1] that passes the residual test of
:func:`~splinevis.bb.roots.tolerance.root_tolerance_k`; they often return a later root than the first one.
"""

from __future__ import annotations

import numpy as np

from .bernstein import _eval_deriv, _inflection_points
from .tolerance import EPS32, _check_dtype, _check_univariate, root_tolerance_k

__all__ = ["newton_secure", "newton_three_starts"]


def _newton_from_starts(cc, n, x, iterations, dtype):
    """Twin of ``sv_newton_from_starts``: ``iterations`` Newton steps from the starts x (..., 4), then the
    smallest x in [0, 1] passing ``|f(x)| <= K_n eps32 sum_k |c_k| B_k(x)``; (root or NaN, x, accepted)."""
    c4 = cc[..., None, :]  # broadcast the coefficients over the four starts
    for _ in range(iterations):
        f, fp = _eval_deriv(c4, x, dtype)
        nz = fp != 0.0                                       # bvec4 nz = notEqual(fp, vec4(0.0));
        xn = x - f / np.where(nz, fp, dtype(1.0))            # vec4 xn = x - f / mix(vec4(1.0), fp, nz);
        ok = nz & (np.abs(xn) < 1e30)                        # keep x where f' = 0 or step not finite
        x = np.where(ok, xn, x).astype(dtype)                # x = mix(x, xn, ok);
    f, _ = _eval_deriv(c4, x, dtype)
    S, _ = _eval_deriv(np.abs(c4), x, dtype)                 # S = sum |c_k| B_k(x)
    tol = dtype(root_tolerance_k(n)) * dtype(EPS32) * S      # vec4 tol = sv_root_tol_k(n) * SV_ROOT_EPS32 * S;
    accept = (x >= 0.0) & (x <= 1.0) & (np.abs(f) <= tol)
    best = np.min(np.where(accept, x, np.inf), axis=-1)
    return np.where(np.isfinite(best), best, np.nan), x, accept


def newton_secure(c, iterations: int = 6, *, dtype=np.float64, return_candidates: bool = False):
    """First root in [0, 1] by Newton iteration from secure starting points (the GPU method).

    The method of [Reis2008, sec. V]. Mirrors ``sv_first_root_newton4`` in ``glsl/lib/core/roots.glsl``
    line by line (``sv_first_root`` with ``SV_ROOTS_PAPER`` defined):

    1. inflection points ``w0 <= w1`` (roots of ``f''``); ``w0 := 1/3`` unless in (0, 1), ``w1 := 2/3``
       unless in (0, 1) (the pseudo-code of [Reis2008, sec. V]);
    2. ``iterations`` Newton steps ``x <- x - f(x)/f'(x)`` from each of ``x = (0, w0, w1, 1)``; a start
       with ``f'(x) = 0`` or a non-finite step keeps its ``x``; nothing is clamped;
    3. the result is the smallest of the four ``x`` in [0, 1] with
       ``|f(x)| <= K_n eps32 sum_k |c_k| B_k(x)`` (:func:`root_tolerance_k`), NaN if none.

    Parameters
    ----------
    c : (..., n + 1) array_like
        Coefficients, degree n in 0..4.
    iterations : int
        Newton steps, 1..8 (the paper uses 6: "full floating point accuracy").
    dtype : {numpy.float64, numpy.float32}
        Arithmetic precision; float64 is the reference twin, float32 emulates the GPU (without FMA).
        The constants 1/3 and 2/3 are the float32 values in both cases, as on the GPU.
    return_candidates : bool
        Also return the four final iterates ``(..., 4)`` and the acceptance mask ``(..., 4)``.

    Returns
    -------
    ndarray, shape ``c.shape[:-1]``
        The first accepted root, NaN if none (the GLSL returns -1.0). The zero polynomial gives 0.

    Examples
    --------
    >>> float(newton_secure([3 / 16, -1 / 16, -7 / 48, -1 / 16, 3 / 16]))  # (t - 1/4)(t - 3/4)
    0.25
    >>> float(newton_secure([0.25, 0.0, -1 / 12, 0.0, 0.25]))  # (t - 1/2)^2: a double root it misses
    nan
    """
    c = _check_univariate(c)
    if isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer)) or not 1 <= iterations <= 8:
        raise ValueError(f"iterations must be an integer in 1..8; got {iterations!r}.")
    dtype = _check_dtype(dtype)
    n = c.shape[-1] - 1
    with np.errstate(all="ignore"):
        cc = c.astype(dtype)
        w0, w1 = _inflection_points(cc, dtype)
        # if (!(w0 > 0.0 && w0 < 1.0)) w0 = 1.0 / 3.0;  (float32 constants, as the GPU folds them)
        w0 = np.where((w0 > 0.0) & (w0 < 1.0), w0, dtype(np.float32(1.0 / 3.0)))
        w1 = np.where((w1 > 0.0) & (w1 < 1.0), w1, dtype(np.float32(2.0 / 3.0)))
        # vec4 x = vec4(0.0, w0, w1, 1.0);
        x = np.stack([np.zeros_like(w0), w0, w1, np.ones_like(w0)], axis=-1).astype(dtype)
        root, x, accept = _newton_from_starts(cc, n, x, iterations, dtype)
    if return_candidates:
        return root, x, accept
    return root


def newton_three_starts(c, iterations: int = 5, *, dtype=np.float64):
    """First root in [0, 1] of cubic BB polynomials by [Kalbe2008]'s Newton from three starts (NaN if none).

    Mirrors ``sv_first_root_newton3`` in ``glsl/lib/core/roots.glsl`` line by line: ``iterations`` Newton steps
    from ``0``, the inflection point ``w`` (root of ``f''``; ``1/2`` unless in (0, 1)) and ``1`` ([Kalbe2008],
    sec. 5.3, ``I = 5``), then the smallest iterate in [0, 1] passing the residual test
    ``|f(x)| <= K_3 EPS32 sum |c_k| B_k(x)`` of :func:`newton_secure`. A start with ``f' = 0`` or a
    non-finite step keeps its ``x``; nothing is clamped. The zero polynomial gives 0.

    Parameters
    ----------
    c : (..., 4) array_like
        BB coefficients of degree 3.
    iterations : int
        1..8.
    dtype : {numpy.float64, numpy.float32}

    Examples
    --------
    >>> c = [3 / 16, -7 / 48, -7 / 48, 3 / 16]  # (t - 1/4)(t - 3/4)
    >>> round(float(newton_three_starts(c)), 12)
    0.25
    """
    c = _check_univariate(c, high=3)
    if c.shape[-1] != 4:
        raise ValueError(f"newton_three_starts needs 4 coefficients (degree 3), got {c.shape[-1]}.")
    if isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer)) or not 1 <= iterations <= 8:
        raise ValueError(f"iterations must be an integer in 1..8; got {iterations!r}.")
    dt = _check_dtype(dtype)
    with np.errstate(all="ignore"):
        cc = c.astype(dt)
        w0, _ = _inflection_points(cc, dt)
        w0 = np.where((w0 > 0.0) & (w0 < 1.0), w0, dt(0.5))          # if (!(w0 > 0 && w0 < 1)) w0 = 0.5;
        x = np.stack([np.zeros_like(w0), w0, np.ones_like(w0), w0], axis=-1).astype(dt)
        root, _, _ = _newton_from_starts(cc, 3, x, iterations, dt)
    return root

"""The interpolating C2 box spline (scheme ``C2-interp``): the box spline of ``C2`` with prefiltered heights,
so that the spline passes through every sample.

The C2 scheme sets the coefficients of the quartic box spline ``M`` (directions (1,0), (0,1), (1,1), each
twice) to the heights themselves, ``s = sum_j c_j M(. - j)`` with ``c = pad(z)`` (the cubic padding of
:func:`splinevis.terrain.engine._pad_cubic`, one layer). At a grid point ``k`` the spline is the 7-point
convolution

    s(k) = (K * c)(k) = 1/2 c_k + 1/12 (c_(k±(1,0)) + c_(k±(0,1)) + c_(k±(1,1))),

(``M(0) = 1/2``, ``M = 1/12`` at the 6 mesh neighbours, 0 at the other grid points), so plain C2 smooths the
data and only reproduces linear functions (order 2, worse than linear interpolation by a constant factor).
``C2-interp`` instead solves for heights ``d`` with

    K * pad(d) = z  at every grid point,

and hands ``d`` to the unchanged C2 stencil: the coefficients, the GPU program and everything downstream are
those of C2. The spline then interpolates the samples and reproduces every cubic up to the boundary (the
cubic padding is exact for cubics, and the system is nonsingular), so the values converge with order 4 and
the gradients with order 3 (the approximation order of the box spline's space is 4 = m(Xi); the quartics
``x^4 - 2 x^3 y`` and ``y^4 - 2 x y^3``, the rest of that space, are reproduced away from the boundary only).

The system. On the infinite grid ``K`` has the symbol
``K^(w) = 1/2 + (cos w1 + cos w2 + cos(w1 + w2)) / 6``, with maximum 1 at ``w = 0`` and minimum ``1/4`` at
``w = ±(2 pi/3, 2 pi/3)`` (:func:`symbol_range`): positive, so cardinal interpolation is well posed and its
2-norm condition number is 4. On an ``ny x nx`` grid with the padding, the matrix ``A = R K P`` (``P`` pads
one layer by cubic extrapolation, x then y; ``R`` keeps the grid points) has 7 to 16 nonzeros per row; its
2-norm condition number is 37.5 and ``||A^-1||_inf`` = 13.9 for every size from 16 x 16 up (the boundary rows
carry the padding's weights 4, -6, 4, -1; measured in ``tests/test_terrain_interpolating.py``).

The solve. ``A`` is sparse and non-symmetric (the padding), so BiCGSTAB (:func:`scipy.sparse.linalg.bicgstab`)
is run in a loop of iterative refinement on the max-norm residual: ``d += bicgstab(A, z - A d)`` until
``max |z - A d| <= 2 gamma_(S+1) max(|A| |d| + |z|)``, the level at which the residual of the exact solution
itself is no longer resolved in float64 (``S`` = nonzeros per row, ``gamma_m = m u / (1 - m u)``,
``u = 2^-53``). BiCGSTAB needs about 20 iterations for every grid size here (the spectrum does not depend on
the size), each a sparse product with ~7 n^2 nonzeros.

Why our own code: scipy's B-spline prefilters (``scipy.ndimage.spline_filter``) are separable filters for
tensor-product B-splines; this box spline on the three-direction mesh has a non-separable 7-point symbol and
the boundary rule of the terrain schemes (cubic padding), for which no library offers a prefilter. Prefiltering
for cardinal interpolation follows [Unser1993]; the box spline's cardinal interpolation, its symbol and the
polynomials in its span (cubics plus two quartics) are those of [DeBoor1993].

Out of core (:mod:`splinevis.outofcore`) the scheme is refused: every coefficient depends on every height (the
influence decays geometrically with the distance, but a tile would need a halo and a local solve that the
tile engine does not have); ``C2-cubic`` is the same spline with a local cubic-exact prefilter (also order 4).

References
----------
.. [Unser1993] Unser, Aldroubi, Eden 1993, B-spline signal processing I.
.. [DeBoor1993] de Boor, Hoellig, Riemenschneider 1993, Box splines.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["symbol", "symbol_range", "interpolation_matrix", "prefilter_heights", "node_values"]

_U = 2.0 ** -53

#: Values of the box spline ``M`` at the grid points (the 7-point stencil ``K``), offsets ``(dx, dy)``.
KERNEL = {(0, 0): 0.5, (1, 0): 1.0 / 12.0, (-1, 0): 1.0 / 12.0, (0, 1): 1.0 / 12.0, (0, -1): 1.0 / 12.0,
          (1, 1): 1.0 / 12.0, (-1, -1): 1.0 / 12.0}


def symbol(w1, w2):
    """The symbol of ``K``: ``K^(w) = sum_k K(k) exp(-i k.w) = 1/2 + (cos w1 + cos w2 + cos(w1 + w2)) / 6``.

    Examples
    --------
    >>> float(symbol(0.0, 0.0)), float(symbol(2 * np.pi / 3, 2 * np.pi / 3))
    (1.0, 0.25)
    """
    w1, w2 = np.asarray(w1, dtype=np.float64), np.asarray(w2, dtype=np.float64)
    return 0.5 + (np.cos(w1) + np.cos(w2) + np.cos(w1 + w2)) / 6.0


def symbol_range():
    """``(min, max)`` of the symbol over the torus, exactly: ``(1/4, 1)``.

    ``cos a + cos b + cos(a + b) >= -3/2`` (with equality at ``a = b = ±2 pi/3``): writing it as
    ``2 cos((a+b)/2) cos((a-b)/2) + 2 cos^2((a+b)/2) - 1``, for fixed ``t = cos((a+b)/2)`` the minimum over the
    other factor is ``-2 |t| + 2 t^2 - 1``, smallest at ``|t| = 1/2``: ``-3/2``. The maximum 3 is at ``0``. So the
    infinite-grid interpolation operator has condition number 4.

    Examples
    --------
    >>> symbol_range()
    (0.25, 1.0)
    """
    return 0.25, 1.0


def _pad_matrix(n):
    """(n + 2, n) sparse: one layer of cubic extrapolation on each side (the rule of ``_pad_cubic``)."""
    import scipy.sparse as sp

    rows = [0, 0, 0, 0] + list(range(1, n + 1)) + [n + 1] * 4
    cols = [0, 1, 2, 3] + list(range(n)) + [n - 4, n - 3, n - 2, n - 1]
    vals = [4.0, -6.0, 4.0, -1.0] + [1.0] * n + [-1.0, 4.0, -6.0, 4.0]
    return sp.csr_matrix((vals, (rows, cols)), shape=(n + 2, n))


@functools.lru_cache(maxsize=8)
def interpolation_matrix(ny, nx):
    """The sparse ``(ny nx, ny nx)`` matrix ``A`` with ``(A d)[j nx + i] = (K * pad(d))(i, j)``: the C2 spline's
    values at the grid points from the heights ``d`` it is given (row-major, ``d[j, i]`` at index point
    ``(i, j)``). Needs ``ny, nx >= 4`` (the cubic padding).

    Examples
    --------
    >>> A = interpolation_matrix(4, 5)
    >>> A.shape, bool(np.allclose(A @ np.ones(20), 1.0))  # constants: K sums to 1 and the padding keeps them
    ((20, 20), True)
    """
    import scipy.sparse as sp

    if ny < 4 or nx < 4:
        raise ValueError(f"C2-interp needs at least 4x4 heights (its cubic padding), got {ny}x{nx}.")
    Px, Py = _pad_matrix(nx), _pad_matrix(ny)

    def pick(n, o):  # (n, n + 2): padded index i + 1 + o
        return sp.csr_matrix((np.ones(n), (np.arange(n), np.arange(n) + 1 + o)), shape=(n, n + 2))

    A = None
    for (ox, oy), w in KERNEL.items():
        term = w * sp.kron(pick(ny, oy) @ Py, pick(nx, ox) @ Px, format="csr")
        A = term if A is None else A + term
    A = A.tocsr()
    A.sum_duplicates()
    return A


def prefilter_heights(z, *, max_refinements=10, return_info=False):
    """Heights ``d`` whose C2 spline interpolates ``z``: ``K * pad(d) = z`` at every grid point.

    Parameters
    ----------
    z : (ny, nx) float64 array
        Finite heights, at least 4 x 4.
    max_refinements : int
        Outer steps of iterative refinement (2 or 3 are used; more means the solver failed: RuntimeError).
    return_info : bool
        Also return a dict: ``residual`` (max |z - A d|), ``tolerance`` (the derived stopping level),
        ``refinements``, ``iterations`` (BiCGSTAB iterations in all).

    Examples
    --------
    >>> y, x = np.mgrid[0:6, 0:7].astype(float)
    >>> z = x ** 3 - 2 * x * y ** 2 + y        # a cubic: d is the cubic K^-1 z (K maps cubics to cubics)
    >>> d = prefilter_heights(z)
    >>> bool(np.abs(node_values(d) - z).max() < 1e-12 * np.abs(z).max())
    True
    """
    from scipy.sparse.linalg import bicgstab

    z = np.asarray(z, dtype=np.float64)
    ny, nx = z.shape
    A = interpolation_matrix(ny, nx)
    absA = abs(A)
    S = int(np.diff(A.indptr).max())
    g = (S + 1) * _U / (1 - (S + 1) * _U)
    b = z.reshape(-1)
    d = np.zeros_like(b)
    r = b.copy()
    iterations = [0]

    def count(_):
        iterations[0] += 1

    for k in range(max_refinements + 1):
        tol = 2.0 * g * float((absA @ np.abs(d) + np.abs(b)).max())
        res = float(np.abs(r).max())
        if res <= tol:
            break
        if k == max_refinements:
            raise RuntimeError(f"C2-interp prefilter: the residual {res:.3g} is still above the rounding level "
                               f"{tol:.3g} after {k} refinements of BiCGSTAB; please report this grid.")
        step, _ = bicgstab(A, r, rtol=1e-10, atol=0.0, maxiter=500, callback=count)
        d = d + step
        r = b - A @ d
    d = d.reshape(ny, nx)
    if return_info:
        return d, {"residual": res, "tolerance": tol, "refinements": k, "iterations": iterations[0]}
    return d


def node_values(d):
    """The C2 spline's values at the grid points from heights ``d``: ``K * pad(d)`` (what ``C2-interp`` makes
    equal to the data).

    Examples
    --------
    >>> y, x = np.mgrid[0:4, 0:5].astype(float)
    >>> bool(np.allclose(node_values(x + 2 * y), x + 2 * y, rtol=0, atol=1e-14))  # K reproduces linear functions
    True
    """
    from .engine import _pad_cubic

    d = np.asarray(d, dtype=np.float64)
    ny, nx = d.shape
    p = _pad_cubic(d, 1, 1, 1, 1)
    out = np.zeros((ny, nx))
    for (ox, oy), w in KERNEL.items():
        out += w * p[1 + oy:1 + oy + ny, 1 + ox:1 + ox + nx]
    return out

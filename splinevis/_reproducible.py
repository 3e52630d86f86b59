"""Float64 reductions and small solves whose bits do not depend on the machine's BLAS.

Why: numpy's ``vdot``, ``dot``, ``@`` on float arrays and ``np.linalg`` call OpenBLAS/LAPACK, which picks its
kernels at run time (Haswell, SkylakeX, Zen, Prescott, ...: with or without fused multiply-add, 4 or 8 partial
sums) and splits long dot products over threads. Their last bits follow the machine. An iterative optimizer
(the spherical parametrization's L-BFGS, :mod:`splinevis.geometry_image.relax`) turns those bits into different
iterates, different stopping steps and a different map: measured on the cheburashka scan, largest stretch 2.96
under Haswell kernels, 4.03 under SkylakeX and 2.78 under Prescott, and a mesh that passed the check on one
machine failed it on another. The functions here use numpy's elementwise ufuncs (one rounding per operation, no
contraction into FMA) and ``np.add.reduce`` (pairwise summation in a fixed order compiled into numpy), so the
same inputs give the same bits on every machine and with any number of threads. They are slower than BLAS only
by a constant factor on the vector lengths they serve (a few 1e5).

No library of the stack offers this: numpy and scipy route every dot product through BLAS.
"""

from __future__ import annotations

import numpy as np

__all__: list = []  # private: used by the iterative solvers whose results are stored or judged


def dot(a, b) -> float:
    """``sum(a * b)`` over all entries, in numpy's fixed pairwise order.

    >>> dot(np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0]))
    32.0
    """
    return float(np.add.reduce(np.multiply(a, b).ravel()))


def norm(a) -> float:
    """The Euclidean norm of all entries of ``a`` (``sqrt(dot(a, a))``).

    >>> norm(np.array([3.0, 4.0]))
    5.0
    """
    return float(np.sqrt(dot(a, a)))


def weighted_sum(w, X) -> np.ndarray:
    """``w @ X`` for a ``(N,)`` weight vector and an ``(N, k)`` array: per column ``sum_i w_i X_ik``.

    >>> weighted_sum(np.array([1.0, 2.0]), np.array([[1.0, 0.0], [0.5, 3.0]])).tolist()
    [2.0, 6.0]
    """
    return np.add.reduce(np.asarray(w)[:, None] * X, axis=0)


def weighted_quantile(x, w, q: float) -> float:
    """The ``q`` quantile of ``x`` weighted by ``w`` (the smallest ``x`` with at least ``q`` of the weight at or
    below it), after a stable sort and a cumulative sum in a fixed order: the same value on every machine.

    >>> weighted_quantile(np.array([3.0, 1.0, 2.0]), np.array([1.0, 1.0, 2.0]), 0.5)
    2.0
    """
    x = np.asarray(x)
    order = np.argsort(x, kind="stable")
    c = np.cumsum(np.asarray(w, dtype=np.float64)[order])
    return float(x[order][min(int(np.searchsorted(c, q * c[-1])), len(c) - 1)])


def solve_small(A, b) -> np.ndarray:
    """The solution of ``A x = b`` for one or a batch of ``2 x 2`` or ``3 x 3`` matrices ``A`` (``(..., k, k)``,
    ``b`` ``(..., k)``), by Cramer's rule (the adjugate over the determinant). Singular systems give inf/nan as
    a division by zero would; callers guard them.

    >>> solve_small(np.array([[2.0, 1.0], [1.0, 3.0]]), np.array([3.0, 5.0])).round(12).tolist()
    [0.8, 1.4]
    >>> solve_small(np.diag([2.0, 4.0, 8.0]), np.array([2.0, 2.0, 2.0])).tolist()
    [1.0, 0.5, 0.25]
    """
    A = np.asarray(A, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if A.shape[-2:] == (2, 2):
        a, c, d, e = A[..., 0, 0], A[..., 0, 1], A[..., 1, 0], A[..., 1, 1]
        det = a * e - c * d
        return np.stack([(e * b[..., 0] - c * b[..., 1]) / det, (a * b[..., 1] - d * b[..., 0]) / det], axis=-1)
    if A.shape[-2:] == (3, 3):
        c0, c1, c2 = A[..., :, 0], A[..., :, 1], A[..., :, 2]
        det = _det3(c0, c1, c2)
        return np.stack([_det3(b, c1, c2) / det, _det3(c0, b, c2) / det, _det3(c0, c1, b) / det], axis=-1)
    raise ValueError(f"solve_small solves 2 x 2 and 3 x 3 systems, got matrices of shape {A.shape[-2:]}.")


def _det3(u, v, w):
    """``det[u, v, w]`` of columns ``(..., 3)``."""
    return (u[..., 0] * (v[..., 1] * w[..., 2] - v[..., 2] * w[..., 1])
            - u[..., 1] * (v[..., 0] * w[..., 2] - v[..., 2] * w[..., 0])
            + u[..., 2] * (v[..., 0] * w[..., 1] - v[..., 1] * w[..., 0]))


def mat(A, B) -> np.ndarray:
    """``A @ B`` for a stack of row vectors or a small matrix ``A`` (``(..., k)`` or ``(..., m, k)``) and a
    small matrix ``B`` (``(k, l)``), by numpy's einsum loops instead of BLAS's gemm.

    >>> mat(np.array([[1.0, 2.0]]), np.array([[0.0, 1.0], [1.0, 0.0]])).tolist()
    [[2.0, 1.0]]
    """
    return np.einsum("...k,kl->...l", np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64))


def spd_factor(A):
    """A function ``b -> A^-1 b`` for a sparse symmetric positive definite ``A`` (``(n, n)``; ``b`` ``(n,)`` or
    ``(n, k)``): a sparse Cholesky factorization by Eigen (libigl's ``min_quad_with_fixed``, which minimizes
    ``x^T A x / 2 + x^T B``, so ``A x = -B``). Eigen's kernels are compiled into the library, where SciPy's
    SuperLU calls OpenBLAS: its factors differed in their last bits between OpenBLAS's Haswell, SkylakeX and
    Prescott kernels, Eigen's are the same bits (and factored a 50k-vertex Laplacian in half SuperLU's time).

    >>> from scipy.sparse import csc_matrix
    >>> solve = spd_factor(csc_matrix(np.array([[4.0, 1.0], [1.0, 3.0]])))
    >>> solve(np.array([1.0, 2.0])).round(12).tolist()
    [0.090909090909, 0.636363636364]
    """
    import igl
    from scipy.sparse import csc_matrix

    A = csc_matrix(A, dtype=np.float64)
    n = A.shape[0]
    if n == 0:  # no unknowns (a Tutte disk without inner vertices)
        return lambda b: np.zeros_like(np.asarray(b, dtype=np.float64))
    data = igl.min_quad_with_fixed_data()
    igl.min_quad_with_fixed_precompute(A, np.zeros(0, dtype=np.int64), csc_matrix((0, n)), True, data)

    def solve(b):
        b = np.asarray(b, dtype=np.float64)
        B = np.ascontiguousarray(-b.reshape(n, -1))
        x = igl.min_quad_with_fixed_solve(data, B, np.zeros((0, B.shape[1])), np.zeros((0, B.shape[1])))
        return np.asarray(x).reshape(b.shape)

    return solve


def conjugate_gradients(A, b, x0, *, diagonal, rtol: float, maxiter: int):
    """Jacobi-preconditioned conjugate gradients [HestenesStiefel1952] for the sparse symmetric positive definite
    ``A`` and each column of ``b`` (``(n, k)``) at once, from ``x0``; column ``j`` stops when its residual is at
    most ``rtol |b_j|`` (SciPy's ``cg`` test), its inner products by :func:`dot`'s fixed order, so the iterates
    are the same bits on every machine (SciPy's ``cg`` takes them from BLAS). Returns ``(x, iterations)``,
    ``iterations[j]`` the steps column ``j`` took, or -1 where it did not converge in ``maxiter``.

    >>> from scipy.sparse import csr_matrix
    >>> A = csr_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
    >>> x, its = conjugate_gradients(A, np.array([[1.0], [2.0]]), np.zeros((2, 1)), diagonal=A.diagonal(),
    ...                              rtol=1e-12, maxiter=10)
    >>> x.ravel().round(12).tolist(), its
    ([0.090909090909, 0.636363636364], [2])
    """
    b = np.asarray(b, dtype=np.float64)
    x = np.array(x0, dtype=np.float64)
    inv = 1.0 / np.asarray(diagonal, dtype=np.float64)[:, None]
    cols = lambda u, v: np.add.reduce(u * v, axis=0)  # noqa: E731  per-column inner products, fixed order
    r = b - A @ x
    goal = rtol * np.sqrt(cols(b, b))
    z = inv * r
    p = z.copy()
    rz = cols(r, z)
    k = b.shape[1]
    iterations = [0] * k
    active = np.sqrt(cols(r, r)) > goal
    for step in range(1, int(maxiter) + 1):
        if not active.any():
            break
        Ap = A @ p
        alpha = np.where(active, rz / np.where(active, cols(p, Ap), 1.0), 0.0)
        x += alpha * p
        r -= alpha * Ap
        done = active & (np.sqrt(cols(r, r)) <= goal)
        for j in np.flatnonzero(done):
            iterations[j] = step
        active &= ~done
        z = inv * r
        rz_new = cols(r, z)
        beta = np.where(active, rz_new / np.where(rz != 0.0, rz, 1.0), 0.0)
        p = z + beta * p
        rz = rz_new
    for j in np.flatnonzero(active):
        iterations[j] = -1
    return x, iterations

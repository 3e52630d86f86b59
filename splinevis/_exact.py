"""Exact rational linear algebra for the derivations of stored tables (tools/gen_*.py and the quadratic volume
scheme's :func:`splinevis.volume.schemes.derive_weights`).

Why: a float64 solve's last bits follow the BLAS/LAPACK kernels of the machine (OpenBLAS picks Haswell, SkylakeX,
Zen, ... kernels at run time), so a table printed from a float64 solve differs between machines in its last
digits, and a test comparing the committed text with the generator's output flips with the machine. The
derivations' systems are rational, so their solutions are rational: solved here exactly (python-flint's
``fmpq_mat``, FLINT's fraction-free rational matrices; sympy's pure-Python ``DomainMatrix`` took 16 s for the
volume system, FLINT well under one), and printed from the exact value (:func:`literal`: the shortest repr of
the correctly rounded double), the generated text is the same bytes on every machine. A greedy derivation
(impose a condition if it stays consistent) decided in float64 can even decide differently: the quadratic volume
scheme's did under one OpenBLAS SkylakeX thread (56 instead of 84 exact conditions); decided exactly it cannot.
No library of the stack offers exact consistency tests, particular solutions and null spaces on top of FLINT's
``rref``; :func:`solve_any` and :func:`nullspace` are the two dozen lines that do. python-flint is imported
lazily (the package renders from stored tables; only the derivations need it).

The package's derivations build their systems in float64. :func:`rationals` recovers the exact entries: each
float is replaced by the fraction of denominator <= ``max_den`` nearest to it, which must lie within ``tol``
of it. Two such fractions differ by at least ``1 / max_den**2`` (1e-6 for 1000), far beyond the float64
rounding of entries of size O(1) (1e-13 here), so the recovery is unique; the generators then check that the
exact system is consistent (an entry recovered wrongly would make it inconsistent).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

__all__: list = []  # private: used by the derivations (tools/gen_*.py, splinevis.volume.schemes)


def flint_module():
    """python-flint, or an ImportError saying how to get it."""
    try:
        import flint
    except ImportError as err:  # pragma: no cover - the test extra installs it
        raise ImportError("this derivation solves in exact rational arithmetic with python-flint: "
                          "pip install python-flint (part of splinevis' test extra).") from err
    return flint


def rationals(a, *, max_den: int = 1000, tol: float = 1e-12, what: str = "entry") -> list:
    """The exact fractions behind the float64 array ``a`` (flattened, C order): for each value the fraction
    of denominator <= ``max_den`` nearest to it, which must lie within ``tol`` (raises ValueError naming the
    index and value otherwise)."""
    flat = np.asarray(a, dtype=np.float64).ravel()
    out = []
    cache: dict = {}
    for k, x in enumerate(flat):
        x = float(x)
        q = cache.get(x)
        if q is None:
            q = Fraction(x).limit_denominator(max_den)
            if abs(float(q) - x) > tol:
                raise ValueError(f"{what} {np.unravel_index(k, np.shape(a))} = {x!r} is no fraction of denominator "
                                 f"<= {max_den} within {tol:g}: the system is not the rational one assumed.")
            cache[x] = q
        out.append(q)
    return out


def qmat(a, **kw):
    """``flint.fmpq_mat`` of the exact fractions behind the float64 matrix ``a`` (2-D; see :func:`rationals`)."""
    flint = flint_module()

    a = np.atleast_2d(np.asarray(a, dtype=np.float64))
    qs = rationals(a, **kw)
    return flint.fmpq_mat(a.shape[0], a.shape[1], [flint.fmpq(q.numerator, q.denominator) for q in qs])


def fractions_of(m) -> list:
    """Rows of ``fractions.Fraction`` of an ``fmpq_mat``."""
    return [[Fraction(int(v.p), int(v.q)) for v in m.table()[i]] for i in range(m.nrows())]


def lstsq_full_rank(A, B):
    """Exact least-squares solution ``X = (A^T A)^-1 A^T B`` of ``A X ~ B`` for ``A`` of full column rank
    (fmpq_mat in and out); the value float64 ``lstsq`` approximates. Raises if the rank is short."""
    At = A.transpose()
    N = At * A
    if N.rank() != A.ncols():
        raise ValueError(f"least squares: the matrix has rank {N.rank()} < {A.ncols()} columns.")
    return N.solve(At * B)


def _pivot_rows(A) -> list:
    """Indices of a maximal set of linearly independent rows of ``A`` (the pivot columns of rref(A^T))."""
    R, rank = A.transpose().rref()
    rows = []
    tab = R.table()
    for i in range(rank):
        rows.append(next(j for j, v in enumerate(tab[i]) if v != 0))
    return rows


def least_norm(A, b):
    """Exact least-norm solution of the consistent system ``A x = b`` (fmpq_mat in and out): with ``A_r`` a
    maximal set of independent rows, ``x = A_r^T (A_r A_r^T)^-1 b_r`` (the pseudo-inverse solution ``A^+ b``,
    which float64 ``lstsq`` approximates). Raises if ``A x = b`` has no solution."""
    flint = flint_module()

    rows = _pivot_rows(A)
    tab, btab = A.table(), b.table()
    Ar = flint.fmpq_mat(len(rows), A.ncols(), [v for i in rows for v in tab[i]])
    br = flint.fmpq_mat(len(rows), b.ncols(), [v for i in rows for v in btab[i]])
    x = Ar.transpose() * (Ar * Ar.transpose()).solve(br)
    if A * x != b:
        raise ValueError("least norm: the system is inconsistent (no exact solution).")
    return x, len(rows)


def literal(q: Fraction) -> str:
    """The shortest decimal literal that reads back as the correctly rounded double of ``q`` (``float(q)``
    rounds correctly; ``repr`` is the shortest round-trip string), with a ``.0`` where repr has no point.

    >>> literal(Fraction(1, 3)), literal(Fraction(2)), literal(Fraction(-5, 192))
    ('0.3333333333333333', '2.0', '-0.026041666666666668')
    """
    r = repr(float(q))
    return r if ("." in r or "e" in r or "n" in r) else r + ".0"


def _pivots(R, rank) -> list:
    tab = R.table()
    return [next(j for j, v in enumerate(tab[i]) if v != 0) for i in range(rank)]


def solve_any(A, b):
    """A solution ``x`` of ``A x = b`` (fmpq_mat; ``b`` one column), the free unknowns zero, or None if the
    system is inconsistent (a pivot of ``rref([A | b])`` in the last column).

    >>> import flint
    >>> A = flint.fmpq_mat(2, 2, [1, 1, 2, 2])
    >>> solve_any(A, flint.fmpq_mat(2, 1, [3, 6])).entries(), solve_any(A, flint.fmpq_mat(2, 1, [3, 7]))
    ([3, 0], None)
    """
    flint = flint_module()
    n = A.ncols()
    M = flint.fmpq_mat(A.nrows(), n + 1, [v for ra, rb in zip(A.table(), b.table()) for v in ra + rb])
    R, rank = M.rref()
    piv = _pivots(R, rank)
    if piv and piv[-1] == n:
        return None
    tab = R.table()
    x = [flint.fmpq(0)] * n
    for i, j in enumerate(piv):
        x[j] = tab[i][n]
    return flint.fmpq_mat(n, 1, x)


def nullspace(A):
    """A basis of ``{x : A x = 0}`` as the columns of an fmpq_mat (``ncols x k``; ``k = 0`` gives an empty one):
    one column per free unknown of ``rref(A)``.

    >>> import flint
    >>> nullspace(flint.fmpq_mat(1, 3, [1, 1, 0])).table()
    [[-1, 0], [1, 0], [0, 1]]
    """
    flint = flint_module()
    n = A.ncols()
    R, rank = A.rref()
    piv = _pivots(R, rank)
    free = [j for j in range(n) if j not in set(piv)]
    tab = R.table()
    cols = []
    for f in free:
        v = [flint.fmpq(0)] * n
        v[f] = flint.fmpq(1)
        for i, j in enumerate(piv):
            v[j] = -tab[i][f]
        cols.append(v)
    return flint.fmpq_mat(n, len(cols), [cols[c][r] for r in range(n) for c in range(len(cols))])

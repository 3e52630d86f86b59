"""Quartic Bernstein-Bezier form on the two triangles of a type-1 grid cell: index tables, collocation
at the domain points, and the C^r conditions between the triangles of neighbouring cells.

Exact tables without validation, shared by the scheme definitions (:mod:`splinevis.terrain.schemes`) and
the derivation of the C1 scheme (:mod:`splinevis.terrain.c1_scheme`).
"""

from __future__ import annotations

import functools
from math import factorial

import numpy as np

from ..bb import simplex as _bb

_DEG = 4
_MI = _bb.multi_indices(_DEG, 2)                      # (15, 3), lexicographic descending
_IDX = {tuple(int(v) for v in a): q for q, a in enumerate(_MI)}
#: Triangle vertices in cell units, relative to the cell's lower-left corner.
_TRI = (np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)]), np.array([(0.0, 0.0), (1.0, 1.0), (0.0, 1.0)]))
# d(lambda_k)/dx and d(lambda_k)/dy on T0 (lam = (1-x, x-y, y)) and T1 (lam = (1-y, x, y-x)).
_DLAM = (np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]]), np.array([[0.0, 1.0, -1.0], [-1.0, 0.0, 1.0]]))


def _bern(alpha, lam):
    """Quartic Bernstein polynomial ``B^4_alpha`` at barycentric coordinates ``lam``."""
    return factorial(_DEG) / np.prod([factorial(int(a)) for a in alpha]) * np.prod(np.asarray(lam, float) ** alpha)


@functools.lru_cache(maxsize=None)
def _collocation_inverse():
    """Inverse of the 15x15 matrix B[p, q] = B^4_q(domain point p): BB coefficients = Binv @ values."""
    B = np.array([[_bern(a, b / _DEG) for a in _MI] for b in _MI])
    Binv = np.linalg.inv(B)
    Binv.setflags(write=False)
    return Binv


def _domain_points(t):
    """(15, 2) domain points of triangle Tt in cell units."""
    return _MI @ _TRI[t] / _DEG


def _monomial_bb(a, b, t):
    """Quartic BB coefficients of x^a y^b (a + b <= 4) on triangle Tt of the cell at the origin."""
    p = _domain_points(t)
    return _collocation_inverse() @ (p[:, 0] ** a * p[:, 1] ** b)


def _edge_conditions(r):
    """C^0..C^r conditions between the triangles of neighbouring cells, as identities between coefficients.

    Returns a list of relations; each relation is a list of ``(cell_shift, t, q, weight)`` with
    ``sum weight * coef[cell + cell_shift, t, q] == 0`` required for every cell. The three pairs (T0, T1)
    of the same cell (diagonal edge), T0 of a cell and T1 of the cell below (horizontal edge), T0 and T1
    of the cell to the right (vertical edge) cover every interior edge. For triangles A, B sharing an edge,
    with B's opposite vertex e having barycentric coordinates lam w.r.t. A, the C^rho condition is
    ``c^B_beta = sum_{|g| = rho} B^rho_g(lam) c^A_{alpha0 + g}`` for every beta with beta_e = rho, where
    alpha0 carries beta's exponents on the shared vertices [Farin2002, ch. 18; LaiSchumaker2007, Thm. 2.28].
    """
    rels = []
    pairs = [((0, 0), 0, (0, 0), 1), ((0, 0), 0, (0, -1), 1), ((0, 0), 0, (1, 0), 1)]
    for dA, tA, dB, tB in pairs:
        VA = _TRI[tA] + dA
        VB = _TRI[tB] + dB
        match = {k: m for k in range(3) for m in range(3) if np.array_equal(VA[k], VB[m])}
        eB = next(m for m in range(3) if m not in match.values())
        M = np.vstack([VA.T, np.ones(3)])
        lam = np.linalg.solve(M, np.append(VB[eB], 1.0))
        lam = np.round(lam * 8) / 8  # exact: the type-1 triangulation gives integer coordinates
        for rho in range(r + 1):
            for beta in _MI:
                if beta[eB] != rho:
                    continue
                alpha0 = np.zeros(3, dtype=np.int64)
                for k, m in match.items():
                    alpha0[k] = beta[m]
                terms = [(dB, tB, _IDX[tuple(int(v) for v in beta)], -1.0)]
                for g in _bb.multi_indices(rho, 2):
                    w = factorial(rho) / np.prod([factorial(int(v)) for v in g]) * np.prod(lam ** g)
                    if w != 0.0:
                        terms.append((dA, tA, _IDX[tuple(int(v) for v in alpha0 + g)], float(w)))
                rels.append(terms)
    return rels

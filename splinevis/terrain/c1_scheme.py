"""The C1 terrain scheme: its data stencil and the derivation of its weights from C1 conditions and
cubic reproduction (least-norm solution of one linear system; see ``docs/terrain-schemes.md``). The scheme
reads the solution stored in :mod:`splinevis.terrain._c1_weights` (``tools/gen_scheme_weights.py``); the
derivation here is its proof."""

from __future__ import annotations

import functools

import numpy as np

from .cell import _edge_conditions, _monomial_bb
from .engine import _offsets, _Stencil

__all__ = ["C1_STENCIL", "c1_system"]

#: Data offsets of the C1 scheme (22 points; symmetric under x <-> y and under (x, y) -> (1-x, 1-y)):
#: the 4x4 block [-1, 2]^2 without its corners (-1, 2), (2, -1), plus two points beyond each side.
C1_STENCIL = tuple(sorted(
    [(x, y) for x in range(-1, 3) for y in range(-1, 3) if (x, y) not in ((-1, 2), (2, -1))]
    + [(-2, 0), (-2, 1), (3, 0), (3, 1), (0, -2), (1, -2), (0, 3), (1, 3)], key=lambda o: (o[1], o[0])))


def c1_system(offsets=C1_STENCIL, *, smoothness=1, reproduce=3):
    """The linear system whose solution is the C1 scheme's weights (see ``docs/terrain-schemes.md``).

    Unknowns ``w[s, tq]`` (``s`` over ``offsets``, ``tq = 15 t + q`` over the 30 coefficients of a cell),
    flattened as ``s * 30 + tq``. Rows: (i) for every C^0..C^smoothness edge condition of
    :func:`splinevis.terrain.cell._edge_conditions` and every data offset ``o``, the weight of ``z(cell + o)`` in the condition
    must vanish (the condition holds for all data; a neighbour cell's weights are the stencil shifted by
    the cell offset); (ii) for every monomial ``x^a y^b`` with ``a + b <= reproduce`` and every coefficient,
    the weights applied to the monomial's samples give its BB coefficient (its blossom at the domain
    point). Returns ``(A, rhs, n_smooth_rows)``.

    Examples
    --------
    >>> A, rhs, n_smooth = c1_system()
    >>> A.shape, n_smooth  # 22 offsets x 30 coefficients unknowns
    ((1002, 660), 702)
    >>> w = np.linalg.lstsq(A, rhs, rcond=None)[0]
    >>> bool(np.abs(A @ w - rhs).max() < 1e-12)  # consistent: C1 and cubic reproduction hold exactly
    True
    """
    oi = {o: k for k, o in enumerate(offsets)}
    S = len(offsets)
    rows, rhs = [], []
    for terms in _edge_conditions(smoothness):
        outs = sorted({(o[0] + d[0], o[1] + d[1]) for d, _, _, _ in terms for o in offsets})
        for u in outs:
            row = {}
            for d, t, q, w in terms:
                s = oi.get((u[0] - d[0], u[1] - d[1]))
                if s is not None:
                    key = s * 30 + t * 15 + q
                    row[key] = row.get(key, 0.0) + w
            row = {k: v for k, v in row.items() if v != 0.0}
            if row:
                rows.append(row)
                rhs.append(0.0)
    n_smooth = len(rows)
    off = np.array(offsets, float)
    for a in range(reproduce + 1):
        for b in range(reproduce + 1 - a):
            samples = off[:, 0] ** a * off[:, 1] ** b
            for t in range(2):
                bb = _monomial_bb(a, b, t)
                for q in range(15):
                    rows.append({s * 30 + t * 15 + q: samples[s] for s in range(S) if samples[s] != 0.0})
                    rhs.append(bb[q])
    A = np.zeros((len(rows), S * 30))
    for k, row in enumerate(rows):
        for c, v in row.items():
            A[k, c] = v
    return A, np.array(rhs), n_smooth


@functools.lru_cache(maxsize=None)
def _c1_solution():
    """Least-norm weights of the C1 system (unique, hence symmetric) and the system's diagnostics."""
    A, rhs, n_smooth = c1_system()
    x, _, rank, _ = np.linalg.lstsq(A, rhs, rcond=None)
    resid = A @ x - rhs
    W = x.reshape(len(C1_STENCIL), 30)
    diag = {"rows": A.shape[0], "unknowns": A.shape[1], "rank": int(rank),
            "smoothness_residual": float(np.abs(resid[:n_smooth]).max()),
            "exactness_residual": float(np.abs(resid[n_smooth:]).max())}
    if max(diag["smoothness_residual"], diag["exactness_residual"]) > 1e-12:  # pragma: no cover
        raise RuntimeError(f"C1 weight system is inconsistent: {diag}")
    W.setflags(write=False)
    return W, diag


@functools.lru_cache(maxsize=None)
def _c1():
    """The C1 scheme's weights on the 6x6 window ``[-2, 3]^2``, read from the stored solution
    :mod:`splinevis.terrain._c1_weights` (no solve at run time; written by ``tools/gen_scheme_weights.py`` from
    :func:`_c1_solution`, which tests/test_scheme_weights.py re-runs and compares bit for bit)."""
    from ._c1_weights import C1_FLOATS

    Wc = np.array(C1_FLOATS, dtype=np.float64)
    offs = _offsets(-2, -2, 6, 6)
    W = np.zeros((36, 30))
    for s, o in enumerate(C1_STENCIL):
        W[offs.index(o)] = Wc[s]
    return _Stencil(-2, -2, 6, 6, 1, W)

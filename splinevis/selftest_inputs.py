"""Random inputs of the GLSL self-test (:mod:`splinevis.selftest`), cast to float32 *first*: BB polynomials of
evaluation, restriction and root finding, with hard ones (roots close together, double roots, magnitudes
over many decades).
"""

from __future__ import annotations

from math import comb

import numpy as np


__all__: list = []  # private helpers of splinevis.selftest (which re-exports them for the tests)

def _power_to_bb(p):
    """Ascending power coefficients (..., n+1) -> BB coefficients: c_k = sum_{j<=k} C(k,j)/C(n,j) p_j."""
    n = p.shape[-1] - 1
    mat = np.zeros((n + 1, n + 1))
    for k in range(n + 1):
        for j in range(k + 1):
            mat[k, j] = comb(k, j) / comb(n, j)
    return p @ mat.T


def _from_roots(roots, scale):
    """BB coefficients of scale * prod_i (t - r_i); roots (M, n), complex allowed in conjugate pairs."""
    m, n = roots.shape
    p = np.ones((m, 1), dtype=complex)
    for i in range(n):
        # multiply ascending coefficients by (t - r)
        q = np.zeros((m, p.shape[1] + 1), dtype=complex)
        q[:, 1:] += p
        q[:, :-1] -= roots[:, i, None] * p
        p = q
    return _power_to_bb(p.real) * scale[:, None]


def _magnitudes(rng, m):
    return 10.0 ** rng.uniform(-6, 6, size=m)


def _eval_inputs(rng, m, n):
    """Coefficients (m, n+1) and t (m,) as float32, with labelled hard cases."""
    kinds = rng.choice(6, size=m, p=[0.3, 0.2, 0.1, 0.15, 0.15, 0.1])
    c = rng.normal(size=(m, n + 1)) * _magnitudes(rng, m)[:, None]                       # 0: common scale
    spread = rng.normal(size=(m, n + 1)) * 10.0 ** rng.uniform(-6, 6, size=(m, n + 1))  # 1: 1e-6..1e6 mixed
    c = np.where((kinds == 1)[:, None], spread, c)
    flat = _magnitudes(rng, m)[:, None] * (1.0 + 1e-6 * rng.normal(size=(m, n + 1)))    # 2: nearly flat
    c = np.where((kinds == 2)[:, None], flat, c)
    rts = rng.uniform(-0.2, 1.2, size=(m, n))
    rts[:, 1 % n] = rts[:, 0]  # a double root (for n = 1: a simple one)
    c = np.where((kinds == 3)[:, None], _from_roots(rts, _magnitudes(rng, m)), c)      # 3: cancellation
    alt = (-1.0) ** np.arange(n + 1) * _magnitudes(rng, m)[:, None] * (1 + 0.01 * rng.random((m, n + 1)))
    c = np.where((kinds == 4)[:, None], alt, c)                                        # 4: alternating
    c = np.where((kinds == 5)[:, None], np.round(rng.normal(size=(m, n + 1)) * 8), c)  # 5: small integers
    tk = rng.choice(5, size=m, p=[0.6, 0.1, 0.1, 0.1, 0.1])
    t = rng.random(m)
    t = np.where(tk == 1, 0.0, t)
    t = np.where(tk == 2, 1.0, t)
    t = np.where(tk == 3, 10.0 ** -rng.uniform(1, 8, size=m), t)
    t = np.where(tk == 4, 1.0 - 10.0 ** -rng.uniform(1, 7, size=m), t)
    t = np.where(np.arange(m) < 3, [0.0, 0.5, 1.0][: min(m, 3)] + [0.0] * max(0, m - 3), t) if m >= 3 else t
    return c.astype(np.float32), t.astype(np.float32)


_ROOT_KINDS = ("random_roots", "double_root", "near_double_root", "near_miss_complex_pair", "complex_pair",
               "root_at_0_or_1", "coefficients_1e-6_to_1e6", "nearly_flat")


def _root_inputs(rng, m, n):
    """Coefficients (m, n+1) float32 with roots in [0, 1], double roots, roots at 0 and 1, flat ones."""
    kind = rng.choice(8, size=m, p=[0.25, 0.15, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1])
    rts = np.where(rng.random((m, n)) < 0.6, rng.random((m, n)), rng.uniform(-1.0, 2.0, size=(m, n))).astype(complex)
    # 1: double root inside
    dbl = kind == 1
    rts[dbl, 1] = rts[dbl, 0] = rng.random(dbl.sum())
    # 2: near-double roots (separation 1e-7..1e-3)
    nd = kind == 2
    rts[nd, 0] = rng.random(nd.sum())
    rts[nd, 1] = rts[nd, 0] + 10.0 ** rng.uniform(-7, -3, size=nd.sum())
    # 3: complex pair close to the real axis (a near miss), 4: complex pair anywhere
    for kk, im in ((3, lambda s: 10.0 ** rng.uniform(-6, -2, size=s)), (4, lambda s: rng.uniform(0.05, 1, size=s))):
        sel = kind == kk
        re = rng.random(sel.sum())
        ii = im(sel.sum())
        rts[sel, 0] = re + 1j * ii
        rts[sel, 1] = re - 1j * ii
    c = _from_roots(rts, _magnitudes(rng, m) * np.where(rng.random(m) < 0.5, -1.0, 1.0))
    # 5: root exactly at 0 or at 1 (coefficient set to exactly zero)
    at = kind == 5
    end = rng.random(m) < 0.5
    c[at & end, 0] = 0.0
    c[at & ~end, n] = 0.0
    # 6: random coefficients with magnitudes spanning 1e-6..1e6
    sp = kind == 6
    c[sp] = rng.normal(size=(sp.sum(), n + 1)) * 10.0 ** rng.uniform(-6, 6, size=(sp.sum(), n + 1))
    # 7: nearly flat (no root, |f| ~ 1e-6 of its scale variation)
    fl = kind == 7
    c[fl] = _magnitudes(rng, fl.sum())[:, None] * (1.0 + 1e-6 * rng.normal(size=(fl.sum(), n + 1)))
    return c.astype(np.float32), kind


def _restrict_inputs(rng, m):
    b = rng.normal(size=(m, 15)) * _magnitudes(rng, m)[:, None]
    spread = rng.normal(size=(m, 15)) * 10.0 ** rng.uniform(-6, 6, size=(m, 15))
    b = np.where((rng.random(m) < 0.3)[:, None], spread, b)
    pts = []
    for _ in range(2):
        lam = rng.dirichlet(np.ones(3), size=m)
        edge = rng.random(m) < 0.15
        lam[edge, rng.integers(0, 3, size=edge.sum())] = 0.0
        vert = rng.random(m) < 0.05
        lam[vert] = np.eye(3)[rng.integers(0, 3, size=vert.sum())]
        outside = rng.random(m) < 0.1
        lam[outside] += rng.normal(scale=0.2, size=(outside.sum(), 3))
        lam /= lam.sum(axis=1, keepdims=True)
        pts.append(lam)
    return b.astype(np.float32), pts[0].astype(np.float32), pts[1].astype(np.float32)

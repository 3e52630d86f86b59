"""Stretch relaxation on the sphere without flipping a triangle (stage 3 of :mod:`.sphere`), shared by the
coarse-to-fine start (:mod:`.hierarchy`): L-BFGS [Nocedal1980] on the tangent planes with the stretch
energy's preconditioner (:mod:`.stretch`), each step halved for the vertices of any triangle it would turn
inward (:func:`_safe_step`). "Inward" is decided against :data:`DET_BOUND`, the rounding bound of a
determinant of unit vectors.

Why our own code: the energy and its constraint (every triangle outward) are the parametrization's own.
"""

from __future__ import annotations

import numpy as np

from .._reproducible import dot, spd_factor

__all__ = ["DET_BOUND"]

#: Smallest ``det[a, b, c]`` of unit vectors that counts as outward: the rounding error of ``a . (b x c)`` is at
#: most ``5 u sum_i |a_i| (|b_j c_k| + |b_k c_j|) <= 5 sqrt(2) u`` (two products and a difference per component
#: of the cross product, three products and two sums in the dot product; ``u`` the unit roundoff, first order,
#: Cauchy-Schwarz), so a computed det above ``8 u`` is positive in exact arithmetic too.
DET_BOUND = 8 * np.finfo(np.float64).eps / 2

#: Largest change of the spherical triangles' area sum a step may make: a step that keeps every triangle outward
#: can still jump (vertices move up to half a radian) to a map covering the sphere twice, whose areas sum to
#: ``8 pi``; rounding moves the sum by ``~1e-16`` per triangle, far below this and far below the ``4 pi`` jump.
DEGREE_TOLERANCE = 1e-6

#: The relaxation factors its preconditioner anew every this many steps.
REFACTOR = 4

#: Steps before the relaxation may stop for slow progress (L-BFGS learns the curvature in its first steps).
MIN_STEPS = 10


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _det(X, F):
    XT = np.ascontiguousarray(X.T)
    a, b, c = XT[:, F[:, 0]], XT[:, F[:, 1]], XT[:, F[:, 2]]
    return (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))


def _safe_step(X, d, lam, F, incident):
    """``unit(X + lam d)`` with per-vertex steps ``lam`` (changed in place) such that no triangle is flipped: the
    vertices of flipped triangles halve their step, then only the triangles around them are checked again. A
    vertex halved 40 times stops (step 0); a triangle whose three vertices stop is as in ``X``, unflipped, so
    this ends."""
    Y = _unit(X + lam[:, None] * d)
    halved = np.zeros(len(X), dtype=np.int64)
    faces = np.arange(len(F))
    while True:
        bad = faces[~(_det(Y, F[faces]) > DET_BOUND)]
        if not bad.size:
            return Y
        moved = np.unique(F[bad])
        halved[moved] += 1
        lam[moved] = np.where(halved[moved] > 40, 0.0, 0.5 * lam[moved])
        Y[moved] = _unit(X[moved] + lam[moved, None] * d[moved])
        faces = np.unique(incident[moved].indices)


def _tangent(v, X):
    return v - np.einsum("ij,ij->i", v, X)[:, None] * X


def _relax(X, S, iterations, progress, tol, memory=8):
    """Stage 3: descent of the stretch energy on the sphere, never flipping a triangle: L-BFGS directions
    [Nocedal1980] on the tangent planes, with the
    preconditioner as the initial inverse Hessian. A step that does not lower the energy enough (Armijo) is
    halved; where it would flip a triangle it is halved for that triangle's vertices (:func:`_safe_step`)."""
    F = S.F
    incident = (S.gather @ _corner_face(len(F))).tocsr()  # vertex -> its triangles
    E, g, sph = S.gradient(X)
    area_start = float(np.add.reduce(sph))  # 4 pi times the degree: every accepted step keeps it
    g = _tangent(g, X)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=iterations, desc="stretch relaxation", unit="step")
    steps, history, energies = 0, [], [E]
    for _ in range(iterations):
        if steps % REFACTOR == 0:  # the preconditioner changes slowly: factor it every REFACTOR-th step
            # symmetric positive definite: a sparse Cholesky factor (Eigen's: the same bits on every machine)
            solve = spd_factor(S.preconditioner(sph))
        # two-loop recursion
        q = g.copy()
        alphas = []
        for s_k, y_k, rho in reversed(history):
            a = rho * dot(s_k, q)
            q -= a * y_k
            alphas.append(a)
        r = solve(q)
        if history:
            s_k, y_k, _ = history[-1]
            r *= dot(s_k, y_k) / max(dot(y_k, solve(y_k)), 1e-300)
        for (s_k, y_k, rho), a in zip(history, reversed(alphas)):
            r += (a - rho * dot(y_k, r)) * s_k
        d = -_tangent(r, X)
        slope = float(dot(g, d))
        if slope >= 0 or not np.isfinite(slope):
            history = []
            d = -_tangent(solve(g), X)
            slope = float(dot(g, d))
            if slope >= 0:
                break
        if history:
            step = 1.0
        else:  # no curvature pairs yet: minimize the quadratic model along d (its curvature from a small step)
            eps = 1e-4 / max(np.abs(d).max(), 1e-300)
            curv = float(dot(_tangent(S.gradient(_unit(X + eps * d))[1], X) - g, d)) / eps
            step = -slope / curv if curv > 0 else 1.0
        step = min(step, 0.5 / np.linalg.norm(d, axis=1).max())  # no vertex moves more than half a radian
        accepted = False
        for _ in range(40):
            Y = _safe_step(X, d, np.full(len(X), step), F, incident)
            E_new, area = S.energy_and_area(Y)
            if E_new <= E + 1e-4 * step * slope and abs(area - area_start) <= DEGREE_TOLERANCE:
                accepted = True
                break
            step *= 0.5
        if bar is not None:
            bar.update(1)
        if not accepted:
            break
        steps += 1
        energies.append(E_new)
        E, g_new, sph = S.gradient(Y)
        g_new = _tangent(g_new, Y)
        s_k, y_k = Y - X, g_new - _tangent(g, Y)
        sy = dot(s_k, y_k)
        if sy > 1e-12 * dot(s_k, s_k) ** 0.5 * dot(y_k, y_k) ** 0.5:
            history = (history + [(s_k, y_k, 1.0 / sy)])[-memory:]
        X, g = Y, g_new
        if len(energies) > MIN_STEPS and energies[-6] - E < 5 * tol * E:  # under tol a step over the last 5 steps
            break
    if bar is not None:
        bar.close()
    return X, steps


def _corner_face(F):
    """``(3 F, F)`` sparse: corner ``3 t + k`` belongs to triangle ``t``."""
    from scipy.sparse import coo_matrix

    return coo_matrix((np.ones(3 * F), (np.arange(3 * F), np.repeat(np.arange(F), 3))), shape=(3 * F, F))

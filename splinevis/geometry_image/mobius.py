"""Möbius transformations of the unit sphere, and the one that centres a mass distribution on it: the
normalization between a conformal spherical map and its stretch relaxation (:mod:`.sphere`).

For ``|c| < 1`` the map ``x -> (1 - |c|^2) (x + c) / |x + c|^2 + c`` sends the unit sphere onto itself
(``|.|^2 = (1 - |c|^2) + |c|^2``), is the identity at ``c = 0`` and, being continuous in ``c``, keeps the
orientation of every triangle; it fixes ``-c / |c|`` and ``c / |c|``, stretching lengths by
``(1 + |c|) / (1 - |c|)`` at the first and shrinking them by its inverse at the second. A conformal map of a
surface to the sphere is unique up to these (and rotations), so among them we pick the one that puts the
surface's area-weighted centroid of the images at the origin (the normalization of [Baden2018]): it undoes the crowding of a stereographic projection.

At ``c = 0`` the centroid ``mu(c) = sum_i w_i x_i(c)`` has the derivative ``2 (I - sum_i w_i x_i x_i^T)`` (from
``d x_i / dc = 2 (I - x_i x_i^T)``), so :func:`center_on_sphere` takes Newton steps, each a new transformation of
the current points, capped at ``|c| = 1/2`` (a factor 3 in length) and halved while the centroid does not
shrink; when all the mass sits at one point the derivative is singular along it and the least-squares step with
the cap still moves it away.

Why our own code: a few lines of numpy; no kept library has Möbius transformations of point sets.
"""

from __future__ import annotations

import numpy as np

from .._reproducible import dot, norm, solve_small, weighted_sum

__all__ = ["mobius_transform", "center_on_sphere"]


def mobius_transform(X, c) -> np.ndarray:
    """The Möbius transformation ``x -> (1 - |c|^2) (x + c) / |x + c|^2 + c`` of unit vectors ``X`` (``(N, 3)``),
    ``|c| < 1``: a bijection of the sphere keeping orientation, expanding about ``-c``.

    >>> Y = mobius_transform(np.eye(3), [0.0, 0.0, 0.5])
    >>> np.linalg.norm(Y, axis=1).round(12).tolist(), Y[2].tolist()  # on the sphere; c / |c| is fixed
    ([1.0, 1.0, 1.0], [0.0, 0.0, 1.0])
    """
    X = np.asarray(X, dtype=np.float64)
    c = np.asarray(c, dtype=np.float64)
    if not norm(c) < 1.0:
        raise ValueError(f"a Möbius transformation of the sphere needs |c| < 1, got |c| = {norm(c):.6g}.")
    y = X + c
    Y = (1.0 - dot(c, c)) * y / (y * y).sum(axis=1, keepdims=True) + c
    return Y / np.linalg.norm(Y, axis=1, keepdims=True)  # remove rounding off the sphere


def center_on_sphere(X, mass, *, tol: float = 1e-12, max_steps: int = 200) -> np.ndarray:
    """Unit vectors ``X`` (``(N, 3)``) moved by a Möbius transformation so that ``sum_i mass_i X_i`` is 0 (to
    ``tol`` times the total mass), by the Newton steps of the module docstring.

    >>> rng = np.random.default_rng(1)
    >>> X = rng.normal(size=(500, 3)) + [0.0, 0.0, 3.0]  # crowded about the north pole
    >>> X /= np.linalg.norm(X, axis=1, keepdims=True)
    >>> Y = center_on_sphere(X, np.ones(500))
    >>> bool(np.linalg.norm(X.mean(axis=0)) > 0.8 and np.linalg.norm(Y.mean(axis=0)) < 1e-12)
    True
    """
    X = np.asarray(X, dtype=np.float64)
    w = np.asarray(mass, dtype=np.float64)
    w = w / w.sum()
    mu = weighted_sum(w, X)
    for _ in range(int(max_steps)):
        if norm(mu) < tol:
            break
        J = 2.0 * (np.eye(3) - np.einsum("i,ij,ik->jk", w, X, X))
        c = -solve_small(J, mu)  # J is positive definite unless all points lie on one line
        if not np.all(np.isfinite(c)):
            break
        if norm(c) > 0.5:
            c *= 0.5 / norm(c)
        for _ in range(60):
            Y = mobius_transform(X, c)
            mu_new = weighted_sum(w, Y)
            if norm(mu_new) < norm(mu):
                break
            c *= 0.5
        else:
            break
        X, mu = Y, mu_new
    return X

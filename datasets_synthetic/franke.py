"""Franke's test function [Franke1982], the surface of the accuracy table [Reis2008, Table I], and its
exact gradient."""

from __future__ import annotations

import numpy as np

__all__ = ["franke", "franke_gradient", "franke_grid"]


def _terms(x, y):
    return (
        (0.75, -((9 * x - 2) ** 2) / 4 - ((9 * y - 2) ** 2) / 4),
        (0.75, -((9 * x + 1) ** 2) / 49 - (9 * y + 1) / 10),
        (0.5, -((9 * x - 7) ** 2) / 4 - ((9 * y - 3) ** 2) / 4),
        (-0.2, -((9 * x - 4) ** 2) - (9 * y - 7) ** 2),
    )


def franke(x, y):
    """Franke's function on [0, 1]^2 (values in about [0, 1.22])."""
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    return sum(a * np.exp(e) for a, e in _terms(x, y))


def franke_gradient(x, y):
    """Exact (df/dx, df/dy) of :func:`franke`, stacked on the last axis."""
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    (a1, e1), (a2, e2), (a3, e3), (a4, e4) = _terms(x, y)
    fx = (a1 * np.exp(e1) * (-9 * (9 * x - 2) / 2) + a2 * np.exp(e2) * (-18 * (9 * x + 1) / 49)
          + a3 * np.exp(e3) * (-9 * (9 * x - 7) / 2) + a4 * np.exp(e4) * (-18 * (9 * x - 4)))
    fy = (a1 * np.exp(e1) * (-9 * (9 * y - 2) / 2) + a2 * np.exp(e2) * (-9 / 10)
          + a3 * np.exp(e3) * (-9 * (9 * y - 3) / 2) + a4 * np.exp(e4) * (-18 * (9 * y - 7)))
    return np.stack([fx, fy], axis=-1)


def franke_grid(n: int):
    """Heights of Franke's function on an (n+1) x (n+1) grid over [0, 1]^2 and the spacing 1/n."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n must be a positive integer number of grid intervals, got {n!r}.")
    t = np.linspace(0.0, 1.0, int(n) + 1)
    x, y = np.meshgrid(t, t, indexing="ij")
    return franke(x, y), 1.0 / n

"""Derived error bounds for comparing float32 GPU results with float64 references."""

from __future__ import annotations

import numpy as np

from .rays import window_depth

__all__ = ["U32", "ray_depth_error_bound"]

#: float32 unit roundoff
U32 = 2.0 ** -24


def ray_depth_error_bound(gradient, coef_max, matrix, origins, directions, t, coord_magnitude) -> np.ndarray:
    """Per-pixel bound on |GPU depth - float64 depth| for graph surfaces z = f(x, y) hit at ray parameters t.

    Derivation (float32 arithmetic, unit roundoff u = 2^-24):

    * The shader evaluates g(t) = f(ray_xy(t)) - ray_z(t) through four triangle de Casteljau levels for
      the blossoms (each level <= 4 roundings on a convex combination: 16 u max|b|), one univariate
      de Casteljau of degree 4 (12 u sum|c_k| B_k <= 12 u (max|b| + |z|)) and the ray's height
      z0 + t dz (4 u (|z0| + |t dz|)): together eps_f = 32 u (max|b| + |z|).
    * The barycentric/index coordinates of the ray are computed in float32 from coordinates of size
      ``coord_magnitude`` = (|X|, |Y|) (physical units): an error of 4 u |X| in x moves f by |f_x| times
      that, so eps_x = 4 u (|X| |f_x| + |Y| |f_y|).
    * The root finder stops at a zero of the computed g, so the root moves by at most
      (eps_f + eps_x) / |g'(t)| with g'(t) = grad f . d_xy - d_z (first-order perturbation of a simple
      root). Window depth moves by |d'(t)| times that; computing depth from clip coordinates costs
      8 u more and the depth buffer quantizes to 2^-24.

    Near tangential rays g' -> 0 and the bound grows, as the problem's condition does.
    """
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    p = o + t[..., None] * d
    grad = gradient(p[..., :2])
    gprime = np.abs(np.einsum("...i,...i->...", grad, d[..., :2]) - d[..., 2])
    eps_f = 32.0 * U32 * (coef_max + np.abs(p[..., 2]))
    cm = np.asarray(coord_magnitude, dtype=np.float64)
    eps_x = 4.0 * U32 * np.einsum("...i,...i->...", cm, np.abs(grad))
    dt = (eps_f + eps_x) / np.maximum(gprime, 1e-300)
    h = 1e-6 * np.maximum(1.0, np.abs(t))
    dd_dt = np.abs(window_depth(matrix, o + (t + h)[..., None] * d) - window_depth(matrix, o + (t - h)[..., None] * d)) / (2 * h)
    return dd_dt * dt + 8.0 * U32 + 2.0 ** -24

"""A ray against quartic BB triangle patches of a graph surface, vectorized: the float64 twin of
glsl/lib/simplex/graph_patch.glsl, shared by the analytic patch and the terrain ray casters."""

from __future__ import annotations

import numpy as np

from . import roots as _roots
from . import simplex as _simplex

__all__ = ["graph_patch_first_hit", "start_tolerance"]

U32 = 2.0 ** -24


def start_tolerance(b_max, z_max, L, z_range):
    """Rounding error of the restricted coefficients c_k = f(ray) - z(ray) the shader computes in float32
    (glsl/lib/simplex/graph_patch.glsl), within which a segment's start counts as on the surface.

    Blossoming four levels of barycentric combinations of coefficients up to ``b_max`` and subtracting the
    ray's height (up to ``z_max``): 32 u (b_max + z_max) [Higham2002, sec. 3.4]; the ray's barycentric
    coordinates (magnitude ``L``) carry 4 u L, which moves a quartic by at most its barycentric slope
    4 ``z_range``: 16 u L z_range.

    >>> float(start_tolerance(1.0, 1.0, 1.0, 0.0)) == 64 * 2.0 ** -24
    True
    """
    return U32 * (32.0 * (np.asarray(b_max) + np.asarray(z_max)) + 16.0 * np.asarray(L) * np.asarray(z_range))

_K = np.arange(5) / 4.0


def graph_patch_first_hit(b, lam_o, lam_d, oz, dz, ta, tb, *, margin=0.0, method="reference", iterations=8):
    """First t in [ta, tb] where rays meet quartic graph patches, NaN where they do not.

    Parameters
    ----------
    b : (N, 15) ndarray
        Patch coefficients (heights), multi_indices(4, 2) order.
    lam_o, lam_d : (N, 3) ndarray
        The ray's barycentric coordinates are ``lam_o + t lam_d``.
    oz, dz : (N,) ndarray
        The ray's height is ``oz + t dz``.
    ta, tb : (N,) ndarray
        Parameter interval to search.
    margin : float
        Barycentric coordinates down to ``-margin`` count as inside.
    method : {"reference", "gpu", "paper"}
        First root by the robust reference, by the shader's bracketed Newton (float64 twin), or by the
        four-start Newton of [Reis2008, sec. V] (the shader with SV_ROOTS_PAPER).

    Steps as in the shader: clip to the triangle and to the coefficient slab (widened by a few thousand
    ulps so a flat patch does not collapse it), restrict by blossoming, subtract the ray's height,
    first root [Reis2008, sec. V].

    Examples
    --------
    Two vertical rays from height 2 down onto the plane z = 0.5, one through the centroid, one outside
    the triangle:

    >>> b = np.full((2, 15), 0.5)
    >>> lam_o, lam_d = np.array([[1 / 3, 1 / 3, 1 / 3], [2.0, -0.5, -0.5]]), np.zeros((2, 3))
    >>> graph_patch_first_hit(b, lam_o, lam_d, np.full(2, 2.0), np.full(2, -1.0), np.zeros(2), np.full(2, np.inf))
    array([1.5, nan])
    """
    t0, t1 = ta.astype(np.float64).copy(), tb.astype(np.float64).copy()
    with np.errstate(divide="ignore", invalid="ignore"):
        for k in range(3):
            flat = np.abs(lam_d[:, k]) < 1e-300
            tc = (-margin - lam_o[:, k]) / lam_d[:, k]
            t0 = np.where(~flat & (lam_d[:, k] > 0), np.maximum(t0, tc), t0)
            t1 = np.where(~flat & (lam_d[:, k] < 0), np.minimum(t1, tc), t1)
            t1 = np.where(flat & (lam_o[:, k] < -margin), -np.inf, t1)
        zlo, zhi = b.min(axis=-1), b.max(axis=-1)
        zpad = 1e-12 * (np.maximum(np.abs(zlo), np.abs(zhi)) + np.abs(oz)) + 1e-300
        zlo, zhi = zlo - zpad, zhi + zpad
        flat = np.abs(dz) < 1e-300
        za, zb = (zlo - oz) / dz, (zhi - oz) / dz
        t0 = np.where(flat, t0, np.maximum(t0, np.minimum(za, zb)))
        t1 = np.where(flat, np.where((oz < zlo) | (oz > zhi), -np.inf, t1), np.minimum(t1, np.maximum(za, zb)))
    out = np.full(t0.shape, np.nan)
    idx = np.nonzero(t0 <= t1)[0]
    if idx.size == 0:
        return out
    a, e = t0[idx], t1[idx]
    c = _simplex.restrict_to_segment(b[idx], lam_o[idx] + a[:, None] * lam_d[idx], lam_o[idx] + e[:, None] * lam_d[idx], d=2)
    z0, z1 = oz[idx] + a * dz[idx], oz[idx] + e * dz[idx]
    c = c - (z0[:, None] * (1 - _K) + z1[:, None] * _K)
    sign_change = (c.min(axis=-1) <= 0) & (c.max(axis=-1) >= 0)
    s = np.full(idx.shape, np.nan)
    if method != "reference":
        # the shader's rule: a segment starting on the surface within the float32 rounding of c is a hit at
        # its start (see start_tolerance); the reference finds the true root instead
        lam_a = lam_o[idx] + a[:, None] * lam_d[idx]
        L = (np.abs(lam_a) + np.abs(e - a)[:, None] * np.abs(lam_d[idx])).max(axis=-1)
        eps = start_tolerance(np.maximum(np.abs(zlo[idx]), np.abs(zhi[idx])), np.maximum(np.abs(z0), np.abs(z1)), L,
                              zhi[idx] - zlo[idx])
        at_start = np.abs(c[:, 0]) <= eps
        s[at_start] = 0.0
        sign_change &= ~at_start
    if sign_change.any():
        cc = c[sign_change]
        if method == "reference":
            s[sign_change] = _roots.first_root_reference(cc)
        elif method == "paper":
            s[sign_change] = _roots.newton_secure(cc, iterations=iterations)
        else:
            s[sign_change] = _roots.first_root_bracketed(cc, iterations=iterations)
    out[idx] = a + s * (e - a)
    return out

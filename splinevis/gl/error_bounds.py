"""Derived error bounds for comparing float32 GPU results with float64 references.

Every spline program's ``depth_bound`` (:class:`splinevis.gl.contract.SplineProgram`) is built from these:
the per-pixel window-depth error a float32 ray cast may make against its float64 twin, derived from the
rounding errors of each step (no tuned constants), plus the rasterizer's sub-pixel snapping.
"""

from __future__ import annotations

import numpy as np

from .camera import window_depth

__all__ = ["U32", "SUBPIXEL", "ray_depth_error_bound", "isosurface_depth_error_bound", "subpixel_depth_slack", "root_shift",
           "depth_error",
           "model_frame_matrix"]

#: float32 unit roundoff
U32 = 2.0 ** -24


def ray_depth_error_bound(gradient, coef_max, matrix, origins, directions, t, coord_magnitude,
                          proxy_size: float = 0.0) -> np.ndarray:
    """Per-pixel bound on |GPU depth - float64 depth| for graph surfaces z = f(x, y) hit at ray parameters t.

    Derivation (float32 arithmetic, unit roundoff u = 2^-24):

    * The shader evaluates g(t) = f(ray_xy(t)) - ray_z(t) through four triangle de Casteljau levels for
      the blossoms (each level <= 4 roundings on a convex combination: 16 u max|b|), one univariate
      de Casteljau of degree 4 (12 u sum|c_k| B_k <= 12 u (max|b| + |z|)) and the ray's height
      z0 + t dz (4 u (|z0| + |t dz|)): together eps_f = 32 u (max|b| + |z|).
    * The barycentric/index coordinates of the ray are computed in float32 from coordinates of size
      ``coord_magnitude`` = (|X|, |Y|) (physical units): an error of 4 u |X| in x moves f by |f_x| times
      that, so eps_x = 4 u (|X| |f_x| + |Y| |f_y|).
    * The ray itself is rounded: it starts at the fragment's interpolated position on the proxy (a few
      roundings of coordinates bounded by the proxy's size P) and its direction is normalized in float32
      (relative error ~ 3 u, i.e. a sideways shift of 3 u per unit of length travelled, at most P inside
      the proxy). Together a sideways shift of 8 u P, which moves the height difference g by
      eps_r = 8 u P (1 + |grad f|).
    * The root finder stops at a zero of the computed g = g + e with |e| <= eps. Taylor with
      g'(t) = grad f . d_xy - d_z and g'' = d_xy^T H d_xy: if 2 |g''| eps < g'^2, the perturbed root
      lies within 2 eps / |g'| (the smaller root of |g'| x - |g''| x^2 / 2 = eps is below that);
      otherwise the root is ill-conditioned (near tangential ray, a near double root) and moves by up
      to 2 sqrt(2 eps / |g''|). Window depth moves by |d'(t)| times that.
    * Depth from clip coordinates: clip z and w are 4-term dot products (error 4 u sum_j |M_ij p_j|
      each), so ndc z = z/w is off by 4 u (sum_j |M_2j p_j| + |ndc z| sum_j |M_3j p_j|) / |w| + u, and
      window depth by half that plus one rounding; the depth buffer quantizes to 2^-24.

    Near tangential rays g' -> 0 and the bound grows, as the problem's condition does. g'' is taken by
    central differences of g' in float64 (relative error ~1e-4, immaterial at this scale).

    Examples
    --------
    A vertical ray onto the plane z = 0.5 with the identity camera (window depth (z + 1) / 2): the root
    moves by 2 eps_f / |g'| = 64 u, the depth by half of that, plus the clip-space arithmetic:

    >>> o, d, t = np.array([[0.2, 0.2, 2.0]]), np.array([[0.0, 0.0, -1.0]]), np.array([1.5])
    >>> b = ray_depth_error_bound(lambda q: np.zeros(q.shape), 0.5, np.eye(4), o, d, t, np.zeros((1, 2)))
    >>> (b / U32).round(6)  # in units of u = 2^-24
    array([36.5])
    """
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    p = o + t[..., None] * d
    grad = gradient(p[..., :2])
    gprime = np.abs(np.einsum("...i,...i->...", grad, d[..., :2]) - d[..., 2])
    eps_f = 32.0 * U32 * (coef_max + np.abs(p[..., 2]))
    cm = np.asarray(coord_magnitude, dtype=np.float64)
    eps_x = 4.0 * U32 * np.einsum("...i,...i->...", cm, np.abs(grad))
    eps_r = 8.0 * U32 * proxy_size * (1.0 + np.linalg.norm(grad, axis=-1))
    eps = eps_f + eps_x + eps_r
    h = 1e-6 * np.maximum(1.0, np.abs(t))

    def slope(tt):
        q = o + tt[..., None] * d
        return np.einsum("...i,...i->...", gradient(q[..., :2]), d[..., :2]) - d[..., 2]

    gsecond = np.abs(slope(t + h) - slope(t - h)) / (2 * h)
    return depth_error(matrix, o, d, t, h, root_shift(eps, gprime, gsecond))


def isosurface_depth_error_bound(value_and_gradient, value_scale, spacing, matrix, origins, directions, t,
                                 model_extent, degree: int) -> np.ndarray:
    """Per-pixel bound on |GPU depth - float64 depth| for an isosurface s = iso hit at ray parameters t.

    ``value_and_gradient(p)`` returns the spline value and world gradient at points ``p``; ``matrix`` acts on
    model-frame points (world - offset); ``origins`` are model-frame; ``value_scale`` bounds
    |data - reference value| over the volume; ``model_extent`` bounds |model-frame coordinates|.

    Derivation (float32, u = 2^-24; n = degree):

    * value of g(t) = s(ray(t)) - iso as the shader computes it: data stored as float32 (u F, F =
      ``value_scale``), a coefficient as a sum of at most 27 weighted data (27 u F), restriction to the
      segment by n levels of 4-term barycentric combinations (4 n u F, the barycentric weights on the
      segment are near the tetrahedron), the isovalue subtracted (u F) and the root finders' acceptance:
      a Newton root is accepted at a residual up to K_n eps32 S = 6 n u S (splinevis.bb.roots.root_tolerance_k,
      S <= F): eps_f = (29 + 10 n) u F.
    * position: the cube-local start point is interpolated across the proxy face from exact corners
      (about 16 u of a cube) and the direction is normalized and scaled (3 u relative over at most 2 cube
      diagonals): a shift of 24 u cubes, i.e. eps_x = 24 u |grad s| h with h the largest spacing.
    * with g'(t) = grad s . d: simple roots move by <= 2 eps / |g'| (as in :func:`ray_depth_error_bound`),
      near-tangential ones by 2 sqrt(2 eps / |g''|); g'' by central differences.
    * the hit point is ro + t rd in the model frame, ro rounded to 4 u of the model extent X: a window
      depth error of |d depth / dt| 4 u X / |d|; plus the clip-space arithmetic and depth quantization of
      :func:`ray_depth_error_bound`.

    Examples
    --------
    The level set s = z of a cubic spline (data within 1 of the reference value, spacing 0.1), hit by a
    vertical ray, identity camera:

    >>> value_and_gradient = lambda p: (p[..., 2], np.broadcast_to([0.0, 0.0, 1.0], p.shape))
    >>> o, d, t = np.array([[0.2, 0.2, 2.0]]), np.array([[0.0, 0.0, -1.0]]), np.array([1.5])
    >>> b = isosurface_depth_error_bound(value_and_gradient, 1.0, (0.1, 0.1, 0.1), np.eye(4), o, d, t, 1.0, 3)
    >>> (b / U32).round(6)  # in units of u = 2^-24
    array([67.9])
    """
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    p = o + t[..., None] * d
    _, grad = value_and_gradient(p)
    gnorm = np.linalg.norm(grad, axis=-1)
    gprime = np.abs(np.einsum("...i,...i->...", grad, d))
    h = float(np.max(spacing))
    eps = (29 + 10 * degree) * U32 * value_scale + 24.0 * U32 * gnorm * h
    dl = 1e-6 * np.maximum(1.0, np.abs(t))

    def slope(tt):
        q = o + tt[..., None] * d
        return np.einsum("...i,...i->...", value_and_gradient(q)[1], d)

    gsecond = np.abs(slope(t + dl) - slope(t - dl)) / (2 * dl)
    dt = root_shift(eps, gprime, gsecond) + 4.0 * U32 * model_extent / np.linalg.norm(d, axis=-1)
    return depth_error(matrix, o, d, t, dl, dt)


def root_shift(eps, gprime, gsecond):
    """Bound on the move of a root of g when g is perturbed by at most eps: 2 eps / |g'| for simple roots
    (2 |g''| eps < g'^2), else 2 sqrt(2 eps / |g''|) (near-tangential rays, double roots).

    Examples
    --------
    >>> root_shift(np.array([1e-6, 1e-6]), np.array([2.0, 0.0]), np.array([1.0, 2.0]))  # simple; tangential
    array([1.e-06, 2.e-03])
    """
    simple = 2.0 * gsecond * eps < gprime ** 2
    return np.where(simple, 2.0 * eps / np.maximum(gprime, 1e-300), 2.0 * np.sqrt(2.0 * eps / np.maximum(gsecond, 1e-300)))


def depth_error(matrix, o, d, t, h, dt):
    """Window-depth error of a hit at ray parameter t known to within dt: |d depth/dt| dt, plus the float32
    clip-space arithmetic (clip z and w are 4-term dot products, 4 u sum |M_ij p_j| each; ndc = z / w; window
    depth = half of it plus a rounding) and the 2^-24 depth-buffer quantization.

    Examples
    --------
    Identity camera, hit at z = 0 along +z: window depth changes by 1/2 per unit of t.

    >>> o, d, t, h = np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([0.5]), np.array([1e-3])
    >>> (depth_error(np.eye(4), o, d, t, h, np.array([0.0])) / U32).round(6)  # arithmetic only, units of u
    array([4.5])
    >>> (depth_error(np.eye(4), o, d, t, h, np.array([1e-3])) / U32).round(6)  # plus 1/2 * 1e-3 / u = 8388.608
    array([8393.108])
    """
    p = o + t[..., None] * d
    dd_dt = np.abs(window_depth(matrix, o + (t + h)[..., None] * d) - window_depth(matrix, o + (t - h)[..., None] * d)) / (2 * h)
    m = np.asarray(matrix, dtype=np.float64)
    ph = np.concatenate([p, np.ones(p.shape[:-1] + (1,))], axis=-1)
    w = ph @ m[3]
    ndc = (ph @ m[2]) / w
    s2 = np.abs(ph * m[2]).sum(axis=-1)
    s3 = np.abs(ph * m[3]).sum(axis=-1)
    depth_arith = 0.5 * (4.0 * U32 * (s2 + np.abs(ndc) * s3) / np.abs(w) + U32) + U32
    return dd_dt * dt + depth_arith + 2.0 ** -24


def model_frame_matrix(matrix, offset) -> np.ndarray:
    """The camera matrix acting on model-frame points (world = model + ``offset``).

    >>> import numpy as np
    >>> model_frame_matrix(np.eye(4), (1.0, 2.0, 3.0))[:3, 3]
    array([1., 2., 3.])
    """
    T = np.eye(4)
    T[:3, 3] = np.asarray(offset, dtype=np.float64).reshape(3)
    return np.asarray(matrix, dtype=np.float64) @ T


#: Sub-pixel precision of the rasterizer: vertices are snapped to 2^-8 of a pixel (llvmpipe's fixed-point
#: setup, FIXED_ORDER = 8; the same order as GPUs' 8 sub-pixel bits).
SUBPIXEL = 2.0 ** -8


def subpixel_depth_slack(ref_depth: np.ndarray) -> np.ndarray:
    """Depth change over a sub-pixel offset of the ray: ``SUBPIXEL * (|d depth/dx| + |d depth/dy|)`` per pixel.

    The shader's ray passes through the fragment's interpolated position on the proxy, and the proxy's
    vertices were snapped to SUBPIXEL before interpolation: the ray is that of a point up to SUBPIXEL
    (per axis) away from the pixel centre (found on a one-voxel sheet whose isosurface lies on cube faces).
    The slope is the larger one-sided difference of the float64 reference depth to a neighbour that also
    hits (0 where none does).

    >>> import numpy as np
    >>> float(subpixel_depth_slack(np.array([[0.5, 0.5 + 2.0 ** -10]]))[0, 0]) == SUBPIXEL * 2.0 ** -10
    True
    """
    r = np.asarray(ref_depth, dtype=np.float64)
    ok = np.isfinite(r) & (r >= 0) & (r <= 1)
    slope = np.zeros_like(r)
    for axis in (0, 1):
        per_axis = np.zeros_like(r)
        for shift in (1, -1):
            nb = np.roll(r, shift, axis=axis)
            nok = np.roll(ok, shift, axis=axis)
            edge = np.zeros_like(ok)
            index = [slice(None), slice(None)]
            index[axis] = 0 if shift == 1 else -1
            edge[tuple(index)] = True
            per_axis = np.maximum(per_axis, np.where(ok & nok & ~edge, np.abs(r - nb), 0.0))
        slope += per_axis
    return SUBPIXEL * slope

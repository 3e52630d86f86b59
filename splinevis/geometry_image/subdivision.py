"""Bicubic subdivision of a padded geometry image: the float64 twin (and CPU fallback) of the GPU passes
[Losasso2003, sec. 5, Table 1].

The closed surface is the uniform bicubic B-spline ``P(s, t)`` whose control points are the padded image
(:func:`splinevis.geometry_image.image.pad`, width 1). One subdivision step is ``g^{k+1} = A[L[g^k]]``:

* :func:`split` ``L``: bilinear quadrisection, the paper's floor formula: the sample ``(i, j)`` of ``L[g]`` is
  ``g`` bilinearly interpolated at ``(i / 2, j / 2)``; a padded ``[0..m]^2`` image becomes ``[0..2m]^2``.
* :func:`average` ``A``: the mask ``[1 2 1]^T [1 2 1] / 16`` with the outermost sample cropped on every side,
  so ``[0..2m]^2`` becomes ``[0..2m-2]^2``: a padded ``(P, P)`` image becomes ``(2P - 3, 2P - 3)``, the
  padded image of the ``2N``-interval interior, and its one-sample padding is again the X-cut padding of
  that interior (bit for bit: every mask is summed in an order that the half turns of the padding rules
  map onto itself).
* :func:`limit` ``E``: ``[1 4 1]^T [1 4 1] / 36``, the limit positions ``p^k`` (the B-spline at the
  image's integer parameters).
* :func:`tangents` ``T_s, T_t``: the derivatives of ``P`` along columns (``s``) and rows (``t``) in sample
  units of the level: Table 1's mask ``(1/6) [[-1, 0, 1], [-4, 0, 4], [-1, 0, 1]]`` halved (Table 1's
  scale is twice the derivative; the direction of ``T_s x T_t`` does not care).
* :func:`normals` ``unit(T_s x T_t)``: outward for an image whose octahedral map is outward (the lead's
  :func:`splinevis.geometry_image.image.octahedral_to_sphere` layout). At the four cut vertices
  [Losasso2003, eq. 1] the tangent masks vanish for any data; with the centroid constraint (eq. 2,
  appendix) ``P_ss``, ``P_st``, ``P_tt`` are coplanar and near the vertex
  ``P_s x P_t = s^2 P_ss x P_st + s t P_ss x P_tt + t^2 P_st x P_tt`` is a definite quadratic form times
  the normal, so the normal there is ``unit(P_ss x P_st + P_st x P_tt)`` (:func:`second_derivatives`).
  It is one surface point with one normal at every level, so :func:`subdivide` computes the four normals
  once from the level-0 image (:func:`cut_normals`) and uses them at every level (as the GPU does: the
  formula's second differences lose ``4^k`` of float32's precision at level ``k``).
* :func:`curvature` mean ``H`` and Gaussian ``K`` from the first and second fundamental forms, with the
  sign convention of the NURBS programs (:func:`splinevis.nurbs.surface.fundamental_curvature`,
  ``glsl/programs/nurbs.glsl``): second derivatives dotted with the normal ``unit(T_s x T_t)``, so a
  sphere with outward normals has ``H = -1/r`` and ``K = 1/r^2``.

Continuous level of detail (sec. 5): :func:`subsample` (negative subdivision), :func:`linear_subdivide`
and :func:`geomorph` on the triangulation whose diagonals all join ``(r, c)`` and ``(r + 1, c + 1)``
(:func:`grid_faces`), and :func:`displace` (scalar displacement along the normal).

Why our own code: no library subdivides geometry images with the X-cut's padding and cut vertices; the
masks are the paper's, and scipy's B-splines are the reference the tests check them against.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .image import _check_n, cut_neighbours, cut_vertices, pad

__all__ = [
    "split",
    "average",
    "limit",
    "tangents",
    "second_derivatives",
    "cut_normals",
    "normals",
    "curvature",
    "Subdivision",
    "subdivide",
    "subsample",
    "linear_subdivide",
    "geomorph",
    "displace",
    "grid_faces",
]


def _image(Gp, least: int = 3) -> np.ndarray:
    g = np.asarray(Gp, dtype=np.float64)
    if g.ndim < 2 or g.shape[0] != g.shape[1] or g.shape[0] < least:
        raise ValueError(f"expected a square image of at least {least} x {least} samples, got shape {g.shape}.")
    return g


def split(Gp) -> np.ndarray:
    """The splitting step ``L`` [Losasso2003, Table 1]: ``(m + 1, m + 1, ...)`` -> ``(2m + 1, 2m + 1, ...)``.

    Sample ``(i, j)`` is the paper's floor formula with ``(I, J)`` the integer and ``(a, b)`` the fractional
    parts of ``(i / 2, j / 2)``: ``(1-a)(1-b) g[I, J] + a(1-b) g[I+1, J] + (1-a) b g[I, J+1] + a b g[I+1, J+1]``.
    An odd-odd sample is summed as ``((g[I, J] + g[I+1, J+1]) + (g[I+1, J] + g[I, J+1])) / 4``, pairs a half
    turn of the padding rules swaps (the GPU pass ``glsl/passes/gi_split.glsl`` sums the same pairs).

    Examples
    --------
    >>> split(np.array([[0.0, 4.0], [8.0, 16.0]]))
    array([[ 0.,  2.,  4.],
           [ 4.,  7., 10.],
           [ 8., 12., 16.]])
    """
    g = _image(Gp, 2)
    m = g.shape[0] - 1
    out = np.empty((2 * m + 1, 2 * m + 1) + g.shape[2:])
    out[0::2, 0::2] = g
    out[1::2, 0::2] = 0.5 * g[:-1] + 0.5 * g[1:]
    out[0::2, 1::2] = 0.5 * g[:, :-1] + 0.5 * g[:, 1:]
    out[1::2, 1::2] = 0.25 * ((g[:-1, :-1] + g[1:, 1:]) + (g[1:, :-1] + g[:-1, 1:]))
    return out


def average(Gp) -> np.ndarray:
    """The averaging step ``A`` [Losasso2003, Table 1]: mask ``[1 2 1]^T [1 2 1] / 16``, then the outermost
    sample cropped on every side: ``(Q, Q, ...)`` -> ``(Q - 2, Q - 2, ...)``. Separable, each direction summed
    as ``(a + b) + (b + c)``, then one exact division by 16 (as in ``glsl/passes/gi_average.glsl``).

    Examples
    --------
    >>> g = np.zeros((5, 5)); g[2, 2] = 16.0
    >>> average(g)
    array([[1., 2., 1.],
           [2., 4., 2.],
           [1., 2., 1.]])
    """
    g = _image(Gp)
    h = (g[:, :-2] + g[:, 1:-1]) + (g[:, 1:-1] + g[:, 2:])
    return ((h[:-2] + h[1:-1]) + (h[1:-1] + h[2:])) / 16.0


def limit(Gp) -> np.ndarray:
    """The limit positions ``E[g]`` [Losasso2003, Table 1]: mask ``[1 4 1]^T [1 4 1] / 36`` on the interior of
    a padded image, ``(Q, Q, ...)`` -> ``(Q - 2, Q - 2, ...)``.

    The integer-weight sum is divided by 36 once, so data whose sums are exact (small integers, dyadic
    fractions) give correctly rounded limit points: the same bits from every level of subdivision.

    Examples
    --------
    >>> g = np.zeros((3, 3)); g[1, 1] = 36.0
    >>> limit(g)
    array([[16.]])
    """
    g = _image(Gp)
    h = (g[:, :-2] + g[:, 2:]) + 4.0 * g[:, 1:-1]
    return ((h[:-2] + h[2:]) + 4.0 * h[1:-1]) / 36.0


def tangents(Gp) -> tuple[np.ndarray, np.ndarray]:
    """``(T_s, T_t)``: the derivatives of the B-spline at the interior samples of a padded image, ``T_s``
    along columns (``s``, increasing column index), ``T_t`` along rows (``t``, increasing row index), in
    sample units of this level: the mask ``(1/12) [[-1, 0, 1], [-4, 0, 4], [-1, 0, 1]]`` and its transpose
    (half of Table 1's ``T_s``).

    Examples
    --------
    >>> r, c = np.mgrid[0:5, 0:5].astype(float)
    >>> ts, tt = tangents(3.0 * c + 2.0 * r)  # a linear function: its own slopes
    >>> bool((ts == 3.0).all()), bool((tt == 2.0).all())
    (True, True)
    """
    g = _image(Gp)
    d = g[:, 2:] - g[:, :-2]
    ts = ((d[:-2] + d[2:]) + 4.0 * d[1:-1]) / 12.0
    d = g[2:] - g[:-2]
    tt = ((d[:, :-2] + d[:, 2:]) + 4.0 * d[:, 1:-1]) / 12.0
    return ts, tt


def second_derivatives(Gp) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(P_ss, P_st, P_tt)`` at the interior samples of a padded image, in sample units of this level:
    ``P_ss`` = ``[1, -2, 1]`` along columns times ``[1, 4, 1] / 6`` along rows, ``P_tt`` its transpose and
    ``P_st = (1/4) [[1, 0, -1], [0, 0, 0], [-1, 0, 1]]`` (rows ``r - 1, r, r + 1``, columns ``c - 1, c, c + 1``).

    Examples
    --------
    >>> r, c = np.mgrid[0:5, 0:5].astype(float)
    >>> pss, pst, ptt = second_derivatives(c ** 2 + 3.0 * r * c)
    >>> bool((pss == 2.0).all()), bool((pst == 3.0).all()), bool((ptt == 0.0).all())
    (True, True, True)
    """
    g = _image(Gp)
    e = (g[:, :-2] + g[:, 2:]) - 2.0 * g[:, 1:-1]
    pss = ((e[:-2] + e[2:]) + 4.0 * e[1:-1]) / 6.0
    e = (g[:-2] + g[2:]) - 2.0 * g[1:-1]
    ptt = ((e[:, :-2] + e[:, 2:]) + 4.0 * e[:, 1:-1]) / 6.0
    d = g[:, 2:] - g[:, :-2]
    pst = (d[2:] - d[:-2]) / 4.0
    return pss, pst, ptt


def _cross(a, b) -> np.ndarray:
    """``a x b`` over the last axis (np.cross, without its copies of large inputs)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def _unit(v) -> np.ndarray:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, norm, out=np.zeros_like(v), where=norm > 0.0)


def _xyz(Gp, what: str) -> np.ndarray:
    g = _image(Gp)
    if g.ndim != 3 or g.shape[2] < 3:
        raise ValueError(f"{what} need xyz in channels 0-2 of a (Q, Q, C) image, got shape {g.shape}.")
    _check_n(g.shape[0] - 2)
    return g[..., :3]


def cut_normals(Gp) -> np.ndarray:
    """``(4, 3)``: the unit normals ``unit(P_ss x P_st + P_st x P_tt)`` at the four cut vertices of a padded
    geometry image, in the order of :func:`splinevis.geometry_image.image.cut_vertices` (see the module
    docstring). The same surface point at every level of subdivision, so the same normal (in exact
    arithmetic the level-``k`` value is the level-0 one: its second derivatives are ``4^-k`` times theirs).

    Examples
    --------
    >>> from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere, pad
    >>> G = pad(apply_cut_constraint(octahedral_to_sphere(image_uv(9))))
    >>> (cut_normals(G).round(12) + 0.0).tolist()  # -Z, +Z, +Y, -Y: outward
    [[0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0]]
    """
    g = _xyz(Gp, "cut normals")
    out = np.empty((4, 3))
    for i, (r, c) in enumerate(cut_vertices(g.shape[0] - 2)):
        pss, pst, ptt = second_derivatives(g[r:r + 3, c:c + 3])
        out[i] = _cross(pss[0, 0], pst[0, 0]) + _cross(pst[0, 0], ptt[0, 0])
    return _unit(out)


def normals(Gp, at_cut=None) -> np.ndarray:
    """Unit normals ``unit(T_s x T_t)`` at the interior samples of a padded geometry image (channels 0-2 are
    xyz), ``(Q, Q, C)`` -> ``(Q - 2, Q - 2, 3)``; at the four cut vertices ``at_cut`` (``(4, 3)``, in
    :func:`splinevis.geometry_image.image.cut_vertices` order), by default this level's
    :func:`cut_normals`. A zero vector gives a zero normal.

    Examples
    --------
    The unit sphere's octahedral image: the normals point outward (here level 0, a coarse 9 x 9 image):

    >>> from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere, pad
    >>> G = pad(apply_cut_constraint(octahedral_to_sphere(image_uv(9))))
    >>> nrm, p = normals(G), limit(G)
    >>> bool(((nrm * p).sum(axis=-1) > 0.5).all()), bool(np.allclose(np.linalg.norm(nrm, axis=-1), 1.0))
    (True, True)
    """
    g = _xyz(Gp, "normals")
    ts, tt = tangents(g)
    v = _unit(_cross(ts, tt))
    cv = cut_vertices(g.shape[0] - 2)
    at_cut = cut_normals(g) if at_cut is None else np.asarray(at_cut, dtype=np.float64)
    if at_cut.shape != (4, 3):
        raise ValueError(f"at_cut must be the (4, 3) normals at the cut vertices, got shape {at_cut.shape}.")
    v[cv[:, 0], cv[:, 1]] = at_cut
    return v


def curvature(Gp) -> tuple[np.ndarray, np.ndarray]:
    """Mean ``H`` and Gaussian ``K`` curvature at the interior samples of a padded geometry image,
    ``(Q, Q, C)`` -> two ``(Q - 2, Q - 2)`` arrays.

    With ``T_s, T_t`` (:func:`tangents`), ``P_ss, P_st, P_tt`` (:func:`second_derivatives`),
    ``v = T_s x T_t``, ``D = v . v`` (``= EG - F^2``, without its cancellation) and ``n = v / sqrt(D)``:
    ``E, F, G = T_s . T_s, T_s . T_t, T_t . T_t``, ``L, M, N = P_ss . n, P_st . n, P_tt . n``,
    ``H = (E N - 2 F M + G L) / (2 D)``, ``K = (L N - M^2) / D`` [DoCarmo1976, sec. 3-3]. Invariant under
    the parametrization, so the same numbers at every level. Sign: that of the NURBS programs (module
    docstring): ``H < 0`` where the surface bends away from its normal, ``H = -1/r`` on a sphere with outward
    normals.

    At the four cut vertices ``T_s = T_t = 0``: the first fundamental form is singular and the surface's
    curvature there is unbounded in general [Losasso2003, appendix]. What is returned there is NOT the
    surface's curvature but a finite stand-in (so colour maps have no holes): the mean of the values at the
    cut vertex's four neighbours in the closed mesh
    (:func:`splinevis.geometry_image.image.cut_neighbours`, the samples of the centroid constraint), at this
    level, summed as ``((a + b) + (c + d)) / 4``. Elsewhere ``D = 0`` (a degenerate image) gives NaN.

    Examples
    --------
    The unit sphere's octahedral image: bicubic, so close to (not exactly) ``H = -1``, ``K = 1``:

    >>> from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere, pad
    >>> g = pad(apply_cut_constraint(octahedral_to_sphere(image_uv(33))))
    >>> H, K = curvature(average(split(g)))
    >>> H.shape, bool((H < 0).all() and (K > 0).all()), round(float(H[32, 32]), 2), round(float(K[32, 32]), 2)
    ((65, 65), True, -1.05, 1.1)
    """
    g = _xyz(Gp, "curvatures")
    ts, tt = tangents(g)
    pss, pst, ptt = second_derivatives(g)
    v = _cross(ts, tt)
    D = (v * v).sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        n = v / np.sqrt(D)[..., None]
        E, F, G = (ts * ts).sum(axis=-1), (ts * tt).sum(axis=-1), (tt * tt).sum(axis=-1)
        L, M, N = (pss * n).sum(axis=-1), (pst * n).sum(axis=-1), (ptt * n).sum(axis=-1)
        H = (E * N - 2.0 * F * M + G * L) / (2.0 * D)
        K = (L * N - M * M) / D
    m = g.shape[0] - 2
    for (r, c), nb in zip(cut_vertices(m), cut_neighbours(m)):
        for a in (H, K):
            v4 = a[nb[:, 0], nb[:, 1]]
            a[r, c] = ((v4[0] + v4[1]) + (v4[2] + v4[3])) / 4.0
    return H, K


class Subdivision(NamedTuple):
    """What :func:`subdivide` returns: limit positions ``p`` and unit normals ``n`` of the interior samples
    (``(n, n, 3)`` with ``n = 2^k N + 1``) and the padded control image ``g`` (``(n + 2, n + 2, C)``).

    Examples
    --------
    >>> s = Subdivision(np.zeros((3, 3, 3)), np.zeros((3, 3, 3)), np.zeros((5, 5, 3)))
    >>> s.g.shape
    (5, 5, 3)
    """

    p: np.ndarray
    n: np.ndarray
    g: np.ndarray


def subdivide(G, levels: int) -> Subdivision:
    """``levels`` steps ``g^{k+1} = A[L[g^k]]`` of the geometry image ``G`` (``(n, n, C)``, unpadded; padded
    once here), then ``p^k = E[g^k]`` and ``n^k`` (:func:`normals`, with the cut vertices' normals from the
    level-0 image: :func:`cut_normals`) [Losasso2003, sec. 5].

    Examples
    --------
    >>> from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere
    >>> G = apply_cut_constraint(octahedral_to_sphere(image_uv(5)))
    >>> p, n, g = subdivide(G, 2)
    >>> p.shape, n.shape, g.shape
    ((17, 17, 3), (17, 17, 3), (19, 19, 3))
    """
    levels = int(levels)
    if levels < 0:
        raise ValueError(f"levels must be >= 0, got {levels}.")
    g = pad(np.asarray(G, dtype=np.float64), 1)
    at_cut = cut_normals(g)
    for _ in range(levels):
        g = average(split(g))
    return Subdivision(limit(g), normals(g, at_cut), g)


def subsample(p, j: int) -> np.ndarray:
    """Every ``2^j``-th sample of an ``(n, n, ...)`` image: "negative" subdivision [Losasso2003, sec. 5]
    (valid when ``N = n - 1`` is divisible by ``2^(j+1)``, so that the result is again an odd image).

    Examples
    --------
    >>> subsample(np.arange(25.0).reshape(5, 5), 1)
    array([[ 0.,  2.,  4.],
           [10., 12., 14.],
           [20., 22., 24.]])
    """
    p = np.asarray(p)
    N = _check_n(p.shape[0])
    step = 1 << int(j)
    if j < 0 or N % step or (N // step) % 2:
        raise ValueError(f"cannot subsample a {N + 1}-sample image by 2^{j}: N = {N} must be divisible by "
                         f"2^{int(j) + 1}.")
    return p[::step, ::step]


def linear_subdivide(p) -> np.ndarray:
    """``p`` (``(n, n, ...)``) linearly subdivided on the triangulation whose diagonals join ``(r, c)`` and
    ``(r + 1, c + 1)``: ``(2n - 1, 2n - 1, ...)``, edge midpoints on the new samples (an odd-odd sample is the
    midpoint of its diagonal), the connectivity of the next level with the shape of this one.

    Examples
    --------
    >>> linear_subdivide(np.array([[0.0, 2.0], [4.0, 8.0]]))
    array([[0., 1., 2.],
           [2., 4., 5.],
           [4., 6., 8.]])
    """
    p = np.asarray(p, dtype=np.float64)
    n = p.shape[0]
    out = np.empty((2 * n - 1, 2 * n - 1) + p.shape[2:])
    out[0::2, 0::2] = p
    out[1::2, 0::2] = 0.5 * p[:-1] + 0.5 * p[1:]
    out[0::2, 1::2] = 0.5 * p[:, :-1] + 0.5 * p[:, 1:]
    out[1::2, 1::2] = 0.5 * p[:-1, :-1] + 0.5 * p[1:, 1:]
    return out


def geomorph(p_k, p_k1, alpha: float, *, unit: bool = False) -> np.ndarray:
    """The continuous level ``k + alpha`` [Losasso2003, sec. 5]: ``(1 - alpha) L_lin[p^k] + alpha p^{k+1}``
    with ``L_lin`` = :func:`linear_subdivide`; ``alpha = 0`` gives the linearly subdivided ``p^k`` and
    ``alpha = 1`` gives ``p^{k+1}``, both exactly. ``unit=True`` normalizes the result (for normals).

    Examples
    --------
    >>> pk, pk1 = np.zeros((3, 3, 3)), np.ones((5, 5, 3))
    >>> float(geomorph(pk, pk1, 0.25)[2, 3, 0])
    0.25
    >>> geomorph(pk, pk1, 1.0, unit=True)[0, 0].round(4)
    array([0.5774, 0.5774, 0.5774])
    """
    lin = linear_subdivide(p_k)
    fine = np.asarray(p_k1, dtype=np.float64)
    if fine.shape != lin.shape:
        raise ValueError(f"p_k1 must be the next level of p_k, shape {lin.shape}; got {fine.shape}.")
    out = (1.0 - alpha) * lin + alpha * fine
    return _unit(out) if unit else out


def displace(p, n, d) -> np.ndarray:
    """``p + d n``: limit positions ``p`` moved along unit normals ``n`` (both ``(n, n, 3)``) by a scalar
    displacement map ``d`` (``(n, n)``) [Losasso2003, sec. 5].

    Examples
    --------
    >>> displace(np.zeros((3, 3, 3)), np.tile([0.0, 0.0, 1.0], (3, 3, 1)), np.full((3, 3), 0.5))[1, 1]
    array([0. , 0. , 0.5])
    """
    p, n = np.asarray(p, dtype=np.float64), np.asarray(n, dtype=np.float64)
    d = np.asarray(d, dtype=np.float64)
    if d.shape != p.shape[:2] or n.shape != p.shape:
        raise ValueError(f"displace needs p and n of one shape and d of shape p.shape[:2]; got {p.shape}, "
                         f"{n.shape}, {d.shape}.")
    return p + d[..., None] * n


def grid_faces(n: int) -> np.ndarray:
    """Triangles ``(2 (n - 1)^2, 3)`` of an ``n x n`` sample grid (vertex ``r n + c``), each quad split along
    its ``(r, c)``-``(r + 1, c + 1)`` diagonal and ordered counterclockwise in ``(s, t) = (c, r)``, so a
    triangle's normal has the direction of ``T_s x T_t``.

    Examples
    --------
    >>> grid_faces(2)
    array([[0, 1, 3],
           [0, 3, 2]])
    """
    n = int(n)
    if n < 2:
        raise ValueError(f"a grid needs at least 2 x 2 samples, got {n}.")
    r, c = np.mgrid[0:n - 1, 0:n - 1]
    v00 = (r * n + c).ravel()
    v01, v10, v11 = v00 + 1, v00 + n, v00 + n + 1
    faces = np.stack([np.stack([v00, v01, v11], axis=1), np.stack([v00, v11, v10], axis=1)], axis=1)
    return faces.reshape(-1, 3)

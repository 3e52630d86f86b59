"""Bicubic subdivision of a geometry image as fragment-shader passes [Losasso2003, sec. 5, Table 1].

The image is padded once on the CPU (:func:`splinevis.geometry_image.image.pad`, width 1) and uploaded as an
RGBA32F texture (xyz in rgb; a fourth channel, if any, is subdivided along; missing channels are 0). Then
:class:`splinevis.gl.passes.PassChain` runs, all on the GPU,

* ``levels`` times ``glsl/passes/gi_split.glsl`` (``L``) and ``glsl/passes/gi_average.glsl`` (``A`` with the
  one-sample crop): the padding stays the X-cut padding through the passes, as in the paper, so nothing is
  re-padded between levels;
* once ``glsl/passes/gi_limit.glsl``: the limit positions ``p^k = E[g^k]`` and the unit normals ``n^k``
  (``unit(T_s x T_t)``; at the four cut vertices the normals ``unit(P_ss x P_st + P_st x P_tt)`` computed
  once in float64 from the level-0 image, :func:`splinevis.geometry_image.subdivision.cut_normals`, and
  passed as the uniform ``sv_cut_normal[4]``: in float32 the formula's second differences of ``g^k`` would
  lose ``4^k`` of the precision).

:func:`curvature_gpu` (``glsl/passes/gi_curvature.glsl``) computes mean and Gaussian curvature per sample.

:func:`geomorph_gpu` (``glsl/passes/gi_geomorph.glsl``) blends two levels for continuous level of detail and
:func:`displace_gpu` (``glsl/passes/gi_displace.glsl``) applies a scalar displacement map. The float64 twin
of every pass is :mod:`splinevis.geometry_image.subdivision`; the GPU test compares them within derived
float32 bounds.

Why our own code: no library subdivides geometry images (the X-cut padding, the cut vertices); the passes
are the paper's masks on :mod:`splinevis.gl.passes`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..gl.passes import Pass, PassChain
from .image import _check_n, pad
from .subdivision import Subdivision, cut_normals

__all__ = ["subdivision_passes", "CurvedSubdivision", "subdivide_gpu", "curvature_gpu", "geomorph_gpu", "displace_gpu"]

SPLIT = "passes/gi_split.glsl"
AVERAGE = "passes/gi_average.glsl"
LIMIT = "passes/gi_limit.glsl"
GEOMORPH = "passes/gi_geomorph.glsl"
DISPLACE = "passes/gi_displace.glsl"
CURVATURE = "passes/gi_curvature.glsl"


def subdivision_passes(n: int, levels: int, at_cut, *, curvature: bool = False) -> list:
    """The passes that subdivide the padded texture ``"g"`` of an ``n x n`` image ``levels`` times and write
    the limit positions ``"p"`` and normals ``"n"``: ``L, A`` per level, then the limit pass, whose normals
    at the four cut vertices are ``at_cut`` (``(4, 3)``, :func:`splinevis.geometry_image.subdivision.cut_normals`
    of the level-0 padded image); with ``curvature`` also the curvature pass, writing ``"k"`` = ``(H, K, 0, 0)``.
    The texture ``"g"`` ends as the padded control image of the last level.

    Examples
    --------
    >>> at_cut = np.eye(3)[[2, 2, 1, 1]]
    >>> [(p.label, p.shape) for p in subdivision_passes(5, 1, at_cut)]  # doctest: +NORMALIZE_WHITESPACE
    [('passes/gi_split.glsl', (13, 13)), ('passes/gi_average.glsl', (11, 11)),
     ('passes/gi_limit.glsl', (9, 9))]
    """
    _check_n(n)
    at_cut = np.asarray(at_cut, dtype=np.float64)
    if at_cut.shape != (4, 3) or not np.isfinite(at_cut).all():
        raise ValueError(f"at_cut must be the (4, 3) finite normals at the cut vertices, got shape {at_cut.shape}.")
    levels = int(levels)
    if levels < 0:
        raise ValueError(f"levels must be >= 0, got {levels}.")
    P = n + 2  # padded size
    passes = []
    for _ in range(levels):
        passes.append(Pass(SPLIT, {"sv_src": "g"}, "l", shape=(2 * P - 1, 2 * P - 1)))
        passes.append(Pass(AVERAGE, {"sv_src": "l"}, "g", shape=(2 * P - 3, 2 * P - 3)))
        P = 2 * P - 3
    normals = [tuple(float(x) for x in v) for v in at_cut]
    passes.append(Pass(LIMIT, {"sv_src": "g"}, ("p", "n"), shape=(P - 2, P - 2), uniforms={"sv_cut_normal": normals}))
    if curvature:
        passes.append(Pass(CURVATURE, {"sv_src": "g"}, "k", shape=(P - 2, P - 2)))
    return passes


class CurvedSubdivision(NamedTuple):
    """What :func:`subdivide_gpu` returns with ``curvature=True``: :class:`.subdivision.Subdivision`'s ``p``,
    ``n``, ``g`` and ``curvature``, ``(m, m, 2)`` float32 ``(H, K)`` (:func:`curvature_gpu`), or the
    ``(H, K, 0, 0)`` texture.

    Examples
    --------
    >>> CurvedSubdivision(*([np.zeros((3, 3, 3))] * 3), np.zeros((3, 3, 2))).curvature.shape
    (3, 3, 2)
    """

    p: np.ndarray
    n: np.ndarray
    g: np.ndarray
    curvature: np.ndarray


def subdivide_gpu(G, levels: int, *, readback: bool = True, curvature: bool = False):
    """:func:`splinevis.geometry_image.subdivision.subdivide` on the GPU: ``levels`` subdivision steps of the
    geometry image ``G`` (``(n, n, C)``, C = 3 or 4, unpadded; padded here once), then limit positions and
    normals (at the cut vertices the float64 :func:`splinevis.geometry_image.subdivision.cut_normals` of the
    level-0 image, rounded to float32).

    Parameters
    ----------
    G : (n, n, C) array_like
    levels : int
    readback : bool
        True: float32 arrays ``p`` ``(m, m, 3)``, ``n`` ``(m, m, 3)`` and the padded control image ``g``
        ``(m + 2, m + 2, C)``, ``m = 2^levels (n - 1) + 1``. False: the three RGBA32F moderngl textures,
        which belong to the caller (use and release them inside :func:`splinevis.gl.context.current`).
    curvature : bool
        Also run ``glsl/passes/gi_curvature.glsl`` on the last level (:func:`curvature_gpu`).

    Returns
    -------
    Subdivision, or CurvedSubdivision with ``curvature``

    Examples
    --------
    >>> from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.subdivision import subdivide
    >>> G = apply_cut_constraint(octahedral_to_sphere(image_uv(9)))
    >>> p, n, g = subdivide_gpu(G, 2)
    >>> p.shape, n.shape, g.shape, p.dtype
    ((33, 33, 3), (33, 33, 3), (35, 35, 3), dtype('float32'))
    >>> bool(np.abs(p - subdivide(G, 2).p).max() < 1e-6)
    True
    >>> subdivide_gpu(G, 2, curvature=True).curvature.shape
    (33, 33, 2)
    """
    G = np.asarray(G, dtype=np.float64)
    if G.ndim != 3 or G.shape[2] not in (3, 4):
        raise ValueError(f"subdivide_gpu needs an (n, n, 3) or (n, n, 4) geometry image, got shape {G.shape}.")
    channels = G.shape[2]
    Gp = pad(G, 1)
    chain = PassChain(subdivision_passes(G.shape[0], levels, cut_normals(Gp), curvature=curvature))
    out = chain.run({"g": Gp}, result=("p", "n", "g", "k") if curvature else ("p", "n", "g"), readback=readback)
    kind = CurvedSubdivision if curvature else Subdivision
    if not readback:
        return kind(*out)
    p, n, g = out[:3]
    return kind(p[..., :3], n[..., :3], g[..., :channels], *(k[..., :2] for k in out[3:]))


def curvature_gpu(Gp, *, readback: bool = True):
    """:func:`splinevis.geometry_image.subdivision.curvature` on the GPU (``glsl/passes/gi_curvature.glsl``):
    mean ``H`` and Gaussian ``K`` at the interior samples of a padded control image, with the cut vertices'
    stand-in values (the mean of their four closed-mesh neighbours; not the surface's curvature there).

    Parameters
    ----------
    Gp : (Q, Q, C) array, or an RGBA32F moderngl texture (e.g. ``subdivide_gpu(G, k, readback=False).g``)
        A padded control image, xyz in channels 0-2.
    readback : bool
        True: ``(H, K)``, two float32 ``(Q - 2, Q - 2)`` arrays; False: the RGBA32F texture holding
        ``(H, K, 0, 0)`` (the caller's).

    Examples
    --------
    >>> from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.subdivision import curvature, subdivide
    >>> G = apply_cut_constraint(octahedral_to_sphere(image_uv(17)))
    >>> H, K = curvature_gpu(subdivide_gpu(G, 2).g)
    >>> H.shape, H.dtype, bool((H < 0).all() and (K > 0).all())  # outward normals: H < 0 on a sphere
    ((65, 65), dtype('float32'), True)
    >>> bool(np.abs(H - curvature(subdivide(G, 2).g)[0]).max() < 1e-3)
    True
    """
    g = _check_grid(Gp, "Gp")
    if isinstance(g, np.ndarray):
        if g.ndim != 3 or not 3 <= g.shape[2] <= 4:
            raise ValueError(f"curvature_gpu needs a padded (Q, Q, 3) or (Q, Q, 4) image, got shape {g.shape}.")
        _check_n(g.shape[0] - 2)
        g = g.astype(np.float32)
        Q = g.shape[0]
    else:
        Q = g.size[0]
        _check_n(Q - 2)
    step = Pass(CURVATURE, {"sv_src": "g"}, "k", shape=(Q - 2, Q - 2))
    out = PassChain([step]).run({"g": g}, readback=readback)
    return (out[..., 0], out[..., 1]) if readback else out


def _check_grid(a, name: str):
    if hasattr(a, "size") and hasattr(a, "read_into") and not isinstance(a, np.ndarray):
        return a  # a texture: used as it is
    a = np.asarray(a)
    if a.ndim not in (2, 3) or a.shape[0] != a.shape[1]:
        raise ValueError(f"{name} must be a square (n, n) or (n, n, C) image, got shape {a.shape}.")
    return a


def geomorph_gpu(p_k, p_k1, alpha: float, *, unit: bool = False, readback: bool = True):
    """:func:`splinevis.geometry_image.subdivision.geomorph` on the GPU: ``(1 - alpha) L_lin[p^k] + alpha
    p^{k+1}``, normalized when ``unit`` (normals). ``p_k`` may be ``subsample(p_k1, 1)``, the paper's way to
    save a texture.

    Parameters
    ----------
    p_k, p_k1 : (n, n, 3) and (2n - 1, 2n - 1, 3) arrays, or RGBA32F moderngl textures of those sizes
    alpha : float
    unit : bool
    readback : bool
        True: a float32 ``(2n - 1, 2n - 1, 3)`` array; False: the moderngl texture (the caller's).

    Examples
    --------
    >>> pk, pk1 = np.zeros((3, 3, 3)), np.ones((5, 5, 3))
    >>> out = geomorph_gpu(pk, pk1, 0.25)
    >>> out.shape, float(out[2, 3, 0])
    ((5, 5, 3), 0.25)
    """
    coarse, fine = _check_grid(p_k, "p_k"), _check_grid(p_k1, "p_k1")
    if isinstance(coarse, np.ndarray) and isinstance(fine, np.ndarray):
        want = (2 * coarse.shape[0] - 1,) * 2
        if fine.shape[:2] != want:
            raise ValueError(f"p_k1 must be the next level of p_k, {want} samples; got shape {fine.shape}.")
    step = Pass(GEOMORPH, {"sv_fine": "fine", "sv_coarse": "coarse"}, "out",
                uniforms={"sv_alpha": float(alpha), "sv_unit": int(bool(unit))})
    out = PassChain([step]).run({"fine": fine, "coarse": coarse}, readback=readback)
    return out[..., :3] if readback else out


def displace_gpu(p, n, d, *, readback: bool = True):
    """:func:`splinevis.geometry_image.subdivision.displace` on the GPU: ``p + d n``.

    Parameters
    ----------
    p, n : (m, m, 3) arrays or RGBA32F moderngl textures
        Limit positions and unit normals (e.g. from :func:`subdivide_gpu` with ``readback=False``).
    d : (m, m) array or a moderngl texture (channel 0)
        The scalar displacement map.
    readback : bool
        True: a float32 ``(m, m, 3)`` array; False: the moderngl texture (the caller's).

    Examples
    --------
    >>> up = np.tile([0.0, 0.0, 1.0], (3, 3, 1))
    >>> displace_gpu(np.zeros((3, 3, 3)), up, np.full((3, 3), 0.5))[1, 1]
    array([0. , 0. , 0.5], dtype=float32)
    """
    p, n, d = _check_grid(p, "p"), _check_grid(n, "n"), _check_grid(d, "d")
    if all(isinstance(a, np.ndarray) for a in (p, n, d)) and not (p.shape[:2] == n.shape[:2] == d.shape[:2]):
        raise ValueError(f"p, n and d must have one size; got shapes {p.shape}, {n.shape}, {d.shape}.")
    step = Pass(DISPLACE, {"sv_p": "p", "sv_n": "n", "sv_d": "d"}, "out")
    out = PassChain([step]).run({"p": p, "n": n, "d": d}, readback=readback)
    return out[..., :3] if readback else out

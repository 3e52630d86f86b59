"""Bicubic subdivision of a geometry image as fragment-shader passes [Losasso2003, sec. 5, Table 1].

The image is padded once on the CPU (:func:`splinevis.geometry_image.image.pad`, width 1) and uploaded as an
RGBA32F texture (xyz in rgb; a fourth channel, if any, is subdivided along; missing channels are 0). Then
:class:`splinevis.gl.passes.PassChain` runs, all on the GPU,

* ``levels`` times ``glsl/passes/gi_split.glsl`` (``L``) and ``glsl/passes/gi_average.glsl`` (``A`` with the
  one-sample crop): the padding stays the X-cut padding through the passes, as in the paper, so nothing is
  re-padded between levels;
* once ``glsl/passes/gi_limit.glsl``: the limit positions ``p^k = E[g^k]`` and the unit normals ``n^k``
  (``unit(T_s x T_t)``, and ``unit(P_ss x P_st + P_st x P_tt)`` at the four cut vertices).

:func:`geomorph_gpu` (``glsl/passes/gi_geomorph.glsl``) blends two levels for continuous level of detail and
:func:`displace_gpu` (``glsl/passes/gi_displace.glsl``) applies a scalar displacement map. The float64 twin
of every pass is :mod:`splinevis.geometry_image.subdivision`; the GPU test compares them within derived
float32 bounds.

Why our own code: no library subdivides geometry images (the X-cut padding, the cut vertices); the passes
are the paper's masks on :mod:`splinevis.gl.passes`.
"""

from __future__ import annotations

import numpy as np

from ..gl.passes import Pass, PassChain
from .image import _check_n, pad
from .subdivision import Subdivision

__all__ = ["subdivision_passes", "subdivide_gpu", "geomorph_gpu", "displace_gpu"]

SPLIT = "passes/gi_split.glsl"
AVERAGE = "passes/gi_average.glsl"
LIMIT = "passes/gi_limit.glsl"
GEOMORPH = "passes/gi_geomorph.glsl"
DISPLACE = "passes/gi_displace.glsl"


def subdivision_passes(n: int, levels: int) -> list:
    """The passes that subdivide the padded texture ``"g"`` of an ``n x n`` image ``levels`` times and write
    the limit positions ``"p"`` and normals ``"n"``: ``L, A`` per level, then the limit pass. The texture
    ``"g"`` ends as the padded control image of the last level.

    Examples
    --------
    >>> [(p.label, p.shape) for p in subdivision_passes(5, 1)]  # doctest: +NORMALIZE_WHITESPACE
    [('passes/gi_split.glsl', (13, 13)), ('passes/gi_average.glsl', (11, 11)),
     ('passes/gi_limit.glsl', (9, 9))]
    """
    _check_n(n)
    levels = int(levels)
    if levels < 0:
        raise ValueError(f"levels must be >= 0, got {levels}.")
    P = n + 2  # padded size
    passes = []
    for _ in range(levels):
        passes.append(Pass(SPLIT, {"sv_src": "g"}, "l", shape=(2 * P - 1, 2 * P - 1)))
        passes.append(Pass(AVERAGE, {"sv_src": "l"}, "g", shape=(2 * P - 3, 2 * P - 3)))
        P = 2 * P - 3
    passes.append(Pass(LIMIT, {"sv_src": "g"}, ("p", "n"), shape=(P - 2, P - 2)))
    return passes


def subdivide_gpu(G, levels: int, *, readback: bool = True) -> Subdivision:
    """:func:`splinevis.geometry_image.subdivision.subdivide` on the GPU: ``levels`` subdivision steps of the
    geometry image ``G`` (``(n, n, C)``, C = 3 or 4, unpadded; padded here once), then limit positions and
    normals.

    Parameters
    ----------
    G : (n, n, C) array_like
    levels : int
    readback : bool
        True: float32 arrays ``p`` ``(m, m, 3)``, ``n`` ``(m, m, 3)`` and the padded control image ``g``
        ``(m + 2, m + 2, C)``, ``m = 2^levels (n - 1) + 1``. False: the three RGBA32F moderngl textures,
        which belong to the caller (use and release them inside :func:`splinevis.gl.context.current`).

    Returns
    -------
    Subdivision

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
    """
    G = np.asarray(G, dtype=np.float64)
    if G.ndim != 3 or G.shape[2] not in (3, 4):
        raise ValueError(f"subdivide_gpu needs an (n, n, 3) or (n, n, 4) geometry image, got shape {G.shape}.")
    channels = G.shape[2]
    chain = PassChain(subdivision_passes(G.shape[0], levels))
    out = chain.run({"g": pad(G, 1)}, result=("p", "n", "g"), readback=readback)
    if not readback:
        return Subdivision(*out)
    p, n, g = out
    return Subdivision(p[..., :3], n[..., :3], g[..., :channels])


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

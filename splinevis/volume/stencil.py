"""The 27-point data stencil of a cube and the padded volume it reads, shared by both volume schemes.

Every data point ``volume[k, j, i]`` is the centre of one cube; a scheme sets each BB coefficient of the
cube as a fixed combination of the 27 values at the offsets :data:`STENCIL` around it, reading one layer
of linear extrapolation (``f[-1] = 2 f[0] - f[1]``) beyond the boundary.
"""

from __future__ import annotations

import functools

import numpy as np

from .._validation import as_float64_array

__all__ = ["STENCIL", "PADDINGS", "pad_volume"]

#: Boundary paddings: the name -> the degree of the polynomial extrapolated through the outermost samples.
#: ``"linear"`` (the paper's, ``f[-1] = 2 f[0] - f[1]``) keeps linear data linear; the gradients of the
#: splines then converge at order 1 only in the outer half-cube, where they read the padding (its error
#: is O(h^2), a gradient error O(h) after the division by h). ``"quadratic"`` (``3 f[0] - 3 f[1] + f[2]``,
#: error O(h^3)) keeps order 2 for gradients up to the boundary, ``"cubic"`` (``4 f[0] - 6 f[1] + 4 f[2] -
#: f[3]``, error O(h^4)) also order 3 for the values of the prefiltered splines
#: (:mod:`splinevis.volume.prefilter`). Noise in the samples grows by the 2-norm of the extrapolation weights
#: in the padded layer: sqrt(5) = 2.2, sqrt(19) = 4.4 and sqrt(69) = 8.3.
PADDINGS = {"linear": (2.0, -1.0), "quadratic": (3.0, -3.0, 1.0), "cubic": (4.0, -6.0, 4.0, -1.0)}

#: Data offsets (x, y, z) of the 27-point stencil of a cube, z slowest, x fastest.
STENCIL = np.array([(x, y, z) for z in (-1, 0, 1) for y in (-1, 0, 1) for x in (-1, 0, 1)], dtype=np.int64)
_BIG = np.array([(x, y, z) for z in range(-2, 3) for y in range(-2, 3) for x in range(-2, 3)], dtype=np.int64)
_BIG_ID = {tuple(int(v) for v in o): n for n, o in enumerate(_BIG)}
_S27 = np.array([_BIG_ID[tuple(int(v) for v in o)] for o in STENCIL])


def _lift(M27, shift):
    """(..., 27) stencil weights of the cube at offset `shift` -> (..., 125) weights on offsets -2..2."""
    out = np.zeros(M27.shape[:-1] + (125,))
    for j, o in enumerate(STENCIL):
        out[..., _BIG_ID[tuple(int(v) for v in o + shift)]] += M27[..., j]
    return out


def _check_volume(volume, what="the 27-point stencil of the spline schemes"):
    """``volume`` as a finite 3-D float64 array with >= 2 samples per axis, else ValueError (``what`` names
    the reader of the neighbours in the message)."""
    vol = as_float64_array(volume, "volume", finite=False)
    if vol.ndim != 3:
        raise ValueError(f"volume must be a 3-D array of shape (nz, ny, nx) with volume[k, j, i] the value at "
                         f"(x, y, z) = (i, j, k); got {vol.ndim}-D shape {vol.shape}.")
    if min(vol.shape) < 2:
        ax = "zyx"[int(np.argmin(vol.shape))]
        raise ValueError(f"volume must have at least 2 samples along every axis ({what} reads one neighbour on each "
                         f"side, and the boundary layer is extrapolated linearly from two samples); got shape "
                         f"{vol.shape} with {min(vol.shape)} along {ax}. Resample or pad the data to >= 2 per axis.")
    bad = ~np.isfinite(vol)
    if bad.any():
        k, j, i = (int(v) for v in np.argwhere(bad)[0])
        raise ValueError(f"volume must be finite; found {int(bad.sum())} non-finite value(s), the first, "
                         f"{float(vol[k, j, i])!r}, at voxel [k, j, i] = [{k}, {j}, {i}] (x={i}, y={j}, z={k}). "
                         f"Replace them (e.g. by a background value) before building a spline.")
    return vol


def check_padding(padding, shape=None) -> tuple:
    """The extrapolation weights of ``padding`` (a key of :data:`PADDINGS`), else ValueError; with ``shape``
    also checks that every axis has as many samples as the weights read.

    >>> check_padding("quadratic")
    (3.0, -3.0, 1.0)
    """
    if padding not in PADDINGS:
        raise ValueError(f"padding must be one of {sorted(PADDINGS)}, got {padding!r}.")
    w = PADDINGS[padding]
    if shape is not None and min(shape) < len(w):
        raise ValueError(f"padding={padding!r} extrapolates from {len(w)} samples per axis; the volume has shape (nz, ny, "
                         f"nx) = {tuple(shape)}. Use padding='linear' (2 samples) or a larger volume.")
    return w


def _pad(vol, padding: str = "linear"):
    """Polynomial extrapolation by one layer (:data:`PADDINGS`), axis after axis (corners too), in one float64
    allocation. The linear case keeps its two-operation form (bit for bit the earlier padding)."""
    v = np.asarray(vol, dtype=np.float64)
    nz, ny, nx = v.shape
    P = np.zeros((nz + 2, ny + 2, nx + 2))  # borders are all overwritten; zeros keep garbage out of the arithmetic
    P[1:-1, 1:-1, 1:-1] = v
    w = PADDINGS["linear"] if padding == "linear" else check_padding(padding, v.shape)
    for ax in range(3):
        Q = np.moveaxis(P, ax, 0)  # a view
        if padding == "linear":
            np.subtract(2 * Q[1], Q[2], out=Q[0])
            np.subtract(2 * Q[-2], Q[-3], out=Q[-1])
            continue
        Q[0] = sum(c * Q[1 + m] for m, c in enumerate(w))
        Q[-1] = sum(c * Q[-2 - m] for m, c in enumerate(w))
    return P


def pad_volume(volume, padding: str = "linear") -> np.ndarray:
    """The volume with one layer of extrapolation on every side (``padding="linear"``: ``f[-1] = 2 f[0] -
    f[1]``; ``"quadratic"``, ``"cubic"``: :data:`PADDINGS`), axis by axis, so edges and corners too: shape
    ``(nz + 2, ny + 2, nx + 2)``; ``padded[k + 1, j + 1, i + 1] = volume[k, j, i]``. Polynomial data of the
    padding's degree stay polynomial. Every axis needs >= 2 samples (3 quadratic, 4 cubic).

    Examples
    --------
    >>> padded = pad_volume(np.arange(8.0).reshape(2, 2, 2))  # f = x + 2 y + 4 z
    >>> padded.shape, padded[1, 1]  # the row y = 0, z = 0, extended to x = -1 and x = 2
    ((4, 4, 4), array([-1.,  0.,  1.,  2.]))
    >>> float(padded[0, 0, 0])  # the corner (-1, -1, -1): -1 - 2 - 4
    -7.0
    >>> pad_volume(np.arange(4.0)[None, None, :].repeat(3, 0).repeat(3, 1) ** 2, "quadratic")[1, 1]  # x^2 at -1, 4
    array([ 1.,  0.,  1.,  4.,  9., 16.])
    """
    vol = _check_volume(volume)
    check_padding(padding, vol.shape)
    return _pad(vol, padding)


def _stencil_data(vol):
    """(nz, ny, nx, 27) data of every cube's 27-point stencil (padded volume)."""
    P = _pad(vol)
    nz, ny, nx = vol.shape
    return np.stack([P[1 + oz:1 + oz + nz, 1 + oy:1 + oy + ny, 1 + ox:1 + ox + nx] for ox, oy, oz in STENCIL], axis=-1)


def _apply_point_weights(vol, W, tmap):
    """BB coefficients ``(nz, ny, nx, 24, m)`` of every cube of ``vol`` (checked) from the domain-point
    weights ``W`` (number of domain points, 27) and the tetrahedron map ``tmap`` (24, m)."""
    return (_stencil_data(vol) @ W.T)[..., tmap]


@functools.lru_cache(maxsize=None)
def _stored_weights(scheme):
    """(number of domain points, 27) weights of ``scheme`` ("quadratic" or "cubic"), read from the exact
    fractions stored in :mod:`splinevis.volume._scheme_weights`: no linear algebra at run time. Read-only; bit
    for bit the result of the scheme's ``derive_weights`` (checked by tests/test_scheme_weights.py)."""
    from . import _scheme_weights as stored

    start = 0
    for name, (shape, den) in stored.TABLES.items():
        if name == scheme:
            num = np.array(stored.NUMERATORS.split(), dtype=np.int64)[start:start + shape[0] * shape[1]]
            W = num.reshape(shape).astype(np.float64) / den  # correctly rounded: float64(n / den)
            W.setflags(write=False)
            return W
        start += shape[0] * shape[1]
    raise ValueError(f"no stored weights for the volume scheme {scheme!r}.")

"""Volume splines tile by tile: the quadratic and cubic schemes of :mod:`splinevis.volume.schemes` and the
per-cube bounds of :class:`splinevis.volume.model.VolumeSpline` on a dask array.

Why our own code: dask does the chunking, but the schemes read the 27 samples around each cube and one layer
of linear extrapolation beyond the volume (``f[-1] = 2 f[0] - f[1]``, z then y then x), and a tile must see
exactly those. The border layers are built from the volume's first and last two slices with the same
arithmetic as :func:`splinevis.volume.stencil.pad_volume`; each tile of cubes then reads its samples plus a
halo of two padded samples after it along every axis (the window of 3 minus one sample per cube).

What the volume model keeps is the padded data (the GPU's data texture is that minus a reference value), the
per-cube coefficient bounds ``cube_ranges`` (float32, rounded outward) and their min-max octree; the
coefficients themselves are 240 (quadratic) or 480 (cubic) numbers per cube, 2 TB for 1024^3, and are made
where needed. :func:`volume_cube_ranges_dask` gives the bounds (bit for bit those of the model),
:func:`volume_coefficients_dask` the coefficients (``spline_coefficients``' values) for what fits.
"""

from __future__ import annotations

import numpy as np

from ..volume.model import _box3, _negative_mass
from ..volume.schemes import STENCIL, _check_scheme, _point_weights, _tet_weights
from ..volume.stencil import PADDINGS, check_padding
from .halo import _check_tile, _pad_axis_lazy, _sample_chunks, _window_map, _window_read, as_dask_array, tile_chunks

__all__ = ["padded_volume_dask", "volume_coefficients_dask", "volume_cube_ranges_dask", "volume_input_chunks"]

_HALO = 2  # a window of 3 samples per cube, one sample per cube


def _linear_pad(axis):
    def pad(b, lo, hi):
        b = np.moveaxis(np.asarray(b, dtype=np.float64), axis, 0)
        parts = ([np.subtract(2 * b[0], b[1])[None]] if lo else []) + [b] + \
                ([np.subtract(2 * b[-1], b[-2])[None]] if hi else [])
        return np.moveaxis(np.concatenate(parts, axis=0), 0, axis)
    return pad


def _poly_pad(axis, padding):
    """The one-layer extrapolation of :data:`splinevis.volume.stencil.PADDINGS` along ``axis``, with the
    arithmetic of :func:`splinevis.volume.stencil._pad` (same values, bit for bit)."""
    if padding == "linear":
        return _linear_pad(axis)
    w = PADDINGS[padding]

    def pad(b, lo, hi):
        b = np.moveaxis(np.asarray(b, dtype=np.float64), axis, 0)
        parts = ([sum(c * b[m] for m, c in enumerate(w))[None]] if lo else []) + [b] + \
                ([sum(c * b[-1 - m] for m, c in enumerate(w))[None]] if hi else [])
        return np.moveaxis(np.concatenate(parts, axis=0), 0, axis)
    return pad


def _pad_lazy(v, padding):
    for ax in range(3):
        v = _pad_axis_lazy(v, ax, 1, 1, len(PADDINGS[padding]), _poly_pad(ax, padding))
    return v


def _tiles3(chunks):
    t = (chunks,) * 3 if np.isscalar(chunks) else tuple(chunks)
    if len(t) != 3 or not all(isinstance(v, (int, np.integer)) and v > 0 for v in t):
        raise ValueError(f"chunks must be a positive number of cubes per tile or a triple (z, y, x) of them, "
                         f"got {chunks!r}.")
    for v, ax in zip(t, "zyx"):
        _check_tile(int(v), _HALO, 1, "the 27-point volume stencil (one sample on each side of a cube)", ax)
    return tuple(int(v) for v in t)


def padded_volume_dask(samples, *, chunks=64, scheme="quadratic", prefilter="none", padding="linear"):
    """The data a scheme reads, lazily: the volume (or, with ``prefilter="local"``, its local prefilter
    ``2 f - K f`` of :mod:`splinevis.volume.prefilter`, which reads one more layer around each tile) with its
    layer of extrapolation (``padding``) on every side; ``VolumeSpline(..., prefilter=, padding=).padded`` bit
    for bit. ``prefilter="interpolate"`` is a global solve and is refused.

    Parameters
    ----------
    samples : (nz, ny, nx) dask array, zarr array, zarr path or array_like; >= 2 samples per axis
    chunks : int or (int, int, int)
        Chunks of the input when it is not a dask array yet.
    scheme : {"quadratic", "cubic"}
        Whose centre stencil the local prefilter inverts (ignored without a prefilter).
    prefilter : {"none", "local"}
    padding : {"linear", "quadratic", "cubic"}

    Returns
    -------
    (nz + 2, ny + 2, nx + 2) float64 dask array

    Examples
    --------
    >>> from splinevis.volume.schemes import pad_volume
    >>> from splinevis.volume.model import VolumeSpline
    >>> v = np.random.default_rng(2).random((5, 6, 7))
    >>> bool((padded_volume_dask(v, chunks=3).compute() == pad_volume(v)).all())
    True
    >>> P = padded_volume_dask(v, chunks=3, scheme="cubic", prefilter="local", padding="quadratic").compute()
    >>> bool((P == VolumeSpline(v, "cubic", prefilter="local", padding="quadratic", order="zyx").padded).all())
    True
    """
    from ..volume.prefilter import centre_kernel, check_prefilter

    if check_prefilter(prefilter) == "interpolate":
        raise ValueError("prefilter='interpolate' solves one linear system over the whole volume (every spline "
                         "coefficient depends on every sample), so it is not built tile by tile. Use prefilter='local' "
                         "(quadratics reproduced, values of order 3; one more halo layer) or build the spline in memory "
                         "with VolumeSpline(..., prefilter='interpolate').")
    v = as_dask_array(samples, chunks=chunks)
    if v.ndim != 3:
        raise ValueError(f"samples must be a 3-D array of shape (nz, ny, nx); got {v.ndim}-D shape {v.shape}.")
    if min(v.shape) < 2:
        raise ValueError(f"samples must have at least 2 values along every axis (the border layer is "
                         f"extrapolated from two); got shape {v.shape}.")
    v = v.astype(np.float64)
    check_padding(padding, v.shape)
    if prefilter == "local":
        # d = 2 f - K pad(f), the operations of prefilter.prefilter_data / centre_values in their order
        P1 = _pad_lazy(v, padding)
        K = centre_kernel(_check_scheme(scheme))
        nz, ny, nx = v.shape
        cv = None
        for dz in range(3):
            for dy in range(3):
                for dx in range(3):
                    if K[dz, dy, dx]:
                        term = K[dz, dy, dx] * P1[dz:dz + nz, dy:dy + ny, dx:dx + nx]
                        cv = (0.0 + term) if cv is None else cv + term
        v = (2.0 * v - cv).rechunk(v.chunks)
    return _pad_lazy(v, padding)


def _cells3(v, chunks):
    return tuple(tile_chunks(n, t) for n, t in zip(v.shape, _tiles3(chunks)))


def volume_input_chunks(shape, chunks=64):
    """Chunks of the samples that make the padded tiles plain unions of sample chunks: ``(t - 1, t, ..., rest)``
    per axis (the padding adds one layer in front). With other chunks every tile straddles two sample chunks
    per axis, and the scheduler keeps a whole slab of sample chunks in memory while it sweeps the volume.

    Examples
    --------
    >>> volume_input_chunks((130, 64, 10), 64)
    ((63, 64, 3), (64,), (10,))
    """
    out = []
    for n, c in zip(shape, _tile_chunks_list(shape, chunks)):
        if len(c) == 1:
            out.append((int(n),))
            continue
        v = [c[0] - 1, *c[1:-1], c[-1] + 1]
        out.append(tuple(int(x) for x in v))
    return tuple(out)


def _tile_chunks_list(shape, chunks):
    return [tile_chunks(n, t) for n, t in zip(shape, _tiles3(chunks))]


def _tiled_padded(samples, chunks, **data_options):
    """``(padded, cells)``: the padded volume already cut into the tiles' sample chunks, and the tiles (data
    that is not a dask array yet is first cut by :func:`volume_input_chunks`)."""
    import dask.array as da

    t = _tiles3(chunks)
    v = as_dask_array(samples)
    if not isinstance(samples, da.Array) and v.ndim == 3:
        v = v.rechunk(volume_input_chunks(v.shape, t))
    P = padded_volume_dask(v, **data_options)
    cells = _cells3(v, chunks)
    return P.rechunk(tuple(_sample_chunks(c, 1, _HALO) for c in cells)), cells


def volume_coefficients_dask(samples, scheme="quadratic", *, chunks=32):
    """Lazy BB coefficients of every cube of a volume, one dask task per tile of cubes.

    Parameters
    ----------
    samples : (nz, ny, nx) dask array, zarr array, zarr path or array_like
        ``samples[k, j, i]`` at index point ``(i, j, k)``, finite.
    scheme : {"quadratic", "cubic"}
    chunks : int or (int, int, int)
        Cubes per tile (z, y, x), at least 2. A quadratic tile of 32^3 cubes holds 63 MB of coefficients.

    Returns
    -------
    (nz, ny, nx, 24, m) float64 dask array, m = 10 or 20
        Computed, ``spline_coefficients(samples, scheme)`` (up to the rounding of the matrix product, which
        depends on how many rows it is given: a few units in the last place).

    Examples
    --------
    >>> from splinevis.volume.schemes import spline_coefficients
    >>> v = np.random.default_rng(3).random((6, 7, 8))
    >>> c = volume_coefficients_dask(v, "quadratic", chunks=4)
    >>> c.shape, c.chunks[:3]
    ((6, 7, 8, 24, 10), ((4, 2), (4, 3), (4, 4)))
    >>> bool(np.allclose(c.compute(), spline_coefficients(v, "quadratic"), rtol=0, atol=1e-15))
    True
    """
    scheme = _check_scheme(scheme)
    P, cells = _tiled_padded(samples, chunks)
    return _coefficients(P, cells, scheme)


def _coefficients(P, cells, scheme, stored=None):
    W, tmap = _point_weights(scheme)
    WT = W.T

    def tile(block):
        if not np.isfinite(block).all():
            raise ValueError(f"samples must be finite; a tile or its halo holds {int((~np.isfinite(block)).sum())} "
                             f"non-finite value(s).")
        nz, ny, nx = (s - _HALO for s in block.shape)
        S = np.stack([block[1 + oz:1 + oz + nz, 1 + oy:1 + oy + ny, 1 + ox:1 + ox + nx] for ox, oy, oz in STENCIL],
                     axis=-1)
        return (S @ WT)[..., tmap]

    if stored is not None:
        return _window_read(stored, tile, cells, (1, 1, 1), (_HALO,) * 3, (24, tmap.shape[1]))
    return _window_map(P, tile, cells, (1, 1, 1), (_HALO,) * 3, (24, tmap.shape[1]))


def volume_cube_ranges_dask(samples, scheme="quadratic", *, chunks=64):
    """Lazy per-cube ``(lo, hi)`` float32 bounds of the BB coefficients, as ``VolumeSpline.cube_ranges``.

    Parameters
    ----------
    samples : (nz, ny, nx) dask array, zarr array, zarr path or array_like
    scheme : {"quadratic", "cubic"}
    chunks : int or (int, int, int)
        Cubes per tile.

    Returns
    -------
    (nz, ny, nx, 2) float32 dask array
        ``[..., 0]`` the lower, ``[..., 1]`` the upper bounds; computed, bit for bit those of the model.

    Examples
    --------
    >>> from splinevis.volume.model import VolumeSpline
    >>> v = np.random.default_rng(4).random((6, 7, 8))
    >>> r = volume_cube_ranges_dask(v, "cubic", chunks=3).compute()
    >>> lo, hi = VolumeSpline(v, "cubic", order="zyx").cube_ranges()
    >>> r.dtype, bool((r[..., 0] == lo).all() and (r[..., 1] == hi).all())
    (dtype('float32'), True)
    """
    scheme = _check_scheme(scheme)
    P, cells = _tiled_padded(samples, chunks)
    return _cube_ranges(P, cells, scheme)


def _cube_ranges(P, cells, scheme, stored=None):
    N = _negative_mass(_tet_weights(scheme))

    def tile(block):
        B = block.astype(np.float32)
        mn, mx = _box3(B, np.minimum), _box3(B, np.maximum)
        if N > 0:  # the model's widening by the scheme's negative weights (none for the schemes of today)
            spread = mx - mn
            mn = mn - np.float32(N) * spread * np.float32(1 + 1e-6)
            mx = mx + np.float32(N) * spread * np.float32(1 + 1e-6)
        lo = np.nextafter(mn, np.float32(-np.inf), out=mn)
        hi = np.nextafter(mx, np.float32(np.inf), out=mx)
        return np.stack([lo, hi], axis=-1)

    if stored is not None:
        return _window_read(stored, tile, cells, (1, 1, 1), (_HALO,) * 3, (2,), dtype=np.float32)
    return _window_map(P, tile, cells, (1, 1, 1), (_HALO,) * 3, (2,), dtype=np.float32)

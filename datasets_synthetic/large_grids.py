"""Grids larger than memory, as lazy dask arrays computed chunk by chunk from closed-form functions: a
fractal-like DEM (16k x 16k by default, 2 GB of float64) and a Marschner-Lobb volume (1024^3 by default,
8.6 GB). Nothing is materialized whole: each chunk evaluates the function at its own samples, so a chunk
is the same whatever the chunking (tested), and the stores of :mod:`splinevis.outofcore` can be built from
them in bounded memory.

>>> dem = large_dem(4096, chunks=1024)
>>> dem.shape, dem.chunks[0][:2], dem.dtype
((4096, 4096), (1024, 1024), dtype('float64'))
>>> vol = large_volume(256, chunks=64)
>>> vol.shape, vol.nbytes // 2**20  # MiB if it were computed at once
((256, 256, 256), 128)
"""

from __future__ import annotations

import numpy as np

__all__ = ["large_dem", "large_volume", "dem_value", "marschner_lobb_value"]


def _octaves(seed, octaves):
    """Directions, frequencies, phases and amplitudes of the DEM's sines (deterministic in ``seed``)."""
    rng = np.random.default_rng(seed)
    k = np.arange(octaves)
    freq = 1.5 * 2.0 ** k * (1.0 + 0.2 * rng.random(octaves))
    ang = rng.random(octaves) * 2 * np.pi
    return np.cos(ang) * freq, np.sin(ang) * freq, rng.random(octaves) * 2 * np.pi, 0.55 ** k


def dem_value(u, v, *, seed=0, octaves=12, amplitude=900.0):
    """Heights of the synthetic DEM at unit-square coordinates ``(u, v)`` (arrays broadcast): a sum of
    ``octaves`` sines of doubling frequency and decaying amplitude in random directions, plus a ridge.

    Examples
    --------
    >>> float(dem_value(0.25, 0.5)) == float(dem_value(np.array([0.25]), np.array([0.5]))[0])
    True
    >>> bool(abs(dem_value(np.linspace(0, 1, 101), 0.3)).max() < 2 * 900.0)
    True
    """
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    ax, ay, ph, amp = _octaves(seed, octaves)
    z = np.zeros(np.broadcast(u, v).shape)
    for a, b, p, w in zip(ax, ay, ph, amp):
        z += w * np.sin(2 * np.pi * (a * u + b * v) + p)
    z += 0.8 * np.exp(-((u - 0.5 - 0.15 * np.sin(3 * v)) / 0.08) ** 2)  # a winding ridge
    return amplitude * z / 2.0


def large_dem(n=16384, *, chunks=1024, seed=0, octaves=12, amplitude=900.0):
    """A lazy ``(n, n)`` float64 DEM: :func:`dem_value` at ``(i / (n - 1), j / (n - 1))`` for ``z[j, i]``.

    Examples
    --------
    >>> z = large_dem(64, chunks=16)
    >>> bool((z.compute() == large_dem(64, chunks=64).compute()).all())  # chunks do not change the values
    True
    """
    import dask.array as da

    n = int(n)

    def block(block_info=None):
        (r0, r1), (c0, c1) = block_info[None]["array-location"]
        v = (np.arange(r0, r1, dtype=np.float64) / (n - 1))[:, None]
        u = (np.arange(c0, c1, dtype=np.float64) / (n - 1))[None, :]
        return dem_value(u, v, seed=seed, octaves=octaves, amplitude=amplitude)

    proto = da.empty((n, n), chunks=chunks, dtype=np.float64)
    return da.map_blocks(block, chunks=proto.chunks, dtype=np.float64, meta=np.empty((0, 0)))


def marschner_lobb_value(x, y, z, *, fm=6.0, alpha=0.25):
    """The Marschner-Lobb test signal at points of ``[-1, 1]^3`` (level 0.5 is the classic isosurface).

    Examples
    --------
    >>> round(float(marschner_lobb_value(0.0, 0.0, 0.0)), 12)  # (1 + alpha (1 + cos(2 pi fm))) / (2 (1 + alpha))
    0.6
    """
    x, y, z = (np.asarray(a, dtype=np.float64) for a in (x, y, z))
    r = np.sqrt(x * x + y * y)
    rho = np.cos(2 * np.pi * fm * np.cos(np.pi * r / 2))
    return (1 - np.sin(np.pi * z / 2) + alpha * (1 + rho)) / (2 * (1 + alpha))


def large_volume(n=1024, *, chunks=128):
    """A lazy ``(n, n, n)`` float64 volume: :func:`marschner_lobb_value` sampled on ``[-1, 1]^3``.

    Examples
    --------
    >>> v = large_volume(16, chunks=5)
    >>> bool((v.compute() == large_volume(16, chunks=16).compute()).all())
    True
    """
    import dask.array as da

    n = int(n)

    def block(block_info=None):
        (k0, k1), (j0, j1), (i0, i1) = block_info[None]["array-location"]
        s = lambda a, b: -1.0 + 2.0 * np.arange(a, b, dtype=np.float64) / (n - 1)  # noqa: E731
        return marschner_lobb_value(s(i0, i1)[None, None, :], s(j0, j1)[None, :, None], s(k0, k1)[:, None, None])

    proto = da.empty((n, n, n), chunks=chunks, dtype=np.float64)
    return da.map_blocks(block, chunks=proto.chunks, dtype=np.float64, meta=np.empty((0, 0, 0)))

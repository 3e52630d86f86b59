"""Min-max pyramids built chunk by chunk, level for level those of :class:`splinevis.hierarchy.MinMaxPyramid`.

Why our own code: a pyramid of a 16k x 16k terrain has a level 0 of 268 million (min, max) pairs, built from
coefficients that never sit in memory together. A node of level L covers the cells ``[2^L k, 2^L (k + 1))``
per axis (clipped at the end), so level L + 1 is the 2 x ... x 2 reduction of level L inside every chunk as
long as the chunks have even sizes; where halving made them odd (or tiny), they are merged into larger even
chunks first. Min and max are exact, so every level equals the in-memory pyramid's, bit for bit.
"""

from __future__ import annotations

import numpy as np

from ..hierarchy.pyramid import _reduce

__all__ = ["pyramid_levels_dask"]

_MERGE = 64  # cells per axis per chunk once the halved chunks get small (under a quarter of it) or odd


def _even_chunks(a):
    """``a`` rechunked so that every chunk but the last has an even size (small chunks merged)."""
    out = {}
    for ax, ch in enumerate(a.chunks):
        if len(ch) > 1 and max(ch) < _MERGE // 4:
            out[ax] = _MERGE
        elif len(ch) > 1 and any(c % 2 for c in ch[:-1]):
            out[ax] = 2 * -(-max(ch) // 2)
    return a.rechunk(out) if out else a


def _halve(a, fill, op):
    """One pyramid step of a dask array: the 2 x ... x 2 reduction of every (even-sized) chunk."""
    a = _even_chunks(a)
    chunks = tuple(tuple(-(-c // 2) for c in ch) for ch in a.chunks)
    return a.map_blocks(_reduce, fill, op, chunks=chunks, dtype=a.dtype)


def pyramid_levels_dask(lo, hi):
    """All levels of the min-max pyramid of per-cell bounds, lazily.

    Parameters
    ----------
    lo, hi : n-D dask arrays (or array_like) of one shape
        Per-cell lower and upper bounds, level 0.

    Returns
    -------
    list of (lo, hi) dask arrays
        ``levels[L]`` equals ``MinMaxPyramid(lo, hi).levels[L]`` once computed; the last has one node.

    Examples
    --------
    >>> import dask.array as da
    >>> from splinevis.hierarchy.pyramid import MinMaxPyramid
    >>> lo = np.random.default_rng(5).random((37, 21))
    >>> levels = pyramid_levels_dask(da.from_array(lo, chunks=6), da.from_array(lo + 1, chunks=6))
    >>> ref = MinMaxPyramid(lo, lo + 1).levels
    >>> len(levels) == len(ref), all((a.compute() == b[0]).all() for (a, _), b in zip(levels, ref))
    (True, True)
    """
    import dask.array as da

    lo = lo if isinstance(lo, da.Array) else da.from_array(np.asarray(lo))
    hi = hi if isinstance(hi, da.Array) else da.from_array(np.asarray(hi), chunks=lo.chunks)
    if lo.shape != hi.shape or lo.ndim < 1 or lo.size == 0:
        raise ValueError(f"lo and hi must be non-empty arrays of one shape, got {lo.shape} and {hi.shape}.")
    levels = [(lo, hi)]
    while max(levels[-1][0].shape) > 1:
        a, b = levels[-1]
        levels.append((_halve(a, np.inf, np.minimum), _halve(b, -np.inf, np.maximum)))
    return levels

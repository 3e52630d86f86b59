"""Tiles with halos: the lazily padded grid and the windowed map that the chunked schemes share.

Why our own code: dask cuts the data into chunks and hands each chunk its neighbours' rows
(:func:`dask.array.map_overlap`), but how wide the halo is, where the padding at the grid border comes from and
which cells a chunk owns are the schemes' business. Every scheme here is a *window* on the padded data: output
cell ``j`` along an axis reads the padded samples ``step * j .. step * j + k - 1`` (``k`` the window, ``step``
the samples per cell). So a tile of cells ``[a, b)`` needs the padded samples ``[step a, step (b - 1) + k)``:
its own ``step (b - a)`` samples and a halo of ``k - step`` samples *after* them, taken from the next tile
(an asymmetric overlap; the last tile carries the window's tail itself). The border padding is computed from
the first and last samples of the grid with the very functions the in-memory schemes use, so a tile's values
are those of the in-memory construction, bit for bit.
"""

from __future__ import annotations

import numpy as np

__all__ = ["as_dask_array", "tile_chunks"]


def as_dask_array(data, chunks="auto"):
    """A dask array of ``data``: a dask array (kept), a zarr array (read lazily, chunk by chunk), a path to a
    zarr array, a GeoTIFF path (read lazily by windows with rasterio, north-up rows flipped to south first
    as :func:`splinevis.io.read_heights` does), or anything numpy accepts.

    Examples
    --------
    >>> a = as_dask_array(np.arange(12.0).reshape(3, 4), chunks=2)
    >>> a.chunks, float(a.sum().compute())
    (((2, 1), (2, 2)), 66.0)
    """
    import dask.array as da

    if isinstance(data, da.Array):
        return data
    try:
        import zarr
    except ImportError:  # pragma: no cover - zarr is a dependency
        zarr = None
    if zarr is not None and isinstance(data, zarr.Array):
        return da.from_zarr(data, chunks=chunks if chunks != "auto" else data.chunks)
    if isinstance(data, (str, bytes)) or hasattr(data, "__fspath__"):
        from pathlib import Path

        path = Path(data)
        if not path.exists():
            raise FileNotFoundError(f"no data at {str(path)!r}: give a numpy, dask or zarr array, a zarr store "
                                    f"or a GeoTIFF file.")
        if path.suffix.lower() in (".tif", ".tiff"):
            return _geotiff(path, chunks)
        return as_dask_array(zarr.open_array(str(path), mode="r"), chunks)
    return da.from_array(np.asarray(data), chunks=chunks)


def _geotiff(path, chunks):
    """Band 1 of a GeoTIFF as a lazy dask array, one rasterio window per chunk (rows south first)."""
    import dask.array as da
    import rasterio

    with rasterio.open(path) as src:
        h, w, dtype, flip = src.height, src.width, np.dtype(src.dtypes[0]), src.transform.e < 0
    c = chunks if chunks != "auto" else 1024
    proto = da.empty((h, w), chunks=c, dtype=dtype)

    def read(block_info=None):
        from rasterio.windows import Window

        (r0, r1), (c0, c1) = block_info[None]["array-location"]
        if flip:  # stored row 0 is the north: our row j is stored row h - 1 - j
            r0, r1 = h - r1, h - r0
        with rasterio.open(path) as src:
            out = src.read(1, window=Window(c0, r0, c1 - c0, r1 - r0))
        return out[::-1] if flip else out

    return da.map_blocks(read, dtype=dtype, chunks=proto.chunks, meta=np.empty((0, 0), dtype))


def tile_chunks(n_cells, tile):
    """Chunks of ``n_cells`` cells in tiles of ``tile`` cells (the last one shorter).

    Examples
    --------
    >>> tile_chunks(52, 16)
    (16, 16, 16, 4)
    """
    full, rest = divmod(int(n_cells), int(tile))
    return (int(tile),) * full + ((rest,) if rest else ())


def _check_tile(tile, halo, step, what, axis):
    """ValueError when a tile of ``tile`` cells cannot lend the next tile's ``halo`` samples."""
    need = -(-halo // step)
    if tile < max(1, need):
        raise ValueError(
            f"chunks of {tile} cells along {axis} are smaller than the halo of {what}: each tile reads {halo} "
            f"samples beyond its last cell from the next tile, so tiles need at least {max(1, need)} cells. Use "
            f"larger chunks (tiles of 128 to 1024 cells per axis are typical).")


def _sample_chunks(cell_chunks, step, halo):
    """Chunks of the padded samples: ``step`` samples per cell, the window's tail on the last tile."""
    out = [step * c for c in cell_chunks]
    out[-1] += halo
    return tuple(out)


def _window_map(padded, fn, cell_chunks, steps, halos, tail, dtype=np.float64):
    """``fn`` on every tile of ``padded`` plus its halo (after each tile, per axis), giving an array of
    ``cell_chunks`` (a tuple per axis) followed by the fixed trailing axes ``tail``."""
    import dask.array as da

    sample_chunks = tuple(_sample_chunks(c, s, h) for c, s, h in zip(cell_chunks, steps, halos))
    padded = padded.rechunk(sample_chunks)
    nd = padded.ndim
    depth = {ax: (0, int(h)) for ax, h in enumerate(halos)}
    return da.map_overlap(fn, padded, depth=depth, boundary="none", trim=False, dtype=dtype,
                          chunks=tuple(cell_chunks) + tuple((t,) for t in tail),
                          new_axis=list(range(nd, nd + len(tail))) if tail else None,
                          meta=np.empty((0,) * (nd + len(tail)), dtype))


def _window_read(stored, fn, cell_chunks, steps, halos, tail, dtype=np.float64):
    """As :func:`_window_map`, with every tile reading its samples plus halo straight from ``stored`` (a zarr
    array of the padded data, already written): the tiles share no task, so the scheduler streams through
    them and holds one tile per worker (with ``map_overlap`` a tile's neighbours wait in memory for it)."""
    import dask.array as da

    def read(block_info=None):
        loc = block_info[None]["array-location"]
        sl = tuple(slice(s * a, s * b + h) for (a, b), s, h in zip(loc[:len(steps)], steps, halos))
        return fn(np.asarray(stored[sl]))

    nd = len(cell_chunks)
    return da.map_blocks(read, dtype=dtype, chunks=tuple(cell_chunks) + tuple((t,) for t in tail),
                         meta=np.empty((0,) * (nd + len(tail)), dtype))


def _pad_axis_lazy(a, axis, lo, hi, width, pad_fn):
    """``a`` padded along ``axis`` by ``lo`` and ``hi`` samples; each side from its first/last ``width``
    samples through ``pad_fn(strip, lo, hi)`` (the in-memory padding applied to the strip, which gives the
    same values: the padding reads nothing else)."""
    import dask.array as da

    if not lo and not hi:
        return a
    n = a.shape[axis]
    parts = []
    idx = [slice(None)] * a.ndim

    def strip(sl):
        idx[axis] = sl
        s = a[tuple(idx)]
        return s.rechunk({axis: -1})

    if lo:
        s = strip(slice(0, width))
        chunks = list(s.chunks)
        chunks[axis] = (lo,)
        parts.append(s.map_blocks(lambda b: pad_fn(b, lo, 0)[_take(b.ndim, axis, slice(0, lo))],
                                  chunks=tuple(chunks), dtype=np.float64))
    parts.append(a)
    if hi:
        s = strip(slice(n - width, n))
        chunks = list(s.chunks)
        chunks[axis] = (hi,)
        parts.append(s.map_blocks(lambda b: pad_fn(b, 0, hi)[_take(b.ndim, axis, slice(width, width + hi))],
                                  chunks=tuple(chunks), dtype=np.float64))
    return da.concatenate(parts, axis=axis)


def _take(ndim, axis, sl):
    idx = [slice(None)] * ndim
    idx[axis] = sl
    return tuple(idx)

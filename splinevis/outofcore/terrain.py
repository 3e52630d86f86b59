"""Terrain coefficients tile by tile: the schemes of :mod:`splinevis.terrain.schemes` on a dask array.

Why our own code: dask does the chunking and the scheduling, but each scheme reads a fixed window of samples
around a cell (``scheme_stencil``) and pads the grid by cubic extrapolation at its border, and a tile must see
exactly that window, no more padding and no less, to reproduce the in-memory coefficients. The padded border
strips are built from the grid's first and last four rows and columns by the in-memory padding itself
(x first, then y, as :func:`splinevis.terrain.engine._pad_cubic` does), and each tile runs the in-memory stencil
engine on its samples plus a halo of ``window - step`` samples from the next tile. The result equals
:func:`splinevis.terrain.schemes.terrain_coefficients` bit for bit (tested for every scheme and for tiles that
do and do not divide the grid).

Tiles are counted in spline cells: ``C0`` cells are 4 x 4 samples, so its tiles always align with them.
"""

from __future__ import annotations

import numpy as np

from ..terrain.engine import _apply_padded, _pad_cubic
from ..terrain.schemes import _BUILDERS, _MIN_SIZE, SCHEMES, STENCIL_SCHEMES
from .halo import _check_tile, _pad_axis_lazy, _window_map, as_dask_array, tile_chunks

__all__ = ["terrain_halo", "terrain_coefficients_dask", "terrain_input_chunks"]


def terrain_halo(scheme):
    """Reach of a scheme's stencil and the halo a tile needs.

    Returns
    -------
    dict
        ``"offsets"``: ``(first, last)`` data offset of the stencil from a cell's lower-left corner (the same
        along x and y); ``"pad"``: ``(before, after)`` samples of cubic extrapolation at the grid border;
        ``"halo"``: samples a tile reads from the next tile (``window - step``); ``"step"``: samples per cell;
        ``"min_tile"``: the smallest tile, in cells, that can lend that halo.

    Examples
    --------
    >>> terrain_halo("C1")
    {'offsets': (-2, 3), 'pad': (2, 2), 'halo': 5, 'step': 1, 'min_tile': 5}
    >>> terrain_halo("C0")["halo"], terrain_halo("C0")["step"]  # 5 x 5 samples per 4 x 4 macro cell
    (1, 4)
    """
    if scheme not in SCHEMES:
        raise ValueError(f"scheme {scheme!r} is not known; choose one of {', '.join(SCHEMES)}.")
    if scheme not in STENCIL_SCHEMES:
        raise ValueError(f"scheme {scheme} is not supported out of core: its prefilter solves one linear system over the "
                         f"whole grid (every coefficient depends on every height), which tiles cannot do. Use "
                         f"'C2-cubic', the same C2 box spline with a local cubic-exact prefilter (also order 4), or "
                         f"build {scheme} in memory (TerrainSpline.from_heights) on a grid that fits.")
    st = _BUILDERS[scheme]()
    lo_x, hi_x, _, _ = st.pads()
    halo = st.kw - st.step
    return {"offsets": (st.x0, st.x0 + st.kw - 1), "pad": (lo_x, hi_x), "halo": halo, "step": st.step,
            "min_tile": max(1, -(-halo // st.step))}


def _tiles(chunks):
    """(ty, tx) cells per tile from an int or a pair."""
    t = (chunks, chunks) if np.isscalar(chunks) else tuple(chunks)
    if len(t) != 2 or not all(isinstance(v, (int, np.integer)) and v > 0 for v in t):
        raise ValueError(f"chunks must be a positive number of cells per tile or a pair (rows, columns) of them, "
                         f"got {chunks!r}.")
    return int(t[0]), int(t[1])


def _cells(shape, scheme):
    """(ncy, ncx) of a grid, with the in-memory scheme's size checks."""
    ny, nx = shape
    m = _MIN_SIZE[scheme]
    if ny < m or nx < m:
        raise ValueError(f"scheme {scheme} needs at least {m}x{m} heights, got {ny}x{nx} (rows x columns).")
    if scheme == "C0":
        if (nx - 1) % 4 or (ny - 1) % 4:
            raise ValueError(
                f"scheme C0 groups 4x4 samples into one spline cell and needs sizes 4k + 1; got {ny}x{nx}. The "
                f"in-memory resampling (resample_for_c0) is a global cubic B-spline fit and is not supported out of "
                f"core: resample the data to {4 * -(-(ny - 1) // 4) + 1}x{4 * -(-(nx - 1) // 4) + 1} first or use "
                f"another scheme.")
        return (ny - 1) // 4, (nx - 1) // 4
    return ny - 1, nx - 1


def terrain_input_chunks(shape, scheme="C1", chunks=512):
    """Chunks of the heights that make every tile's samples a plain union of height chunks: the first chunk
    shorter by the border padding in front, the last by the padding behind. Heights chunked otherwise work
    as well, but each tile then straddles two height chunks per axis, which the scheduler must keep longer.

    Examples
    --------
    >>> terrain_input_chunks((4096, 1000), "C1", 512)  # C1 pads 2 samples on each side, tiles read 5 more
    ((510, 512, 512, 512, 512, 512, 512, 514), (510, 490))
    """
    halo = terrain_halo(scheme)
    lo, hi = halo["pad"]
    out = []
    for n, t in zip(shape, _tiles(chunks)):
        cells = tile_chunks(_cells(shape, scheme)[len(out)], t)
        s = [halo["step"] * c for c in cells]
        s[-1] += halo["halo"]
        if len(s) == 1:
            out.append((int(n),))
            continue
        s[0] -= lo
        s[-1] -= hi
        out.append(tuple(int(v) for v in s))
    return tuple(out)


def terrain_coefficients_dask(heights, scheme="C1", *, chunks=512):
    """Lazy quartic BB coefficients of a terrain, one dask task per tile of cells.

    Parameters
    ----------
    heights : (ny, nx) dask array, zarr array, path (zarr or GeoTIFF) or array_like
        Heights, ``heights[j, i]`` at index point ``(i, j)`` (the convention of ``terrain_coefficients``).
    scheme : str
        One of :data:`splinevis.terrain.schemes.SCHEMES`.
    chunks : int or (int, int)
        Spline cells per tile (rows, columns); the last tile of a row or column may be shorter. Tiles must
        be at least :func:`terrain_halo` ``["min_tile"]`` cells (5 for C1 and C2-cubic).

    Returns
    -------
    coef : (ncy, ncx, 2, 15) float64 dask array
        Chunked ``(tile, tile, 2, 15)``; computed, it equals ``terrain_coefficients(heights, scheme)[0]``: bit
        for bit for most coefficients, and to the last bits where the BLAS matrix product rounds a row
        differently because the tile hands it a different number of rows (with OpenBLAS: the last row of an
        odd-sized batch; ~1% of the coefficients, <= 3e-16 of the largest for mean-subtracted heights).

    Raises
    ------
    ValueError
        Unknown scheme, not 2-D, too small, C0 sizes other than 4k + 1, tiles smaller than the halo, and,
        when computed, non-finite heights (naming the tile).

    Examples
    --------
    >>> from splinevis.terrain.schemes import terrain_coefficients
    >>> z = np.random.default_rng(1).random((23, 30))
    >>> coef = terrain_coefficients_dask(z, "C1", chunks=8)
    >>> coef.chunks[:2]
    ((8, 8, 6), (8, 8, 8, 5))
    >>> ref = terrain_coefficients(z, "C1")[0]  # equal up to the last bits of a few matrix-product rows
    >>> bool(np.abs(coef.compute() - ref).max() <= 1e-15 * np.abs(ref).max())
    True
    """
    halo = terrain_halo(scheme)
    st = _BUILDERS[scheme]()
    import dask.array as da

    z = as_dask_array(heights)
    if z.ndim != 2:
        raise ValueError(f"heights must be a 2-D array of shape (ny, nx); got {z.ndim}-D shape {z.shape}.")
    if not np.issubdtype(z.dtype, np.number) or np.issubdtype(z.dtype, np.complexfloating):
        raise TypeError(f"heights must be real numbers, got dtype {z.dtype}.")
    z = z.astype(np.float64)
    ncy, ncx = _cells(z.shape, scheme)
    ty, tx = _tiles(chunks)
    for t, axis in ((ty, "y (rows)"), (tx, "x (columns)")):
        _check_tile(t, halo["halo"], st.step, f"scheme {scheme} (stencil offsets {halo['offsets'][0]}.."
                    f"{halo['offsets'][1]} from a cell's corner)", axis)
    if not isinstance(heights, da.Array):  # ours to cut: cut it along the tiles
        z = z.rechunk(terrain_input_chunks(z.shape, scheme, (ty, tx)))
    lo_x, hi_x, lo_y, hi_y = st.pads()
    # the same padding as in memory: x first over the data rows, then y over the padded rows
    P = _pad_axis_lazy(z, 1, lo_x, hi_x, 4, lambda b, lo, hi: _pad_cubic(b, lo, hi, 0, 0))
    P = _pad_axis_lazy(P, 0, lo_y, hi_y, 4, lambda b, lo, hi: _pad_cubic(b, 0, 0, lo, hi))

    def tile(block, block_info=None):
        if not np.isfinite(block).all():
            loc = block_info[None]["chunk-location"] if block_info else "?"
            raise ValueError(f"heights must be finite; the tile at chunk location {loc} (rows, columns of tiles) "
                             f"or its halo holds {int((~np.isfinite(block)).sum())} non-finite value(s).")
        cy = (block.shape[0] - st.kh) // st.step + 1
        cx = (block.shape[1] - st.kw) // st.step + 1
        return _apply_padded(block, st, cy, cx, (-st.x0, -st.y0), threads=1)

    return _window_map(P, tile, (tile_chunks(ncy, ty), tile_chunks(ncx, tx)), (st.step, st.step),
                       (st.kh - st.step, st.kw - st.step), (2, 15))

"""Terrain stores: the coefficients of a terrain in a zarr group, one chunk per tile, with their min-max pyramid.

Why our own code: zarr stores the chunks and dask writes them in parallel; what goes in is ours. The layout:

* ``coefficients`` ``(ncy, ncx, 2, 15)`` float64, chunks ``(tile_y, tile_x, 2, 15)``: the BB coefficients
  relative to ``z_ref``, exactly the array :class:`~splinevis.terrain.model.TerrainSpline` keeps;
* ``pyramid/L`` ``(n_L, m_L, 2)``: level L of the min-max pyramid of the coefficients, (min, max) per node,
  the levels of ``TerrainSpline.hierarchy`` (the quantity the ray caster's traversal and the culling use);
* ``tiles`` ``(nty, ntx, 2)``: (min, max) of each tile's coefficients, what :func:`~.view.tiles_in_view`
  tests against a view;
* ``heights/L`` ``(ny_L, nx_L)``: every ``2^L``-th height sample (L >= 1), what overviews coarser than the
  cells are built from (:mod:`.overview`);
* attributes: ``scheme``, ``cell_spacing``, ``origin``, ``z_ref``, ``data_range``, ``cells``, ``tile``.

Three passes: the mean height (``z_ref``), the data range and the heights pyramid; the coefficients and the
pyramid's level 0, tile by tile; the levels above and the tiles' bounds, reduced from level 0 as written (a
sixteenth of the coefficients' bytes).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .halo import as_dask_array
from .overview import heights_levels
from .pyramid import pyramid_levels_dask
from .schedule import run
from .terrain import _tiles, terrain_coefficients_dask

__all__ = ["write_terrain_store", "open_terrain_store", "TerrainStore"]

_KIND = "splinevis terrain store"


def _group(path, mode):
    import zarr

    return zarr.open_group(str(path), mode=mode)


def _open_store(path, kind: str, what: str, writer: str, scheme):
    """``(group, attrs, path)`` of the store of ``kind`` at ``path`` opened for reading, with the errors of a
    missing path, a zarr group of another kind and a store written with another ``scheme`` (None: any);
    ``what`` names the store in messages ("terrain", "volume") and ``writer`` how to make one."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"no {what} store at {str(p)!r}: write one with {writer}(path, {_DATA[what]}, "
                                f"scheme).")
    group = _group(p, "r")
    attrs = dict(group.attrs)
    if attrs.get("kind") != kind:
        raise ValueError(f"{str(p)!r} is a zarr group but not a {what} store (kind {attrs.get('kind')!r}); write one "
                         f"with {writer}.")
    if scheme is not None and attrs["scheme"] != scheme:
        raise ValueError(f"the {what} store at {str(p)!r} was written with scheme {attrs['scheme']!r}, not "
                         f"{scheme!r}: rebuild it with {writer}(path, {_DATA[what]}, {scheme!r}) or open it "
                         f"without scheme=.")
    return group, attrs, str(p)


_DATA = {"terrain": "heights", "volume": "samples"}


def _codecs(compressor):
    """zarr compressors: "lz4" (blosc lz4 with byte shuffle: twice as fast as zarr's default zstd on float64
    coefficients, 15% larger), "zstd" (zarr's default) or None (raw)."""
    if compressor == "lz4":
        from zarr.codecs import BloscCodec

        return (BloscCodec(cname="lz4", clevel=5, shuffle="shuffle"),)
    if compressor == "zstd":
        return "auto"
    if compressor is None:
        return None
    raise ValueError(f"compressor must be 'lz4', 'zstd' or None, got {compressor!r}.")


def _store(sources, targets):
    """``da.store`` of the sources into the zarr targets, without locks: checked that no zarr chunk gets
    writes from two source blocks (concurrent read-modify-writes of one chunk would lose one)."""
    import dask.array as da

    for src, tgt in zip(sources, targets):
        for ax, (ch, size) in enumerate(zip(src.chunks, tgt.chunks)):
            if any(int(b) % size for b in np.cumsum(ch)[:-1]):
                raise RuntimeError(f"source chunks {ch} along axis {ax} straddle the zarr chunks of {size}: "
                                   f"{tgt.name} would lose concurrent writes.")
    return da.store(sources, targets, lock=False, compute=False)


def _level0(group, name, level0, sources, targets, compressor):
    """Add level 0 of a pyramid ((lo, hi) stacked on a last axis, chunked per tile) to a store's write lists."""
    sub = group.create_group(name)
    sources.append(level0)
    targets.append(sub.create_array("0", shape=level0.shape, chunks=tuple(c[0] for c in level0.chunks),
                                    dtype=level0.dtype, compressors=_codecs(compressor)))


def _upper_levels(group, name, chunk, compressor):
    """Sources and targets of levels 1, 2, ... of a pyramid, reduced from its level 0 as written (a second
    pass: in the first, each tile's bounds have the zarr write as their only reader, so the scheduler drops
    them at once instead of keeping them for reductions that need many tiles)."""
    import dask.array as da

    sub = group[name]
    b0 = da.from_zarr(sub["0"])
    sources, targets = [], []
    for L, (a, b) in enumerate(pyramid_levels_dask(b0[..., 0], b0[..., 1])[1:], start=1):
        arr = da.stack([a, b], axis=-1)
        ch = tuple(min(chunk, max(1, s)) for s in arr.shape[:-1]) + (2,)
        sources.append(arr.rechunk(ch))
        targets.append(sub.create_array(str(L), shape=arr.shape, chunks=ch, dtype=arr.dtype,
                                        compressors=_codecs(compressor)))
    return b0, sources, targets


def write_terrain_store(path, heights, scheme="C1", *, chunks=512, spacing=(1.0, 1.0), origin=(0.0, 0.0),
                        z_ref=None, compressor="lz4", progress=True):
    """Build a terrain spline tile by tile and write it, its min-max pyramid and its metadata to zarr.

    Parameters
    ----------
    path : str or Path
        The zarr group to create (replaced if it exists).
    heights : (ny, nx) dask array, zarr array, path or array_like
        Heights, ``heights[j, i]`` at ``origin + (i, j) * spacing``.
    scheme : str
        A terrain scheme (``C0`` needs sizes 4k + 1; no resampling out of core).
    chunks : int or (int, int)
        Spline cells per tile; also the zarr chunks. Powers of two make the pyramid's level log2(tile) the
        tiles' own bounds.
    spacing, origin : (float, float)
        Sample spacing and position of sample (0, 0), as for ``TerrainSpline.from_heights``.
    z_ref : float, optional
        Reference height subtracted before the scheme; default the mean of the heights (dask's mean: equal
        to numpy's up to the rounding of its summation order).
    compressor : {"lz4", "zstd", None}
        Compression of the arrays: blosc lz4 with byte shuffle (default; the zarr writes are the slowest part,
        and it is twice as fast as zstd on coefficients), zarr's default zstd, or none.
    progress : bool
        Progress bars for the two passes.

    Returns
    -------
    TerrainStore

    Examples
    --------
    >>> import tempfile
    >>> y, x = np.mgrid[0:21, 0:30].astype(float)
    >>> store = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", x + 2 * y, "C1", chunks=8, progress=False)
    >>> store
    TerrainStore(scheme='C1', cells=29x20, tiles=4x3 of 8x8, depth=5, z_ref=34.5)
    >>> round(float(store.window(1, 2, 0, 4).evaluate(12.5, 10.5)), 9)  # a plane is reproduced
    33.5
    """
    import dask

    h = as_dask_array(heights).astype(np.float64)
    if h.ndim != 2:
        raise ValueError(f"heights must be a 2-D array of shape (ny, nx); got {h.ndim}-D shape {h.shape}.")
    ty, tx = _tiles(chunks)
    coef0 = terrain_coefficients_dask(h, scheme, chunks=(ty, tx))  # checks scheme, sizes, tiles first
    group = _group(path, "w")
    # the heights pyramid (overview.py) is written in the pass that reads the heights for their mean
    stats, _ = run([dask.delayed(tuple)([h.mean(), h.min(), h.max()]),
                    _store(*heights_levels(h, scheme, group, _codecs(compressor)))], progress=progress,
                   label="terrain store: mean and range of the heights, heights pyramid" if progress else "")
    mean, zmin, zmax = stats
    z_ref = float(mean) if z_ref is None else float(z_ref)
    coef = terrain_coefficients_dask(h - z_ref, scheme, chunks=(ty, tx)) if z_ref != 0.0 else coef0
    cell = 4 if scheme == "C0" else 1
    ncy, ncx = coef.shape[:2]
    group.attrs.update({
        "kind": _KIND, "scheme": scheme, "cell_spacing": [float(spacing[0]) * cell, float(spacing[1]) * cell],
        "origin": [float(origin[0]), float(origin[1])], "z_ref": z_ref,
        "data_range": [float(zmin), float(zmax)], "cells": [ncy, ncx], "tile": [ty, tx]})
    # the model's per-cell bounds, min and max of the 30 coefficients, in one task per tile (so a tile's
    # coefficients have two readers, the zarr write and this, and are dropped as soon as both ran)
    cy, cx = coef.chunks[:2]
    bounds = coef.map_blocks(lambda b: np.stack([b.reshape(b.shape[:2] + (30,)).min(-1),
                                                 b.reshape(b.shape[:2] + (30,)).max(-1)], axis=-1),
                             chunks=(cy, cx, (2,)), drop_axis=3, dtype=np.float64)
    sources = [coef]
    codecs = _codecs(compressor)
    targets = [group.create_array("coefficients", shape=coef.shape, chunks=(ty, tx, 2, 15), dtype="f8",
                                  compressors=codecs)]
    _level0(group, "pyramid", bounds, sources, targets, compressor)
    run(_store(sources, targets), progress=progress,
        label=f"terrain store: {scheme} coefficients of {ncx}x{ncy} cells" if progress else "")
    b0, sources, targets = _upper_levels(group, "pyramid", max(ty, tx), compressor)
    b0 = b0.rechunk((ty, tx, 2))
    tiles = b0.map_blocks(lambda b: np.stack([b[..., 0].min(), b[..., 1].max()])[None, None],
                          chunks=((1,) * len(cy), (1,) * len(cx), (2,)), dtype=np.float64)
    sources.append(tiles.rechunk(-1))  # one zarr chunk written by one task: no lost concurrent writes
    targets.append(group.create_array("tiles", shape=tiles.shape, chunks=tiles.shape, dtype="f8", compressors=codecs))
    run(_store(sources, targets), progress=progress, label="terrain store: the pyramid" if progress else "")
    return open_terrain_store(path)


def open_terrain_store(path, scheme=None):
    """Open a store written by :func:`write_terrain_store` (nothing is read but the attributes).

    Parameters
    ----------
    path : str or Path
    scheme : str, optional
        Refuse a store written with another scheme.

    Examples
    --------
    >>> import tempfile
    >>> path = tempfile.mkdtemp() + "/t.zarr"
    >>> _ = write_terrain_store(path, np.zeros((9, 9)), "C2", chunks=4, progress=False)
    >>> open_terrain_store(path).tiles
    (2, 2)
    >>> open_terrain_store(path, scheme="C1")
    Traceback (most recent call last):
    ValueError: the terrain store at ... was written with scheme 'C2', not 'C1': rebuild it with ...
    """
    return TerrainStore(*_open_store(path, _KIND, "terrain", "write_terrain_store", scheme))


class TerrainStore:
    """A terrain written tile by tile: windows of it as :class:`~splinevis.terrain.model.TerrainSpline`, and
    its pyramid. Made by :func:`open_terrain_store` / :func:`write_terrain_store`.

    Attributes
    ----------
    scheme : str
    cell_spacing, origin : (float, float)
    z_ref : float
    data_range : (float, float)
    shape : (int, int)
        Cells ``(ncy, ncx)``.
    tile : (int, int)
        Cells per tile ``(rows, columns)``.

    Examples
    --------
    >>> import tempfile
    >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.ones((10, 12)), "linear", chunks=4, progress=False)
    >>> s.shape, s.tile, s.tiles, s.extent
    ((9, 11), (4, 4), (3, 3), (0.0, 11.0, 0.0, 9.0))
    """

    def __init__(self, group, attrs, path):
        self._g = group
        self.path = path
        self.scheme = attrs["scheme"]
        self.cell_spacing = tuple(float(v) for v in attrs["cell_spacing"])
        self.origin = tuple(float(v) for v in attrs["origin"])
        self.z_ref = float(attrs["z_ref"])
        self.data_range = tuple(float(v) for v in attrs["data_range"])
        self.shape = tuple(int(v) for v in attrs["cells"])
        self.tile = tuple(int(v) for v in attrs["tile"])

    @property
    def tiles(self) -> tuple:
        """``(nty, ntx)`` tiles.

        >>> import tempfile
        >>> write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.ones((10, 12)), "linear", chunks=4, progress=False).tiles
        (3, 3)
        """
        return tuple(-(-n // t) for n, t in zip(self.shape, self.tile))

    @property
    def depth(self) -> int:
        """Levels of the pyramid above the cells.

        >>> import tempfile
        >>> write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.ones((10, 12)), "linear", chunks=4, progress=False).depth
        4
        """
        return len(self._g["pyramid"]) - 1

    @property
    def extent(self) -> tuple:
        """``(xmin, xmax, ymin, ymax)`` of the whole terrain.

        >>> import tempfile
        >>> write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.ones((5, 5)), "C0", chunks=1, spacing=(2.0, 3.0),
        ...                     progress=False).extent  # one C0 cell of 4 x 4 samples
        (0.0, 8.0, 0.0, 12.0)
        """
        ncy, ncx = self.shape
        return (self.origin[0], self.origin[0] + ncx * self.cell_spacing[0],
                self.origin[1], self.origin[1] + ncy * self.cell_spacing[1])

    @property
    def coefficients(self):
        """The zarr array of all coefficients (read lazily: index it, or ``dask.array.from_zarr`` it).

        >>> import tempfile
        >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.ones((10, 12)), "linear", chunks=4, progress=False)
        >>> s.coefficients.shape, s.coefficients.chunks
        ((9, 11, 2, 15), (4, 4, 2, 15))
        """
        return self._g["coefficients"]

    def level(self, L):
        """``(lo, hi)`` numpy arrays of pyramid level ``L`` (level 0: one node per cell).

        >>> import tempfile
        >>> y, x = np.mgrid[0:10, 0:12].astype(float)
        >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", x, "linear", chunks=4, progress=False)
        >>> lo, hi = s.level(s.depth)
        >>> float(lo[0, 0]) + s.z_ref, float(hi[0, 0]) + s.z_ref  # the top node: the range of the whole terrain
        (0.0, 11.0)
        """
        if not 0 <= L <= self.depth:
            raise ValueError(f"level must be in 0..{self.depth}, got {L}.")
        a = self._g["pyramid"][str(L)][...]
        return a[..., 0], a[..., 1]

    def tile_bounds(self) -> np.ndarray:
        """``(nty, ntx, 2)`` (min, max) of every tile's coefficients (relative to ``z_ref``).

        >>> import tempfile
        >>> y, x = np.mgrid[0:10, 0:12].astype(float)
        >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", x, "linear", chunks=4, progress=False)
        >>> (s.tile_bounds()[0] + s.z_ref).tolist()  # the first row of tiles: x in [0, 4], [4, 8], [8, 11]
        [[0.0, 4.0], [4.0, 8.0], [8.0, 11.0]]
        """
        return self._g["tiles"][...]

    def pyramid(self, from_level=0):
        """A :class:`~splinevis.hierarchy.MinMaxPyramid` of level ``from_level`` and above (reads that level:
        level 0 is the whole terrain's cells; the levels above a tile are small).

        >>> import tempfile
        >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.ones((10, 12)), "linear", chunks=4, progress=False)
        >>> s.pyramid(2).depth, s.pyramid().depth  # level 2 has 3 x 3 nodes: two more levels above it
        (2, 4)
        """
        from ..hierarchy.pyramid import MinMaxPyramid

        return MinMaxPyramid(*self.level(from_level))

    def window(self, iy0, iy1, ix0, ix1):
        """The tiles ``[iy0, iy1) x [ix0, ix1)`` as a TerrainSpline (only their chunks are read).

        The window's origin is the physical position of its first cell's corner, ``z_ref`` and
        ``data_range`` are the whole terrain's (one colour map for all windows).

        >>> import tempfile
        >>> y, x = np.mgrid[0:10, 0:12].astype(float)
        >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", x * y, "C1", chunks=6, spacing=(10.0, 10.0),
        ...                         origin=(100.0, 0.0), progress=False)
        >>> w = s.window(1, 2, 1, 2)  # cells 6..8 (rows) x 6..10 (columns)
        >>> w.shape, w.origin, round(float(w.evaluate(185.0, 75.0)), 9)  # x y at index (8.5, 7.5)
        ((3, 5), (160.0, 60.0), 63.75)
        """
        from ..terrain.model import TerrainSpline

        nty, ntx = self.tiles
        if not (0 <= iy0 < iy1 <= nty and 0 <= ix0 < ix1 <= ntx):
            raise ValueError(f"window tiles [{iy0}, {iy1}) x [{ix0}, {ix1}) (rows x columns) must be non-empty and "
                             f"inside the store's {nty}x{ntx} tiles.")
        ty, tx = self.tile
        r0, r1 = iy0 * ty, min(iy1 * ty, self.shape[0])
        c0, c1 = ix0 * tx, min(ix1 * tx, self.shape[1])
        coef = self.coefficients[r0:r1, c0:c1]
        org = (self.origin[0] + c0 * self.cell_spacing[0], self.origin[1] + r0 * self.cell_spacing[1])
        out = TerrainSpline(coef, self.cell_spacing, org, self.z_ref, scheme=self.scheme,
                            source=f"{self.path} tiles [{iy0}:{iy1}, {ix0}:{ix1}]")
        out.data_range = self.data_range
        return out

    def __repr__(self):
        ncy, ncx = self.shape
        nty, ntx = self.tiles
        return (f"TerrainStore(scheme={self.scheme!r}, cells={ncx}x{ncy}, tiles={ntx}x{nty} of "
                f"{self.tile[1]}x{self.tile[0]}, depth={self.depth}, z_ref={self.z_ref:g})")

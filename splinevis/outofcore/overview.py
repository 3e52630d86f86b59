"""Heights pyramid of a terrain store: every 2^L-th height sample per level, and splines built from a level.

Why our own code: a renderer can draw only so many cells at once (the coefficient textures, and memory), so
an overview of a 16k x 16k DEM needs a coarser surface than the store's coefficients. Coarser coefficients
cannot be reduced from finer ones (a spline of a decimated grid is another spline), so the writer keeps the
heights themselves, decimated: level ``L`` (``L >= 1``) holds the samples ``heights[::2^L, ::2^L]``, at their
exact positions (spacing ``2^L`` times the data's). They are written in the store's first pass, blockwise from
the heights the mean pass reads anyway, so a lazy DEM is evaluated no extra time; each block's samples are
copied out, so no full height chunk waits in memory for a level's other blocks. Level 1 is a quarter of the
heights' bytes, all levels together a third.

:func:`overview_spline` applies the store's scheme to a level (or a rectangle of it, read chunk by chunk
from zarr, with the margin the scheme's stencil reaches so its cells equal those of the whole level).
"""

from __future__ import annotations

import numpy as np

__all__ = ["heights_levels", "overview_spline", "level_rectangle"]

_CHUNK = 1024  # samples per axis per zarr chunk of a heights level


def _level_sizes(shape, scheme):
    """Sample counts ``(ny, nx)`` of levels 1, 2, ... that the scheme can still build a spline of."""
    from ..terrain.schemes import _MIN_SIZE

    need = max(_MIN_SIZE[scheme], 5 if scheme == "C0" else 2)
    out, L = [], 1
    while True:
        s = 1 << L
        size = tuple((n - 1) // s + 1 for n in shape)
        if min(size) < need:
            return out
        out.append(size)
        L += 1


def _decimate(h, s):
    """Every ``s``-th sample of a 2-D dask array (rows and columns from 0), block by block, copied."""
    def counts(chunks):
        out, a = [], 0
        for c in chunks:
            first = -(-a // s) * s
            out.append(max(0, -(-(a + c - first) // s)))
            a += c
        return tuple(out)

    def block(b, block_info=None):
        (r0, _), (c0, _) = block_info[0]["array-location"]
        return np.array(b[(-r0) % s::s, (-c0) % s::s])

    return h.map_blocks(block, chunks=(counts(h.chunks[0]), counts(h.chunks[1])), dtype=h.dtype)


def heights_levels(h, scheme, group, codecs):
    """Sources (lazy decimations of the dask heights ``h``) and zarr targets of the heights pyramid in the
    group ``heights/L`` of a store being written; the caller stores them in the pass that reads ``h``.

    Examples
    --------
    >>> import dask.array as da, zarr
    >>> g = zarr.open_group(zarr.storage.MemoryStore(), mode="w")
    >>> h = da.from_array(np.arange(81.0).reshape(9, 9), chunks=4)
    >>> src, tgt = heights_levels(h, "linear", g, None)
    >>> [t.shape for t in tgt]  # 9 -> 5 -> 3 -> 2 samples per axis
    [(5, 5), (3, 3), (2, 2)]
    >>> src[0].compute()[1].tolist()  # row 2, every second column
    [18.0, 20.0, 22.0, 24.0, 26.0]
    """
    sub = group.create_group("heights")
    sources, targets = [], []
    for L, size in enumerate(_level_sizes(h.shape, scheme), start=1):
        d = _decimate(h, 1 << L)
        ch = tuple(min(_CHUNK, n) for n in size)
        if any(int(b) % c for cs, c in zip(d.chunks, ch) for b in np.cumsum(cs)[:-1]) or 0 in d.chunks[0] + d.chunks[1]:
            d = d.rechunk(ch)
        sources.append(d)
        targets.append(sub.create_array(str(L), shape=size, chunks=ch, dtype="f8", compressors=codecs))
    return sources, targets


def _levels(store):
    g = store._g
    if "heights" not in g:
        raise ValueError(f"the terrain store at {store.path!r} has no heights pyramid (written by an older "
                         f"write_terrain_store): rewrite it to draw levels coarser than its cells.")
    return g["heights"]


def level_rectangle(store, L, rows, cols):
    """Samples of heights level ``L`` that cover the store's cells ``rows = (r0, r1)``, ``cols = (c0, c1)``,
    rounded outward to the level's whole cells: ``((a_y, b_y), (a_x, b_x))``, inclusive sample indices, and
    the level's cells ``(ncy, ncx)`` over them.

    Examples
    --------
    >>> import tempfile
    >>> from splinevis.outofcore.store import write_terrain_store
    >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.zeros((65, 65)), "C0", chunks=4, progress=False)
    >>> level_rectangle(s, 1, (0, 16), (5, 9))  # C0 cells 5..9 are samples 20..36 = level-1 samples 10..18
    (((0, 32), (8, 20)), (8, 3))
    """
    from .terrain import terrain_halo

    step = terrain_halo(store.scheme)["step"]
    size = _levels(store)[str(L)].shape
    s = 1 << L
    out = []
    for (c0, c1), n in zip((rows, cols), size):
        last = (n - 1) // step * step  # C0: the level's last whole macro cell
        a = min(c0 * step // s // step * step, last - step)
        b = max(min(-(-(-(-c1 * step // s)) // step) * step, last), a + step)
        out.append((int(a), int(b)))
    cells = tuple((b - a) // step for a, b in out)
    return tuple(out), cells


def overview_spline(store, L, rows=None, cols=None):
    """A :class:`~splinevis.terrain.model.TerrainSpline` of the store's scheme built from heights level ``L``,
    over the store's cells ``rows x cols`` (default: all), rounded outward to the level's cells.

    What it is: the spline of every ``2^L``-th height sample, a different, smoother surface than the store's.
    It has the level's samples at their true positions but none of the detail between them: its distance to
    the full-resolution surface is the detail of wavelengths under ``2 * 2^L`` samples, not the scheme's
    approximation error (on the synthetic 16k DEM the docs give it per level). It is what an overview shows
    where a pixel covers many cells anyway. ``z_ref`` and ``data_range`` are the store's (one colour map).

    Reads only the zarr chunks of the rectangle plus the stencil's margin, so its cells equal those of the
    spline of the whole level (up to the last bits of a matrix product, see ``terrain_coefficients_dask``).

    Examples
    --------
    >>> import tempfile
    >>> from splinevis.outofcore.store import write_terrain_store
    >>> y, x = np.mgrid[0:33, 0:33].astype(float)
    >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", x + 2 * y, "C1", chunks=8, progress=False)
    >>> t = overview_spline(s, 2)  # every 4th sample: 9 x 9 samples, 8 x 8 cells of 4 x 4
    >>> t.shape, t.cell_spacing, round(float(t.evaluate(13.0, 7.0)), 9)  # a plane stays a plane
    ((8, 8), (4.0, 4.0), 27.0)
    """
    from ..terrain.model import TerrainSpline
    from ..terrain.schemes import terrain_coefficients
    from .terrain import terrain_halo

    levels = _levels(store)
    if not 1 <= L <= len(levels):
        raise ValueError(f"heights level must be in 1..{len(levels)} (level 0 is the store's own cells), got {L}.")
    rows = (0, store.shape[0]) if rows is None else rows
    cols = (0, store.shape[1]) if cols is None else cols
    (ay, by), (ax, bx) = level_rectangle(store, L, rows, cols)[0]
    halo = terrain_halo(store.scheme)
    m = max(halo["pad"])  # the stencil's reach: cells at the rectangle's edge see the level's samples beyond
    arr = levels[str(L)]
    ry0, ry1 = max(0, ay - m), min(arr.shape[0] - 1, by + m)
    rx0, rx1 = max(0, ax - m), min(arr.shape[1] - 1, bx + m)
    z = arr[ry0:ry1 + 1, rx0:rx1 + 1]
    coef, _ = terrain_coefficients(z - store.z_ref, store.scheme)
    step = halo["step"]
    coef = coef[(ay - ry0) // step:(by - ry0) // step, (ax - rx0) // step:(bx - rx0) // step]
    spacing = tuple(store.cell_spacing[i] / step * (1 << L) for i in range(2))  # samples of level L
    origin = (store.origin[0] + ax * spacing[0], store.origin[1] + ay * spacing[1])
    out = TerrainSpline(coef, (spacing[0] * step, spacing[1] * step), origin, store.z_ref, scheme=store.scheme,
                        source=f"{store.path} heights level {L} samples [{ay}:{by + 1}, {ax}:{bx + 1}]")
    out.data_range = store.data_range
    return out

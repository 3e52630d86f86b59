"""Volume stores: what :class:`~splinevis.volume.model.VolumeSpline` keeps, in a zarr group, one chunk per tile.

Why our own code: zarr stores the chunks, dask writes them; the content is the volume model's:

* ``padded`` ``(nz + 2, ny + 2, nx + 2)`` float64: the samples with the schemes' layer of linear
  extrapolation (``VolumeSpline.padded``; the GPU's data texture is it minus a reference value);
* ``octree/L`` ``(n_L, m_L, k_L, 2)`` float32: level L of the min-max octree of the per-cube coefficient
  bounds (``VolumeSpline.octree``; level 0 is ``cube_ranges``), what the isosurface search descends;
* ``coefficients`` ``(nz, ny, nx, 24, m)`` float64, only when asked (``coefficients=True``): 240 or 480
  numbers per cube, too many for big volumes, which rebuild them per cube from ``padded``;
* attributes: ``scheme``, ``spacing``, ``origin``, ``value_range``, ``shape``, ``tile``.

Four passes: the data range; the padded data (blockwise); the per-cube bounds, each tile reading its samples
and halo from the stored padded data (no task shared between tiles, so memory stays at a tile per worker:
with ``map_overlap`` a tile's neighbours waited in memory for their turn, 3.1 GB at 1024^3 instead of 0.55);
the octree levels above the cubes.
"""

from __future__ import annotations


import numpy as np

from .halo import as_dask_array
from .schedule import run
from .store import _codecs, _level0, _open_store, _store, _upper_levels
from .volume import _coefficients, _cube_ranges, _tiled_padded, _tiles3

__all__ = ["write_volume_store", "open_volume_store", "VolumeStore"]

_KIND = "splinevis volume store"


def write_volume_store(path, samples, scheme="quadratic", *, chunks=64, spacing=(1.0, 1.0, 1.0),
                       origin=(0.0, 0.0, 0.0), coefficients=False, compressor="lz4", progress=True,
                       prefilter="none", padding="linear"):
    """Write a volume spline's padded data, its min-max octree and metadata (and, if asked, its coefficients).

    Parameters
    ----------
    path : str or Path
        The zarr group to create (replaced if it exists).
    samples : (nz, ny, nx) dask array, zarr array, zarr path or array_like
    scheme : {"quadratic", "cubic"}
    chunks : int or (int, int, int)
        Cubes per tile (z, y, x); zarr chunks of the arrays.
    spacing, origin : 3 floats
        ``(dx, dy, dz)`` and the position of sample (0, 0, 0), as for ``VolumeSpline``.
    coefficients : bool
        Also store every cube's BB coefficients (``(nz, ny, nx, 24, m)`` float64: small volumes only).
    compressor : {"lz4", "zstd", None}
        As for :func:`~.store.write_terrain_store`.
    progress : bool
    prefilter, padding
        As for :class:`~splinevis.volume.VolumeSpline`, except ``prefilter="interpolate"`` (a global solve:
        refused); ``"local"`` reads one more sample layer around each tile.

    Returns
    -------
    VolumeStore

    Examples
    --------
    >>> import tempfile
    >>> z, y, x = np.mgrid[0:6, 0:6, 0:6].astype(float)
    >>> store = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x + y, "quadratic", chunks=4, progress=False)
    >>> store
    VolumeStore(scheme='quadratic', cubes=6x6x6, tiles of 4x4x4, depth=3, value_range=(0.0, 10.0))
    >>> store.cube_coefficients([[2, 3, 1]])[0, 0, 0]  # coefficient 0: the cube centre (2, 3, 1)
    np.float64(5.0)
    """
    import dask
    import zarr

    from ..volume.schemes import _check_scheme

    scheme = _check_scheme(scheme)
    t = _tiles3(chunks)
    v = as_dask_array(samples)
    # one padded array, cut into the tiles' samples, feeds the stored data, the bounds and the coefficients
    P, cells = _tiled_padded(samples, t, scheme=scheme, prefilter=prefilter, padding=padding)
    _cube_ranges(P, cells, scheme)  # checks the tiles before anything is computed
    vmin, vmax = run(dask.delayed(tuple)([v.min(), v.max()]), progress=progress,
                     label="volume store: data range" if progress else "")
    group = zarr.open_group(str(path), mode="w")
    group.attrs.update({"kind": _KIND, "scheme": scheme, "spacing": [float(s) for s in spacing],
                        "origin": [float(o) for o in origin], "value_range": [float(vmin), float(vmax)],
                        "shape": list(v.shape), "tile": list(t), "prefilter": prefilter, "padding": padding})
    codecs = _codecs(compressor)
    padded = group.create_array("padded", shape=P.shape, chunks=t, dtype="f8", compressors=codecs)
    # its chunks are the tiles' (the last one two samples longer): no two blocks write one zarr chunk
    run(_store([P], [padded]), progress=progress,
        label=f"volume store: padded data of {'x'.join(map(str, v.shape[::-1]))} samples" if progress else "")
    # the tiles read their halos from the stored data: no task shared between tiles, one tile per worker in memory
    sources, targets = [], []
    _level0(group, "octree", _cube_ranges(P, cells, scheme, stored=padded), sources, targets, compressor)
    if coefficients:
        c = _coefficients(P, cells, scheme, stored=padded)
        sources.append(c)
        targets.append(group.create_array("coefficients", shape=c.shape, chunks=t + c.shape[3:], dtype="f8",
                                          compressors=codecs))
    run(_store(sources, targets), progress=progress,
        label=f"volume store: {scheme} coefficient bounds of the cubes" if progress else "")
    _, sources, targets = _upper_levels(group, "octree", max(t), compressor)
    run(_store(sources, targets), progress=progress, label="volume store: the octree" if progress else "")
    return open_volume_store(path)


def open_volume_store(path, scheme=None):
    """Open a store written by :func:`write_volume_store` (reads the attributes only).

    Examples
    --------
    >>> open_volume_store("/nonexistent/v.zarr")
    Traceback (most recent call last):
    FileNotFoundError: no volume store at '/nonexistent/v.zarr': write one with write_volume_store(path, samples, scheme).
    """
    return VolumeStore(*_open_store(path, _KIND, "volume", "write_volume_store", scheme))


class VolumeStore:
    """A volume spline written tile by tile (made by :func:`open_volume_store` / :func:`write_volume_store`).

    Attributes
    ----------
    scheme : str
    prefilter, padding : str
        What the stored padded data are (:class:`~splinevis.volume.VolumeSpline`'s options).
    spacing, origin : tuples of 3 floats
    shape : (nz, ny, nx) cubes
    tile : (int, int, int) cubes per tile
    value_range : (float, float)

    Examples
    --------
    >>> import tempfile
    >>> s = write_volume_store(tempfile.mkdtemp() + "/v.zarr", np.zeros((3, 4, 5)), "cubic", chunks=2,
    ...                        progress=False)
    >>> s.shape, s.tile, s.padded.shape
    ((3, 4, 5), (2, 2, 2), (5, 6, 7))
    """

    def __init__(self, group, attrs, path):
        self._g = group
        self.path = path
        self.scheme = attrs["scheme"]
        self.spacing = tuple(float(v) for v in attrs["spacing"])
        self.origin = tuple(float(v) for v in attrs["origin"])
        self.shape = tuple(int(v) for v in attrs["shape"])
        self.tile = tuple(int(v) for v in attrs["tile"])
        self.value_range = tuple(float(v) for v in attrs["value_range"])
        self.prefilter = attrs.get("prefilter", "none")  # stores written before the option: the paper's scheme
        self.padding = attrs.get("padding", "linear")

    @property
    def padded(self):
        """The zarr array of the padded data (``VolumeSpline.padded``), read lazily.

        >>> import tempfile
        >>> s = write_volume_store(tempfile.mkdtemp() + "/v.zarr", np.arange(8.0).reshape(2, 2, 2), chunks=2,
        ...                        progress=False)
        >>> s.padded[1, 1].tolist()  # the row y = 0, z = 0 extended to x = -1 and x = 2
        [-1.0, 0.0, 1.0, 2.0]
        """
        return self._g["padded"]

    @property
    def depth(self) -> int:
        """Levels of the octree above the cubes.

        >>> import tempfile
        >>> write_volume_store(tempfile.mkdtemp() + "/v.zarr", np.zeros((5, 4, 3)), chunks=2, progress=False).depth
        3
        """
        return len(self._g["octree"]) - 1

    def level(self, L):
        """``(lo, hi)`` float32 arrays of octree level ``L`` (level 0: ``VolumeSpline.cube_ranges()``).

        >>> import tempfile
        >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
        >>> lo, hi = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x, chunks=2, progress=False).level(0)
        >>> float(hi[1, 1, 1])  # data 0..2 around cube (1, 1, 1), one float32 step outward
        2.000000238418579
        """
        if not 0 <= L <= self.depth:
            raise ValueError(f"level must be in 0..{self.depth}, got {L}.")
        a = self._g["octree"][str(L)][...]
        return a[..., 0], a[..., 1]

    def octree(self, from_level=0):
        """A :class:`~splinevis.hierarchy.MinMaxPyramid` of level ``from_level`` and above.

        >>> import tempfile
        >>> z, y, x = np.mgrid[0:8, 0:8, 0:8].astype(float)
        >>> store = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x, chunks=4, progress=False)
        >>> store.octree().nodes(2.5, 1).shape  # as VolumeSpline(x).octree
        (16, 3)
        """
        from ..hierarchy.pyramid import MinMaxPyramid

        return MinMaxPyramid(*self.level(from_level))

    def cube_coefficients(self, cubes):
        """``(n, 24, m)`` BB coefficients of cubes ``(n, 3)`` ``(i, j, k)``, reading only the padded data around
        them (``VolumeSpline.cube_coefficients``' values).

        >>> import tempfile
        >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
        >>> s = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x + 2 * y + 3 * z, "cubic", chunks=2, progress=False)
        >>> round(float(s.cube_coefficients([[1, 2, 3]])[0, 0, 0]), 9)
        14.0
        """
        from ..volume.schemes import STENCIL, tet_weights

        c = np.asarray(cubes, dtype=np.int64).reshape(-1, 3)
        nz, ny, nx = self.shape
        if len(c) and ((c < 0).any() or (c >= np.array([nx, ny, nz])).any()):
            raise ValueError(f"cubes must be (i, j, k) with 0 <= i < {nx}, 0 <= j < {ny}, 0 <= k < {nz}.")
        W = tet_weights(self.scheme)
        if len(c) == 0:
            return np.zeros((0, 24, W.shape[1]))
        lo, hi = c.min(axis=0), c.max(axis=0) + 3  # padded index of cube c's stencil: c + 1 + (-1 .. 1)
        block = self.padded[lo[2]:hi[2], lo[1]:hi[1], lo[0]:hi[0]]
        idx = c[:, None, :] - lo + 1 + STENCIL[None]
        data = block[idx[..., 2], idx[..., 1], idx[..., 0]]
        return (data @ W.reshape(-1, 27).T).reshape(-1, 24, W.shape[1])

    @property
    def tiles(self) -> tuple:
        """``(ntz, nty, ntx)`` tiles (bricks) of the store.

        >>> import tempfile
        >>> write_volume_store(tempfile.mkdtemp() + "/v.zarr", np.zeros((5, 4, 3)), chunks=2, progress=False).tiles
        (3, 2, 2)
        """
        return tuple(-(-n // t) for n, t in zip(self.shape, self.tile))

    def window(self, k0, k1, j0, j1, i0, i1):
        """The tiles ``[k0, k1) x [j0, j1) x [i0, i1)`` (z, y, x) as an in-memory
        :class:`~splinevis.volume.model.VolumeSpline`: the stored padded data of their cubes and one layer
        around them (the neighbouring samples inside the volume, the store's padding at its border), so its
        coefficients are the whole volume's spline's, bit for bit. Reads those tiles' chunks and the next
        chunk along each axis (the layer above them).

        >>> import tempfile
        >>> z, y, x = np.mgrid[0:8, 0:8, 0:8].astype(float)
        >>> s = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x * y - z, chunks=4, origin=(10.0, 0.0, 0.0),
        ...                        progress=False)
        >>> w = s.window(1, 2, 0, 1, 1, 2)  # cubes 4..7 (z), 0..3 (y), 4..7 (x)
        >>> w.shape, w.origin.tolist(), round(float(w.evaluate([[15.25, 2.5, 4.75]])[0]), 9)
        ((4, 4, 4), [14.0, 0.0, 4.0], 8.375)
        """
        from ..volume.model import VolumeSpline

        ntz, nty, ntx = self.tiles
        if not (0 <= k0 < k1 <= ntz and 0 <= j0 < j1 <= nty and 0 <= i0 < i1 <= ntx):
            raise ValueError(f"window tiles [{k0}, {k1}) x [{j0}, {j1}) x [{i0}, {i1}) (z, y, x) must be non-empty "
                             f"and inside the store's {ntz}x{nty}x{ntx} tiles.")
        (a0, a1), (b0, b1), (c0, c1) = [(lo * t, min(hi * t, n)) for lo, hi, t, n in
                                        zip((k0, j0, i0), (k1, j1, i1), self.tile, self.shape)]
        P = self.padded[a0:a1 + 2, b0:b1 + 2, c0:c1 + 2]  # cube c's sample is padded[c + 1]
        org = tuple(o + c * d for o, c, d in zip(self.origin, (c0, b0, a0), self.spacing))
        w = VolumeSpline.from_padded(P, self.scheme, spacing=self.spacing, origin=org,
                                     source=f"{self.path} tiles [{k0}:{k1}, {j0}:{j1}, {i0}:{i1}]")
        w.prefilter = self.prefilter  # the padded data are the whole volume's (the window's own border is data)
        return w

    def __repr__(self):
        nz, ny, nx = self.shape
        tz, ty, tx = self.tile
        extra = "" if (self.prefilter, self.padding) == ("none", "linear") else \
            f", prefilter={self.prefilter!r}, padding={self.padding!r}"
        return (f"VolumeStore(scheme={self.scheme!r}, cubes={nx}x{ny}x{nz}, tiles of {tx}x{ty}x{tz}, depth={self.depth}, "
                f"value_range={self.value_range}{extra})")

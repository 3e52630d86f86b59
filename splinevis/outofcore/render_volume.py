"""Drawing an isosurface from a volume store: the bricks a view needs, at the finest level that fits.

Why our own code: the isosurface program draws one in-memory :class:`~splinevis.volume.model.VolumeSpline`
(its padded data is one float32 texture), and a 1024^3 store (8.6 GB of padded float64) does not fit memory.
So a view is drawn in three steps, as :mod:`.render` draws a terrain store:

1. the bricks in view: the tiles (bricks) whose coefficient range (the store's octree at the tile's level)
   holds the isovalue and whose box meets the camera's four side planes (:func:`.render.camera_planes`) or
   a world box; no other brick holds a visible piece of the isosurface (convex-hull property);
2. the level: level 0 (the store's cubes) when the box of those bricks has at most ``max_cubes`` cubes and
   its padded data fits the data texture (:func:`splinevis.gl.proxies.pack_rgba32f`: at most
   :data:`~splinevis.gl.proxies.MAX_TEXTURE_ROWS` rows of :data:`~splinevis.gl.proxies.TEXTURE_WIDTH` RGBA
   texels and :data:`~splinevis.gl.proxies.MAX_TEXTURE_BYTES`), else the first level ``L`` (every ``2^L``-th
   sample, read with a stride from the stored padded data) whose spline over that box does;
3. the spline: at level 0 only the bricks in view are read (each with the one-sample layer around it that
   its cubes' stencils need); the other bricks of the box get a constant, and the isosurface keeps only
   the relevant cubes of the bricks in view, which are exactly the whole volume's (same padded data). At
   level ``L >= 1`` the box of the level's samples is read with the layer around it (neighbouring samples
   inside the volume, linear extrapolation at its border, as ``VolumeSpline`` of the decimated volume) and
   all its relevant cubes are drawn (a coarse cube straddles bricks; its surface is not the store's).

The result is added with ``Plotter.add_spline`` (the isosurface program, unchanged); ``actor.store_view``
tells which level and bricks were drawn.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["VolumeView", "view_bricks", "load_volume_view", "add_volume_store", "MAX_CUBES"]

#: Default budget of cubes drawn at once: 2^24 (a 256^3 window, 144 MB of float64 padded data, 69 MB as the
#: float32 texture).
MAX_CUBES = 1 << 24


@dataclass
class VolumeView:
    """What :func:`load_volume_view` loaded: ``level`` (0: the store's cubes; ``L >= 1``: every ``2^L``-th
    sample), ``bricks`` (n, 3) ``(k, j, i)`` in view, ``read`` (bricks read one by one: level 0 only),
    ``cubes`` ``(slice_z, slice_y, slice_x)`` of the store's cubes spanned, ``shape`` ``(nz, ny, nx)`` cubes of
    the spline drawn and ``isosurface`` (its :class:`~splinevis.volume.isosurface.Isosurface`, relevant
    cubes restricted to the bricks in view).

    >>> VolumeView(0, np.zeros((1, 3), int), 1, (slice(0, 8),) * 3, (8, 8, 8), None).shape
    (8, 8, 8)
    """

    level: int
    bricks: np.ndarray
    read: int
    cubes: tuple
    shape: tuple
    isosurface: object


def _open(store):
    from .volume_store import VolumeStore, open_volume_store

    return store if isinstance(store, VolumeStore) else open_volume_store(store)


def brick_ranges(store):
    """``(lo, hi)`` float32 ``(ntz, nty, ntx)`` bounds of every brick's coefficients, from the octree level
    of the largest power of two dividing the tile (reduced over the remaining factor).

    >>> import tempfile
    >>> from splinevis.outofcore import write_volume_store
    >>> z, y, x = np.mgrid[0:12, 0:8, 0:8].astype(float)
    >>> lo, hi = brick_ranges(write_volume_store(tempfile.mkdtemp() + "/v.zarr", z, chunks=(6, 4, 4), progress=False))
    >>> lo.shape, round(float(lo[1, 0, 0]), 5), round(float(hi[0, 0, 0]), 5)  # z = 6..11, 0..5 and a layer
    ((2, 2, 2), 5.0, 6.0)
    """
    t = np.array(store.tile)
    L = int(min(min((int(v) & -int(v)).bit_length() - 1 for v in t), store.depth))
    lo, hi = store.level(L)
    f = t // (1 << L)  # nodes of level L per brick and axis
    for ax in range(3):
        starts = np.arange(0, lo.shape[ax], f[ax])
        lo = np.minimum.reduceat(lo, starts, axis=ax)
        hi = np.maximum.reduceat(hi, starts, axis=ax)
    return lo, hi


def _brick_boxes(store, idx):
    """World boxes (n, 6) ``(xmin, xmax, ymin, ymax, zmin, zmax)`` of bricks ``idx`` (n, 3) ``(k, j, i)``."""
    t = np.array(store.tile[::-1])  # x, y, z
    n = np.array(store.shape[::-1])
    c = idx[:, ::-1]
    lo = np.array(store.origin) + (np.minimum(c * t, n) - 0.5) * np.array(store.spacing)
    hi = np.array(store.origin) + (np.minimum((c + 1) * t, n) - 0.5) * np.array(store.spacing)
    return np.column_stack([lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1], lo[:, 2], hi[:, 2]])


def view_bricks(store, isovalue, box=None, *, renderer=None) -> np.ndarray:
    """Bricks ``(k, j, i)`` of ``store`` whose coefficient range holds ``isovalue`` and whose box meets a world
    ``box`` ``(xmin, xmax, ymin, ymax, zmin, zmax)``, ``"all"`` (the whole volume) or the view of
    ``renderer``'s camera (its four side planes, :func:`.render.camera_planes`).

    >>> import tempfile
    >>> from splinevis.outofcore import write_volume_store
    >>> z, y, x = np.mgrid[0:16, 0:16, 0:16].astype(float)
    >>> s = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x, chunks=4, progress=False)
    >>> b = view_bricks(s, 5.5, "all")  # the plane x = 5.5 lies in the bricks of x = 4..7
    >>> len(b), sorted(set(b[:, 2].tolist())), len(view_bricks(s, 5.5, (0.0, 15.0, 0.0, 2.0, 0.0, 2.0)))
    (16, [1], 1)
    """
    from .render import camera_planes
    from .view import _keep

    store = _open(store)
    iso = float(isovalue)
    if not np.isfinite(iso):
        raise ValueError(f"isovalue must be a finite number, got {isovalue!r}.")
    lo, hi = brick_ranges(store)
    ok = (lo <= iso) & (iso <= hi)
    idx = np.argwhere(ok).astype(np.int64)
    boxes = _brick_boxes(store, idx)
    world, planes = None, None
    if isinstance(box, str):
        if box != "all":
            raise ValueError(f"box must be a world box (xmin, xmax, ymin, ymax, zmin, zmax), 'all' or None (the "
                             f"camera's view), got {box!r}.")
    elif box is not None:
        world = tuple(float(v) for v in box)
        if len(world) != 6:
            raise ValueError(f"box must be (xmin, xmax, ymin, ymax, zmin, zmax), got {len(world)} numbers.")
    elif renderer is None:
        raise ValueError("give a world box, 'all' or a renderer whose camera defines the view.")
    else:
        planes = camera_planes(renderer)
    # the terrain tiles' test: a box meets the world box and lies not wholly outside any plane
    keep = _keep(boxes[:, :4], boxes[:, 4], boxes[:, 5], world, planes)
    return np.ascontiguousarray(idx[keep])


def _level_cubes(store, L):
    """``(nz, ny, nx)`` samples (= cubes) of level ``L``: every ``2^L``-th sample of the store."""
    s = 1 << L
    return tuple(-(-n // s) for n in store.shape)


def _widen(slices, n):
    """Slices of at least 3 cubes (the stencil's span; the volume has that many) inside ``0 .. n``."""
    out = []
    for q, m in zip(slices, n):
        a, b = q.start, q.stop
        if b - a < 3:
            a = max(0, b - 3)
            b = min(m, a + 3)
        out.append(slice(a, b))
    return tuple(out)


def _fits(shape, max_cubes):
    """At most ``max_cubes`` cubes, whose padded data fit one data texture (``pack_rgba32f``'s limits)."""
    from ..gl import proxies

    rows = min(proxies.MAX_TEXTURE_ROWS, proxies.MAX_TEXTURE_BYTES // (proxies.TEXTURE_WIDTH * 16))
    padded = int(np.prod([n + 2 for n in shape]))
    return min(shape) >= 3 and int(np.prod(shape)) <= max_cubes and padded <= 4 * proxies.TEXTURE_WIDTH * rows


def _read_brick(store, k, j, i):
    """The padded data of brick ``(k, j, i)`` and the layer around it (the stencils of its cubes)."""
    (a, b, c), t = (k, j, i), store.tile
    return store.padded[a * t[0]:min((a + 1) * t[0], store.shape[0]) + 2,
                        b * t[1]:min((b + 1) * t[1], store.shape[1]) + 2,
                        c * t[2]:min((c + 1) * t[2], store.shape[2]) + 2]


def _level0(store, bricks, cubes):
    """Padded data of the cubes ``cubes`` (3 slices): the bricks in view read, the others constant."""
    t = store.tile
    (a0, a1), (b0, b1), (c0, c1) = [(s.start, s.stop) for s in cubes]
    P = np.full((a1 - a0 + 2, b1 - b0 + 2, c1 - c0 + 2), np.nan)  # the stored data are finite
    lo = np.inf
    for k, j, i in bricks.tolist():
        B = _read_brick(store, k, j, i)
        z, y, x = k * t[0] - a0, j * t[1] - b0, i * t[2] - c0
        P[z:z + B.shape[0], y:y + B.shape[1], x:x + B.shape[2]] = B
        lo = min(lo, float(B.min()))
    P[np.isnan(P)] = lo  # the other bricks: a value of the read data (their cubes are never drawn)
    return P


def _level_padded(store, L, cubes):
    """Padded data of level ``L`` over the level cubes ``cubes`` (3 slices): the samples with the layer of
    neighbouring samples around them inside the level's volume, linear extrapolation at its border."""
    from ..volume import schemes
    from ..volume.stencil import PADDINGS

    s, n = 1 << L, _level_cubes(store, L)
    ext = [(max(q.start - 1, 0), min(q.stop + 1, m)) for q, m in zip(cubes, n)]
    E = store.padded[1 + s * ext[0][0]:1 + s * (ext[0][1] - 1) + 1:s,
                     1 + s * ext[1][0]:1 + s * (ext[1][1] - 1) + 1:s,
                     1 + s * ext[2][0]:1 + s * (ext[2][1] - 1) + 1:s]
    # extrapolated on every side with the store's padding (linear where the level has too few samples for it);
    # kept only where the window meets the border
    padding = getattr(store, "padding", "linear")
    P = schemes._pad(E, padding if min(E.shape) >= len(PADDINGS[padding]) else "linear")
    sl = tuple(slice(q.start - e0, q.stop - e0 + 2) for q, (e0, _) in zip(cubes, ext))
    return np.ascontiguousarray(P[sl])


def load_volume_view(store, isovalue, bricks, *, max_cubes=MAX_CUBES, level=None) -> VolumeView:
    """The isosurface that draws ``bricks`` (from :func:`view_bricks`): level 0 if their box of cubes fits
    ``max_cubes`` and a texture, else the first decimated level that fits (or ``level`` if given).

    >>> import tempfile
    >>> from splinevis.outofcore import write_volume_store
    >>> z, y, x = np.mgrid[0:16, 0:16, 0:16].astype(float)
    >>> s = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x * x + y + z, chunks=4, progress=False)
    >>> v = load_volume_view(s, 30.0, view_bricks(s, 30.0, (0.0, 15.0, 0.0, 3.0, 0.0, 3.0)))  # x near 5
    >>> v.level, v.read, v.shape, v.cubes[2], len(v.isosurface.relevant.cubes) > 0
    (0, 1, (4, 4, 4), slice(4, 8, None), True)
    >>> v = load_volume_view(s, 30.0, view_bricks(s, 30.0, "all"), max_cubes=1000)  # 16 x 16 x 8 cubes: level 1
    >>> v.level, v.shape, v.read, v.isosurface.spline.spacing.tolist()  # x: 5 cubes of 2 cover -0.5 .. 7.5
    (1, (8, 8, 5), 0, [2.0, 2.0, 2.0])
    """
    from ..volume.isosurface import Isosurface
    from ..volume.model import Relevant, VolumeSpline

    store = _open(store)
    iso = float(isovalue)
    bricks = np.asarray(bricks, dtype=np.int64).reshape(-1, 3)
    if len(bricks) == 0:
        raise ValueError(f"no brick of the volume store {store.path!r} holds the isovalue {iso!r} in the view "
                         f"(values {store.value_range}): point the camera at the volume, give a box that meets "
                         f"it or an isovalue in its range.")
    t = store.tile
    cubes = _widen([slice(int(bricks[:, a].min()) * t[a], min(int(bricks[:, a].max() + 1) * t[a], store.shape[a]))
                    for a in range(3)], store.shape)  # a thin last brick gets a neighbour's cubes (not drawn)
    depth = 0
    while min(_level_cubes(store, depth + 1)) >= 3:
        depth += 1

    def level_slices(L):  # the level's cubes whose domain covers the cubes' (as far as the level reaches)
        s, n = 1 << L, _level_cubes(store, L)
        return _widen([slice((2 * q.start - 1 + s) // (2 * s), min(-(-(2 * q.stop - 1 + s) // (2 * s)), m))
                       for q, m in zip(cubes, n)], n)

    def shape_of(L):
        return tuple(q.stop - q.start for q in level_slices(L))

    if level is None:
        level = next((L for L in range(depth + 1) if _fits(shape_of(L), max_cubes)), None)
        if level is None:
            raise ValueError(f"the view needs {shape_of(0)} cubes and even the coarsest level ({depth}: every "
                             f"{1 << depth}th sample, {shape_of(depth)} cubes) has more than fit (max_cubes="
                             f"{max_cubes}, the texture): zoom in or raise max_cubes.")
    elif not 0 <= level <= depth:
        raise ValueError(f"level must be in 0..{depth} (0: the store's cubes; L: every 2^L-th sample), got {level}.")
    level = int(level)
    s = 1 << level
    q = level_slices(level)
    org = tuple(o + qq.start * s * d for o, qq, d in zip(store.origin, q[::-1], store.spacing))
    spacing = tuple(s * d for d in store.spacing)
    name = f"{store.path} level {level} cubes [{', '.join(f'{a.start}:{a.stop}' for a in q)}]"
    if level == 0:
        P = _level0(store, bricks, cubes)
        read = len(bricks)
    else:
        P, read = _level_padded(store, level, q), 0
    spline = VolumeSpline.from_padded(P, store.scheme, spacing=spacing, origin=org, source=name)
    rel = spline.relevant(iso)
    if level == 0:  # keep the relevant cubes of the bricks in view: the others' stencils may hold the filler
        c = rel.cubes[:, ::-1] + np.array([a.start for a in q])  # (k, j, i)
        ntz, nty, ntx = store.tiles
        code = lambda b: (b[:, 0] * nty + b[:, 1]) * ntx + b[:, 2]  # noqa: E731
        keep = np.isin(code(c // np.array(t)), code(bricks))
        rel = Relevant(rel.isovalue, rel.cubes[keep], rel.masks[keep], rel.candidates, rel.seconds)
    surface = Isosurface(spline, iso, _relevant=rel)
    return VolumeView(level, bricks, read, cubes, spline.shape, surface)


def add_volume_store(plotter, store, isovalue, box=None, *, max_cubes=MAX_CUBES, level=None, **options):
    """Add the isosurface ``s = isovalue`` of the part of a volume store a view needs to ``plotter``, at the
    finest level that fits.

    Parameters
    ----------
    plotter : splinevis.Plotter
    store : VolumeStore or path
    isovalue : float
    box : (xmin, xmax, ymin, ymax, zmin, zmax), "all" or None
        The world box to draw; None: what the plotter's camera sees (set the camera first; it is kept).
    max_cubes : int
        Most cubes drawn at once; views needing more are drawn from a decimated level (every 2^L-th sample:
        a smoother surface).
    level : int, optional
        Force a level (0: the store's cubes).
    **options
        For ``plotter.add_spline`` (effects, ``program_options``, ``newton_iterations``).

    Returns
    -------
    SplineActor
        ``actor.store_view`` is the :class:`VolumeView` (level, bricks, cubes drawn).

    Examples
    --------
    >>> import tempfile
    >>> import splinevis
    >>> from splinevis.outofcore import write_volume_store
    >>> z, y, x = np.mgrid[-1:1:17j, -1:1:17j, -1:1:17j]
    >>> s = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x * x + y * y + z * z, chunks=4,
    ...                        spacing=(0.125,) * 3, origin=(-1.0,) * 3, progress=False)
    >>> pl = splinevis.Plotter(off_screen=True, window_size=(120, 90))
    >>> actor = add_volume_store(pl, s, 0.5, "all", max_cubes=1000, lights=1)  # 16^3 cubes hold it: level 1
    >>> actor.store_view.level, actor.store_view.shape, bool(pl.screenshot().std() > 5)  # 9^3 cover them
    (1, (9, 9, 9), True)
    >>> pl.close()
    """
    store = _open(store)
    bricks = view_bricks(store, isovalue, box, renderer=plotter.renderer if box is None else None)
    view = load_volume_view(store, isovalue, bricks, max_cubes=max_cubes, level=level)
    camera = plotter.camera_position if box is None else None
    actor = plotter.add_spline(view.isosurface, **options)
    if camera is not None:  # add_spline resets the camera to the new actor: the view was the camera's
        plotter.camera_position = camera
        plotter.reset_camera_clipping_range()
    actor.store_view = view
    return actor

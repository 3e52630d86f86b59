"""Drawing a terrain store: the tiles a view needs, at the finest level that fits the renderer.

Why our own code: the terrain program draws one in-memory :class:`~splinevis.terrain.model.TerrainSpline`
whose coefficient tables must fit the textures it checks (:func:`splinevis.terrain.limits.check_grid_size`),
and a 16k x 16k store does not fit memory to begin with. So a view is drawn in three steps:

1. the tiles in view: :func:`~.view.tiles_in_view` with the camera's four side planes (near and far are left
   out: the clipping range is reset to the terrain after it is added) or a world box;
2. the level: level 0 (the store's own cells) when the rectangle of those tiles has at most ``max_cells``
   cells and fits the coefficient textures, else the first heights level ``L`` (every ``2^L``-th sample,
   :mod:`.overview`) whose spline over that rectangle does;
3. the spline: at level 0 only the tiles in view are read (one zarr chunk each); a tile of the rectangle
   that is not in view gets a constant surface at its own lowest coefficient, inside its bounding box, which
   lies outside the view, so no pixel of the view changes. At level ``L >= 1`` the rectangle of the heights
   level is read and the store's scheme applied (:func:`~.overview.overview_spline`).

The result is added with ``Plotter.add_spline`` (the terrain program, unchanged); ``actor.store_view`` tells
which level, tiles and cells were drawn.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["StoreView", "camera_planes", "view_tiles", "load_view", "add_terrain_store", "MAX_CELLS"]

#: Default budget of cells drawn at once: about one cell per pixel of a 1024 x 1024 view (256 MB of
#: float64 coefficients); the coefficient textures themselves take up to 33.5M cells.
MAX_CELLS = 1 << 20


@dataclass
class StoreView:
    """What :func:`load_view` loaded: ``level`` (0: the store's cells; ``L >= 1``: heights level ``L``),
    ``tiles`` (n, 2) in view, ``read`` (tiles whose coefficients were read: level 0 only), ``rows`` and
    ``cols`` (the store's cells of the tiles' rectangle), ``cells`` ``(ncy, ncx)`` of the spline drawn and
    ``terrain`` (that :class:`~splinevis.terrain.model.TerrainSpline`).

    >>> StoreView(0, np.zeros((1, 2), int), 1, (0, 8), (0, 8), (8, 8), None).cells
    (8, 8)
    """

    level: int
    tiles: np.ndarray
    read: int
    rows: tuple
    cols: tuple
    cells: tuple
    terrain: object


def _open(store):
    from .store import TerrainStore, open_terrain_store

    return store if isinstance(store, TerrainStore) else open_terrain_store(store)


def camera_planes(renderer) -> np.ndarray:
    """The four side planes ``(a, b, c, d)`` (inside ``a x + b y + c z + d >= 0``) of a VTK renderer's
    active camera, in world coordinates.

    >>> from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow
    >>> renderer, window = vtkRenderer(), vtkRenderWindow()
    >>> window.SetSize(100, 100); window.AddRenderer(renderer)
    >>> renderer.GetActiveCamera().SetPosition(0, 0, 50)  # looking down -z at the origin, 30 degrees
    >>> p = camera_planes(renderer)
    >>> p.shape, bool((p[:, :3] @ [0, 0, 0] + p[:, 3] >= 0).all()), bool((p[:, :3] @ [20, 0, 0] + p[:, 3] >= 0).all())
    ((4, 4), True, False)
    """
    cam = renderer.GetActiveCamera()
    w, h = renderer.GetSize()
    planes = [0.0] * 24
    cam.GetFrustumPlanes(w / max(h, 1), planes)
    return np.array(planes[:16], dtype=np.float64).reshape(4, 4)


def view_tiles(store, box=None, *, renderer=None) -> np.ndarray:
    """Tiles of ``store`` in a world ``box`` ``(xmin, xmax, ymin, ymax, zmin, zmax)``, ``"all"``, or in the
    view of ``renderer``'s camera (:func:`camera_planes`).

    >>> import tempfile
    >>> from splinevis.outofcore.store import write_terrain_store
    >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.zeros((33, 33)), "C1", chunks=8, progress=False)
    >>> len(view_tiles(s, "all")), view_tiles(s, (1.0, 2.0, 9.0, 10.0, -1.0, 1.0)).tolist()
    (16, [[1, 0]])
    """
    from .view import tiles_in_view

    store = _open(store)
    if isinstance(box, str):
        if box != "all":
            raise ValueError(f"box must be a world box (xmin, xmax, ymin, ymax, zmin, zmax), 'all' or None (the "
                             f"camera's view), got {box!r}.")
        nty, ntx = store.tiles
        return np.argwhere(np.ones((nty, ntx), dtype=bool)).astype(np.int64)
    if box is not None:
        return tiles_in_view(store, box)
    if renderer is None:
        raise ValueError("give a world box, 'all' or a renderer whose camera defines the view.")
    return tiles_in_view(store, planes=camera_planes(renderer))


def _fits(ncx, ncy, max_cells, rows_per_texture):
    from ..terrain import limits

    if ncx * ncy > max_cells:
        return False
    try:
        limits.check_grid_size(ncx, ncy, rows_per_texture)
    except ValueError:
        return False
    return True


def _read_tile(store, iy, ix):
    """The coefficients of one tile (one zarr chunk)."""
    ty, tx = store.tile
    return store.coefficients[iy * ty:(iy + 1) * ty, ix * tx:(ix + 1) * tx]


def _level0(store, tiles, rows, cols):
    """TerrainSpline of the cells ``rows x cols`` from the tiles in view; other tiles constant at their minimum."""
    from ..terrain.model import TerrainSpline

    ty, tx = store.tile
    (r0, r1), (c0, c1) = rows, cols
    coef = np.empty((r1 - r0, c1 - c0, 2, 15))
    bounds = store.tile_bounds()
    inview = {(int(a), int(b)) for a, b in tiles}
    for iy in range(r0 // ty, -(-r1 // ty)):
        for ix in range(c0 // tx, -(-c1 // tx)):
            dst = coef[iy * ty - r0:(iy + 1) * ty - r0, ix * tx - c0:(ix + 1) * tx - c0]
            dst[...] = _read_tile(store, iy, ix) if (iy, ix) in inview else bounds[iy, ix, 0]
    org = (store.origin[0] + c0 * store.cell_spacing[0], store.origin[1] + r0 * store.cell_spacing[1])
    out = TerrainSpline(coef, store.cell_spacing, org, store.z_ref, scheme=store.scheme,
                        source=f"{store.path} cells [{r0}:{r1}, {c0}:{c1}], {len(inview)} tile(s) in view")
    out.data_range = store.data_range
    return out


def load_view(store, tiles, *, max_cells=MAX_CELLS, rows_per_texture=None, level=None) -> StoreView:
    """The spline that draws ``tiles`` (from :func:`view_tiles`): level 0 if their rectangle fits
    ``max_cells`` and the coefficient textures (``rows_per_texture``: the terrain program's option of that
    name), else the first heights level that fits (or ``level`` if given).

    >>> import tempfile
    >>> from splinevis.outofcore.store import write_terrain_store
    >>> y, x = np.mgrid[0:65, 0:65].astype(float)
    >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", x * y, "C1", chunks=16, progress=False)
    >>> v = load_view(s, view_tiles(s, (20.0, 40.0, 0.0, 10.0, 0.0, 1e4)))  # tiles (0, 1), (0, 2)
    >>> v.level, v.read, v.rows, v.cols, round(float(v.terrain.evaluate(30.5, 5.5)), 9)
    (0, 2, (0, 16), (16, 48), 167.75)
    >>> v = load_view(s, view_tiles(s, "all"), max_cells=1100)  # 64 x 64 cells do not fit: level 1, 32 x 32
    >>> v.level, v.cells, v.read
    (1, (32, 32), 0)
    """
    from ..gl.proxies import ROWS_PER_TEXTURE
    from .overview import _levels, level_rectangle, overview_spline

    store = _open(store)
    tiles = np.asarray(tiles, dtype=np.int64).reshape(-1, 2)
    if len(tiles) == 0:
        raise ValueError(f"no tile of the terrain store {store.path!r} (extent {store.extent}) is in the view: "
                         f"point the camera at the terrain or give a box that meets it.")
    rpt = ROWS_PER_TEXTURE if rows_per_texture is None else int(rows_per_texture)
    ty, tx = store.tile
    rows = (int(tiles[:, 0].min()) * ty, min(int(tiles[:, 0].max() + 1) * ty, store.shape[0]))
    cols = (int(tiles[:, 1].min()) * tx, min(int(tiles[:, 1].max() + 1) * tx, store.shape[1]))
    n_levels = len(_levels(store)) if "heights" in store._g else 0
    if level is None:
        candidates = [(0, (rows[1] - rows[0], cols[1] - cols[0]))]
        candidates += [(L, level_rectangle(store, L, rows, cols)[1]) for L in range(1, n_levels + 1)]
        level = next((L for L, (ny, nx) in candidates if _fits(nx, ny, max_cells, rpt)), None)
        if level is None:
            raise ValueError(f"the view needs {candidates[0][1][1]} x {candidates[0][1][0]} cells and even the "
                             f"coarsest of the store's {n_levels} heights level(s) has more than fit (max_cells="
                             f"{max_cells}, coefficient textures): zoom in or raise max_cells.")
    elif not 0 <= level <= n_levels:
        raise ValueError(f"level must be in 0..{n_levels} (0: the store's cells; L: heights level L), got {level}.")
    if level == 0:
        t = _level0(store, tiles, rows, cols)
        return StoreView(0, tiles, len(tiles), rows, cols, t.shape, t)
    t = overview_spline(store, level, rows, cols)
    return StoreView(int(level), tiles, 0, rows, cols, t.shape, t)


def add_terrain_store(plotter, store, box=None, *, max_cells=MAX_CELLS, level=None, **options):
    """Add the part of a terrain store a view needs to ``plotter``, at the finest level that fits.

    Parameters
    ----------
    plotter : splinevis.Plotter
    store : TerrainStore or path
    box : (xmin, xmax, ymin, ymax, zmin, zmax), "all" or None
        The world box to draw; None: what the plotter's camera sees (set the camera first; it is kept).
    max_cells : int
        Most cells drawn at once; views needing more are drawn from a coarser heights level
        (:func:`~.overview.overview_spline`: every 2^L-th sample, a smoother surface).
    level : int, optional
        Force a level (0: the store's cells).
    **options
        For ``plotter.add_spline`` (effects, ``program_options``; its ``rows_per_texture`` is honoured when
        the level is chosen).

    Returns
    -------
    SplineActor
        ``actor.store_view`` is the :class:`StoreView` (level, tiles, cells drawn).

    Examples
    --------
    >>> import tempfile
    >>> import splinevis
    >>> from splinevis.outofcore.store import write_terrain_store
    >>> y, x = np.mgrid[0:65, 0:65].astype(float)
    >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.sin(x / 9) * y, "C0", chunks=4, progress=False)
    >>> pl = splinevis.Plotter(off_screen=True, window_size=(120, 90))
    >>> actor = add_terrain_store(pl, s, "all", max_cells=100, lights=1)  # 16 x 16 cells: level 1 has 8 x 8
    >>> actor.store_view.level, actor.store_view.cells, bool(pl.screenshot().std() > 5)
    (1, (8, 8), True)
    >>> pl.close()
    """
    store = _open(store)
    tiles = view_tiles(store, box, renderer=plotter.renderer if box is None else None)
    rpt = (options.get("program_options") or {}).get("rows_per_texture")
    view = load_view(store, tiles, max_cells=max_cells, rows_per_texture=rpt, level=level)
    camera = plotter.camera_position if box is None else None
    actor = plotter.add_spline(view.terrain, **options)
    if camera is not None:  # add_spline resets the camera to the new actor: the view was the camera's
        plotter.camera_position = camera
        plotter.reset_camera_clipping_range()
    actor.store_view = view
    return actor

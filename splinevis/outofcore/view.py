"""Which tiles of a terrain store a view needs: the tiles' boxes against a world box or frustum planes.

Why our own code: a tile's box is its rectangle of the ground times the range of its coefficients (which
bounds the spline on it, by the convex-hull property); those ranges are the store's ``tiles`` array. The
tiles are visited through a min-max pyramid over them, top down, so a view of a few tiles of a terrain of a
million tiles tests a few dozen nodes; a node entirely outside the box (or one plane) is dropped with all
its tiles.
"""

from __future__ import annotations

import numpy as np

__all__ = ["tiles_in_view"]


def _node_boxes(store, L, idx):
    """World boxes (n, 6) ``(xmin, xmax, ymin, ymax)`` of the tile blocks ``idx`` (n, 2) of level ``L``."""
    ty, tx = store.tile
    ncy, ncx = store.shape
    s = 1 << L
    r0 = np.minimum(idx[:, 0] * s * ty, ncy)
    r1 = np.minimum((idx[:, 0] + 1) * s * ty, ncy)
    c0 = np.minimum(idx[:, 1] * s * tx, ncx)
    c1 = np.minimum((idx[:, 1] + 1) * s * tx, ncx)
    (x0, y0), (dx, dy) = store.origin, store.cell_spacing
    return np.column_stack([x0 + c0 * dx, x0 + c1 * dx, y0 + r0 * dy, y0 + r1 * dy])


def _keep(xy, zlo, zhi, box, planes):
    """Which boxes (xy (n, 4), z in [zlo, zhi]) touch the world box and lie not entirely outside a plane."""
    ok = np.ones(len(xy), dtype=bool)
    if box is not None:
        bx0, bx1, by0, by1, bz0, bz1 = box
        ok &= (xy[:, 0] <= bx1) & (xy[:, 1] >= bx0) & (xy[:, 2] <= by1) & (xy[:, 3] >= by0)
        ok &= (zlo <= bz1) & (zhi >= bz0)
    if planes is not None:
        for a, b, c, d in planes:  # inside: a x + b y + c z + d >= 0; test the box's farthest corner inside
            px = np.where(a >= 0, xy[:, 1], xy[:, 0])
            py = np.where(b >= 0, xy[:, 3], xy[:, 2])
            pz = np.where(c >= 0, zhi, zlo)
            ok &= a * px + b * py + c * pz + d >= 0
    return ok


def tiles_in_view(store, box=None, *, planes=None):
    """Tiles of a :class:`~.store.TerrainStore` whose bounding boxes touch a world box and/or lie not
    entirely outside any of a view's planes.

    Parameters
    ----------
    store : TerrainStore
    box : (xmin, xmax, ymin, ymax, zmin, zmax), optional
        World box (physical x, y and heights).
    planes : (k, 4) array_like, optional
        Planes ``(a, b, c, d)`` with the inside ``a x + b y + c z + d >= 0`` in world coordinates (a view
        frustum's six planes, as :class:`splinevis.hierarchy.FrustumCuller` uses them).

    Returns
    -------
    (n, 2) int64 array
        Tile indices ``(row, column)`` in lexicographic order; feed them to ``store.window``. A tile is
        returned when its box (its cells' rectangle times its coefficient range) meets the box and no plane
        has it entirely outside, so every cell whose box meets the view is in a returned tile.

    Examples
    --------
    >>> import tempfile
    >>> from splinevis.outofcore.store import write_terrain_store
    >>> y, x = np.mgrid[0:33, 0:33].astype(float)
    >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", x, "linear", chunks=8, progress=False)
    >>> tiles_in_view(s, (9.0, 12.0, 0.0, 3.0, -1.0, 100.0)).tolist()  # x = 9 .. 12 near y = 0
    [[0, 1]]
    >>> len(tiles_in_view(s, planes=[(1.0, 0.0, 0.0, -20.0)]))  # x >= 20: two columns of four tiles
    8
    """
    if box is None and planes is None:
        raise ValueError("give a world box (xmin, xmax, ymin, ymax, zmin, zmax) and/or frustum planes.")
    if box is not None:
        box = tuple(float(v) for v in box)
        if len(box) != 6:
            raise ValueError(f"box must be (xmin, xmax, ymin, ymax, zmin, zmax), got {len(box)} numbers.")
    if planes is not None:
        planes = np.asarray(planes, dtype=np.float64).reshape(-1, 4)
    from ..hierarchy.pyramid import MinMaxPyramid

    t = store.tile_bounds() + store.z_ref
    pyr = MinMaxPyramid(t[..., 0], t[..., 1])
    idx = np.zeros((1, 2), dtype=np.int64)
    for L in range(pyr.depth, -1, -1):
        if L < pyr.depth:
            kids = (2 * idx[:, None, :] + pyr._children[None]).reshape(-1, 2)
            idx = kids[(kids < np.array(pyr.levels[L][0].shape)).all(axis=1)]
        lo, hi = pyr.levels[L]
        zlo, zhi = lo[idx[:, 0], idx[:, 1]], hi[idx[:, 0], idx[:, 1]]
        idx = idx[_keep(_node_boxes(store, L, idx), zlo, zhi, box, planes)]
        if len(idx) == 0:
            break
    if len(idx):
        idx = idx[np.lexsort(idx.T[::-1])]
    return np.ascontiguousarray(idx, dtype=np.int64)

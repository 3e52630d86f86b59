"""A geometry image subdivided many levels down, tile by tile: the fold count of the build and the check on level
4 without the whole level in memory.

:func:`.subdivision.subdivide` makes every level of the whole image at once: for a 257 x 257 image, level 4 has
4097 x 4097 limit points, and its splits, averages, tangents and normals held about 12 GB at their peak, whatever
the mesh. Every step of the subdivision [Losasso2003, Table 1] is a stencil on the padded image, so a block of
the padded level-0 image, rows and columns ``[a, b]``, subdivides by itself into the limit points of rows and
columns ``[2^L a, 2^L (b - 2)]``, each computed by the same operations on the same numbers as in the whole
image: the same bits. :func:`limit_tiles` cuts the image into such blocks, neighbouring tiles sharing one row or
column of limit points so that each triangle of the limit grid lies in exactly one tile; :func:`fold_counts_tiled`
counts the folded triangles over the tiles, equal to :func:`.build.fold_counts` of the whole level.

Why our own code: the subdivision is the geometry image's own (:mod:`.subdivision`); this only cuts it up.
"""

from __future__ import annotations

import numpy as np

from .image import cut_vertices, pad
from .subdivision import _cross, _unit, average, cut_normals, limit, split, tangents

__all__ = ["limit_tiles", "fold_counts_tiled", "count_folds", "TILE_CELLS"]

#: Control cells per tile side: a level-4 tile of 64 cells has 1025 x 1025 limit points (25 MB a float64 array).
TILE_CELLS = 64


def _block(g0, r0: int, r1: int, c0: int, c1: int, level: int):
    """Limit points and plain unit normals (no cut-vertex normals) of padded level-0 rows ``[r0, r1]`` and
    columns ``[c0, c1]`` subdivided ``level`` times."""
    g = g0[r0:r1 + 1, c0:c1 + 1]
    for _ in range(level):
        g = average(split(g))
    ts, tt = tangents(g[..., :3])
    return limit(g)[..., :3], _unit(_cross(ts, tt))


def limit_tiles(control, level: int, cells: int = TILE_CELLS):
    """Tiles ``(row, col, points, normals)`` of the limit grid of the ``(n, n, C)`` geometry image ``control``
    subdivided ``level`` times (module docstring): ``points[i, j]`` is limit point ``(row + i, col + j)`` of
    :func:`.subdivision.subdivide`, bit for bit, ``normals`` the unit normals ``unit(T_s x T_t)`` there (at the
    cut vertices the zero vector or whatever the tangents give: :func:`.subdivision.subdivide` puts the level-0
    cut normals there instead). Square tiles of at most ``cells`` control cells a side (as many as divide the
    image evenly) share their last row and column with the next tile.

    >>> from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.subdivision import subdivide
    >>> G = apply_cut_constraint(octahedral_to_sphere(image_uv(17)))
    >>> whole = subdivide(G, 2).p
    >>> tiles = list(limit_tiles(G, 2, cells=8))
    >>> len(tiles), all(np.array_equal(p, whole[r:r + len(p), c:c + len(p)]) for r, c, p, _ in tiles)
    (4, True)
    """
    control = np.asarray(control, dtype=np.float64)
    level, cells = int(level), max(int(cells), 1)
    g0 = pad(control, 1)
    N = control.shape[0] - 1  # control cells a side; padded rows 0 .. N + 2
    tiles = -(-N // cells)
    while N % tiles:  # square tiles (the subdivision steps take square images): a tile count dividing N
        tiles += 1
    cells = N // tiles
    step = 1 << level
    for a in range(0, N, cells):
        b = min(a + cells, N)
        for c in range(0, N, cells):
            d = min(c + cells, N)
            p, nrm = _block(g0, a, b + 2, c, d + 2, level)
            yield a * step, c * step, p, nrm


def _triangle_folds(P, N, r: int, c: int):
    """Whether the two triangles of grid cell ``(r, c)`` of the local arrays ``P``, ``N`` face against the sum
    of their corners' normals: ``(up, lo)`` as :func:`.build.fold_counts` forms them."""
    a, b, cc, d = P[r, c], P[r, c + 1], P[r + 1, c], P[r + 1, c + 1]
    na, nb, nc, nd = N[r, c], N[r, c + 1], N[r + 1, c], N[r + 1, c + 1]
    return (bool(np.cross(b - a, d - a) @ (na + nb + nd) < 0.0), bool(np.cross(d - a, cc - a) @ (na + nd + nc) < 0.0))


def count_folds(P, N, step: int = 1) -> int:
    """Folded triangles of the grid of limit points ``P`` with normals ``N`` (both ``(R, C, 3)``), every
    ``step``-th point of each direction taken: the count of :func:`.build.fold_counts` before the cut vertices
    are set apart (a tile's share of :func:`fold_counts_tiled`).

    >>> i, j = np.mgrid[0:5, 0:5].astype(float)
    >>> P = np.stack([j, i, 0.0 * i], axis=2); up = np.broadcast_to([0.0, 0.0, 1.0], P.shape)
    >>> count_folds(P, up), count_folds(P, -up), count_folds(P, -up, 2)
    (0, 32, 8)
    """
    P, N = P[::step, ::step], N[::step, ::step]
    a, b, c, d = P[:-1, :-1], P[:-1, 1:], P[1:, :-1], P[1:, 1:]
    na, nb, nc, nd = N[:-1, :-1], N[:-1, 1:], N[1:, :-1], N[1:, 1:]
    up = np.einsum("ijk,ijk->ij", np.cross(b - a, d - a), na + nb + nd) < 0.0
    lo = np.einsum("ijk,ijk->ij", np.cross(d - a, c - a), na + nd + nc) < 0.0
    return int(up.sum() + lo.sum())


def fold_counts_tiled(control, level: int, cells: int = TILE_CELLS, workers: int = 1, step: int = 1,
                      tiles=None) -> tuple:
    """``(folded, at_cut)`` of the limit grid of ``control`` subdivided ``level`` times, as
    :func:`.build.fold_counts` counts them on :func:`.subdivision.subdivide`'s points and normals, tile by tile
    (module docstring). The triangles at the four cut vertices (normals there from the level-0 image, as
    :func:`.subdivision.subdivide` sets them) are counted in ``at_cut`` from a small block around each;
    ``workers`` threads share the tiles (numpy releases the interpreter lock in its loops; the counts are integers,
    so the sum does not depend on the order). ``step``: count on every ``step``-th limit point of each direction
    (a power of two up to ``2^level``: the grid of a coarser level's points taken from this level's). ``tiles``:
    the tiles' counts already made (an iterable of ``count_folds(points, normals, step)`` per tile), to share
    one pass over the tiles with other measures.

    >>> from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.subdivision import subdivide
    >>> from splinevis.geometry_image.build import fold_counts
    >>> G = octahedral_to_sphere(image_uv(17))
    >>> G = apply_cut_constraint(G + 0.2 * np.random.default_rng(0).normal(size=G.shape))  # a crumpled sphere
    >>> s = subdivide(G, 3)
    >>> fold_counts(s.p, s.n), fold_counts_tiled(G, 3, cells=4), fold_counts_tiled(G, 3, cells=5, workers=2)
    ((31, 2), (31, 2), (31, 2))
    """
    control = np.asarray(control, dtype=np.float64)
    level, sub = int(level), int(step)
    if sub < 1 or sub & (sub - 1) or sub > 1 << level:
        raise ValueError(f"step must be a power of two from 1 to 2^level = {1 << level}, got {step!r}.")
    scale = (1 << level) // sub  # limit points of the counted grid per control cell
    M = scale * (control.shape[0] - 1) + 1

    def count(tile):
        return count_folds(tile[2], tile[3], sub)

    if tiles is not None:
        folded = int(sum(tiles))
    elif int(workers) > 1:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(int(workers)) as pool:
            folded = sum(pool.map(count, limit_tiles(control, level, cells)))
    else:
        folded = sum(count(t) for t in limit_tiles(control, level, cells))
    g0 = pad(control, 1)
    at_normal = cut_normals(g0)
    n_cells = control.shape[0] - 1
    at_cut = 0
    for k, (vr, vc) in enumerate(cut_vertices(M)):
        # two control cells a side around the cut vertex (a control point), square: limit rows [2^L a, 2^L (a + 2)]
        i, j = vr // scale, vc // scale
        a, c = (min(max(x - 1, 0), n_cells - 2) for x in (i, j))
        P, N = _block(g0, a, a + 4, c, c + 4, level)
        P, N = P[::sub, ::sub], N[::sub, ::sub]
        r0, c0 = a * scale, c * scale
        Ncut = N.copy()
        Ncut[vr - r0, vc - c0] = at_normal[k]
        for cr in (vr - 1, vr):
            for cc in (vc - 1, vc):
                if not (0 <= cr < M - 1 and 0 <= cc < M - 1):
                    continue
                up_corners = {(cr, cc), (cr, cc + 1), (cr + 1, cc + 1)}
                lo_corners = {(cr, cc), (cr + 1, cc + 1), (cr + 1, cc)}
                plain = _triangle_folds(P, N, cr - r0, cc - c0)
                cut = _triangle_folds(P, Ncut, cr - r0, cc - c0)
                for touches, was, now in zip(((vr, vc) in up_corners, (vr, vc) in lo_corners), plain, cut):
                    if touches:
                        folded -= was  # counted in its tile with the plain normal
                        at_cut += now
    return folded, at_cut

"""Bounding geometry of the isosurface program: one box per block of cubes (default) or per relevant cube.

Block proxies: one box per block of ``block_size``^3 cubes holding relevant cubes, with the flat attribute
``sv_cube = (first cube (i, j, k), block id)`` and the interpolated block-local corner coordinates
``sv_local``; each fragment walks the block's cubes front to back. Cube proxies (closest to the paper's
per-tetrahedron proxies [Kalbe2008, sec. 5.2]): one box per relevant cube with ``sv_cube = (i, j, k, low 12
bits of the tetrahedron mask)``, ``sv_cube_extra = (high 12 bits of the mask, the cube's first table row as
two 12-bit halves)`` and ``sv_local``.
"""

from __future__ import annotations

import numpy as np

from ..gl.proxies import BOX_CORNERS, box_triangles
from .model import Relevant, VolumeSpline

__all__ = ["BLOCK_SIZE", "proxy_units", "proxy_geometry", "table_rows"]

#: Cubes per block edge of the default block proxies.
BLOCK_SIZE = 8


def proxy_units(spline: VolumeSpline, rel: Relevant, proxy: str, block_size: int):
    """The proxy boxes as (first cube (n, 3) int, cubes per axis (n, 3) int), in drawing order.

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> spline = VolumeSpline(sphere_grid(12))
    >>> first, size = proxy_units(spline, spline.relevant(0.7), "blocks", 8)  # 12 cubes: blocks of 8 and 4
    >>> first[-1], size[-1], len(first)
    (array([8, 8, 8]), array([4, 4, 4]), 8)
    """
    if proxy == "blocks":
        B = block_size
        if not len(rel.cubes):
            return np.zeros((0, 3), np.int64), np.zeros((0, 3), np.int64)
        nb = np.array(spline.shape[::-1]) // B + 1
        bc = rel.cubes // B
        key = np.unique((bc[:, 0] * nb[1] + bc[:, 1]) * nb[2] + bc[:, 2])  # 1-D unique: (x, y, z) lexicographic
        first = np.column_stack([key // (nb[1] * nb[2]), (key // nb[2]) % nb[1], key % nb[2]]) * B
        return first, np.minimum(B, np.array(spline.shape[::-1]) - first)
    return rel.cubes, np.ones_like(rel.cubes)


def proxy_geometry(spline: VolumeSpline, rel: Relevant, encoding: str, proxy: str = "cubes", block_size: int = 8):
    """Bounding geometry: points (model frame), triangles, flat attributes, varyings.

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> spline = VolumeSpline(sphere_grid(12))
    >>> points, triangles, attributes, varyings = proxy_geometry(spline, spline.relevant(0.7), "data", "blocks")
    >>> points.shape, triangles.shape, sorted(attributes), sorted(varyings)  # 8 boxes, 12 triangles each
    ((64, 3), (96, 3), ['sv_cube'], ['sv_local'])
    """
    if proxy == "blocks":
        first, ext = proxy_units(spline, rel, proxy, block_size)
        n = len(first)
        local = BOX_CORNERS[None] * ext[:, None, :]  # block-local corner coordinates, cube units
        corners = (first[:, None, :] - 0.5 + local) * spline.spacing
        tris = box_triangles(n)
        cube_attr = np.repeat(np.column_stack([first, np.arange(n)]).astype(np.float64), 8, axis=0)  # .w = block id
        attributes = {"sv_cube": cube_attr}
        return corners.reshape(-1, 3), tris, attributes, {"sv_local": local.reshape(-1, 3)}
    n = len(rel.cubes)
    corners = (rel.cubes[:, None, :] - 0.5 + BOX_CORNERS[None]) * spline.spacing  # model frame: origin at data point 0
    tris = box_triangles(n)
    # Masks and rows travel as 12-bit halves so that the shader's int(x + 0.5) is exact: for x >= 2^23 the
    # float32 sum x + 0.5 rounds to the even neighbour, which flipped the low bits of masks with bit 23 set
    # (the cause of the first holes in the sphere; it was first mistaken for VTK attribute precision).
    cube_attr = np.repeat(np.column_stack([rel.cubes, rel.masks & 4095]).astype(np.float64), 8, axis=0)
    extra = np.zeros((n, 3))
    extra[:, 0] = rel.masks >> 12
    if encoding in ("coefficients", "determining"):
        rows = table_rows(rel, encoding)
        extra[:, 1] = rows >> 12
        extra[:, 2] = rows & 4095
    attributes = {"sv_cube": cube_attr, "sv_cube_extra": np.repeat(extra, 8, axis=0)}
    return corners.reshape(-1, 3), tris, attributes, {"sv_local": np.tile(BOX_CORNERS, (n, 1))}


def table_rows(rel: Relevant, encoding: str = "coefficients") -> np.ndarray:
    """Row of each relevant cube's data in the per-isovalue table: its first tetrahedron's row (coefficient
    table) or the cube's own index (determining-set table).

    Examples
    --------
    >>> rel = Relevant(0.5, np.zeros((3, 3), np.int64), np.array([0b111, 0b1, 0b11]), 3, 0.0)
    >>> table_rows(rel), table_rows(rel, "determining")  # 3, 1 and 2 relevant tetrahedra
    (array([0, 3, 4]), array([0, 1, 2]))
    """
    if encoding == "determining":
        return np.arange(len(rel.cubes), dtype=np.int64)
    counts = np.bitwise_count(rel.masks).astype(np.int64)
    return np.concatenate([[0], np.cumsum(counts)[:-1]]) if len(counts) else np.zeros(0, np.int64)

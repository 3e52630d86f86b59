"""The isosurface program's tables: what the shader reads with ``texelFetch`` [Kalbe2008, sec. 5.1].

* the data texture: the padded volume minus a reference value, uploaded once per volume (isovalue
  independent); the shader rebuilds BB coefficients from a cube's 27 values;
* the coefficient table: every BB coefficient of every relevant tetrahedron (the "direct approach");
* the determining-set table (cubic): 56 determining coefficients per relevant cube;
* the per-block cube-info texture of the block proxies (tetrahedron masks, table rows);
* :func:`memory_report`: the bytes of each, for the study.

All are packed by :func:`splinevis.gl.proxies.pack_rgba32f` (one texture width for every program).
"""

from __future__ import annotations

import numpy as np

from ..gl.proxies import pack_rgba32f
from .isosurface import value_reference
from .model import Relevant, VolumeSpline
from .proxies import BLOCK_SIZE, proxy_units, table_rows

__all__ = ["data_texture", "coefficient_table", "determining_table", "mask_texture", "memory_report"]


def data_texture(spline: VolumeSpline) -> np.ndarray:
    """The padded volume minus :func:`~splinevis.volume.isosurface.value_reference`, x fastest, as a table
    texture (:func:`splinevis.gl.proxies.pack_rgba32f`).

    Examples
    --------
    >>> spline = VolumeSpline(np.arange(27.0).reshape(3, 3, 3) + 1000.0, order="zyx")  # 1000 + x + 3 y + 9 z
    >>> table = data_texture(spline)  # 5^3 padded values minus 1013, four per texel
    >>> table.shape, table.dtype, table[0, 0]  # from the padded corner (-1, -1, -1): 987 - 1013
    ((1, 8192, 4), dtype('float32'), array([-26., -25., -24., -23.], dtype=float32))
    """
    return pack_rgba32f(spline.padded, value_reference(spline), name="volume data texture")


def coefficient_table(spline: VolumeSpline, relevant: Relevant) -> np.ndarray:
    """Texture of the coefficients of every relevant tetrahedron (minus the reference value), in cube order
    then tetrahedron order; cube n's first row is ``table_rows(relevant)[n]``.

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> spline = VolumeSpline(sphere_grid(12))
    >>> rel = spline.relevant(0.7)
    >>> rows = coefficient_table(spline, rel).reshape(-1)[: 10 * rel.num_tets].reshape(-1, 10)
    >>> first = spline.cube_coefficients(rel.cubes[:1])[0][(rel.masks[0] >> np.arange(24)) & 1 == 1]
    >>> bool(np.allclose(rows[: len(first)], first - value_reference(spline), atol=1e-6))  # cube 0's tetrahedra
    True
    """
    out = np.empty((relevant.num_tets, spline.ncoef), dtype=np.float64)
    ref = value_reference(spline)
    chunk, pos = 16384, 0
    for s in range(0, len(relevant.cubes), chunk):
        coef = spline.cube_coefficients(relevant.cubes[s:s + chunk])  # (n, 24, m)
        bits = ((relevant.masks[s:s + chunk, None] >> np.arange(24)) & 1).astype(bool)
        sel = coef[bits]  # row-major: cube order, then tetrahedron order
        out[pos:pos + len(sel)] = sel - ref
        pos += len(sel)
    return pack_rgba32f(out)


def memory_report(spline: VolumeSpline, relevant: Relevant, block_size: int = BLOCK_SIZE) -> dict:
    """Bytes of each part for one isovalue: bounding geometry as VTK uploads it (float32 points, the flat
    and interpolated attributes, int indices) for the default block proxies (plus their per-cube info
    texture) and for cube proxies, the data texture, the coefficient table, every coefficient, the paper's
    determining sets (20 / 56 floats per cube), and the octree.

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> spline = VolumeSpline(sphere_grid(12))
    >>> rel = spline.relevant(0.7)
    >>> report = memory_report(spline, rel)
    >>> report["relevant_cubes"], report["proxy_blocks"], report["coefficient_table_bytes"]
    (272, 8, 128640)
    """
    n = len(relevant.cubes)
    m = spline.ncoef
    per_box = 8 * (3 * 4 + 4 * 4 + 3 * 4) + 12 * 3 * 4  # points + sv_cube + sv_local; 12 triangles
    blocks, _ = proxy_units(spline, relevant, "blocks", block_size)
    return {
        "relevant_cubes": n,
        "relevant_tets": relevant.num_tets,
        "proxy_blocks": len(blocks),
        "geometry_bytes": len(blocks) * (per_box + block_size ** 3 * 16),
        "geometry_cubes_bytes": n * (per_box + 8 * 3 * 4),  # + sv_cube_extra
        "data_texture_bytes": int(np.prod(spline.padded.shape)) * 4,
        "coefficient_table_bytes": relevant.num_tets * m * 4,
        "all_coefficients_bytes": n * 24 * m * 4,
        "determining_set_bytes": n * {10: 20, 20: 56}[m] * 4,
        "octree_bytes": spline.octree.nbytes,
    }


def determining_table(spline: VolumeSpline, rel: Relevant) -> np.ndarray:
    """The 56 determining coefficients of every relevant cube (cubic scheme, [Kalbe2008, sec. 5.1, Fig. 4]
    masks), minus the reference value, 56 floats per cube, as a table texture.

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> spline = VolumeSpline(sphere_grid(12), "cubic")
    >>> table = determining_table(spline, spline.relevant(0.7))
    >>> table.shape, table.dtype  # 272 cubes x 56 coefficients fit one row of 8192 texels
    ((1, 8192, 4), dtype('float32'))
    """
    from .cubic import determining_map

    _, K = determining_map()
    ref = value_reference(spline)
    out = np.empty((len(rel.cubes), K.shape[0]), dtype=np.float64)
    for s in range(0, len(rel.cubes), 32768):
        out[s:s + 32768] = (spline.stencil_data(rel.cubes[s:s + 32768]) - ref) @ K.T
    return pack_rgba32f(out)


def mask_texture(spline: VolumeSpline, rel: Relevant, block_size: int = BLOCK_SIZE,
                 encoding: str = "data") -> np.ndarray:
    """Cube-info table of the block proxies: for every block drawn (in :func:`proxy_units` order) one texel per
    cube of the block, ``block_id * B^3 + (a_z B + a_y) B + a_x``: the relevant-tetrahedron mask (exact:
    < 2^24), the cube's first coefficient-table row as two 12-bit halves, 0 = not relevant. Only blocks
    holding relevant cubes are stored.

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> spline = VolumeSpline(sphere_grid(12))
    >>> rel = spline.relevant(0.7)
    >>> info = mask_texture(spline, rel)  # 8 blocks x 8^3 cubes, one texel each
    >>> int((info[..., 0] > 0).sum()) == len(rel.cubes)
    True
    """
    B = block_size
    first, _ = proxy_units(spline, rel, "blocks", B)
    info = np.zeros((len(first) * B ** 3, 4), dtype=np.float32)
    if len(rel.cubes):
        nb = np.array(spline.shape[::-1]) // B + 1
        # proxy_units orders blocks lexicographically (x, then y, then z): a key in the same order
        key = lambda c: (c[:, 0] * nb[1] + c[:, 1]) * nb[2] + c[:, 2]  # noqa: E731
        bkey = key(first // B)
        block_id = np.searchsorted(bkey, key(rel.cubes // B))
        a = rel.cubes - (rel.cubes // B) * B
        k = block_id * B ** 3 + (a[:, 2] * B + a[:, 1]) * B + a[:, 0]
        rows = table_rows(rel, encoding)
        info[k, 0] = rel.masks
        info[k, 1] = rows >> 12
        info[k, 2] = rows & 4095
    return pack_rgba32f(info)

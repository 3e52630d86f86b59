"""Proxy geometry and RGBA32F tables: the parts every GPU program shares.

* Proxies are closed, outward-oriented triangle meshes that enclose the surface; the injection culls their
  front faces, so every pixel the surface can cover gets one fragment on the proxy's far side.
  :func:`boxes` makes axis-aligned boxes (one per terrain, block or cube).
* Tables are float data the shader reads with ``texelFetch``: a flat float32 array packed four floats per
  RGBA32F texel, :data:`TEXTURE_WIDTH` texels per row. Texel ``n`` sits at ``(n % W, n / W)``; the GLSL
  side is ``glsl/lib/core/table.glsl`` (``sv_table_texel``, ``sv_table_float``). One width for every
  program: a table is limited by its total size (W x GL_MAX_TEXTURE_SIZE texels = 537M floats), not by
  the shape of the data (a terrain 3000 cells wide fits).
"""

from __future__ import annotations

import numpy as np

__all__ = ["TEXTURE_WIDTH", "MAX_TEXTURE_ROWS", "MAX_TEXTURE_BYTES", "ROWS_PER_TEXTURE", "BOX_CORNERS",
           "BOX_TRIANGLES", "boxes", "box_triangles", "pack_rgba32f", "split_table"]

#: Texels per row of every table (llvmpipe's and most GPUs' GL_MAX_TEXTURE_SIZE is 16384; 8192 keeps
#: rows of moderate length for small tables). The GLSL constant SV_TABLE_WIDTH must equal it (tested).
TEXTURE_WIDTH = 8192
#: Rows a table may have (GL_MAX_TEXTURE_SIZE of llvmpipe and most GPUs).
MAX_TEXTURE_ROWS = 16384
#: Bytes one texture may hold: llvmpipe refuses larger textures (1 GiB) and the shader then reads zeros, with
#: no error (a 3601^2 terrain drew contour lines only). Larger tables are split (:func:`split_table`).
MAX_TEXTURE_BYTES = 1 << 30
#: Rows of one texture of a split table (TEXTURE_WIDTH RGBA32F texels of 16 bytes per row).
ROWS_PER_TEXTURE = MAX_TEXTURE_BYTES // (TEXTURE_WIDTH * 16)

#: Unit-cube corners, x fastest then y then z.
BOX_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
                       dtype=np.float64)
#: The 12 outward-oriented triangles of a box over :data:`BOX_CORNERS`.
BOX_TRIANGLES = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                          [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]], dtype=np.int64)


def boxes(lo, hi):
    """Axis-aligned boxes ``[lo_i, hi_i]`` as one mesh.

    Parameters
    ----------
    lo, hi : (3,) or (n, 3) array_like
        Opposite corners.

    Returns
    -------
    points : (8 n, 3) float64 ndarray
        Box i's corners are rows ``8 i .. 8 i + 7`` in :data:`BOX_CORNERS` order.
    triangles : (12 n, 3) int64 ndarray
        Outward oriented.

    Examples
    --------
    >>> points, triangles = boxes((0, 0, 0), (1, 2, 3))
    >>> points.shape, triangles.shape, points.max(axis=0).tolist()
    ((8, 3), (12, 3), [1.0, 2.0, 3.0])
    """
    lo = np.atleast_2d(np.asarray(lo, dtype=np.float64))
    hi = np.atleast_2d(np.asarray(hi, dtype=np.float64))
    if lo.shape != hi.shape or lo.shape[-1] != 3:
        raise ValueError(f"lo and hi must both have shape (3,) or (n, 3); got {lo.shape} and {hi.shape}.")
    points = np.where(BOX_CORNERS[None] > 0, hi[:, None, :], lo[:, None, :])  # exact corners, no arithmetic
    return points.reshape(-1, 3), box_triangles(len(lo))


def box_triangles(n: int) -> np.ndarray:
    """(12 n, 3) triangles of n boxes whose corners are rows ``8 i .. 8 i + 7`` in :data:`BOX_CORNERS` order.

    >>> box_triangles(2)[12].tolist()
    [8, 10, 9]
    """
    return (np.arange(n)[:, None, None] * 8 + BOX_TRIANGLES[None]).reshape(-1, 3)


def split_table(table: np.ndarray, rows_per_texture: int = ROWS_PER_TEXTURE) -> list:
    """The rows of a table texture in pieces of at most ``rows_per_texture`` rows (views, no copy): one texture
    each, so that none exceeds :data:`MAX_TEXTURE_BYTES`. Row r of the table is row ``r % rows_per_texture`` of
    piece ``r // rows_per_texture`` (``glsl/lib/core/table.glsl``).

    >>> [p.shape[0] for p in split_table(np.zeros((5, 8192, 4), np.float32), 2)]
    [2, 2, 1]
    """
    if rows_per_texture < 1:
        raise ValueError(f"rows_per_texture must be >= 1, got {rows_per_texture}.")
    return [table[r: r + rows_per_texture] for r in range(0, table.shape[0], rows_per_texture)]


def pack_rgba32f(values, shift: float = 0.0, *, name: str = "table", split: bool = False) -> np.ndarray:
    """Pack ``values - shift`` (any shape, read flat) into a table texture, four floats per texel.

    The subtraction happens into the float32 buffer (no float64 temporary of the table's size); the tail
    of the last row is zero.

    Parameters
    ----------
    values : array_like
    shift : float
        Subtracted before rounding to float32 (e.g. a reference value that keeps float32 precision).
    name : str
        Named in the error when the table is too large.
    split : bool
        The caller splits the table into textures of at most :data:`MAX_TEXTURE_BYTES` (:func:`split_table`);
        otherwise a table beyond that size is refused here, before the driver silently drops it.

    Returns
    -------
    (rows, TEXTURE_WIDTH, 4) float32 ndarray

    Examples
    --------
    >>> t = pack_rgba32f([1.0, 2.0, 3.0, 4.0, 5.0], shift=1.0)
    >>> t.shape, t[0, :2].tolist()
    ((1, 8192, 4), [[0.0, 1.0, 2.0, 3.0], [4.0, 0.0, 0.0, 0.0]])
    """
    flat = np.asarray(values).reshape(-1)
    texels = -(-len(flat) // 4)
    rows = max(1, -(-texels // TEXTURE_WIDTH))
    if rows > MAX_TEXTURE_ROWS:
        raise ValueError(f"{name} needs {rows} rows of {TEXTURE_WIDTH} texels; at most {MAX_TEXTURE_ROWS} fit one "
                         f"texture ({len(flat)} floats > {4 * TEXTURE_WIDTH * MAX_TEXTURE_ROWS}). Split the data into "
                         "tiles or use a coarser level.")
    if not split and rows * TEXTURE_WIDTH * 16 > MAX_TEXTURE_BYTES:
        raise ValueError(f"{name} needs {rows * TEXTURE_WIDTH * 16 / 2**20:.0f} MB; one texture holds at most "
                         f"{MAX_TEXTURE_BYTES / 2**20:.0f} MB on this OpenGL (larger ones read as zeros). Use a "
                         "coarser grid or split the data.")
    buf = np.empty(rows * TEXTURE_WIDTH * 4, dtype=np.float32)
    np.subtract(flat, shift, out=buf[: len(flat)], casting="same_kind")
    buf[len(flat):] = 0
    return buf.reshape(rows, TEXTURE_WIDTH, 4)

"""How large a terrain the GPU program can draw, checked from the grid's size before any coefficient is built.

A coefficient table of 8 texels per cell is split into textures of at most 1 GiB
(:data:`splinevis.gl.proxies.MAX_TEXTURE_BYTES`: llvmpipe silently reads zeros from larger ones); the shader has
branches for :data:`MAX_TABLE_TEXTURES` of them: 33.5M cells, e.g. 5792 x 5792 or two SRTM tiles.
"""

from __future__ import annotations

import numpy as np

from ..gl.proxies import MAX_TEXTURE_ROWS, ROWS_PER_TEXTURE, TEXTURE_WIDTH

__all__ = ["MAX_TABLE_TEXTURES", "HEIGHT_LIMIT", "check_grid_size", "check_height_range"]

#: Largest |height| (and height span) the terrain program accepts: the GPU computes in float32, whose
#: largest finite number is 3.4e38; heights are shifted and their differences scaled on the GPU, so the
#: limit keeps a margin of 1e6 below it.
HEIGHT_LIMIT = float(np.finfo(np.float32).max) / 1e6


def check_height_range(heights) -> None:
    """ValueError when heights exceed :data:`HEIGHT_LIMIT` (the GPU's float32 would overflow: a blank image).

    >>> check_height_range(np.array([[0.0, 1e300]]))
    Traceback (most recent call last):
    ...
    ValueError: heights: the largest |height| is 1e+300 (span 1e+300), beyond the limit 3.4e+32 the GPU program can take (it computes in float32, max 3.4e38; the limit keeps a margin for its arithmetic), so the picture would be blank. Rescale the heights (e.g. heights / 1e300, or other units) before building the terrain.
    """
    v = np.asarray(heights, dtype=np.float64)
    top = float(np.abs(v).max())
    span = float(v.max() - v.min())
    if top > HEIGHT_LIMIT or span > HEIGHT_LIMIT:
        raise ValueError(f"heights: the largest |height| is {top:.6g} (span {span:.6g}), beyond the limit "
                         f"{HEIGHT_LIMIT:.3g} the GPU program can take (it computes in float32, max 3.4e38; "
                         "the limit keeps a margin for its arithmetic), so the picture would be blank. Rescale "
                         "the heights (e.g. heights / 1e300, or other units) before building the terrain.")

#: Textures a split coefficient table may use (the shader's branches).
MAX_TABLE_TEXTURES = 4


def check_grid_size(ncx: int, ncy: int, rows_per_texture: int = ROWS_PER_TEXTURE) -> None:
    """Refuse a grid of ``ncx x ncy`` cells whose tables cannot be drawn, before its coefficients are built.

    Coefficient tables over 1 GiB are split by rows into up to :data:`MAX_TABLE_TEXTURES` textures
    (:func:`splinevis.gl.proxies.split_table`).

    >>> check_grid_size(3600, 3600)   # an SRTM tile: 1.7 GB of coefficients in 2 textures
    >>> check_grid_size(8000, 8000)
    Traceback (most recent call last):
    ...
    ValueError: a terrain of 8000 x 8000 cells needs 8 textures of 1024 MB for its coefficients; at most 4 are drawn: resample it coarser or split it into tiles of at most 33554432 cells.
    """
    texels = 8 * ncx * ncy
    rows = -(-texels // TEXTURE_WIDTH)
    pieces = -(-rows // rows_per_texture)
    if pieces > MAX_TABLE_TEXTURES or rows > MAX_TABLE_TEXTURES * MAX_TEXTURE_ROWS:
        per = rows_per_texture * TEXTURE_WIDTH * 16 / 2**20
        limit = MAX_TABLE_TEXTURES * rows_per_texture * TEXTURE_WIDTH // 8
        raise ValueError(f"a terrain of {ncx} x {ncy} cells needs {pieces} textures of {per:.0f} MB for its "
                         f"coefficients; at most {MAX_TABLE_TEXTURES} are drawn: resample it coarser or split it "
                         f"into tiles of at most {limit} cells.")

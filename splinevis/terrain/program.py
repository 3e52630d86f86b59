"""The GPU program of a TerrainSpline: textures (coefficients, min/max hierarchy) and uniforms."""

from __future__ import annotations

import numpy as np

from .._validation import check_choice, check_degree
from ..gl.spec import ProgramSpec
from .model import TerrainSpline

__all__ = ["terrain_program", "MAX_TEXTURE_WIDTH"]

#: GL_MAX_TEXTURE_SIZE of llvmpipe (and most GPUs); the coefficient table is 8 texels per cell wide.
MAX_TEXTURE_WIDTH = 16384


def _box(lo, hi):
    x = np.array([[lo[0], lo[1], lo[2]], [hi[0], lo[1], lo[2]], [hi[0], hi[1], lo[2]], [lo[0], hi[1], lo[2]],
                  [lo[0], lo[1], hi[2]], [hi[0], lo[1], hi[2]], [hi[0], hi[1], hi[2]], [lo[0], hi[1], hi[2]]])
    tris = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                     [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    return x, tris


def coefficient_table(terrain: TerrainSpline) -> np.ndarray:
    """(ncy, 8 ncx, 4) float32: per cell 8 RGBA texels, T0's 15 then T1's 15 coefficients, 2 zeros."""
    ncy, ncx = terrain.shape
    flat = np.zeros((ncy, ncx, 32), dtype=np.float32)
    flat[..., :30] = terrain.coefficients.reshape(ncy, ncx, 30)
    return flat.reshape(ncy, ncx * 8, 4)


def minmax_atlas(terrain: TerrainSpline):
    """(ncy, W, 4) float32 atlas of the hierarchy (level L at columns offsets[L]...), and the offsets."""
    levels = terrain.minmax_pyramid()
    widths = [lv.shape[1] for lv in levels]
    offsets = np.concatenate([[0], np.cumsum(widths)[:-1]])
    ncy = levels[0].shape[0]
    atlas = np.zeros((ncy, int(sum(widths)), 4), dtype=np.float32)
    for off, lv in zip(offsets, levels):
        # Round bounds outward to float32 so the stored box still encloses the float64 coefficients.
        lo = np.nextafter(lv[..., 0].astype(np.float32), np.float32(-np.inf))
        hi = np.nextafter(lv[..., 1].astype(np.float32), np.float32(np.inf))
        atlas[: lv.shape[0], off: off + lv.shape[1], 0] = lo
        atlas[: lv.shape[0], off: off + lv.shape[1], 1] = hi
    return atlas, offsets


def terrain_program(terrain: TerrainSpline, *, newton_iterations: int = 8, max_steps: int | None = None,
                    hierarchy: bool | int = True, roots: str = "bracketed") -> ProgramSpec:
    """Describe the ray-cast program of ``terrain`` (glsl/programs/terrain.glsl).

    ``roots``: ``"bracketed"`` (default: bracketed Newton on convex pieces) or ``"paper"`` (paper 000's
    Newton from four secure starting points, compiled in with ``SV_ROOTS_PAPER_NEWTON``).
    ``hierarchy``: True walks the full min/max quadtree; False walks cell by cell (level 0 only); an
    int caps the top level (what the benchmarks use to measure the hierarchy's effect).

    The model frame is centred on the terrain (``terrain.offset``): the shader works in local
    coordinates whatever the data's origin.
    """
    if not isinstance(terrain, TerrainSpline):
        raise TypeError(f"terrain must be a TerrainSpline, got {type(terrain).__name__}.")
    iterations = check_degree(newton_iterations, "newton_iterations", low=1, high=8)
    check_choice(roots, "roots", {"bracketed", "paper"})
    ncy, ncx = terrain.shape
    if 8 * ncx > MAX_TEXTURE_WIDTH or ncy > MAX_TEXTURE_WIDTH:
        raise ValueError(
            f"terrain of {ncx}x{ncy} cells exceeds the coefficient texture limit ({MAX_TEXTURE_WIDTH // 8} cells in x, "
            f"{MAX_TEXTURE_WIDTH} in y); split it into tiles."
        )
    levels = terrain.minmax_pyramid()
    if len(levels) > 16:
        raise ValueError(f"terrain needs {len(levels)} hierarchy levels; at most 16 are supported.")
    atlas, offsets = minmax_atlas(terrain)
    if hierarchy is True:
        top = len(levels) - 1
    elif hierarchy is False:
        top = 0
    else:
        top = check_degree(hierarchy, "hierarchy", low=0, high=len(levels) - 1)
    off = terrain.offset
    x0, x1, y0, y1 = terrain.extent
    cmin, cmax = float(terrain.coefficients.min()), float(terrain.coefficients.max())
    pad = 1e-6 * max(1.0, cmax - cmin)
    lo = np.array([x0 - off[0], y0 - off[1], cmin - pad])
    hi = np.array([x1 - off[0], y1 - off[1], cmax + pad])
    points, triangles = _box(lo, hi)
    sx, sy = terrain.cell_spacing
    level_offsets = np.zeros(16)
    level_offsets[: len(offsets)] = offsets
    return ProgramSpec(
        name="terrain",
        entry="programs/terrain.glsl",
        points=points,
        triangles=triangles,
        offset=tuple(off),
        defines={"SV_ROOTS_PAPER_NEWTON": roots == "paper"},
        uniforms={
            "sv_level_offset[]": level_offsets,
            "sv_top_level": top,
            "sv_ncells": (float(ncx), float(ncy)),
            "sv_index_scale": (1.0 / sx, 1.0 / sy),
            # u = (x_mc + off_x - x0) / sx
            "sv_index_shift": ((off[0] - x0) / sx, (off[1] - y0) / sy),
            "sv_zrange": (cmin - pad, cmax + pad),
            "sv_max_steps": int(max_steps if max_steps is not None else 4 * (ncx + ncy) + 64),
            "sv_newton_iterations": iterations,
            "sv_scalar_offset": float(terrain.z_ref),
            "sv_scalar_range": terrain.zrange,
        },
        textures={"sv_terrain_coef": coefficient_table(terrain), "sv_terrain_minmax": atlas},
    )

"""The terrain program: a ray cast through a min/max quadtree on one box proxy (glsl/programs/terrain.glsl).

Declares :data:`PROGRAM` for the registry: the GPU spec (coefficient and hierarchy tables, uniforms), the
float64 twin (:func:`splinevis.terrain.raycast.raycast_terrain`), the derived depth bound and the hard cases
(:mod:`splinevis.terrain.hard_cases`).

The walk runs in rounds (the hierarchy walk in its own loop, then one cell test for the whole SIMD group: llvmpipe
runs a loop body's every instruction for all fragments of a group); the previous walk, with the cell test inside the
walk's loop body and the same hits bit for bit, stays compiled under the flag ``SV_TERRAIN_LEGACY``
(``actor.set_variant({"SV_TERRAIN_LEGACY": True})``) for the side-by-side timing of benchmarks/bench_speedup.py.
"""

from __future__ import annotations

import numpy as np

from .._validation import check_degree
from ..bb.root_options import check_root_method, root_defines
from ..gl.contract import SplineProgram
from ..gl.error_bounds import model_frame_matrix, ray_depth_error_bound
from ..gl.proxies import ROWS_PER_TEXTURE, boxes, pack_rgba32f, split_table
from ..gl.spec import ProgramSpec
from .hard_cases import hard_cases
from .limits import check_grid_size
from .model import TerrainSpline
from .raycast import raycast_terrain
from .renderers import RENDERERS

__all__ = ["terrain_program", "coefficient_table", "hierarchy_table", "check_grid_size", "terrain_depth_bound",
           "debug_defines", "DEBUG_MODES", "PROGRAM"]

ROOTS = ("bracketed", "paper")
#: Proxies of the program (option ``proxy``): the bounding box, or the lifted mesh (splinevis.terrain.mesh_proxy).
PROXIES = ("box", "mesh")
#: Hierarchy level whose blocks the mesh proxy's tracing skips when the ray passes one wholly on its side.
MESH_SKIP_LEVEL = 2
#: Debug builds of the program (option ``debug``; none is compiled unless asked for, see :func:`debug_defines`).
DEBUG_MODES = ("counters", "flat", "restrict", "traversal", "raymarch")
#: Levels the shader's hierarchy uniforms hold.
MAX_LEVELS = 16


def coefficient_table(terrain: TerrainSpline, spare=None) -> np.ndarray:
    """Table texture of the coefficients: 8 texels per cell, cells row after row (cell (i, j) is number
    ``j ncx + i``), T0's 15 then T1's 15 coefficients, 2 zeros (:func:`splinevis.gl.proxies.pack_rgba32f`), or
    instead of the zeros the two values per cell of ``spare`` (ncy, ncx, 2) (the mesh proxy's Hessian bounds).

    Examples
    --------
    >>> terrain = TerrainSpline.from_heights(np.arange(30.0).reshape(5, 6), "linear")
    >>> table = coefficient_table(terrain)
    >>> table.shape, table.dtype  # 20 cells x 8 texels, in one row of the table width
    ((1, 8192, 4), dtype('float32'))
    >>> bool((table[0, :8].ravel()[:30] == terrain.coefficients[0, 0].ravel()).all())
    True
    """
    ncy, ncx = terrain.shape
    flat = np.zeros((ncy, ncx, 32), dtype=np.float32)
    flat[..., :30] = terrain.coefficients.reshape(ncy, ncx, 30)
    if spare is not None:
        flat[..., 30:] = spare
    return pack_rgba32f(flat, name="terrain coefficient table", split=True)


def hierarchy_table(terrain: TerrainSpline):
    """Table texture of the min/max quadtree, level after level (one texel per block, .rg = (min, max),
    rounded outward to float32 so each stored range still encloses the float64 coefficients), and the
    texel offset and width (blocks per row) of each level.

    Examples
    --------
    >>> y, x = np.mgrid[0:5, 0:6].astype(float)
    >>> terrain = TerrainSpline.from_heights(x + 2 * y, "linear")  # 5 x 4 cells, z_ref = 6.5
    >>> table, offsets, widths = hierarchy_table(terrain)
    >>> offsets.tolist(), widths.tolist()  # levels of 5 x 4, 3 x 2, 2 x 1 and 1 x 1 blocks
    ([0, 20, 26, 28], [5, 3, 2, 1])
    >>> table[0, offsets[-1], :2]  # the top node: all coefficients, rounded outward
    array([-6.5000005,  6.5000005], dtype=float32)
    """
    levels = terrain.hierarchy.levels
    widths = np.array([lo.shape[1] for lo, _ in levels])
    sizes = np.array([lo.size for lo, _ in levels])
    offsets = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    texels = np.zeros((int(sizes.sum()), 4), dtype=np.float32)
    for off, (lo, hi) in zip(offsets, levels):
        texels[off: off + lo.size, 0] = np.nextafter(lo.astype(np.float32), np.float32(-np.inf)).ravel()
        texels[off: off + lo.size, 1] = np.nextafter(hi.astype(np.float32), np.float32(np.inf)).ravel()
    return pack_rgba32f(texels, name="terrain hierarchy table"), offsets, widths


def debug_defines(debug: str | None) -> tuple:
    """Compile-time flags and uniforms of a debug build of the terrain program (``None``: none at all, so the
    default program's source is unchanged).

    ``"counters"``
        The fragment writes per-fragment work counts instead of its colour (``glsl/lib/core/counters.glsl``;
        read them with :func:`splinevis.analysis.profile.fragment_counters`); misses are written at the far
        plane instead of discarded, so their work is counted too. Uniform ``sv_counter_select``.
    ``"flat"``
        Shading replaced by the constant base colour (the hit's normal is then not evaluated either).
    ``"restrict"``
        As ``"flat"``, and a triangle whose restricted quartic changes sign is hit at its segment's start: the
        walk, the coefficient loads, clipping and restriction by blossoming, without the root finder.
    ``"traversal"``
        The hierarchy walk only: the first candidate cell (a level-0 cell whose height range the ray meets)
        is taken as the hit at the ray's entry, no coefficients loaded, no root finding; constant colour.
    ``"raymarch"``
        A reference height-field march instead of the exact ray cast: ``sv_march_steps`` fixed steps
        (uniform, default 64; set ``actor.extra_uniforms["sv_march_steps"]``) through the terrain's box, one
        coefficient texel read per step; constant colour. For benchmarks only: not exact.

    Examples
    --------
    >>> debug_defines(None)
    ({}, {})
    >>> debug_defines("traversal")
    ({'SV_DEBUG_NO_SHADING': True, 'SV_DEBUG_TRAVERSAL_ONLY': True}, {})
    >>> debug_defines("profile")
    Traceback (most recent call last):
    ValueError: debug must be None or one of 'counters', 'flat', 'restrict', 'traversal', 'raymarch'; got 'profile'.
    """
    if debug is None:
        return {}, {}
    if debug not in DEBUG_MODES:
        raise ValueError(f"debug must be None or one of {', '.join(map(repr, DEBUG_MODES))}; got {debug!r}.")
    if debug == "counters":
        return {"SV_DEBUG_COUNTERS": True}, {"sv_counter_select": 0}
    defines = {"SV_DEBUG_NO_SHADING": True}
    if debug == "restrict":
        defines["SV_DEBUG_NO_ROOTS"] = True
    if debug == "traversal":
        defines["SV_DEBUG_TRAVERSAL_ONLY"] = True
    if debug == "raymarch":
        defines["SV_DEBUG_RAYMARCH"] = True
        return defines, {"sv_march_steps": 64}
    return defines, {}


def terrain_program(terrain: TerrainSpline, style=None, *, newton_iterations: int = 8, max_steps: int | None = None,
                    hierarchy: bool | int = True, roots: str = "bracketed",
                    rows_per_texture: int = ROWS_PER_TEXTURE, debug: str | None = None, proxy: str = "box",
                    mesh_samples: int = 1, mesh_steps: int = 32) -> ProgramSpec:
    """Describe the ray-cast program of ``terrain`` (glsl/programs/terrain.glsl).

    ``roots``: ``"bracketed"`` (default: bracketed Newton on convex pieces) or ``"paper"`` (Newton from four
    secure starting points [Reis2008, sec. V]); names as in :mod:`splinevis.bb.root_options`.
    ``hierarchy``: True walks the full min/max quadtree; False walks cell by cell (level 0 only); an
    int caps the top level (what the benchmarks use to measure the hierarchy's effect).
    ``rows_per_texture``: rows of one texture of the coefficient table (default: 1 GiB textures; smaller
    values split small tables too, which the tests use to check the split path). ``debug``: None (default)
    or a debug build for profiling (:func:`debug_defines`). ``style`` decides nothing.
    ``proxy``: ``"box"`` (default: one box around the terrain, drawn from its far side) or ``"mesh"`` (the
    lifted tessellation of :mod:`splinevis.terrain.mesh_proxy` with ``mesh_samples`` x ``mesh_samples``
    sub-squares per cell; each fragment traces its ray from its own point to the first root by steps that
    cannot pass it, at most ``mesh_steps`` of them, then falls back to the full walk).

    The model frame is centred on the terrain (``terrain.offset``): the shader works in local
    coordinates whatever the data's origin.

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.terrain.model import TerrainSpline
    >>> t = TerrainSpline.from_heights(np.zeros((5, 9)), "C2")
    >>> spec = terrain_program(t, hierarchy=False)
    >>> spec.uniforms["sv_top_level"], spec.textures["sv_terrain_coef"].shape
    (0, (1, 8192, 4))
    """
    if not isinstance(terrain, TerrainSpline):
        raise TypeError(f"terrain must be a TerrainSpline, got {type(terrain).__name__}.")
    if proxy not in PROXIES:
        raise ValueError(f"proxy must be one of {', '.join(map(repr, PROXIES))}; got {proxy!r}.")
    if proxy == "mesh" and debug is not None:
        raise ValueError("proxy='mesh' has no debug builds.")
    iterations = check_degree(newton_iterations, "newton_iterations", low=1, high=8)
    extra_defines, extra_uniforms = debug_defines(debug)
    check_root_method(roots, ROOTS, degree=4)
    ncy, ncx = terrain.shape
    rows_per_texture = check_degree(rows_per_texture, "rows_per_texture", low=1, high=ROWS_PER_TEXTURE)
    check_grid_size(ncx, ncy, rows_per_texture)
    spare = None
    if proxy == "mesh":  # each cell's bounds for the tracing (mesh_proxy.trace_bounds), rounded up to float32
        from .mesh_proxy import trace_bounds

        k = check_degree(mesh_samples, "mesh_samples", low=1, high=16)
        spare = np.nextafter(trace_bounds(terrain, k).astype(np.float32), np.float32(np.inf))
    pieces = split_table(coefficient_table(terrain, spare), rows_per_texture)
    levels = terrain.hierarchy.levels
    if len(levels) > MAX_LEVELS:
        raise ValueError(f"terrain of {ncx}x{ncy} cells needs {len(levels)} hierarchy levels; at most {MAX_LEVELS} "
                         "are supported: split it into tiles.")
    table, offsets, widths = hierarchy_table(terrain)
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
    points, triangles = boxes([x0 - off[0], y0 - off[1], cmin - pad], [x1 - off[0], y1 - off[1], cmax + pad])
    sx, sy = terrain.cell_spacing
    level_offsets, level_widths = np.zeros(MAX_LEVELS, np.int64), np.zeros(MAX_LEVELS, np.int64)
    level_offsets[: len(offsets)] = offsets
    level_widths[: len(widths)] = widths
    mesh_options = {}
    if proxy == "mesh":
        from pathlib import Path

        from .mesh_proxy import lifted_mesh

        mesh = lifted_mesh(terrain, check_degree(mesh_samples, "mesh_samples", low=1, high=16))
        points, triangles = mesh.points, mesh.triangles
        # the repository's glsl/ first when the package runs from a source tree (a worktree whose editable
        # install points elsewhere); in an installed package the folder does not exist and is skipped
        src = Path(__file__).resolve().parents[2] / "glsl"
        # the eye (possibly) inside the region under the mesh, or the near plane cutting it where it is seen
        inside = lambda eye, view, parallel, near: ((not parallel and mesh.eye_inside(eye))
                                                    or mesh.near_cuts(eye, view, near))
        mesh_options = dict(attributes={"sv_mesh_cell": mesh.cells}, cull_front=False,
                            defines_per_frame=lambda eye, view, parallel, near: (
                                {"SV_TERRAIN_MESH_INSIDE": True} if inside(eye, view, parallel, near) else {}),
                            # the fragments of the faces the shader discards are not drawn at all (llvmpipe: the
                            # discarded back faces cost a third of the frame); the shader's test stays the rule
                            cull_per_frame=lambda eye, view, parallel, near: (
                                "front" if inside(eye, view, parallel, near) else "back"),
                            glsl_roots=(src,) if (src / "lib" / "terrain" / "mesh_guided.glsl").is_file() else ())
        extra_defines = {**extra_defines, "SV_TERRAIN_MESH": True}
        extra_uniforms = {**extra_uniforms, "sv_mesh_steps": check_degree(mesh_steps, "mesh_steps", low=0, high=256),
                          "sv_mesh_skip_level": min(MESH_SKIP_LEVEL, len(levels) - 1)}
    return ProgramSpec(
        name="terrain",
        entry="programs/terrain.glsl",
        points=points,
        triangles=triangles,
        offset=tuple(off),
        defines={**root_defines(roots), "SV_TERRAIN_SPLIT": len(pieces) > 1, "SV_TERRAIN_SPLIT3": len(pieces) > 2,
                 "SV_TERRAIN_SPLIT4": len(pieces) > 3, "SV_ROWS_PER_TEXTURE": int(rows_per_texture), **extra_defines},
        uniforms={
            "sv_level_offset[]": level_offsets,
            "sv_level_width[]": level_widths,
            "sv_top_level": top,
            "sv_ncells": (float(ncx), float(ncy)),
            "sv_index_scale": (1.0 / sx, 1.0 / sy),
            # u = (x_mc + off_x - x0) / sx
            "sv_index_shift": ((off[0] - x0) / sx, (off[1] - y0) / sy),
            "sv_zrange": (cmin - pad, cmax + pad),
            "sv_max_steps": int(max_steps if max_steps is not None else 4 * (ncx + ncy) + 64),
            "sv_newton_iterations": iterations,
            "sv_scalar_offset": float(terrain.z_ref),
            "sv_scalar_range": terrain.data_range if terrain.data_range is not None else terrain.zrange,
            **extra_uniforms,
        },
        textures={"sv_terrain_minmax": table,
                  **{"sv_terrain_coef" + (str(k) if k else ""): piece for k, piece in enumerate(pieces)}},
        **mesh_options,
    )


def terrain_depth_bound(terrain: TerrainSpline, matrix, origins, directions, t, *,
                        surface=None) -> np.ndarray:
    """Derived bound on |GPU - float64| window depth at hits ``origins + t directions`` (world): the shader
    works in the model frame (world - offset) and in index coordinates, so the rounded coordinates are
    bounded by the terrain's extent (:func:`splinevis.gl.error_bounds.ray_depth_error_bound`). The bound depends on
    the hits' positions only: ``surface`` (the contract's hit parameters) is not read.

    Examples
    --------
    >>> y, x = np.mgrid[0:5, 0:6].astype(float)
    >>> terrain = TerrainSpline.from_heights(x + 2 * y, "C1", spacing=(10.0, 10.0), origin=(100.0, 200.0))
    >>> o, d = np.array([[125.0, 215.0, 50.0]]), np.array([[0.0, 0.0, -1.0]])
    >>> t = raycast_terrain(terrain, o, d).t
    >>> bound = terrain_depth_bound(terrain, np.eye(4), o, d, t)  # identity camera: depth (z + 1) / 2
    >>> bool(0.0 < bound[0] < 1e-4)
    True
    """
    off = terrain.offset
    o_mc = np.asarray(origins) - off
    p = o_mc + np.asarray(t)[..., None] * np.asarray(directions)
    x0, x1, y0, y1 = terrain.extent
    coord = np.broadcast_to(np.array([x1 - x0, y1 - y0]), p[..., :2].shape)
    return ray_depth_error_bound(lambda q: terrain.gradient(q[..., 0] + off[0], q[..., 1] + off[1]),
                                 float(np.abs(terrain.coefficients).max()), model_frame_matrix(matrix, off),
                                 o_mc, directions, t, coord, proxy_size=float(max(x1 - x0, y1 - y0, np.ptp(terrain.zrange))))


def _model_from(heights, scheme: str = "C1", presmooth: int = 0, **read_options) -> TerrainSpline:
    """A TerrainSpline from anything :func:`splinevis.io.read_heights` reads, or a HeightGrid."""
    return TerrainSpline.from_heights(heights, scheme, presmooth=presmooth, **read_options)


PROGRAM = SplineProgram(
    "terrain", "raycast", TerrainSpline, terrain_program, reference=raycast_terrain, depth_bound=terrain_depth_bound,
    hard_cases=hard_cases, model_from=_model_from, root_methods=ROOTS, newton_iterations=8,
    options=("max_steps", "hierarchy", "roots", "rows_per_texture", "debug", "proxy", "mesh_samples", "mesh_steps"),
    description="quartic spline on the type-1 triangulation of a height grid, ray-cast through a min/max quadtree",
    renderers=RENDERERS)

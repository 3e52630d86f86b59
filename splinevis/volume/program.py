"""The GPU program of a volume isosurface (glsl/programs/isosurface.glsl): proxies, textures, uniforms.

Data streams (paper 003, sec. 5.1), two encodings selectable for measurement:

* ``encoding="data"`` (default): one float32 texture of the padded volume (``data - value_ref``), uploaded
  once per volume and independent of the isovalue; the shader fetches a cube's 27 values and rebuilds the
  BB coefficients of a tetrahedron with the scheme's averaging rules (generated
  glsl/lib/volume_stencil_*.glsl). This is paper 003's determining-set encoding taken one step further:
  the paper stores the 20 (quadratic) or 56 (cubic) determining coefficients per cube, which are
  themselves averages of the data; storing the data is 1 value per cube.
* ``encoding="coefficients"``: every BB coefficient of every relevant tetrahedron in a table (the "direct
  approach" the paper compares with), rebuilt for every isovalue.
* ``encoding="determining"`` (cubic): paper 003's own encoding, the 56 determining coefficients of every
  relevant cube (Fig. 4 masks); the shader derives the other 119 from them (generated
  glsl/lib/volume_determining_cubic.glsl).

Bounding geometry: one box per relevant cube (8 vertices, 12 triangles), with flat attributes
``sv_cube = (i, j, k, low 12 bits of the tet mask)``, ``sv_cube_extra = (high 12 bits of the mask, row of the
cube's first tetrahedron in the table as two 12-bit halves)``, and the
interpolated cube-local corner coordinates ``sv_local``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validation import check_choice, check_degree
from ..gl.spec import ProgramSpec
from .model import Relevant, VolumeSpline

__all__ = ["Isosurface", "isosurface_program", "set_isovalue", "data_texture", "coefficient_table", "memory_report",
           "TEXTURE_WIDTH", "CUBE_MARGIN", "INNER_MARGIN"]

#: Cubes per block edge of the default block proxies.
BLOCK_SIZE = 8
#: Texels per row of the linear data/coefficient textures (GL_MAX_TEXTURE_SIZE of llvmpipe is 16384).
TEXTURE_WIDTH = 8192
#: Clip margin (barycentric units) across the cube's faces (lam_0 >= -margin; lam_0 vanishes on the face of
#: the cube that tetrahedron [vQ, wF, u, u'] touches), against cracks between neighbouring cubes: each cube's
#: fragment gets its cube-local position by interpolation from exact corners, accurate to a few float32 ulps
#: of 1 (~1e-7); 2^-16 leaves a factor > 100. Both schemes are C1 across cube faces, so a polynomial
#: extended this far differs from its neighbour by O(margin^2) only.
CUBE_MARGIN = 2.0**-16
#: Margin across the faces inside a cube. One fragment computes all its tetrahedra from the same ray, so
#: only the rounding of the face parameters (~1e-7) must be covered; kept small because the quadratic
#: scheme is only C0 across 12 inner faces, where an extension deviates by margin x (normal-derivative jump).
INNER_MARGIN = 2.0**-21

_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
                    dtype=np.float64)
_BOX_TRIS = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                      [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]], dtype=np.int64)


@dataclass
class Isosurface:
    """The isosurface ``s = isovalue`` of a :class:`VolumeSpline`, what :meth:`splinevis.Plotter.add_spline`
    draws. ``relevant`` is computed on first use (and is all that changes with the isovalue)."""

    spline: VolumeSpline
    isovalue: float
    _relevant: Relevant | None = field(default=None, repr=False)

    def __post_init__(self):
        if not isinstance(self.spline, VolumeSpline):
            raise TypeError(f"spline must be a VolumeSpline, got {type(self.spline).__name__}.")
        self.isovalue = float(self.isovalue)
        if not np.isfinite(self.isovalue):
            raise ValueError(f"isovalue must be finite, got {self.isovalue!r}.")

    @property
    def relevant(self) -> Relevant:
        if self._relevant is None or self._relevant.isovalue != self.isovalue:
            self._relevant = self.spline.relevant(self.isovalue)
        return self._relevant

    @property
    def extent(self):  # texture coordinates span the volume's x/y (Style.texture_extent)
        b = self.spline.bounds
        return (b[0], b[1], b[2], b[3])


def value_reference(spline: VolumeSpline) -> float:
    """The value subtracted from the data before float32 upload (mid-range; isovalue independent)."""
    lo, hi = spline.value_range
    return 0.5 * (lo + hi)


def _linear_texture(values: np.ndarray, shift: float = 0.0) -> np.ndarray:
    """Values (minus ``shift``) packed 4 per RGBA32F texel, row after row of TEXTURE_WIDTH texels."""
    flat = np.asarray(values).reshape(-1)
    ntex = -(-len(flat) // 4)
    rows = max(1, -(-ntex // TEXTURE_WIDTH))
    buf = np.empty(rows * TEXTURE_WIDTH * 4, dtype=np.float32)
    np.subtract(flat, shift, out=buf[: len(flat)], casting="same_kind")  # no float64 temporary
    buf[len(flat):] = 0
    return buf.reshape(rows, TEXTURE_WIDTH, 4)


def data_texture(spline: VolumeSpline) -> np.ndarray:
    """(rows, TEXTURE_WIDTH, 4) float32: the padded volume minus :func:`value_reference`, x fastest."""
    return _linear_texture(spline.padded, value_reference(spline))


def coefficient_table(spline: VolumeSpline, relevant: Relevant) -> np.ndarray:
    """Texture of the coefficients of every relevant tetrahedron (minus the reference value), in cube order
    then tetrahedron order; cube n's first row is ``_table_rows(relevant)[n]``."""
    out = np.empty((relevant.num_tets, spline.ncoef), dtype=np.float64)
    ref = value_reference(spline)
    chunk, pos = 16384, 0
    for s in range(0, len(relevant.cubes), chunk):
        coef = spline.cube_coefficients(relevant.cubes[s:s + chunk])  # (n, 24, m)
        bits = ((relevant.masks[s:s + chunk, None] >> np.arange(24)) & 1).astype(bool)
        sel = coef[bits]  # row-major: cube order, then tetrahedron order
        out[pos:pos + len(sel)] = sel - ref
        pos += len(sel)
    return _linear_texture(out)


def memory_report(spline: VolumeSpline, relevant: Relevant, block_size: int = BLOCK_SIZE) -> dict:
    """Bytes of each part for one isovalue: bounding geometry as VTK uploads it (float32 points, the flat
    and interpolated attributes, int indices) for the default block proxies (plus their per-cube info
    texture) and for cube proxies, the data texture, the coefficient table, every coefficient, the paper's
    determining sets (20 / 56 floats per cube), and the octree."""
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


def isosurface_program(model: Isosurface, *, newton_iterations: int = 6, encoding: str = "data",
                       roots: str | None = None, color_field=None, proxy: str = "blocks",
                       block_size: int = BLOCK_SIZE) -> ProgramSpec:
    """Describe the ray-cast program of an isosurface.

    Parameters
    ----------
    model : Isosurface
    newton_iterations : int, 1..8
        Iterations of the Newton-type root finders (cubic, or ``roots != "analytic"``).
    encoding : {"data", "coefficients", "determining"}
        Where the shader gets BB coefficients from (module docstring); ``"determining"`` (cubic only) is
        paper 003's encoding: the 56 determining coefficients per relevant cube.
    roots : {"analytic", "bracketed", "paper"}, default "analytic"
        ``"analytic"``: the stable closed form (quadratic formula; for the cubic the trigonometric/Cardano
        form on the BB coefficients, ``sv_first_root_cubic``); ``"bracketed"``: bracketed Newton on convex
        pieces; ``"paper"``: paper 003's Newton from the three starts 0, inflection point (1/2 if none), 1 with
        ``newton_iterations`` steps (sec. 5.3; cubic scheme only, the paper solves quadratics in closed form).
    proxy : {"blocks", "cubes"}
        Bounding geometry: ``"blocks"`` (default) draws one box per block of ``block_size``^3 cubes holding
        relevant cubes; each fragment walks the block's cubes front to back and stops at the first hit.
        ``"cubes"`` draws one box per relevant cube (closest to paper 003's per-tetrahedron proxies: every
        relevant cube a ray crosses costs a fragment, measured in the study).
    color_field : array-like (nz, ny, nx) or VolumeGrid, optional
        A second field on the same grid; the surface is coloured by its spline (same scheme) at the hit
        through the Style's colormap (``scalar_range`` defaults to the field's range).
    """
    if not isinstance(model, Isosurface):
        raise TypeError(f"model must be an Isosurface, got {type(model).__name__}.")
    spline = model.spline
    iterations = check_degree(newton_iterations, "newton_iterations", low=1, high=8)
    check_choice(encoding, "encoding", {"data", "coefficients", "determining"})
    check_choice(proxy, "proxy", {"blocks", "cubes"})
    block_size = check_degree(block_size, "block_size", low=1, high=16)
    cubic = spline.degree == 3
    if encoding == "determining" and not cubic:
        raise ValueError("encoding='determining' stores the cubic scheme's 56 determining coefficients per cube (paper "
                         "003 sec. 5.1); the quadratic scheme here takes its inner coefficients from the data, not from "
                         "its 20 edge coefficients: use encoding='data' (1 value per cube) or 'coefficients'.")
    if roots is None:
        roots = "analytic"
    check_choice(roots, "roots", {"analytic", "bracketed", "paper"})
    if roots == "paper" and not cubic:
        raise ValueError("roots='paper' is paper 003's Newton iteration for cubics; for quadratics the paper (and "
                         "roots='analytic') uses the closed form. Use roots='analytic' or 'bracketed'.")
    rel = model.relevant
    points, tris, attributes, varyings = _proxies(spline, rel, encoding, proxy, block_size)
    ref = value_reference(spline)
    textures = {}
    if proxy == "blocks":
        textures["sv_volume_mask"] = mask_texture(spline, rel, block_size, encoding)
    if encoding == "data":
        textures["sv_volume_data"] = data_texture(spline)
    elif encoding == "determining":
        textures["sv_volume_det"] = determining_table(spline, rel)
    else:
        textures["sv_volume_coef"] = coefficient_table(spline, rel)
    nz, ny, nx = spline.shape
    scalar_range = spline.value_range
    if color_field is not None:
        values = np.asarray(getattr(color_field, "values", color_field), dtype=np.float64)
        if values.shape != spline.shape:
            raise ValueError(f"color_field must have the volume's shape (nz, ny, nx) = {spline.shape}, got {values.shape}.")
        if not np.isfinite(values).all():
            k, j, i = (int(v) for v in np.argwhere(~np.isfinite(values))[0])
            raise ValueError(f"color_field has a non-finite value at voxel [k, j, i] = [{k}, {j}, {i}].")
        from .schemes import _pad

        textures["sv_color_data"] = _linear_texture(_pad(values))
        scalar_range = (float(values.min()), float(values.max()))
    return ProgramSpec(
        name="isosurface",
        entry="programs/isosurface.glsl",
        points=points,
        triangles=tris,
        offset=tuple(spline.origin),
        defines={"SV_VOLUME_CUBIC": cubic, "SV_VOLUME_TABLE": encoding == "coefficients",
                 "SV_VOLUME_DETERMINING": encoding == "determining",
                 "SV_VOLUME_COLOR_FIELD": color_field is not None, "SV_VOLUME_BLOCKS": proxy == "blocks",
                 "SV_ROOTS_PAPER_NEWTON3": roots == "paper", "SV_ROOTS_BRACKETED": roots == "bracketed"},
        uniforms={
            "sv_inv_spacing": tuple(1.0 / spline.spacing),
            "sv_iso_shifted": model.isovalue - ref,
            "sv_value_ref": ref,
            "sv_newton_iterations": iterations,
            "sv_cube_margin": CUBE_MARGIN,
            "sv_inner_margin": INNER_MARGIN,
            "sv_tex_width": TEXTURE_WIDTH,
            "sv_padded_dims": (float(nx + 2), float(ny + 2), float(nz + 2)),
            "sv_cube_count": (float(nx), float(ny), float(nz)),
            "sv_block_size": block_size,
            "sv_scalar_range": scalar_range,
        },
        textures=textures,
        attributes=attributes,
        varyings=varyings,
    )


def _table_rows(rel: Relevant, encoding: str = "coefficients") -> np.ndarray:
    """Row of each relevant cube's data in the per-isovalue table: its first tetrahedron's row (coefficient
    table) or the cube's own index (determining-set table)."""
    if encoding == "determining":
        return np.arange(len(rel.cubes), dtype=np.int64)
    counts = np.bitwise_count(rel.masks).astype(np.int64)
    return np.concatenate([[0], np.cumsum(counts)[:-1]]) if len(counts) else np.zeros(0, np.int64)


def determining_table(spline: VolumeSpline, rel: Relevant) -> np.ndarray:
    """(rows, TEXTURE_WIDTH, 4) float32: the 56 determining coefficients of every relevant cube (cubic scheme,
    paper 003 sec. 5.1 / Fig. 4 masks), minus the reference value, one row of 56 floats per cube."""
    from .cubic import determining_map

    _, K = determining_map()
    ref = value_reference(spline)
    out = np.empty((len(rel.cubes), K.shape[0]), dtype=np.float64)
    for s in range(0, len(rel.cubes), 32768):
        out[s:s + 32768] = (spline.stencil_data(rel.cubes[s:s + 32768]) - ref) @ K.T
    return _linear_texture(out)


def mask_texture(spline: VolumeSpline, rel: Relevant, block_size: int = BLOCK_SIZE,
                 encoding: str = "data") -> np.ndarray:
    """(rows, TEXTURE_WIDTH, 4) float32: for every block drawn (in :func:`proxy_units` order) one texel per
    cube of the block, ``block_id * B^3 + (a_z B + a_y) B + a_x``: the relevant-tetrahedron mask (exact:
    < 2^24), the cube's first coefficient-table row as two 12-bit halves, 0 = not relevant. Only blocks
    holding relevant cubes are stored."""
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
        rows = _table_rows(rel, encoding)
        info[k, 0] = rel.masks
        info[k, 1] = rows >> 12
        info[k, 2] = rows & 4095
    return _linear_texture(info)


def proxy_units(spline: VolumeSpline, rel: Relevant, proxy: str, block_size: int):
    """The proxy boxes as (first cube (n, 3) int, cubes per axis (n, 3) int), in drawing order."""
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


def _proxies(spline: VolumeSpline, rel: Relevant, encoding: str, proxy: str = "cubes", block_size: int = 8):
    """Bounding geometry: points (model frame), triangles, flat attributes, varyings."""
    if proxy == "blocks":
        first, ext = proxy_units(spline, rel, proxy, block_size)
        n = len(first)
        local = _CORNERS[None] * ext[:, None, :]  # block-local corner coordinates, cube units
        corners = (first[:, None, :] - 0.5 + local) * spline.spacing
        tris = (np.arange(n)[:, None, None] * 8 + _BOX_TRIS[None]).reshape(-1, 3)
        cube_attr = np.repeat(np.column_stack([first, np.arange(n)]).astype(np.float64), 8, axis=0)  # .w = block id
        attributes = {"sv_cube": cube_attr}
        return corners.reshape(-1, 3), tris, attributes, {"sv_local": local.reshape(-1, 3)}
    n = len(rel.cubes)
    corners = (rel.cubes[:, None, :] - 0.5 + _CORNERS[None]) * spline.spacing  # model frame: origin at data point 0
    tris = (np.arange(n)[:, None, None] * 8 + _BOX_TRIS[None]).reshape(-1, 3)
    # Masks and rows travel as 12-bit halves so that the shader's int(x + 0.5) is exact: for x >= 2^23 the
    # float32 sum x + 0.5 rounds to the even neighbour, which flipped the low bits of masks with bit 23 set
    # (the cause of the first holes in the sphere; it was first mistaken for VTK attribute precision).
    cube_attr = np.repeat(np.column_stack([rel.cubes, rel.masks & 4095]).astype(np.float64), 8, axis=0)
    extra = np.zeros((n, 3))
    extra[:, 0] = rel.masks >> 12
    if encoding in ("coefficients", "determining"):
        rows = _table_rows(rel, encoding)
        extra[:, 1] = rows >> 12
        extra[:, 2] = rows & 4095
    attributes = {"sv_cube": cube_attr, "sv_cube_extra": np.repeat(extra, 8, axis=0)}
    return corners.reshape(-1, 3), tris, attributes, {"sv_local": np.tile(_CORNERS, (n, 1))}


def set_isovalue(actor, isovalue: float) -> Relevant:
    """Change the isovalue of a rendered isosurface in place.

    Only what depends on the isovalue is rebuilt: the relevant cubes (found through the spline's existing
    min-max octree), the proxy geometry, the ``sv_iso_shifted`` uniform and, for ``encoding="coefficients"``,
    the coefficient table. The data texture, the octree and the compiled program are kept (tested).
    Returns the new :class:`Relevant`.
    """
    model = actor.model
    if not isinstance(model, Isosurface):
        raise TypeError(f"set_isovalue needs the SplineActor of an Isosurface, got one of {type(model).__name__}.")
    model.isovalue = float(isovalue)
    if not np.isfinite(model.isovalue):
        raise ValueError(f"isovalue must be finite, got {isovalue!r}.")
    spline, rel = model.spline, model.relevant
    defines = actor.spec.defines
    encoding = ("coefficients" if defines.get("SV_VOLUME_TABLE") else
                "determining" if defines.get("SV_VOLUME_DETERMINING") else "data")
    blocks = bool(actor.spec.defines.get("SV_VOLUME_BLOCKS"))
    B = int(actor.spec.uniforms.get("sv_block_size", BLOCK_SIZE))
    points, tris, attributes, varyings = _proxies(spline, rel, encoding, "blocks" if blocks else "cubes", B)
    actor.set_geometry(points, tris, {**attributes, **varyings})
    if blocks:
        actor.set_texture("sv_volume_mask", mask_texture(spline, rel, B, encoding))
    if encoding == "coefficients":
        actor.set_texture("sv_volume_coef", coefficient_table(spline, rel))
    elif encoding == "determining":
        actor.set_texture("sv_volume_det", determining_table(spline, rel))
    actor.extra_uniforms["sv_iso_shifted"] = model.isovalue - value_reference(spline)
    culler = getattr(actor, "culler", None)
    if culler is not None:
        culler.refresh()
    return rel

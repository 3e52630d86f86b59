"""The isosurface program (glsl/programs/isosurface.glsl): spec, float64 twin, depth bound, culling.

Declares :data:`PROGRAM` for the registry. Data streams [Kalbe2008, sec. 5.1], three encodings selectable
for measurement (tables in :mod:`splinevis.volume.tables`):

* ``encoding="data"`` (default): one float32 texture of the padded volume (``data - value_ref``), uploaded
  once per volume and independent of the isovalue; the shader fetches a cube's 27 values and rebuilds the
  BB coefficients of a tetrahedron with the scheme's averaging rules (generated
  glsl/lib/type6/stencil_*.glsl). This is the paper's determining-set encoding taken one step further:
  the paper stores the 20 (quadratic) or 56 (cubic) determining coefficients per cube, which are
  themselves averages of the data; storing the data is 1 value per cube.
* ``encoding="coefficients"``: every BB coefficient of every relevant tetrahedron in a table (the "direct
  approach" the paper compares with), rebuilt for every isovalue.
* ``encoding="determining"`` (cubic): the paper's own encoding, the 56 determining coefficients of every
  relevant cube (Fig. 4 masks); the shader derives the other 119 from them (generated
  glsl/lib/type6/determining_cubic.glsl).

Bounding geometry: :mod:`splinevis.volume.proxies`; hard cases: :mod:`splinevis.volume.hard_cases`.

The block's cubes are walked in rounds and a cube's tetrahedra tested once per candidate (the ray's clip by all 24
at once finds them); the previous code, with the same hits bit for bit, stays compiled under the flag
``SV_VOLUME_LEGACY`` (``actor.set_variant({"SV_VOLUME_LEGACY": True})``) for the side-by-side timing of
benchmarks/bench_speedup.py.
"""

from __future__ import annotations

import numpy as np

from .._validation import check_choice, check_degree
from ..bb.root_options import check_root_method, root_defines
from ..gl.contract import SplineProgram
from ..gl.error_bounds import isosurface_depth_error_bound, model_frame_matrix
from ..gl.proxies import box_triangles, pack_rgba32f
from ..gl.spec import ProgramSpec
from ..hierarchy.culling import FrustumCuller
from .hard_cases import hard_cases
from .isosurface import Isosurface, value_reference
from .model import Relevant, VolumeSpline
from .proxies import BLOCK_SIZE, proxy_geometry, proxy_units
from .raycast import raycast_isosurface
from .renderers import RENDERERS
from .tables import coefficient_table, data_texture, determining_table, mask_texture

__all__ = ["Isosurface", "isosurface_program", "set_isovalue", "isosurface_depth_bound", "attach_culling",
           "CUBE_MARGIN", "INNER_MARGIN", "PROGRAM"]

ROOTS = ("analytic", "bracketed", "paper")
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


def isosurface_program(model: Isosurface, style=None, *, newton_iterations: int = 6, encoding: str = "data",
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
        the encoding of [Kalbe2008, sec. 5.1]: the 56 determining coefficients per relevant cube.
    roots : {"analytic", "bracketed", "paper"}, default "analytic"
        The one roots option (:mod:`splinevis.bb.root_options`). ``"analytic"``: the stable closed form
        (quadratic formula; for the cubic the trigonometric/Cardano form on the BB coefficients,
        ``sv_first_root_cubic``); ``"bracketed"``: bracketed Newton on convex pieces; ``"paper"``: Newton from
        the three starts 0, inflection point (1/2 if none), 1 with ``newton_iterations`` steps
        [Kalbe2008, sec. 5.3] (cubic scheme only: the paper solves quadratics in closed form).
    proxy : {"blocks", "cubes"}
        Bounding geometry: ``"blocks"`` (default) draws one box per block of ``block_size``^3 cubes holding
        relevant cubes; each fragment walks the block's cubes front to back and stops at the first hit.
        ``"cubes"`` draws one box per relevant cube (closest to the per-tetrahedron proxies of [Kalbe2008]: every
        relevant cube a ray crosses costs a fragment, measured in the study).
    color_field : array-like (nz, ny, nx) or VolumeGrid, optional
        A second field on the same grid; the surface is coloured by its spline (same scheme) at the hit
        through the Style's colormap (``scalar_range`` defaults to the field's range).

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> surface = Isosurface(VolumeSpline(sphere_grid(12)), 0.7)  # |x| on [-1, 1]^3: a sphere
    >>> spec = isosurface_program(surface)  # 8 blocks of 8^3 cubes hold the 272 relevant cubes
    >>> spec.points.shape, sorted(spec.textures), sorted(k for k, v in spec.defines.items() if v)
    ((64, 3), ['sv_volume_data', 'sv_volume_mask'], ['SV_ROOTS_ANALYTIC', 'SV_VOLUME_BLOCKS'])
    >>> spec = isosurface_program(surface, encoding="coefficients", proxy="cubes")  # one box per cube
    >>> spec.points.shape, sorted(spec.textures)
    ((2176, 3), ['sv_volume_coef'])
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
        raise ValueError("encoding='determining' stores the cubic scheme's 56 determining coefficients per cube "
                         "[Kalbe2008, sec. 5.1]; the quadratic scheme here takes its inner coefficients from the data, not from "
                         "its 20 edge coefficients: use encoding='data' (1 value per cube) or 'coefficients'.")
    check_root_method("analytic" if roots is None else roots, ROOTS, degree=spline.degree)
    roots = "analytic" if roots is None else roots
    rel = model.relevant
    points, tris, attributes, varyings = proxy_geometry(spline, rel, encoding, proxy, block_size)
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

        textures["sv_color_data"] = pack_rgba32f(_pad(values), name="color_field texture")
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
                 **root_defines(roots)},
        uniforms={
            "sv_inv_spacing": tuple(1.0 / spline.spacing),
            "sv_iso_shifted": model.isovalue - ref,
            "sv_value_ref": ref,
            "sv_newton_iterations": iterations,
            "sv_cube_margin": CUBE_MARGIN,
            "sv_inner_margin": INNER_MARGIN,
                        "sv_padded_dims": (float(nx + 2), float(ny + 2), float(nz + 2)),
            "sv_cube_count": (float(nx), float(ny), float(nz)),
            "sv_block_size": block_size,
            "sv_scalar_range": scalar_range,
        },
        textures=textures,
        attributes=attributes,
        varyings=varyings,
        world_frame=world_frame(spline),  # a rotated lattice: the actor draws the lattice frame rotated into the world
    )


def set_isovalue(actor, isovalue: float) -> Relevant:
    """Change the isovalue of a rendered isosurface in place.

    Only what depends on the isovalue is rebuilt: the relevant cubes (found through the spline's existing
    min-max octree), the proxy geometry, the ``sv_iso_shifted`` uniform and, for ``encoding="coefficients"``,
    the coefficient table; an attached culler (:func:`attach_culling`) gets the new blocks. The data texture,
    the octree and the compiled program are kept (tested). Returns the new :class:`Relevant`.

    Examples
    --------
    >>> from splinevis.plotting import Plotter
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> pl = Plotter(off_screen=True, window_size=(64, 48))
    >>> actor = pl.add_isosurface(sphere_grid(12), 0.7)  # |x| on [-1, 1]^3: a sphere; culling attached
    >>> blocks = len(actor.culler.units)
    >>> rel = set_isovalue(actor, 0.4)  # a smaller sphere: fewer cubes
    >>> len(rel.cubes), actor.model.isovalue, round(actor.extra_uniforms["sv_iso_shifted"], 9)
    (80, 0.4, -0.544754986)
    >>> blocks, len(actor.culler.units)  # the culler tests only the blocks still holding cubes
    (8, 4)
    >>> pl.close()
    """
    model = actor.model
    if not isinstance(model, Isosurface):
        raise TypeError(f"set_isovalue needs the SplineActor of an Isosurface, got one of {type(model).__name__}.")
    iso = float(isovalue)
    if not np.isfinite(iso):
        raise ValueError(f"isovalue must be finite, got {isovalue!r}.")
    old_iso = model.isovalue
    model.isovalue = iso
    try:
        check_isovalue_in_range(model)
    except ValueError:
        model.isovalue = old_iso  # the actor keeps drawing the previous isosurface
        raise
    spline, rel = model.spline, model.relevant
    defines = actor.spec.defines
    encoding = ("coefficients" if defines.get("SV_VOLUME_TABLE") else
                "determining" if defines.get("SV_VOLUME_DETERMINING") else "data")
    blocks = bool(actor.spec.defines.get("SV_VOLUME_BLOCKS"))
    B = int(actor.spec.uniforms.get("sv_block_size", BLOCK_SIZE))
    points, tris, attributes, varyings = proxy_geometry(spline, rel, encoding, "blocks" if blocks else "cubes", B)
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
        culler.set_units(proxy_units(spline, rel, "blocks" if blocks else "cubes", B)[0])
    return rel


def isosurface_depth_bound(model: Isosurface, matrix, origins, directions, t, *,
                           surface=None) -> np.ndarray:
    """Derived bound on |GPU - float64| window depth at hits ``origins + t directions`` (world), from
    :func:`splinevis.gl.error_bounds.isosurface_depth_error_bound` in the model frame. The bound depends on the hits'
    positions only: ``surface`` (the contract's hit parameters) is not read.

    Examples
    --------
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> surface = Isosurface(VolumeSpline(sphere_grid(12)), 0.7)  # |x| on [-1, 1]^3: a sphere
    >>> o = np.array([[0.0, 0.0, 3.0], [3.0, 0.0, 0.0]])
    >>> d = -o / 3  # two rays to the centre, along -z and -x
    >>> t = raycast_isosurface(surface, o, d).t
    >>> bound = isosurface_depth_bound(surface, np.eye(4), o, d, t)  # identity camera: depth (z + 1) / 2
    >>> bound.shape, bool(np.all((0.0 < bound) & (bound < 1e-5)))  # one bound per hit
    ((2,), True)
    """
    sp = model.spline
    frame = world_frame(sp)
    if frame is not None:  # a rotated lattice: the camera matrix and the rays act on lattice-frame points
        R, pivot = frame
        W = np.eye(4)
        W[:3, :3], W[:3, 3] = R, pivot - R @ pivot
        matrix = np.asarray(matrix, dtype=np.float64) @ W
        origins, directions = _lattice_rays(model, origins, directions)
    off = sp.origin
    lo, hi = sp.data_range  # the texture holds the padded (and prefiltered) data
    ref = value_reference(sp)
    scale = max(abs(hi - ref), abs(lo - ref), abs(model.isovalue - ref))
    box = np.array(sp.bounds).reshape(3, 2)
    b = box - off[:, None]
    # the bound's slope steps t +- 1e-6 |t| along the ray; for a hit on a face of the domain (an isosurface cut
    # by the volume's boundary) that step leaves the domain: it is clamped to it (a one-sided difference there)
    return isosurface_depth_error_bound(lambda q: sp.evaluate(np.clip(q + off, box[:, 0], box[:, 1]), gradient=True), scale,
                                        sp.spacing,
                                        model_frame_matrix(matrix, off), np.asarray(origins) - off, directions, t,
                                        float(np.abs(b).max()), sp.degree)


def _model_from(volume, isovalue, scheme="quadratic", prefilter="none", padding="linear", **read_options) -> Isosurface:
    """An :class:`Isosurface` of a VolumeSpline, a VolumeGrid or anything :func:`splinevis.io.read_volume`
    reads (``scheme``, ``prefilter``, ``padding`` and ``read_options`` are ignored for a VolumeSpline)."""
    spline = volume if isinstance(volume, VolumeSpline) else VolumeSpline(volume, scheme, prefilter=prefilter,
                                                                           padding=padding, **read_options)
    surface = Isosurface(spline, isovalue)
    check_isovalue_in_range(surface)
    return surface


def world_frame(spline):
    """``(rotation, pivot)`` of a spline on a rotated lattice (world = pivot + rotation @ (lattice - pivot),
    pivot = the grid origin), or None for an axis-aligned one.

    >>> from splinevis.io import VolumeGrid
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> world_frame(VolumeSpline(sphere_grid(6))) is None
    True
    """
    grid = spline.grid
    if not getattr(grid, "is_rotated", False):
        return None
    return np.asarray(grid.direction, dtype=np.float64), np.asarray(grid.origin, dtype=np.float64)


def _lattice_rays(model, origins, directions):
    """World rays into the lattice frame of a rotated volume (unchanged for an axis-aligned one)."""
    frame = world_frame(model.spline)
    if frame is None:
        return origins, directions
    R, pivot = frame
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    return pivot + (o - pivot) @ R, d @ R  # R^T (o - pivot) + pivot, R^T d (row vectors)


def raycast_world(model: Isosurface, origins, directions, tmin=0.0, **options):
    """:func:`~splinevis.volume.raycast.raycast_isosurface` on WORLD rays, with world results: for a volume
    on a rotated lattice the rays are mapped into the lattice frame, cast there, and the hits come back in
    the world (``t`` is the same: the map is a rigid motion; points = ``pivot + R (p - pivot)``, i.e. the
    world ray at ``t``; normals = ``R n``).

    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> surface = Isosurface(VolumeSpline(sphere_grid(12)), 0.7)
    >>> float(raycast_world(surface, [[0.0, 0.0, 3.0]], [[0.0, 0.0, -1.0]]).t[0]) == float(
    ...     raycast_isosurface(surface, [[0.0, 0.0, 3.0]], [[0.0, 0.0, -1.0]]).t[0])
    True

    A quarter turn about z (pivot at the grid origin, the centre of the sphere's lattice is moved): the
    ray along world -y meets the sphere where the lattice ray along -x does; points and normals are world.

    >>> from splinevis.io import VolumeGrid
    >>> g = sphere_grid(12)
    >>> turn = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]  # lattice +x is world +y
    >>> turned = Isosurface(VolumeSpline(VolumeGrid(g.values, spacing=g.spacing, origin=g.origin,
    ...                                             direction=turn)), 0.7)
    >>> pivot = np.array(g.origin)
    >>> centre = pivot + np.array(turn) @ (0.0 - pivot)  # the world image of the lattice point 0
    >>> h = raycast_world(turned, [centre + [0.0, 3.0, 0.0]], [[0.0, -1.0, 0.0]])
    >>> ((h.points[0] - centre).round(3) + 0.0).tolist(), (h.normals[0] / np.linalg.norm(h.normals[0])).round(6).tolist()
    ([0.0, 0.688, 0.0], [0.0, 1.0, 0.0])
    """
    o, d = _lattice_rays(model, origins, directions)
    hits = raycast_isosurface(model, o, d, tmin, **options)
    frame = world_frame(model.spline)
    if frame is None:
        return hits
    R = frame[0]
    ow, dw = np.broadcast_arrays(np.asarray(origins, dtype=np.float64), np.asarray(directions, dtype=np.float64))
    hits.points = ow + hits.t[..., None] * dw  # the world ray at t: pivot + R (p - pivot) without its round-off
    hits.normals = hits.normals @ R.T  # R n (row vectors)
    return hits


def check_isovalue_in_range(surface: Isosurface, what: str = "isovalue") -> None:
    """No blank picture without a word: raise or warn when the isosurface is empty or may be
    (:func:`splinevis.volume.isovalue_range.isovalue_verdict`).

    * Proven empty with the isovalue outside the data's ``[min, max]``: ValueError giving the data's and the
      spline's range and what to do. (An isovalue outside the samples' range that the spline still reaches,
      an overshoot between samples, is drawn.)
    * Proven empty inside the data's range (the spline smooths the data's peak below it), or not proven
      non-empty (no vertex value beyond the isovalue: an isovalue at the data's extreme, a surface that may be
      empty, a few points or tiny bubbles): a warning with the spline's range and the options
      (``prefilter="interpolate"`` makes the spline reach the samples).

    An empty :class:`Isosurface` built directly stays allowed: ``add_spline`` draws nothing.

    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> check_isovalue_in_range(Isosurface(VolumeSpline(sphere_grid(6)), 9.0))
    Traceback (most recent call last):
    ValueError: isovalue=9.0 lies outside the volume's data range [...] and the spline's [...]: the isosurface is empty (a blank picture). Pass an isovalue inside the spline's range, e.g. ...
    """
    from .._warnings import warn_user
    from .isovalue_range import coefficient_range, isovalue_verdict

    v = isovalue_verdict(surface)
    if v.status == "non-empty":
        return
    lo, hi = v.data_range
    clo, chi = coefficient_range(surface.spline)
    iso = v.isovalue
    source = surface.spline.grid.source
    spline_range = (f"the spline's values lie within [{clo:.6g}, {chi:.6g}] (the range of its BB coefficients, "
                    "which bounds it)")
    options = ("prefilter='interpolate' makes the spline pass through the samples (it reaches the data's range); "
               f"or pass an isovalue inside [{clo:.6g}, {chi:.6g}], e.g. {0.5 * (clo + chi):.6g}")
    if v.status == "empty" and not lo <= iso <= hi:
        raise ValueError(f"{what}={iso!r} lies outside the volume's data range [{lo!r}, {hi!r}] and the spline's "
                         f"[{clo:.6g}, {chi:.6g}]: the isosurface is empty (a blank picture). Pass an isovalue "
                         f"inside the spline's range, e.g. its middle {0.5 * (clo + chi):.6g}.")
    at_extreme = " (the data's extreme)" if iso in (lo, hi) else ""
    if v.status == "empty":
        msg = (f"{source}: {what}={iso!r} lies inside the data's range [{lo:.6g}, {hi:.6g}]{at_extreme} but outside "
               f"what the spline reaches: {spline_range}, smoothing the data's extremes: the isosurface is empty "
               f"and the picture blank. {options}.")
    else:
        vlo, vhi = v.vertex_range
        msg = (f"{source}: the isosurface {what}={iso!r}{at_extreme} may be empty, a few points or tiny bubbles: the "
               f"spline's values at the vertices of the {v.tetrahedra} tetrahedra that could hold it lie in "
               f"[{vlo:.6g}, {vhi:.6g}], not on both sides of it, and {spline_range}. {options}.")
    warn_user(msg)


def attach_culling(actor, plotter, *, culling: bool = True) -> None:
    """Hierarchical view-frustum culling of the proxies before every frame (``actor.culler``): blocks of
    2^theta cubes tested against the camera's planes by the octree over them
    (:class:`splinevis.hierarchy.FrustumCuller`); images with and without are identical (tested). A volume
    on a rotated lattice is culled in its lattice frame: the culler gets the actor's rigid motion and maps the
    camera's planes into that frame (the blocks stay axis-aligned there).

    Examples
    --------
    >>> from splinevis.plotting import Plotter
    >>> from splinevis.volume.hard_cases import sphere_grid
    >>> surface = Isosurface(VolumeSpline(sphere_grid(12)), 0.7)  # |x| on [-1, 1]^3: a sphere
    >>> pl = Plotter(off_screen=True, window_size=(64, 48))
    >>> actor = pl.add_spline(surface)
    >>> attach_culling(actor, pl)
    >>> pl.camera_position = [(0.0, 0.0, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    >>> _ = pl.screenshot()  # the first frame
    >>> actor.culler.visible_units, len(actor.culler.units)  # all 8 blocks in view
    (8, 8)
    >>> pl.camera_position = [(0.0, 0.0, 3.0), (0.0, 0.0, 6.0), (0.0, 1.0, 0.0)]  # looking away
    >>> pl.render()
    >>> actor.culler.visible_units, actor.poly.GetNumberOfPolys()
    (0, 0)
    >>> pl.close()
    """
    if not culling:
        return
    spec, model = actor.spec, actor.model
    blocks = bool(spec.defines.get("SV_VOLUME_BLOCKS"))
    B = int(spec.uniforms.get("sv_block_size", BLOCK_SIZE)) if blocks else 1
    units, _ = proxy_units(model.spline, model.relevant, "blocks" if blocks else "cubes", B)
    spacing = model.spline.spacing

    def show(visible):
        actor.set_triangles(box_triangles(len(visible))[np.repeat(visible, 12)])

    # a culling node must enclose every proxy box assigned to it: theta >= log2(block size)
    actor.culler = FrustumCuller(units, spacing=spacing, origin=-0.5 * spacing, grid_shape=model.spline.shape,
                                 min_level=int(np.ceil(np.log2(B))), offset=actor.model_position, rotation=actor.rotation,
                                 on_change=show)
    actor.culler.attach(plotter.renderer)


PROGRAM = SplineProgram(
    "isosurface", "raycast", Isosurface, isosurface_program, reference=raycast_world,
    depth_bound=isosurface_depth_bound, hard_cases=hard_cases, model_from=_model_from, on_add=attach_culling,
    root_methods=ROOTS, newton_iterations=6, options=("encoding", "roots", "color_field", "proxy", "block_size"),
    description="isosurface of a trivariate spline on the type-6 partition, ray-cast in relevant cubes",
    renderers=RENDERERS)

"""Choice of renderer by accuracy: the cheapest way to draw a spline whose screen-space error stays below
``max_error_px`` for the current camera (``Plotter.add_terrain/add_isosurface(..., max_error_px=...)``).

**The table.** :data:`RENDERERS` lists, per program, the renderers that can draw its models: a name, a cost
rank (lower is cheaper), the levels tried in order of cost (samples per cell ``k`` for meshes), an error
function ``error_px(model, view, level, cache) -> (pixels, proven)``, how to build it and, for meshes, a
triangle count and the styles or models it refuses. :func:`choose` walks the table in cost order, takes the
first entry (and for a mesh the smallest ``k``) whose error is at most ``max_error_px`` and whose triangle
count is within :data:`TRIANGLE_CAP`; if none meets the request, the exact renderer (the ray cast) is
chosen and the choice says that the request is not met. A mesh-guided ray cast (program option
``proxy="mesh"``) is one more entry: its error is the ray cast's, its cost rank the measured one.

**Cost ranks** come from the studies' measurements on this machine (Mesa llvmpipe, 2 cores):
docs/results/terrain/pareto.md (800 x 600): a mesh of 2,097,152 triangles draws in 148 ms, the terrain ray
cast in 135-242 ms; docs/results/volume/volume.md (400 x 300): marching-cubes meshes of 4,176-65,840
triangles in 4-16 ms, the isosurface ray cast in 251-667 ms. Hence meshes rank below the ray cast and the
triangle cap is the largest mesh measured cheaper than the ray cast; benchmarks/bench_choice.py times the
choices beside the ray cast (docs/results/choice/choice.md: the 2,097,152-triangle mesh 1.6x cheaper). The terrain's mesh-guided proxy was
measured slower than the box proxy on llvmpipe (about 1.15x at k = 1 to 2x at k = 4:
:mod:`splinevis.terrain.mesh_proxy`): as a row of the table its rank would be above the ray cast's here, so
it would be drawn only where the box ray cast is refused.

**Screen-space error** is the distance, in pixels on the screen, between a point the renderer shows and
the point of the exact (float64) spline it stands for; world errors become pixels by
:class:`splinevis.gl.screen_error.View` (a conservative bound at the worst point, derived there).

For a mesh the displacement is bounded per cell (or cube) and the pixels are bounded over the cell's box
(largest r and smallest Z over its corners): the maximum over the boxes in the view frustum is the
"nearest visible point" of the bound. A box reaching behind the eye plane (or closer than e) that meets the
frustum makes the mesh's error unbounded (a mesh seen from that close can be off by any number of pixels):
the ray cast is chosen. Every renderer adds the rasterizer's sub-pixel snapping, sqrt(2) 2^-8 pixels
(:data:`splinevis.gl.error_bounds.SUBPIXEL`).

* Terrain mesh (:mod:`splinevis.terrain.sampled_mesh`): **proven**, vertical chord <= M h^2 / 4 per cell
  plus the float32 rounding of the vertices.
* Isosurface mesh (:mod:`splinevis.volume.sampled_mesh`): value error on the mesh proven, turned into a
  distance with an **estimated** lower bound of |grad s| (the smallest at the ``k = 1`` mesh's vertices).
* Ray cast: the program's derived float32 depth bound (``SplineProgram.depth_bound``) on a grid of 32 x 24
  sample rays, less its depth-arithmetic and depth-buffer terms (they change the depth written, not the
  point shown; a mesh's depth has them too), turned into a distance along the ray and converted to pixels
  as if it were sideways: an **estimate** over the screen (bounds at the sampled pixels). It over-states the
  ray cast's error where rays graze the surface (near silhouettes): there the root, hence the depth, moves
  along the ray by up to 2 sqrt(2 eps / |g''|) while the shown surface moves sideways by about
  eps / |grad| only (0.15 px on the terrain study's view, against 0.66 px for a k = 4 mesh).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .gl.error_bounds import U32, depth_error
from .gl.screen_error import SNAP_PX, View
from .plotting_options import split_read_options

__all__ = ["Renderer", "Option", "Choice", "RENDERERS", "TRIANGLE_CAP", "choose", "check_max_error",
           "add_by_accuracy", "raycast_error_px"]

log = logging.getLogger("splinevis")

#: Largest mesh (triangles) the choice builds: the largest mesh measured cheaper than the ray cast
#: (docs/results/terrain/pareto.md: 1025 x 1025 vertices, 2,097,152 triangles, 148 ms vs 135-242 ms).
TRIANGLE_CAP = 2_097_152


def check_max_error(max_error_px) -> float:
    """``max_error_px`` as a float; ValueError unless it is a positive finite number.

    >>> check_max_error(0.5)
    0.5
    >>> check_max_error(0)
    Traceback (most recent call last):
    ValueError: max_error_px must be a positive finite number of pixels (e.g. 0.5), got 0.
    """
    ok = isinstance(max_error_px, (int, float, np.integer, np.floating)) and not isinstance(max_error_px, bool)
    if not ok or not math.isfinite(float(max_error_px)) or float(max_error_px) <= 0:
        raise ValueError(f"max_error_px must be a positive finite number of pixels (e.g. 0.5), got {max_error_px!r}.")
    return float(max_error_px)


@dataclass(frozen=True)
class Renderer:
    """One row of :data:`RENDERERS` (module docstring): ``error_px(model, view, level, cache) -> (pixels,
    proven)``; ``build(plotter, model, style, level, cache, spline_options, add_options) -> actor``;
    ``triangles(model, level, cache) -> int`` (None: not a mesh); ``refuses(model, style) -> reason or None``;
    ``exact``: draws the spline itself (what is drawn when nothing meets the request).

    >>> Renderer("raycast", 10, (None,), raycast_error_px, build=None).name
    'raycast'
    """

    name: str
    rank: int
    levels: tuple
    error_px: Callable
    build: Callable | None
    triangles: Callable | None = None
    refuses: Callable | None = None
    exact: bool = False


@dataclass(frozen=True)
class Option:
    """A renderer considered: its name, level (``k``; None for ray casts), screen-space error (pixels),
    whether that error is proven, triangles (meshes), whether it meets the request and why not.

    >>> str(Option("mesh", 2, 0.8, True, 1024, True))
    'mesh k=2 0.8 px (proven, 1,024 triangles)'
    """

    name: str
    level: object
    error_px: float
    proven: bool
    triangles: int | None = None
    meets: bool = False
    reason: str = ""

    def __str__(self):
        label = self.name + ("" if self.level is None else f" k={self.level}")
        if self.reason:
            return f"{label}: {self.reason}"
        extra = "proven" if self.proven else "estimate"
        if self.triangles is not None:
            extra += f", {self.triangles:,} triangles"
        return f"{label} {self.error_px:.3g} px ({extra})"


@dataclass(frozen=True)
class Choice:
    """What :func:`choose` picked (``chosen``), for which request and ``view``, among ``options`` (every
    candidate looked at, in cost order); ``meets`` is False when no renderer reaches ``max_error_px`` (the
    exact renderer, the ray cast, is drawn then).

    >>> c = Choice("terrain", 0.5, Option("mesh", 2, 0.4, True, 512, True), (Option("mesh", 1, 1.6, True, 128),))
    >>> c.renderer, c.level, c.meets
    ('mesh', 2, True)
    >>> c.message
    'splinevis: terrain drawn as mesh k=2 0.4 px (proven, 512 triangles) <= max_error_px=0.5; considered: mesh k=1 1.6 px (proven, 128 triangles)'
    """

    program: str
    max_error_px: float
    chosen: Option
    options: tuple
    view: View | None = field(default=None, repr=False)

    @property
    def renderer(self) -> str:
        """Name of the chosen renderer.

        >>> Choice("terrain", 0.5, Option("raycast", None, 0.01, False, meets=True), ()).renderer
        'raycast'
        """
        return self.chosen.name

    @property
    def level(self):
        """Level of the chosen renderer (samples per cell ``k`` of a mesh; None for a ray cast).

        >>> Choice("terrain", 0.5, Option("mesh", 3, 0.3, True, 4608, True), ()).level
        3
        """
        return self.chosen.level

    @property
    def error_px(self) -> float:
        """Screen-space error of the chosen renderer, pixels.

        >>> Choice("terrain", 0.5, Option("mesh", 3, 0.3, True, 4608, True), ()).error_px
        0.3
        """
        return self.chosen.error_px

    @property
    def meets(self) -> bool:
        """Whether the chosen renderer's error is within ``max_error_px``.

        >>> Choice("terrain", 1e-4, Option("raycast", None, 0.006, False), ()).meets
        False
        """
        return self.chosen.meets

    @property
    def message(self) -> str:
        """One line: what was chosen, its error against the request, the alternatives considered.

        >>> Choice("terrain", 1e-4, Option("raycast", None, 0.006, False), ()).message
        'splinevis: terrain drawn as raycast 0.006 px (estimate); nothing meets max_error_px=0.0001, drawing the exact renderer'
        """
        head = f"splinevis: {self.program} drawn as {self.chosen}"
        head += (f" <= max_error_px={self.max_error_px:g}" if self.meets
                 else f"; nothing meets max_error_px={self.max_error_px:g}, drawing the exact renderer")
        others = [str(o) for o in self.options if o is not self.chosen]
        return head + ("; considered: " + ", ".join(others) if others else "")


# ---------------------------------------------------------------------------------------------- ray cast
def raycast_error_px(model, view, level, cache, *, rays=(32, 24)):
    """(pixels, False): the program's float32 depth bound on ``rays`` sample rays converted to pixels
    (module docstring), plus the sub-pixel snapping; the program is ``cache["program"]``.

    >>> import numpy as np
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:9, 0:9] / 8.0
    >>> t = TerrainSpline.from_heights(np.sin(3 * x) * y, "C1", spacing=(1 / 8, 1 / 8))
    >>> v = View((0.5, -1.5, 1.5), (0.5, 0.5, 0.0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 5))
    >>> px, proven = raycast_error_px(t, v, None, {"program": "terrain"})
    >>> round(px, 3), round(SNAP_PX, 4), proven  # the float32 error is far below a pixel; the snapping is half
    (0.011, 0.0055, False)
    """
    from .gl.camera import pixel_rays, window_depth
    from .programs import get

    program = get(cache["program"])
    m = view.matrix()
    o, d = pixel_rays(m, *rays)
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    hits = program.reference(model, o, d)
    t = np.asarray(hits.t, dtype=np.float64).reshape(-1)
    ok = np.isfinite(t)
    if not ok.any():
        return SNAP_PX, False
    o, d, t = o[ok], d[ok], t[ok]
    bound = np.asarray(program.depth_bound(model, m, o, d, t), dtype=np.float64)
    h = 1e-6 * np.maximum(1.0, np.abs(t))
    # the bound is |d depth / dt| dt + the depth arithmetic and quantization (depth_error with dt = 0), which
    # move no point (a mesh's depth has them too): keep the part that moves the hit along its ray
    moved = np.maximum(bound - depth_error(m, o, d, t, h, np.zeros_like(t)), 0.0)
    slope = np.abs(window_depth(m, o + (t + h)[:, None] * d) - window_depth(m, o + (t - h)[:, None] * d)) / (2 * h)
    world = moved / np.maximum(slope, 1e-300) * np.linalg.norm(d, axis=1)
    return float(view.point_pixels(o + t[:, None] * d, world).max()) + SNAP_PX, False


def _add_raycast(plotter, model, style, level, cache, spline_options, add_options):
    from .programs import get

    actor = plotter.add_spline(model, style, **spline_options)
    program = get(cache["program"])
    if program.on_add is not None:
        program.on_add(actor, plotter, **(add_options or {}))
    return actor


def _mesh_refuses(model, style):
    from .gl.mesh_effects import MESH_EFFECTS

    extra = sorted(set(style.effect_set()) - MESH_EFFECTS)
    if extra:
        return f"a mesh cannot show {', '.join(extra)}"
    if style.output == "curvature":
        return "a mesh has no curvature array"
    return None


def _float32_margin(lo, hi):
    """World error of float32 vertex positions and their 4-term transform: 8 u of the largest coordinate."""
    return 8.0 * U32 * float(np.abs(np.concatenate([lo, hi])).max())


def _add_mesh(plotter, mesh, style, spline_options):
    from .gl.mesh_effects import add_mesh_with_effects

    unknown = sorted(set(spline_options) - {"name", "newton_iterations"})  # the root finder's: unused by a mesh
    if unknown:
        raise TypeError(f"options {unknown} are ray-cast program options; the chosen renderer is a mesh.")
    return add_mesh_with_effects(plotter, mesh, style, name=spline_options.get("name"))


# ------------------------------------------------------------------------------------------ terrain mesh
def _terrain_cache(model, cache):
    from .terrain import sampled_mesh as sm

    if "boxes" not in cache:
        lo, hi = sm.cell_boxes(model)
        cache["boxes"] = (lo.reshape(-1, 3), hi.reshape(-1, 3))
        cache["hessian"] = sm.chord_bounds(model, 1).reshape(-1) * 4.0  # M: the k = 1 chord bound is M / 4
    return cache["boxes"], cache["hessian"]


def _terrain_mesh_error(model, view, k, cache):
    (lo, hi), M = _terrain_cache(model, cache)
    err = M / (4.0 * k * k) + _float32_margin(lo, hi)  # chord_bounds(model, k) without recomputing M
    return float(view.box_pixels(lo, hi, err).max()) + SNAP_PX, True


def _terrain_mesh_triangles(model, k, cache):
    from .terrain.sampled_mesh import mesh_triangles

    return mesh_triangles(model, k)


def _terrain_mesh_build(plotter, model, style, k, cache, spline_options, add_options):
    from .terrain.sampled_mesh import sampled_mesh

    return _add_mesh(plotter, sampled_mesh(model, k), style, spline_options)


# --------------------------------------------------------------------------------------- isosurface mesh
def _iso_mesh1(model, cache):
    """The k = 1 mesh (its triangle count scales the others'; its vertices give the gradient estimate)."""
    from .volume.sampled_mesh import sampled_mesh

    if ("mesh", 1) not in cache:
        cache["mesh", 1] = sampled_mesh(model.spline, model.isovalue, 1, model.relevant)
    return cache["mesh", 1]


def _iso_cache(model, cache):
    from .volume import sampled_mesh as sm

    if "hessian" not in cache:
        spline = model.spline
        cubes = model.relevant.cubes
        h = np.asarray(spline.spacing, dtype=np.float64)
        lo = np.asarray(spline.origin, dtype=np.float64) - 0.5 * h + cubes * h
        cache["boxes"] = (lo, lo + h)
        cache["hessian"] = sm.hessian_bounds(spline, cubes) if len(cubes) else np.zeros(0)
        cache["gradient"] = sm.gradient_floor(spline, _iso_mesh1(model, cache))
    return cache


def _iso_mesh_error(model, view, k, cache):
    c = _iso_cache(model, cache)
    lo, hi = c["boxes"]
    if len(lo) == 0:
        return SNAP_PX, False
    h = np.asarray(model.spline.spacing, dtype=np.float64) / k
    delta = c["hessian"] * (h.max() ** 2 / 8.0 + (h ** 2).sum() / 2.0)  # as volume.sampled_mesh.distance_estimates
    g = c["gradient"]
    err = (delta / g if g > 0 else np.full(len(delta), np.inf)) + _float32_margin(lo, hi)
    return float(view.box_pixels(lo, hi, err).max()) + SNAP_PX, False


def _iso_mesh_triangles(model, k, cache):
    from .volume.sampled_mesh import fine_points, MAX_FINE_POINTS

    if fine_points(model.spline, k) > MAX_FINE_POINTS:
        raise ValueError(f"{fine_points(model.spline, k):,} fine samples (more than {MAX_FINE_POINTS:,})")
    return int(_iso_mesh1(model, cache).n_cells) * k * k  # surface area / fine cell area ~ k^2


def _iso_mesh_build(plotter, model, style, k, cache, spline_options, add_options):
    from .volume.sampled_mesh import sampled_mesh

    mesh = cache.get(("mesh", k))
    if mesh is None:
        mesh = sampled_mesh(model.spline, model.isovalue, k, model.relevant)
    return _add_mesh(plotter, mesh, style, spline_options)


def _iso_refuses(model, style):
    if not np.allclose(np.asarray(model.spline.grid.direction, dtype=np.float64), np.eye(3)):
        return "rotated lattices are drawn by the ray cast only"
    return _mesh_refuses(model, style)


_MESH_K = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64)


def _add_mesh_guided(plotter, model, style, level, cache, spline_options, add_options):
    options = dict(spline_options)
    options["program_options"] = {**options.get("program_options", {}), "proxy": "mesh", "mesh_samples": 1}
    return _add_raycast(plotter, model, style, level, cache, options, add_options)


#: Renderers per program, any order (sorted by ``rank`` when used). The mesh-guided ray cast draws the same
#: picture as the ray cast (the same hard cases agree with the float64 twin) at 2.5-4x less time per frame on
#: this machine (benchmarks/bench_mesh_guided.py), so it ranks between meshes and the box ray cast.
RENDERERS = {
    "terrain": (
        Renderer("mesh", 0, _MESH_K, _terrain_mesh_error, _terrain_mesh_build, _terrain_mesh_triangles, _mesh_refuses),
        Renderer("mesh_guided", 5, (None,), raycast_error_px, _add_mesh_guided, exact=True),
        Renderer("raycast", 10, (None,), raycast_error_px, _add_raycast, exact=True),
    ),
    "isosurface": (
        Renderer("mesh", 0, _MESH_K[:8], _iso_mesh_error, _iso_mesh_build, _iso_mesh_triangles, _iso_refuses),
        Renderer("raycast", 10, (None,), raycast_error_px, _add_raycast, exact=True),
    ),
}


def choose(program: str, model, view: View, max_error_px: float, style=None, *,
           triangle_cap: int = TRIANGLE_CAP, cache: dict | None = None, exclude: dict | None = None) -> Choice:
    """The cheapest renderer of :data:`RENDERERS[program] <RENDERERS>` meeting ``max_error_px`` for ``view``
    (module docstring). Every renderer's error is computed (meshes: up to the first ``k`` that meets the
    request or the cap) so that the choice can say what it passed over. ``exclude`` maps renderer names to
    the reason they may not be used.

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:17, 0:17] / 16.0
    >>> t = TerrainSpline.from_heights(0.3 * np.sin(4 * x) * np.cos(3 * y), "C1", spacing=(1 / 16, 1 / 16))
    >>> v = View((0.5, -1.5, 1.5), (0.5, 0.5, 0.0), (0, 0, 1), 30.0, width=320, height=240)
    >>> [(c.renderer, c.level) for c in (choose("terrain", t, v, e) for e in (2.0, 0.2, 0.02))]
    [('mesh', 1), ('mesh', 3), ('mesh', 12)]
    >>> c = choose("terrain", t, v, 0.02, triangle_cap=50_000)  # k = 12 has 73,728 triangles
    >>> c.renderer, c.meets, [str(o) for o in c.options[-3:]]  # the exact renderers: the cheaper one
    ('mesh_guided', True, ['mesh k=12: over the cap of 50,000 triangles', 'mesh_guided 0.0177 px (estimate)', 'raycast 0.0177 px (estimate)'])
    """
    from .effects import Style

    max_error_px = check_max_error(max_error_px)
    if program not in RENDERERS:
        raise ValueError(f"no renderer table for program {program!r}; known: {', '.join(sorted(RENDERERS))}.")
    style = Style() if style is None else style
    cache = {} if cache is None else cache
    cache["program"] = program
    options, chosen = [], None
    for r in sorted(RENDERERS[program], key=lambda r: r.rank):
        reason = (exclude or {}).get(r.name) or (r.refuses(model, style) if r.refuses is not None else None)
        if reason:
            options.append(Option(r.name, None, math.inf, False, reason=reason))
            continue
        for level in r.levels:
            try:
                tri = r.triangles(model, level, cache) if r.triangles is not None else None
            except ValueError as e:  # too large to build at all
                options.append(Option(r.name, level, math.inf, False, reason=str(e)))
                break
            if tri is not None and tri > triangle_cap:
                options.append(Option(r.name, level, math.inf, False, tri, reason=f"over the cap of {triangle_cap:,} triangles"))
                break
            px, proven = r.error_px(model, view, level, cache)
            options.append(Option(r.name, level, float(px), proven, tri, meets=px <= max_error_px))
            if px <= max_error_px:
                break
        if chosen is None:
            chosen = next((o for o in options if o.meets), None)
    if chosen is None:  # the exact renderer: its error estimate over-states grazing rays (module docstring)
        exact = {r.name for r in RENDERERS[program] if r.exact}
        pool = [o for o in options if not o.reason]
        chosen = min([o for o in pool if o.name in exact] or pool, key=lambda o: o.error_px)
    return Choice(program, max_error_px, chosen, tuple(options), view)


def _model_bounds(model):
    if hasattr(model, "spline"):  # an isosurface: the spline's domain
        return tuple(model.spline.bounds)
    x0, x1, y0, y1 = model.extent
    z0, z1 = model.zrange
    return (x0, x1, y0, y1, z0, z1)


def add_by_accuracy(plotter, program: str, args, read_options, style, options, max_error_px, *, style_from,
                    add_options=None):
    """Build the model of ``program`` from ``args``, choose its renderer for ``max_error_px`` and add it
    (what ``Plotter.add_terrain/add_isosurface(..., max_error_px=...)`` do).

    The view is the plotter's camera if it was set, else pyvista's default view fitted to the model's bounds
    (what the first render would show); the camera is then set to that view (moving it closer afterwards
    can break the request: call again or choose for the final camera). The reader's keywords (``order``,
    ``spacing``, ``origin``) may be in ``options`` as in ``read_options``
    (:func:`splinevis.plotting_options.split_read_options`). The actor gets ``renderer_choice`` (a
    :class:`Choice`); the one-line ``Choice.message`` goes to the ``"splinevis"`` logger at INFO.

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.plotting import Plotter
    >>> z = np.add.outer(np.sin(np.linspace(0, 3, 17)), np.cos(np.linspace(0, 3, 17)))
    >>> pl = Plotter(off_screen=True, window_size=(160, 120))
    >>> actor = pl.add_terrain(z, "C1", read_options={"spacing": (0.2, 0.2)}, max_error_px=0.5)
    >>> actor.renderer_choice.renderer, actor.renderer_choice.meets
    ('mesh', True)
    >>> pl.close()
    """
    from vtkmodules.vtkRenderingCore import vtkCamera

    from .programs import get

    max_error_px = check_max_error(max_error_px)
    read_options, options = split_read_options(program, read_options, options)
    spline_options = {k: options.pop(k) for k in ("name", "newton_iterations", "program_options", "program")
                      if k in options}
    st = style_from(style, options)
    model = get(program).model_from(*args, **read_options)
    ren = plotter.renderer
    if not ren.camera_set:  # pyvista's view at the first render: the theme's direction, fitted to the bounds
        b = list(_model_bounds(model))
        vb = ren.ComputeVisiblePropBounds()
        if vb[0] <= vb[1]:
            b = [min(b[i], vb[i]) if i % 2 == 0 else max(b[i], vb[i]) for i in range(6)]
        centre = np.array([b[0] + b[1], b[2] + b[3], b[4] + b[5]]) / 2.0
        theme = plotter.theme.camera
        ren.camera_position = [centre + np.asarray(theme.position, dtype=np.float64), centre, theme.viewup]
        ren.ResetCamera(*b)
    cam = ren.GetActiveCamera()
    saved = vtkCamera()
    saved.DeepCopy(cam)
    given = sorted({"program_options", "program"} & set(spline_options))
    exclude = {r.name: f"{' and '.join(given)} given (ray-cast options)" for r in RENDERERS[program]
               if given and r.name != "raycast"}  # meshes take none; the mesh-guided build sets its own
    choice = choose(program, model, View.from_renderer(ren, plotter.window_size), max_error_px, st,
                    cache=(cache := {}), exclude=exclude)
    entry = next(r for r in RENDERERS[program] if r.name == choice.renderer)
    actor = entry.build(plotter, model, st, choice.level, cache, spline_options, add_options)
    cam.DeepCopy(saved)
    ren.ResetCameraClippingRange()
    for key, value in (("renderer_choice", choice), ("model", model)):
        try:
            setattr(actor, key, value)
        except AttributeError:  # a pyvista Actor takes new attributes only this way
            import pyvista as pv

            pv.set_new_attribute(actor, key, value)
    log.info(choice.message)
    return actor

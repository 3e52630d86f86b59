"""Choice of renderer by accuracy: the cheapest way to draw a spline whose screen-space error stays below
``max_error_px`` and whose shading normals stay within ``max_normal_error_deg`` of the spline's for the current
camera (``Plotter.add_spline/add_terrain/add_isosurface/add_nurbs/add_geometry_image(..., max_error_px=...)``),
made again when the camera moves (:func:`add_model_by_accuracy`).

**The renderers are part of each family's contract.** A family lists on its program
(``SplineProgram.renderers``, :class:`splinevis.gl.renderers.Renderer`) the ways its models can be drawn: a
name, a cost rank (lower is cheaper), the levels tried in order of cost (samples per cell ``k`` for meshes),
an error function ``error_px(model, view, level, cache) -> (pixels, proven)``, how to build it and, for
meshes, a triangle count and the styles or models it refuses; its error functions and builders live in its
own folder (e.g. ``splinevis/terrain/renderers.py``). This module knows no family: :func:`choose` takes the
renderers of ``program_for(model)`` (:func:`renderers_for`), walks them in cost order and takes the first
(for a mesh the smallest ``k``) whose error is at most ``max_error_px`` (and normal error, ``error_px``'s
twin ``normal_error_deg``, at most ``max_normal_error_deg``) and whose triangle count is within
:data:`TRIANGLE_CAP`, the cheapest of those (below); if none meets the request, the exact renderer closest to
it is chosen and the choice says that the request is not met. A program that declares no exact renderer gets its own (the
program itself, named after its kind); one that declares no renderers at all is drawn by its own only, and
the choice says so.

**Cost.** Among the renderers whose error meets the request (for a mesh, its smallest such ``k``) the choice
draws the one of least estimated frame time when each declares ``Renderer.cost``
(:func:`splinevis.gl.renderers.estimated_ms`: nanoseconds per pixel of the model's screen rectangle, a
family's measured constant for its ray cast, and a mesh's per-pixel and per-triangle constants), else the one of
lowest ``rank``. The constants were measured on this machine (Mesa llvmpipe, 2 cores) by
benchmarks/bench_choice.py (docs/results/choice/choice.md): there a terrain mesh of 131,072 triangles took
as long as the terrain's ray cast in pyvista's default view (32 against 35 ms) and one of 2,097,152 six times
as long, while the NURBS program took 787 ms against 12-32 ms for tessellations within 2-0.1 px; hence ranks
alone (meshes first) were not enough. The triangle cap :data:`TRIANGLE_CAP` still bounds what is built. On a
GPU the constants should be measured again.

**Screen-space error** is the distance, in pixels on the screen, between a point the renderer shows and
the point of the exact (float64) spline it stands for; world errors become pixels by
:class:`splinevis.gl.screen_error.View` (a conservative bound at the worst point, derived there).

For a mesh the displacement is bounded per cell (or cube) and the pixels are bounded over the cell's box
(largest r and smallest Z over its corners): the maximum over the boxes in the view frustum is the
"nearest visible point" of the bound. A box reaching behind the eye plane (or closer than e) that meets the
frustum makes the mesh's error unbounded (a mesh seen from that close can be off by any number of pixels):
an exact renderer is chosen. Every renderer adds the rasterizer's sub-pixel snapping, sqrt(2) 2^-8 pixels
(:data:`splinevis.gl.error_bounds.SUBPIXEL`). The families' mesh bounds (proven or estimated) are derived
in their renderer modules.

A renderer that declares no error function has the program's own: for a program with a float64 twin and a
derived depth bound, :func:`raycast_error_px`: the bound (``SplineProgram.depth_bound``) on a grid of 32 x 24
sample rays, less its depth-arithmetic and depth-buffer terms (they change the depth written, not the point
shown; a mesh's depth has them too), turned into a distance along the ray and converted to pixels as if it
were sideways: an **estimate** over the screen (bounds at the sampled pixels). It over-states the ray cast's
error where rays graze the surface (near silhouettes): there the root, hence the depth, moves along the ray
by up to 2 sqrt(2 eps / |g''|) while the shown surface moves sideways by about eps / |grad| only (0.15 px on
the terrain study's view, against 0.66 px for a k = 4 mesh). Other programs' own error is unknown (shown as
such; it never meets a request).
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .gl.error_bounds import depth_error
from .gl.renderers import Choice, Option, Renderer, model_bounds
from .gl.screen_error import SNAP_PX, View
from .plotting_options import split_read_options

__all__ = ["Renderer", "Option", "Choice", "TRIANGLE_CAP", "choose", "renderers_for", "check_max_error", "check_requests",
           "add_by_accuracy", "add_model_by_accuracy", "raycast_error_px", "add_renderer", "fit_default_camera"]

log = logging.getLogger("splinevis")

#: Largest mesh (triangles) the choice builds: the largest mesh measured cheaper than the ray cast when the cap
#: was set (docs/results/terrain/pareto.md: 1025 x 1025 vertices, 2,097,152 triangles, 148 ms against 135-242
#: ms; since the ray cast walks in rounds, 182 against 55-76 ms: the estimated costs, not the cap, now keep
#: such meshes from being drawn where the ray cast is cheaper).
TRIANGLE_CAP = 2_097_152

#: Keywords of ``add_spline`` that go to the program, not to the style.
_SPLINE_KEYS = ("name", "newton_iterations", "program_options", "program")


def check_max_error(max_error_px, what: str = "max_error_px", unit: str = "pixels (e.g. 0.5)") -> float:
    """``max_error_px`` (or the request named ``what``) as a float; ValueError unless it is a positive finite
    number.

    >>> check_max_error(0.5)
    0.5
    >>> check_max_error(0)
    Traceback (most recent call last):
    ValueError: max_error_px must be a positive finite number of pixels (e.g. 0.5), got 0.
    >>> check_max_error(-1, "max_normal_error_deg", "degrees (e.g. 1)")
    Traceback (most recent call last):
    ValueError: max_normal_error_deg must be a positive finite number of degrees (e.g. 1), got -1.
    """
    ok = isinstance(max_error_px, (int, float, np.integer, np.floating)) and not isinstance(max_error_px, bool)
    if not ok or not math.isfinite(float(max_error_px)) or float(max_error_px) <= 0:
        raise ValueError(f"{what} must be a positive finite number of {unit}, got {max_error_px!r}.")
    return float(max_error_px)


def check_requests(max_error_px, max_normal_error_deg) -> tuple:
    """``(max_error_px, max_normal_error_deg)`` checked; a request not given bounds nothing (``max_error_px``
    inf, the normal request None), but one of the two must be given.

    >>> check_requests(None, 1), check_requests(0.5, None)
    ((inf, 1.0), (0.5, None))
    """
    if max_error_px is None and max_normal_error_deg is None:
        raise ValueError("give max_error_px (pixels) or max_normal_error_deg (degrees), or both.")
    px = math.inf if max_error_px is None else check_max_error(max_error_px)
    deg = None if max_normal_error_deg is None else check_max_error(max_normal_error_deg, "max_normal_error_deg",
                                                                      "degrees (e.g. 1)")
    return px, deg


def _normal_error(renderer, model, view, level, cache):
    """``(degrees, proven)`` of ``renderer`` (:attr:`Renderer.normal_error_deg`; exact renderers without one
    shade with the spline's own normals: 0, meshes without one: unknown)."""
    if renderer.normal_error_deg is not None:
        return renderer.normal_error_deg(model, view, level, cache)
    return (0.0, False) if renderer.exact else (math.inf, False)


# ---------------------------------------------------------------------------------------------- ray cast
def raycast_error_px(model, view, level, cache, *, rays=(32, 24)):
    """(pixels, False): the program's float32 depth bound on ``rays`` sample rays converted to pixels
    (module docstring), plus the sub-pixel snapping; the program is ``cache["program"]`` (a
    :class:`~splinevis.gl.contract.SplineProgram` or a registered name).

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

    program = _program(model, cache["program"])
    m = view.matrix()
    o, d = pixel_rays(m, *rays)
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    hits = program.reference(model, o, d)
    t = np.asarray(hits.t, dtype=np.float64).reshape(-1)
    ok = np.isfinite(t)
    if not ok.any():
        return SNAP_PX, False
    surface = hits.surface_at(ok)  # the family's parameters of the hits (its bound need not find them again)
    o, d, t = o[ok], d[ok], t[ok]
    bound = np.asarray(program.depth_bound(model, m, o, d, t, surface=surface), dtype=np.float64)
    h = 1e-6 * np.maximum(1.0, np.abs(t))
    # the bound is |d depth / dt| dt + the depth arithmetic and quantization (depth_error with dt = 0), which
    # move no point (a mesh's depth has them too): keep the part that moves the hit along its ray
    moved = np.maximum(bound - depth_error(m, o, d, t, h, np.zeros_like(t)), 0.0)
    slope = np.abs(window_depth(m, o + (t + h)[:, None] * d) - window_depth(m, o + (t - h)[:, None] * d)) / (2 * h)
    world = moved / np.maximum(slope, 1e-300) * np.linalg.norm(d, axis=1)
    return float(view.point_pixels(o + t[:, None] * d, world).max()) + SNAP_PX, False


def _unknown_error_px(model, view, level, cache):
    return math.inf, False


def _add_own(plotter, model, style, level, cache, spline_options, add_options, renderer):
    """The program draws the model itself, with the renderer's program options, then runs its ``on_add``."""
    program = cache["program"]
    options = dict(spline_options, program=program.name)
    if renderer.program_options:
        options["program_options"] = {**options.get("program_options", {}), **dict(renderer.program_options)}
    actor = plotter.add_spline(model, style, **options)
    if program.on_add is not None:
        program.on_add(actor, plotter, **(add_options or {}))
    return actor


def _program(model, program):
    from .programs import get, program_for

    if program is None:
        return program_for(model)
    return get(program) if isinstance(program, str) else program


def _own_error(program):
    """The error function of the program's own renderers (module docstring)."""
    return raycast_error_px if program.reference is not None and program.depth_bound is not None else _unknown_error_px


def renderers_for(program) -> tuple:
    """``(renderers, note)``: the renderers :func:`choose` walks for ``program`` (a SplineProgram or a
    registered name) in cost order, its own exact renderer added when it declares none (module docstring),
    and what the choice says about that ("" when the program declares an exact renderer).

    >>> [(r.name, r.rank, r.exact) for r in renderers_for("terrain")[0]]
    [('mesh', 0, False), ('raycast', 10, True), ('mesh_guided', 15, True)]
    >>> rows, note = renderers_for("analytic_patch")
    >>> [(r.name, r.exact) for r in rows], note
    ([('raycast', True)], "program 'analytic_patch' declares no renderers: drawn by its own (raycast), its error estimated")
    """
    program = _program(None, program)
    rows = tuple(program.renderers)
    note = ""
    if not any(r.exact for r in rows):
        name = program.kind if program.kind not in {r.name for r in rows} else "program"
        rows += (Renderer(name, max((r.rank for r in rows), default=0) + 1, exact=True),)
        error = "its error estimated" if _own_error(program) is raycast_error_px else "its error unknown"
        note = (f"program {program.name!r} declares " + ("no exact renderer: its own" if len(rows) > 1
                else "no renderers: drawn by its own") + f" ({program.kind}), {error}")
    return tuple(sorted(rows, key=lambda r: r.rank)), note


def choose(model, view: View, max_error_px: float | None, style=None, *, program=None, triangle_cap: int = TRIANGLE_CAP,
           cache: dict | None = None, exclude: dict | None = None, max_normal_error_deg: float | None = None) -> Choice:
    """The cheapest renderer of ``model``'s program (``program``: a name or SplineProgram; default
    ``program_for(model)``) meeting ``max_error_px`` for ``view`` (module docstring), and
    ``max_normal_error_deg`` when given (the normals it shades with within that many degrees of the spline's:
    :attr:`Renderer.normal_error_deg`; either request may be None, not both). Every renderer's error is
    computed (meshes: up to the first ``k`` that meets the request or the cap) so that the choice can say what
    it passed over. ``exclude`` maps renderer names to the reason they may not be used; ``cache`` (a dict)
    keeps what the error functions computed for this model across calls.

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.terrain.model import TerrainSpline
    >>> y, x = np.mgrid[0:17, 0:17] / 16.0
    >>> t = TerrainSpline.from_heights(0.3 * np.sin(4 * x) * np.cos(3 * y), "C1", spacing=(1 / 16, 1 / 16))
    >>> v = View((0.5, -1.5, 1.5), (0.5, 0.5, 0.0), (0, 0, 1), 30.0, width=320, height=240)
    >>> [(c.renderer, c.level) for c in (choose(t, v, e) for e in (2.0, 0.2, 0.02))]  # the least estimated time
    [('mesh', 1), ('mesh', 3), ('raycast', None)]
    >>> c = choose(t, v, 0.02)
    >>> [(o.name, o.level, round(o.cost_ms, 1)) for o in c.options if o.meets]  # 73,728 triangles against the ray cast
    [('mesh', 12, 8.4), ('raycast', None, 5.8), ('mesh_guided', None, 7.8)]
    >>> c = choose(t, v, 0.02, triangle_cap=50_000)  # k = 12 has 73,728 triangles
    >>> c.renderer, c.meets, [str(o) for o in c.options[-3:]]  # the exact renderers: the cheaper one
    ('raycast', True, ['mesh k=12: over the cap of 50,000 triangles', 'raycast 0.0177 px (estimate)', 'mesh_guided 0.0177 px (estimate)'])
    """
    from .effects import Style

    max_error_px, max_deg = check_requests(max_error_px, max_normal_error_deg)
    program = _program(model, program)
    rows, note = renderers_for(program)
    style = Style() if style is None else style
    cache = {} if cache is None else cache
    cache["program"] = program
    options, chosen = [], None
    for r in rows:
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
            px, proven = (r.error_px or _own_error(program))(model, view, level, cache)
            deg, deg_proven = _normal_error(r, model, view, level, cache) if max_deg is not None else (None, False)
            meets = px <= max_error_px and (deg is None or deg <= max_deg)
            cost = r.cost(model, view, level, cache) if meets and r.cost is not None else None
            options.append(Option(r.name, level, float(px), proven, tri, meets=meets,
                                  normal_deg=None if deg is None else float(deg), normal_proven=bool(deg_proven),
                                  cost_ms=cost))
            if meets:
                break
    meeting = [o for o in options if o.meets]  # each renderer's cheapest level meeting the request
    if meeting:  # by estimated frame time where every one has it, else by rank
        chosen = (min(meeting, key=lambda o: o.cost_ms) if all(o.cost_ms is not None for o in meeting)
                  else meeting[0])
    else:  # an exact renderer, the one closest to meeting the request (its error estimate over-states grazing
        exact = {r.name for r in rows if r.exact}  # rays: module docstring)
        pool = [o for o in options if not o.reason]
        if not pool:
            raise ValueError(f"no renderer of program {program.name!r} may draw this: "
                             + "; ".join(str(o) for o in options) + ".")

        def shortfall(o):
            return max(o.error_px / max_error_px, (o.normal_deg or 0.0) / max_deg if max_deg else 0.0)

        chosen = min([o for o in pool if o.name in exact] or pool, key=shortfall)
    return Choice(program.name, max_error_px, chosen, tuple(options), view, note, max_deg)


def _model_bounds(model, program, style):
    """World bounds the default camera is fitted to: ``model.bounds`` if the model has them, else those of
    what the program builds (its proxy, or its dataset)."""
    b = model_bounds(model)
    if b is not None:
        return b
    built = program.make(model, style)
    if hasattr(built, "bounds"):
        return tuple(built.bounds)
    p = np.asarray(built.points, dtype=np.float64) + np.asarray(built.offset, dtype=np.float64)
    lo, hi = p.min(axis=0), p.max(axis=0)
    return (lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])


def add_by_accuracy(plotter, program: str, args, read_options, style, options, max_error_px, *, style_from,
                    add_options=None, max_normal_error_deg=None):
    """Build the model of ``program`` from ``args``, choose its renderer for ``max_error_px`` and add it
    (what ``Plotter.add_terrain/add_isosurface(..., max_error_px=...)`` do; :func:`add_model_by_accuracy`).
    The reader's keywords (``order``, ``spacing``, ``origin``) may be in ``options`` as in ``read_options``
    (:func:`splinevis.plotting_options.split_read_options`).

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
    from .programs import get

    check_requests(max_error_px, max_normal_error_deg)
    read_options, options = split_read_options(program, read_options, options)
    spline_options = {k: options.pop(k) for k in _SPLINE_KEYS if k in options}
    st = style_from(style, options)
    model = get(program).model_from(*args, **read_options)
    return add_model_by_accuracy(plotter, model, st, max_error_px, add_options=add_options,
                                 max_normal_error_deg=max_normal_error_deg, **spline_options)


def add_model_by_accuracy(plotter, model, style, max_error_px, *, add_options=None, program=None,
                          max_normal_error_deg=None, **spline_options):
    """Choose the renderer of ``model`` (its program's, or the one named ``program``) for ``max_error_px`` and
    add it (what ``Plotter.add_spline(model, max_error_px=...)`` does); ``style`` is a Style,
    ``spline_options`` are ``add_spline``'s ``name``, ``newton_iterations``, ``program_options`` (None: not
    given), ``add_options`` go to the program's ``on_add``.

    The view is the plotter's camera if it was set, else pyvista's default view fitted to the model's bounds
    (what the first render would show); the camera is then set to that view. Before every render whose
    camera or window changed, the choice is made again for the new view and the renderer it picks is drawn
    instead (built once per renderer and level, kept hidden while not chosen: :func:`_follow_camera`), so
    the request holds as the camera moves in. Ray-cast options (``program_options``,
    ``program``) exclude every renderer but the program's own plain one. The actor gets ``choice`` (a
    :class:`Choice`; also as ``renderer_choice``) and ``model``; the one-line ``Choice.message`` goes to the ``"splinevis"`` logger at INFO.

    Examples
    --------
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> from splinevis.effects import Style
    >>> from splinevis.plotting import Plotter
    >>> pl = Plotter(off_screen=True, window_size=(64, 48))
    >>> actor = add_model_by_accuracy(pl, QuarticTrianglePatch.demo(), Style(), 0.5)
    >>> actor.renderer_choice.renderer, actor.renderer_choice.meets  # it declares none: its own ray cast
    ('raycast', True)
    >>> pl.close()
    """
    import os

    from vtkmodules.vtkRenderingCore import vtkCamera

    check_requests(max_error_px, max_normal_error_deg)
    spline_options = {k: v for k, v in spline_options.items() if v is not None}
    unknown = sorted(set(spline_options) - set(_SPLINE_KEYS))
    if unknown:
        raise TypeError(f"unknown options {unknown}; add_spline takes {', '.join(_SPLINE_KEYS)} besides the style.")
    prog = _program(model, program)
    if program is not None:
        spline_options["program"] = prog.name
    if not isinstance(model, prog.model_type):  # a file or a type the program converts (SplineProgram.converts)
        if prog.model_from is None or not isinstance(model, (str, os.PathLike) + tuple(prog.converts)):
            raise TypeError(f"program {prog.name!r} draws {prog.model_type.__name__}, not {type(model).__name__}.")
        model = prog.model_from(model)
    ren = plotter.renderer
    if not ren.camera_set:
        fit_default_camera(plotter, model, style, program=prog)
    cam = ren.GetActiveCamera()
    saved = vtkCamera()
    saved.DeepCopy(cam)
    rows, _ = renderers_for(prog)
    given = sorted({"program_options", "program"} & set(spline_options))
    # meshes take no ray-cast options; a renderer with program options of its own (mesh-guided) sets them
    plain = {r.name for r in rows if r.build is None and not r.program_options}
    exclude = {r.name: f"{' and '.join(given)} given (ray-cast options)" for r in rows if given and r.name not in plain}
    cache = {"add_options": dict(add_options or {})}  # the error functions may read how it will be drawn
    choice = choose(model, View.from_renderer(ren, plotter.window_size), max_error_px, style, program=prog,
                    cache=cache, exclude=exclude, max_normal_error_deg=max_normal_error_deg)
    def build(c, options):
        return _build(plotter, model, style, rows, c.renderer, c.level, cache, options, add_options)

    actor = build(choice, spline_options)
    cam.DeepCopy(saved)
    ren.ResetCameraClippingRange()
    for key, value in (("renderer_choice", choice), ("choice", choice), ("model", model), ("drawn", actor)):
        _set_attribute(actor, key, value)
    log.info(choice.message)
    _follow_camera(plotter, actor, choice, build, spline_options,
                   lambda view: choose(model, view, max_error_px, style, program=prog, cache=cache, exclude=exclude,
                                       max_normal_error_deg=max_normal_error_deg))
    return actor


def add_renderer(plotter, model, style, name: str, level=None, *, program=None, cache: dict | None = None):
    """Draw ``model`` with its program's renderer ``name`` at ``level`` (what the choice would build for that
    option): for benchmarks and studies that time or compare renderers side by side.

    >>> import numpy as np
    >>> from splinevis.effects import Style
    >>> from splinevis.plotting import Plotter
    >>> from splinevis.terrain.model import TerrainSpline
    >>> t = TerrainSpline.from_heights(np.zeros((5, 5)), "C1")
    >>> pl = Plotter(off_screen=True, window_size=(64, 48))
    >>> add_renderer(pl, t, Style(), "mesh", 2).GetMapper().GetInput().GetNumberOfCells()  # 2 k^2 per cell
    128
    >>> pl.close()
    """
    prog = _program(model, program)
    rows, _ = renderers_for(prog)
    cache = {} if cache is None else cache
    cache["program"] = prog
    return _build(plotter, model, style, rows, name, level, cache, {}, None)


def _build(plotter, model, style, rows, name, level, cache, spline_options, add_options):
    """Draw ``model`` with the renderer named ``name`` among ``rows`` at ``level``: its ``build``, or the program
    itself with the renderer's program options (:func:`_add_own`)."""
    entry = next((r for r in rows if r.name == name), None)
    if entry is None:
        raise ValueError(f"program {cache['program'].name!r} has no renderer {name!r}; it has "
                         f"{[r.name for r in rows]}.")
    if entry.build is not None:
        return entry.build(plotter, model, style, level, cache, spline_options, add_options)
    return _add_own(plotter, model, style, level, cache, spline_options, add_options, entry)


def fit_default_camera(plotter, model, style=None, *, program=None) -> View:
    """Set ``plotter``'s camera to pyvista's view at the first render: the theme's direction, fitted to the
    model's bounds (:func:`_model_bounds`) and those of what the plotter already shows; return that view (what
    :func:`add_model_by_accuracy` chooses for when no camera was set).

    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> from splinevis.plotting import Plotter
    >>> pl = Plotter(off_screen=True, window_size=(64, 48))
    >>> v = fit_default_camera(pl, QuarticTrianglePatch.demo())
    >>> v.width, v.height, bool(pl.renderer.camera_set)
    (64, 48, True)
    >>> pl.close()
    """
    from .effects import Style

    ren = plotter.renderer
    b = list(_model_bounds(model, _program(model, program), Style() if style is None else style))
    vb = ren.ComputeVisiblePropBounds()
    if vb[0] <= vb[1]:
        b = [min(b[i], vb[i]) if i % 2 == 0 else max(b[i], vb[i]) for i in range(6)]
    centre = np.array([b[0] + b[1], b[2] + b[3], b[4] + b[5]]) / 2.0
    theme = plotter.theme.camera
    ren.camera_position = [centre + np.asarray(theme.position, dtype=np.float64), centre, theme.viewup]
    ren.ResetCamera(*b)
    return View.from_renderer(ren, plotter.window_size)


def _set_attribute(actor, key, value):
    try:
        setattr(actor, key, value)
    except AttributeError:  # a pyvista Actor takes new attributes only this way
        import pyvista as pv

        pv.set_new_attribute(actor, key, value)


def _view_key(view: View) -> tuple:
    """What decides a choice in a view: the camera and the window (not the clipping range, which VTK resets
    at every render)."""
    return (view.position, view.focal_point, view.view_up, view.view_angle, view.parallel, view.parallel_scale,
            view.width, view.height)


def _follow_camera(plotter, actor, choice, build, spline_options, rechoose):
    """Make the choice again before each render whose camera or window differs from the last one chosen for,
    and draw the renderer it picks: each (renderer, level) is built once and kept (hidden while another is
    drawn), so moving back and forth costs no rebuild. ``actor`` (what the user holds) keeps the current
    ``choice`` and the actor ``drawn``; ``actor.choices`` counts how often each (renderer, level) was chosen."""
    ren = plotter.renderer
    built = {(choice.renderer, choice.level): actor}
    state = {"key": (choice.renderer, choice.level), "view": _view_key(View.from_renderer(ren, plotter.window_size)),
             "busy": False}
    _set_attribute(actor, "choices", {state["key"]: 1})

    def before_render(caller, event):
        if state["busy"]:
            return
        view = View.from_renderer(ren, plotter.window_size)
        if _view_key(view) == state["view"]:
            return
        state["busy"] = True
        try:
            state["view"] = _view_key(view)
            new = rechoose(view)
            key = (new.renderer, new.level)
            if key not in built:
                from vtkmodules.vtkRenderingCore import vtkCamera

                saved = vtkCamera()
                saved.DeepCopy(ren.GetActiveCamera())
                name = spline_options.get("name")
                options = dict(spline_options, **({"name": f"{name} ({key[0]} {key[1]})"} if name else {}))
                built[key] = build(new, options)
                ren.GetActiveCamera().DeepCopy(saved)
            if key != state["key"]:
                built[state["key"]].SetVisibility(False)
                built[key].SetVisibility(True)
                log.info(new.message)
            state["key"] = key
            actor.choices[key] = actor.choices.get(key, 0) + 1
            for k, v in (("choice", new), ("renderer_choice", new), ("drawn", built[key])):
                _set_attribute(actor, k, v)
        finally:
            state["busy"] = False

    ren.AddObserver("StartEvent", before_render)

"""What a family declares about the ways its models can be drawn (``SplineProgram.renderers``) and what the
choice by accuracy (:mod:`splinevis.choice`) reports: :class:`Renderer` (one way: its cost rank, levels,
screen-space error as a function of the view, how to build it), :class:`Option` (one renderer at one level,
as considered for a view) and :class:`Choice` (what was picked among them).

A family's renderers live in its own folder (e.g. ``splinevis/terrain/renderers.py``) and are listed on its
program; the generic choice walks them without knowing the family. A renderer without ``build`` is the
program itself (with its ``program_options``); one without ``error_px`` has the program's own error (the
ray cast's derived depth bound turned into pixels, :func:`splinevis.choice.raycast_error_px`, for programs
with a float64 twin; unknown otherwise). The mesh helpers below are shared by the families' mesh renderers.

Mesh vertices are float32 on the GPU: each coordinate is rounded (u = 2^-24 relative) and the 4-term
model-view-projection product rounds again, a few u of the largest coordinate per term; 8 u of the largest
coordinate (:func:`float32_margin`) covers both, as in :mod:`splinevis.gl.error_bounds`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .error_bounds import U32
from .screen_error import View

__all__ = ["Renderer", "Option", "Choice", "MESH_LEVELS", "float32_margin", "mesh_refuses", "add_mesh_actor",
           "MESH_NS_PER_PIXEL", "MESH_NS_PER_TRIANGLE", "estimated_ms", "model_bounds", "model_box", "raycast_cost", "mesh_cost"]

#: Samples per cell (or cube) tried for sampled meshes, in order of cost.
MESH_LEVELS = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64)


@dataclass(frozen=True)
class Renderer:
    """One way to draw a family's models, declared on its program (``SplineProgram.renderers``).

    Attributes
    ----------
    name : str
        Shown in the choice (``"mesh"``, ``"raycast"``).
    rank : int
        Cost rank, lower is cheaper (measured: :mod:`splinevis.choice`).
    levels : tuple
        Levels tried in order of cost (samples per cell ``k`` of a mesh); ``(None,)`` for one level.
    error_px : callable, optional
        ``error_px(model, view, level, cache) -> (pixels, proven)``: the screen-space error for ``view``
        (:class:`splinevis.gl.screen_error.View`); ``cache`` is a dict kept for one model across views.
        None: the program's own error (module docstring).
    build : callable, optional
        ``build(plotter, model, style, level, cache, spline_options, add_options) -> actor``. None: the
        program draws the model itself with ``program_options``.
    triangles : callable, optional
        ``triangles(model, level, cache) -> int`` for meshes (checked against the triangle cap; a
        ValueError means too large to build at all).
    refuses : callable, optional
        ``refuses(model, style) -> reason or None``.
    exact : bool
        Draws the spline itself: among these the choice falls back on when nothing meets the request.
    program_options : tuple of (name, value) pairs
        Program options the program is built with when ``build`` is None (a dict is accepted).
    normal_error_deg : callable, optional
        ``normal_error_deg(model, view, level, cache) -> (degrees, proven)``: the largest angle between the
        normal the renderer shades with and the spline's exact normal at the point it stands for. None: an
        exact renderer evaluates the spline's own normal per pixel (``exact normals``: float32 rounding only,
        which the program's hard cases compare with its float64 twin); a mesh's is unknown and never meets a
        ``max_normal_error_deg`` request.
    measure : callable, optional
        ``measure(model, view, level, cache) -> (pixels, degrees)``: the error measured against the float64
        spline on samples of what the renderer draws (the points it draws against the spline points they stand
        for, in pixels of ``view``; the normals it shades with against the spline's): what the benchmarks and
        tests compare with the declared bounds. None: not measured.
    cost : callable, optional
        ``cost(model, view, level, cache) -> milliseconds``: the estimated frame time on this machine
        (:func:`estimated_ms`). Among the renderers meeting a request the choice draws the one of least
        estimated time when every one of them declares it, else the one of lowest ``rank``.

    Examples
    --------
    >>> Renderer("mesh_guided", 5, exact=True, program_options={"proxy": "mesh"}).program_options
    (('proxy', 'mesh'),)
    >>> Renderer("raycast", 10).levels
    (None,)
    """

    name: str
    rank: int
    levels: tuple = (None,)
    error_px: Callable | None = None
    build: Callable | None = None
    triangles: Callable | None = None
    refuses: Callable | None = None
    exact: bool = False
    program_options: tuple = ()
    normal_error_deg: Callable | None = None
    measure: Callable | None = None
    cost: Callable | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"Renderer.name must be an identifier-like string, got {self.name!r}.")
        if not isinstance(self.levels, tuple) or not self.levels:
            raise ValueError(f"Renderer {self.name!r}: levels must be a nonempty tuple, got {self.levels!r}.")
        if isinstance(self.program_options, dict):
            object.__setattr__(self, "program_options", tuple(sorted(self.program_options.items())))
        if self.program_options and self.build is not None:
            raise ValueError(f"Renderer {self.name!r}: program_options are for the program's own build (build=None).")


@dataclass(frozen=True)
class Option:
    """A renderer considered: its name, level (``k``; None for ray casts), screen-space error (pixels; inf
    when unknown), whether that error is proven, triangles (meshes), whether it meets the request and why not;
    when the request bounds the normals too, the normal error (degrees; 0 for exact normals, inf unknown) and
    whether it is proven (``normal_deg`` None: not asked); for an option meeting the request, its estimated
    frame time ``cost_ms`` (None: its renderer declares no cost).

    >>> str(Option("mesh", 2, 0.8, True, 1024, True))
    'mesh k=2 0.8 px (proven, 1,024 triangles)'
    >>> str(Option("surface", None, float("inf"), False))
    'surface (error unknown)'
    >>> str(Option("mesh", 4, 0.2, True, 4096, True, normal_deg=0.61, normal_proven=True))
    'mesh k=4 0.2 px (proven, 4,096 triangles), normals 0.61 deg (proven)'
    >>> str(Option("raycast", None, 0.01, False, normal_deg=0.0))
    'raycast 0.01 px (estimate), exact normals'
    """

    name: str
    level: object
    error_px: float
    proven: bool
    triangles: int | None = None
    meets: bool = False
    reason: str = ""
    normal_deg: float | None = None
    normal_proven: bool = False
    cost_ms: float | None = None

    def __str__(self):
        label = self.name + ("" if self.level is None else f" k={self.level}")
        if self.reason:
            return f"{label}: {self.reason}"
        if self.error_px == float("inf"):
            return f"{label} (error unknown)"
        extra = "proven" if self.proven else "estimate"
        if self.triangles is not None:
            extra += f", {self.triangles:,} triangles"
        text = f"{label} {self.error_px:.3g} px ({extra})"
        if self.normal_deg is None:
            return text
        if self.normal_deg == 0.0:
            return text + ", exact normals"
        if self.normal_deg == float("inf"):
            return text + ", normal error unknown"
        return text + f", normals {self.normal_deg:.3g} deg ({'proven' if self.normal_proven else 'estimate'})"


@dataclass(frozen=True)
class Choice:
    """What the choice picked (``chosen``) for the program named ``program``, for which request and
    ``view``, among ``options`` (every candidate looked at, in cost order); ``meets`` is False when no renderer
    reaches ``max_error_px`` (an exact renderer is drawn then). ``note`` adds what the message should say
    besides (e.g. that the program declares no renderers).

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
    note: str = ""
    max_normal_error_deg: float | None = None

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
        """One line: what was chosen, its error against the request, the alternatives considered, the note.

        >>> Choice("terrain", 1e-4, Option("raycast", None, 0.006, False), ()).message
        'splinevis: terrain drawn as raycast 0.006 px (estimate); nothing meets max_error_px=0.0001, drawing the exact renderer'
        >>> Choice("dots", 0.5, Option("mesh", None, float("inf"), False), (), note="it declares no renderers").message
        'splinevis: dots drawn as mesh (error unknown); nothing meets max_error_px=0.5, drawing the exact renderer; it declares no renderers'
        """
        head = f"splinevis: {self.program} drawn as {self.chosen}"
        request = f"max_error_px={self.max_error_px:g}"
        if self.max_normal_error_deg is not None:
            request += f", max_normal_error_deg={self.max_normal_error_deg:g}"
        head += (f" <= {request}" if self.meets else f"; nothing meets {request}, drawing the exact renderer")
        others = [str(o) for o in self.options if o is not self.chosen]
        return head + ("; considered: " + ", ".join(others) if others else "") + (f"; {self.note}" if self.note else "")


#: Frame-time model of a mesh on this machine (Mesa llvmpipe, 2 cores, 800 x 600, one light): nanoseconds per
#: pixel of the screen rectangle around the model and per triangle. Fitted to benchmarks/bench_choice.py
#: (docs/results/choice/): terrain meshes of 8,192 to 2,097,152 triangles took 9.2 to 208 ms in one run
#: (95 ns a triangle, about 8 ms for the 275,000 pixels of the model's screen rectangle); geometry-image
#: levels 81 ns a triangle, NURBS tessellations 140.
MESH_NS_PER_PIXEL = 30.0
MESH_NS_PER_TRIANGLE = 95.0


def estimated_ms(view, lo, hi, *, ns_per_pixel: float, triangles: int = 0) -> float:
    """Estimated frame time (ms) of a renderer drawing a model in the box ``lo..hi`` for ``view``:
    ``ns_per_pixel`` times the pixels of the screen rectangle around the box
    (:meth:`~splinevis.gl.screen_error.View.box_area_pixels`) plus :data:`MESH_NS_PER_TRIANGLE` a triangle. A
    ray cast's ``ns_per_pixel`` is its family's (measured, in its renderers module), a mesh's
    :data:`MESH_NS_PER_PIXEL`. Rough (within 2x of the benchmark's frames) but enough to tell a mesh of two
    million triangles from a ray cast of a small view.

    >>> v = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200)
    >>> round(estimated_ms(v, [-1, -1, 0], [1, 1, 0], ns_per_pixel=MESH_NS_PER_PIXEL, triangles=100_000), 3)
    9.512
    """
    return (ns_per_pixel * view.box_area_pixels(lo, hi) + MESH_NS_PER_TRIANGLE * triangles) * 1e-6


def model_bounds(model) -> tuple | None:
    """``model.bounds`` as six floats ``(xmin, xmax, ymin, ymax, zmin, zmax)``, an attribute (pyvista, our
    splines) or a method (NurbsModel); None when the model has none.

    >>> import pyvista as pv
    >>> model_bounds(pv.Box()), model_bounds(object())
    ((-1.0, 1.0, -1.0, 1.0, -1.0, 1.0), None)
    """
    b = getattr(model, "bounds", None)
    b = b() if callable(b) else b
    return None if b is None else tuple(float(v) for v in b)


def model_box(model, cache) -> tuple:
    """``(lo, hi)`` of :func:`model_bounds`, kept in ``cache``.

    >>> import pyvista as pv
    >>> [v.tolist() for v in model_box(pv.Box(), {})]
    [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]
    """
    if "box" not in cache:
        b = model_bounds(model)
        cache["box"] = (np.array(b[0::2], dtype=np.float64), np.array(b[1::2], dtype=np.float64))
    return cache["box"]


def raycast_cost(ns_per_pixel: float):
    """A ``Renderer.cost`` for a program costing ``ns_per_pixel`` per pixel of the model's screen rectangle.

    >>> import pyvista as pv
    >>> v = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200)
    >>> round(raycast_cost(1000.0)(pv.Box(), v, None, {}), 6)  # the box's near face at depth 9: (200 / 9)^2 px
    0.493827
    """
    def cost(model, view, level, cache):
        lo, hi = model_box(model, cache)
        return estimated_ms(view, lo, hi, ns_per_pixel=ns_per_pixel)

    return cost


def mesh_cost(triangles):
    """A ``Renderer.cost`` for a mesh with ``triangles(model, level, cache)`` triangles
    (:data:`MESH_NS_PER_PIXEL`, :data:`MESH_NS_PER_TRIANGLE`).

    >>> import pyvista as pv
    >>> v = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200)
    >>> round(mesh_cost(lambda model, level, cache: 1000 * level)(pv.Box(), v, 10, {}), 4)  # 494 px, 10,000 tri
    0.9648
    """
    def cost(model, view, level, cache):
        lo, hi = model_box(model, cache)
        return estimated_ms(view, lo, hi, ns_per_pixel=MESH_NS_PER_PIXEL, triangles=triangles(model, level, cache))

    return cost


def float32_margin(lo, hi) -> float:
    """World error of float32 vertex positions and their 4-term transform inside the boxes ``lo..hi``: 8 u of
    the largest coordinate (module docstring).

    >>> float32_margin([[0.0, 0.0, 0.0]], [[1.0, 2.0, 0.5]]) == 8 * 2.0 * 2.0**-24
    True
    """
    return 8.0 * U32 * float(np.abs(np.concatenate([np.reshape(lo, (-1, 3)), np.reshape(hi, (-1, 3))])).max())


def mesh_refuses(model, style) -> str | None:
    """Why a mesh cannot draw ``style`` (effects a mesh cannot show, curvature output), or None.

    >>> from splinevis.effects import Style
    >>> mesh_refuses(None, Style(reflection_lines=8)), mesh_refuses(None, Style(colormap="terrain"))
    (None, 'a mesh cannot show colormap')
    """
    from .mesh_effects import MESH_EFFECTS

    extra = sorted(set(style.effect_set()) - MESH_EFFECTS)
    if extra:
        return f"a mesh cannot show {', '.join(extra)}"
    if style.output == "curvature":
        return "a mesh has no curvature array"
    return None


def add_mesh_actor(plotter, mesh, style, spline_options):
    """Add a renderer's mesh with the style's effects; ``spline_options`` may hold ``name`` (and
    ``newton_iterations``, which a mesh does not use); ray-cast program options raise TypeError.

    >>> import pyvista as pv
    >>> from splinevis.effects import Style
    >>> from splinevis.plotting import Plotter
    >>> pl = Plotter(off_screen=True, window_size=(64, 48))
    >>> actor = add_mesh_actor(pl, pv.Sphere(), Style(lights=1), {"name": "ball", "newton_iterations": 6})
    >>> actor is pl.actors["ball"]
    True
    >>> add_mesh_actor(pl, pv.Sphere(), Style(), {"program_options": {"roots": "paper"}})
    Traceback (most recent call last):
    TypeError: options ['program_options'] are ray-cast program options; the chosen renderer is a mesh.
    >>> pl.close()
    """
    from .mesh_effects import add_mesh_with_effects

    unknown = sorted(set(spline_options) - {"name", "newton_iterations"})  # the root finder's: unused by a mesh
    if unknown:
        raise TypeError(f"options {unknown} are ray-cast program options; the chosen renderer is a mesh.")
    return add_mesh_with_effects(plotter, mesh, style, name=spline_options.get("name"))

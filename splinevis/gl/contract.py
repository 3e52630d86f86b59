"""The spline-program contract: what a spline family provides so that the rest of splinevis can draw it,
check it against float64 and study it without knowing its type.

A family (a folder such as ``splinevis/terrain``) declares one :class:`SplineProgram` in its
``program.py`` and the registry (:mod:`splinevis.programs`) lists it. :meth:`splinevis.Plotter.add_spline`,
the per-pixel agreement analysis (:mod:`splinevis.analysis.agreement`), the self-test and the studies look
programs up there by the model they are given; nothing outside the family's folder branches on its type.

Kinds (how the pixels are made):

``raycast``
    A proxy mesh is rasterized and every fragment ray-casts the spline (``build`` returns a
    :class:`~splinevis.gl.spec.ProgramSpec` whose entry defines ``sv_surface_hit``): terrains, volumes.
``surface``
    A mesh carrying surface parameters is rasterized and every fragment evaluates the surface exactly at its
    parameters (``build`` returns a ProgramSpec whose entry defines
    ``bool sv_surface_eval(vec3 pos_mc, out SvHit hit)`` reading its parameters from varyings; the mesh is
    drawn from both sides): NURBS. ``tests/toy_family`` has a working example.
``passes``
    A chain of render-to-texture passes (:mod:`splinevis.gl.passes`) computes the geometry; ``build``
    returns a PyVista dataset (or a texture on one) that is drawn as a mesh: smooth geometry images.
``mesh``
    The CPU tessellates (levels of detail, error bounds); ``build`` returns a PyVista dataset: large models.

Kinds ``raycast`` and ``surface`` become a :class:`~splinevis.gl.inject.SplineActor`; ``passes`` and ``mesh``
become an ordinary mesh actor with the scene's effects compiled in (:mod:`splinevis.gl.mesh_effects`).
Only ``raycast`` programs have a float64 ray caster (``reference``) and a derived ``depth_bound``: the
per-pixel agreement check needs both and refuses programs without them.

How to add a family: ``docs/architecture.md``.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from .renderers import Renderer

__all__ = ["KINDS", "SplineProgram", "HardCase", "RayHits"]

#: The four ways a program makes its pixels (module docstring).
KINDS = ("raycast", "surface", "passes", "mesh")


class RayHits:
    """Result of a float64 ray cast, the one return type of every family's ``reference``.

    Attributes
    ----------
    t : (...) float64 ndarray
        Ray parameter of the first hit, NaN on a miss.
    points : (..., 3) float64 ndarray
        World hit points (NaN on a miss).
    normals : (..., 3) float64 ndarray
        World normals at the hits, not necessarily unit (NaN on a miss).
    hit : (...) bool ndarray
        ``isfinite(t)``.
    surface : dict or None
        The family's own parameters of each hit (for example a NURBS model's ``patch`` and ``uv``), arrays whose
        leading shape is that of ``t``; None where the family has none to give. Only the family that made them
        reads them (its ``depth_bound`` takes them as ``surface``, so it need not find the hits again).

    Examples
    --------
    >>> import numpy as np
    >>> h = RayHits(np.array([1.0, np.nan]), np.zeros((2, 3)), np.zeros((2, 3)), {"patch": np.array([4, -1])})
    >>> h.hit.tolist(), h.surface_at(h.hit)["patch"].tolist()
    ([True, False], [4])
    """

    __slots__ = ("t", "points", "normals", "hit", "surface")

    def __init__(self, t, points, normals, surface=None):
        self.t = t
        self.points = points
        self.normals = normals
        self.hit = np.isfinite(t)
        self.surface = surface

    def surface_at(self, index):
        """``surface`` of the rays ``index`` (any numpy index into ``t``, e.g. a mask of the hits one keeps), or
        None.

        >>> h = RayHits(np.array([[1.0, 2.0], [np.nan, 3.0]]), np.zeros((2, 2, 3)), np.zeros((2, 2, 3)),
        ...             {"uv": np.arange(8.0).reshape(2, 2, 2)})
        >>> h.surface_at(h.hit)["uv"].tolist(), RayHits(h.t, h.points, h.normals).surface_at(h.hit)
        ([[0.0, 1.0], [2.0, 3.0], [6.0, 7.0]], None)
        """
        if self.surface is None:
            return None
        return {k: np.asarray(v)[index] for k, v in self.surface.items()}

    def __repr__(self):
        return f"RayHits(rays={self.t.size}, hits={int(self.hit.sum())})"


@dataclass(frozen=True)
class HardCase:
    """One scene a family says is numerically hard (grazing rays, huge coordinates, flat data, ...).

    Tests and the self-test render it and compare the GPU with the float64 reference per pixel
    (:func:`splinevis.analysis.agreement.depth_agreement`).

    Attributes
    ----------
    name : str
        What makes it hard, as a test id (``"grazing-1-degree"``).
    model : callable
        ``model()`` builds the model (deferred: building can take a while).
    camera : list or callable
        A PyVista camera position ``[eye, focal point, view up]`` in world coordinates, or
        ``camera(model)`` returning one (for views placed relative to the data).
    window_size : (int, int)
    program_options : dict
        Passed to the family's ``build``.
    newton_iterations : int or None
        None: the family's default.
    clipping_range : (float, float) or None
        Set after the camera (cameras inside the model need a near plane close to the eye).
    depth_fraction : float
        Fraction of pixels where both hit whose depth error must be within the derived bound.
    max_disagree : float
        Largest fraction of pixels where exactly one side hits (silhouettes grazed within rounding).
    min_hits : float
        Smallest fraction of pixels where both hit: a case that shows (almost) nothing tests nothing.
    parallel_scale : float or None
        A parallel projection with this half height of the view (world units); None: perspective.

    Examples
    --------
    >>> case = HardCase("far-origin", model=lambda: None, camera=[(0, 0, 5), (0, 0, 0), (0, 1, 0)])
    >>> case.window_size, case.depth_fraction, case.program_options
    ((160, 120), 0.999, {})
    """

    name: str
    model: Callable[[], Any]
    camera: list
    window_size: tuple = (160, 120)
    program_options: dict = field(default_factory=dict)
    newton_iterations: int | None = None
    clipping_range: tuple | None = None
    depth_fraction: float = 0.999
    max_disagree: float = 0.001
    min_hits: float = 0.02
    parallel_scale: float | None = None

    def camera_for(self, model) -> list:
        """The camera position for ``model``.

        Examples
        --------
        >>> above = HardCase("above", model=lambda: 2.0, camera=lambda h: [(0, 0, h + 3), (0, 0, h), (0, 1, 0)])
        >>> above.camera_for(above.model())
        [(0, 0, 5.0), (0, 0, 2.0), (0, 1, 0)]
        """
        return self.camera(model) if callable(self.camera) else self.camera


@dataclass(frozen=True)
class SplineProgram:
    """What one spline family provides (module docstring).

    Attributes
    ----------
    name : str
        Registry key, e.g. ``"terrain"``.
    kind : {"raycast", "surface", "passes", "mesh"}
    model_type : type
        The model class the program draws (subclasses too).
    build : callable
        ``build(model, style, *, newton_iterations, **options) -> ProgramSpec`` (raycast, surface) or a
        PyVista dataset (passes, mesh). Validates ``options`` and raises ``TypeError``/``ValueError`` naming
        the bad one.
    reference : callable, optional
        The float64 twin: ``reference(model, origins, directions, tmin=0.0, *, method="reference",
        iterations=None) -> RayHits`` for world rays of any leading shape; ``method`` is ``"reference"``
        (robust: every root isolated) or one of ``root_methods`` (the GPU's method in float64).
    depth_bound : callable, optional
        ``depth_bound(model, matrix, origins, directions, t, *, surface=None) -> (n,) ndarray``: the derived
        bound on |GPU window depth - float64 window depth| at hits ``origins + t directions`` (world, float64)
        for the camera ``matrix`` (world -> NDC); ``surface`` is :meth:`RayHits.surface_at` of the reference
        cast that found those hits (None: the family finds what it needs from the rays).
    hard_cases : callable, optional
        ``hard_cases() -> list of HardCase``.
    model_from : callable, optional
        ``model_from(data, *args, **kwargs)`` builds a model from user data (arrays, files, grids); what
        the Plotter's convenience methods call.
    converts : tuple of types
        Other model types ``model_from`` turns into a ``model_type`` (``Plotter.add_spline`` converts them,
        e.g. one NURBS surface into a one-patch model).
    on_add : callable, optional
        ``on_add(actor, plotter, **options)`` after the actor is in the scene (e.g. frustum culling).
    root_methods : tuple of str
        GPU root finders the program compiles (``splinevis.bb.root_options``), first = default.
    newton_iterations : int
        Default iteration count of the root finder.
    options : tuple of str
        Names of the program options ``build`` accepts (for messages and documentation).
    description : str
        One line for listings.
    renderers : tuple of :class:`~splinevis.gl.renderers.Renderer`
        The ways its models can be drawn, each with a cost rank and its screen-space error as a function of
        the view, for the choice by accuracy (:mod:`splinevis.choice`); empty: the program itself only.

    Examples
    --------
    A mesh-kind family needs no float64 twin; a raycast family without one is refused:

    >>> class Dots:
    ...     pass
    >>> program = SplineProgram("dots", "mesh", Dots, build=lambda model, style, *, newton_iterations: None)
    >>> program.kind, program.newton_iterations
    ('mesh', 8)
    >>> SplineProgram("dots", "raycast", Dots, build=program.build)
    Traceback (most recent call last):
    ValueError: SplineProgram 'dots': a raycast program needs its float64 twin (reference) and its derived depth_bound; the tests compare the GPU against them.
    """

    name: str
    kind: str
    model_type: type
    build: Callable
    reference: Callable | None = None
    depth_bound: Callable | None = None
    hard_cases: Callable | None = None
    model_from: Callable | None = None
    on_add: Callable | None = None
    root_methods: tuple = ()
    newton_iterations: int = 8
    options: tuple = ()
    description: str = ""
    converts: tuple = ()
    renderers: tuple = ()

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"SplineProgram.name must be an identifier-like string, got {self.name!r}.")
        if self.kind not in KINDS:
            raise ValueError(f"SplineProgram {self.name!r}: kind must be one of {', '.join(KINDS)}; got {self.kind!r}.")
        if not isinstance(self.model_type, type):
            raise TypeError(f"SplineProgram {self.name!r}: model_type must be a class, got {self.model_type!r}.")
        if not callable(self.build):
            raise TypeError(f"SplineProgram {self.name!r}: build must be callable.")
        if self.converts and self.model_from is None:
            raise ValueError(f"SplineProgram {self.name!r}: converts needs a model_from that does the conversion.")
        if not isinstance(self.renderers, tuple) or not all(isinstance(r, Renderer) for r in self.renderers):
            raise TypeError(f"SplineProgram {self.name!r}: renderers must be a tuple of splinevis.gl.renderers.Renderer.")
        if len({r.name for r in self.renderers}) < len(self.renderers):
            raise ValueError(f"SplineProgram {self.name!r}: two renderers have the same name.")
        if self.kind == "raycast" and (self.reference is None or self.depth_bound is None):
            raise ValueError(f"SplineProgram {self.name!r}: a raycast program needs its float64 twin "
                             "(reference) and its derived depth_bound; the tests compare the GPU against them.")

    def accepts(self, model) -> bool:
        """Whether this program draws ``model`` (an instance of ``model_type`` or of a subclass).

        Examples
        --------
        >>> program = SplineProgram("numbers", "mesh", float, build=lambda model, style, **kw: None)
        >>> program.accepts(1.5), program.accepts("1.5")
        (True, False)
        """
        return isinstance(model, self.model_type)

    def make(self, model, style, *, newton_iterations: int | None = None, **options):
        """Call ``build`` with the program's default iteration count and the declared options only.

        Unknown option names raise a ``TypeError`` that lists the known ones.

        Examples
        --------
        >>> build = lambda model, style, *, newton_iterations, size=1: (model, newton_iterations, size)
        >>> program = SplineProgram("echo", "mesh", int, build=build, newton_iterations=6, options=("size",))
        >>> program.make(7, None, size=3)
        (7, 6, 3)
        >>> program.make(7, None, colour="red")
        Traceback (most recent call last):
        TypeError: program 'echo' has no option 'colour'; its options: size.
        """
        unknown = sorted(set(options) - set(self.options))
        if unknown:
            known = ", ".join(self.options) or "none"
            raise TypeError(f"program {self.name!r} has no option {', '.join(map(repr, unknown))}; its options: {known}.")
        its = self.newton_iterations if newton_iterations is None else newton_iterations
        return self.build(model, style, newton_iterations=its, **options)

    def raycast(self, model, origins, directions, tmin=0.0, *, method: str = "reference", iterations=None) -> RayHits:
        """The float64 twin (``reference``) with this program's default iteration count.

        Examples
        --------
        >>> from splinevis import programs
        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> plane = QuarticTrianglePatch(np.full(15, 0.5), [[0, 0], [1, 0], [0, 1]])
        >>> programs.get("analytic_patch").raycast(plane, [[0.2, 0.2, 2.0]], [[0.0, 0.0, -1.0]]).t
        array([1.5])
        """
        if self.reference is None:
            raise TypeError(f"program {self.name!r} ({self.kind}) has no float64 ray caster.")
        its = self.newton_iterations if iterations is None else iterations
        return self.reference(model, origins, directions, tmin, method=method, iterations=its)

    def signature_problems(self) -> list:
        """Mismatches between the callables and the calling conventions above (empty when all is well);
        the registry refuses a program with any.

        Examples
        --------
        >>> SplineProgram("ok", "mesh", int, build=lambda model, style, *, newton_iterations: None).signature_problems()
        []
        >>> SplineProgram("bad", "mesh", int, build=lambda model, colour: None).signature_problems()
        ['build must take (model, style, ...) first, takes (model, colour)', "build must accept the keyword 'newton_iterations'"]
        """
        problems = []
        checks = [("build", self.build, ("model", "style"), ("newton_iterations",)),
                  ("reference", self.reference, ("model", "origins", "directions", "tmin"), ("method", "iterations")),
                  ("depth_bound", self.depth_bound, ("model", "matrix", "origins", "directions", "t"),
                   ("surface",))]
        for label, fn, positional, keywords in checks:
            if fn is None:
                continue
            params = inspect.signature(fn).parameters
            names = list(params)
            # the model parameter may have any name (``terrain``, ``patch``); the others are the contract's
            if len(names) < len(positional) or names[1: len(positional)] != list(positional[1:]):
                problems.append(f"{label} must take ({', '.join(positional)}, ...) first, takes ({', '.join(names)})")
            for kw in keywords:
                if kw not in params and not any(p.kind is p.VAR_KEYWORD for p in params.values()):
                    problems.append(f"{label} must accept the keyword {kw!r}")
        return problems

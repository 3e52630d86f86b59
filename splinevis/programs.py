"""The registry of spline programs: the one list of built-in families, and the place to add one.

Everything that draws, checks or studies a model finds its program here by the model's type
(:func:`program_for`) or by name (:func:`get`); nothing outside a family's folder knows its type.
The built-in families are imported on first use, so ``import splinevis`` stays light.

Examples
--------
>>> from splinevis import programs
>>> [p.name for p in programs.all_programs()]
['analytic_patch', 'terrain', 'isosurface', 'nurbs_lod', 'nurbs', 'geometry_image']
>>> programs.get("terrain").kind
'raycast'
"""

from __future__ import annotations

import importlib

from .gl.contract import SplineProgram

__all__ = ["BUILTIN", "register", "unregister", "all_programs", "get", "program_for"]

#: Modules whose ``PROGRAM`` is a built-in family, in listing order.
BUILTIN = ("splinevis.analytic.program", "splinevis.terrain.program", "splinevis.volume.program",
           # two programs draw NURBS models: the level-of-detail meshes first, so that the per-fragment program,
           # registered later, is the one a NurbsModel finds by type (program_for); the other by name (get)
           "splinevis.nurbs.lod.program", "splinevis.nurbs.program", "splinevis.geometry_image.program")

_programs: dict[str, SplineProgram] = {}
_loaded = False


def _load_builtin() -> None:
    global _loaded
    if _loaded:
        return
    _loaded = True
    for module in BUILTIN:
        program = importlib.import_module(module).PROGRAM
        _programs.setdefault(program.name, program)


def register(program: SplineProgram, *, replace: bool = False) -> SplineProgram:
    """Add a family. Its callables must follow the contract (:class:`~splinevis.gl.contract.SplineProgram`).

    Raises
    ------
    TypeError
        ``program`` is not a SplineProgram, or a callable has the wrong calling convention.
    ValueError
        A program of that name is registered already (pass ``replace=True`` to replace it).

    Examples
    --------
    >>> class Dots:
    ...     pass
    >>> dots = register(SplineProgram("dots", "mesh", Dots, build=lambda model, style, *, newton_iterations: None))
    >>> program_for(Dots()) is dots
    True
    >>> register(dots)
    Traceback (most recent call last):
    ValueError: a program named 'dots' is registered already; pass replace=True to replace it.
    >>> unregister("dots")
    """
    if not isinstance(program, SplineProgram):
        raise TypeError(f"register takes a splinevis.gl.contract.SplineProgram, got {type(program).__name__}.")
    problems = program.signature_problems()
    if problems:
        raise TypeError(f"program {program.name!r} does not follow the contract: " + "; ".join(problems) + ".")
    _load_builtin()
    if program.name in _programs and not replace:
        raise ValueError(f"a program named {program.name!r} is registered already; pass replace=True to replace it.")
    _programs[program.name] = program
    return program


def unregister(name: str) -> None:
    """Remove the family ``name`` (built-in families come back only in a new process).

    Examples
    --------
    >>> class Dots:
    ...     pass
    >>> _ = register(SplineProgram("dots", "mesh", Dots, build=lambda model, style, *, newton_iterations: None))
    >>> unregister("dots")
    >>> "dots" in [p.name for p in all_programs()]
    False
    >>> unregister("dots")
    Traceback (most recent call last):
    KeyError: "no program named 'dots'; registered: analytic_patch, terrain, isosurface, nurbs_lod, nurbs, geometry_image."
    """
    _load_builtin()
    if name not in _programs:
        raise KeyError(f"no program named {name!r}; registered: {', '.join(_programs)}.")
    del _programs[name]


def all_programs() -> list[SplineProgram]:
    """Every registered program, built-in ones first.

    Examples
    --------
    >>> [(p.name, p.kind) for p in all_programs()]
    [('analytic_patch', 'raycast'), ('terrain', 'raycast'), ('isosurface', 'raycast'), ('nurbs_lod', 'mesh'),
     ('nurbs', 'surface'), ('geometry_image', 'passes')]
    """
    _load_builtin()
    return list(_programs.values())


def get(name: str) -> SplineProgram:
    """The program registered as ``name``.

    Examples
    --------
    >>> get("isosurface").root_methods, get("isosurface").newton_iterations
    (('analytic', 'bracketed', 'paper'), 6)
    """
    _load_builtin()
    try:
        return _programs[name]
    except KeyError:
        raise KeyError(f"no program named {name!r}; registered: {', '.join(_programs)}.") from None


def program_for(model) -> SplineProgram:
    """The program that draws ``model``: the one whose model type is nearest in the model's class hierarchy.

    Raises
    ------
    TypeError
        No registered program draws this type; the message lists what can be drawn.

    Examples
    --------
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> program_for(QuarticTrianglePatch.demo()).name
    'analytic_patch'
    >>> program_for(1.5)
    Traceback (most recent call last):
    TypeError: no spline program draws a float; registered programs draw: QuarticTrianglePatch (analytic_patch), ...
    """
    _load_builtin()
    for cls in type(model).__mro__:
        for program in reversed(list(_programs.values())):  # later registrations win on the same type
            if program.model_type is cls:
                return program
    for program in reversed(list(_programs.values())):  # a type a program's model_from converts
        if program.converts and isinstance(model, program.converts):
            return program
    known = ", ".join(f"{p.model_type.__name__} ({p.name})" for p in _programs.values())
    raise TypeError(f"no spline program draws a {type(model).__name__}; registered programs draw: {known}.")

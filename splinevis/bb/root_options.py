"""The one ``roots`` option: the names of the first-root finders, the same in Python and in GLSL.

Every program that solves for the first root of a restricted Bernstein polynomial on [0, 1] takes
``roots=`` with one of these names, compiles the matching ``SV_ROOTS_*`` flag into its shader
(:func:`root_defines`, read by ``glsl/lib/core/roots.glsl`` and the programs), and its float64 twin takes
the same name as ``method=`` (:func:`first_root`), plus ``"reference"``, the robust all-roots finder that
tests measure every method against.

========== ======================================================================= ==================
name       method                                                                  degrees
========== ======================================================================= ==================
analytic   closed form: stable quadratic formula, trigonometric/Cardano cubic      2, 3
bracketed  Newton on convex pieces between secure starting points, bracketed      1..4
paper      Newton from secure starting points without a bracket: four starts for   3, 4
           quartics [Reis2008, sec. V], three for cubics [Kalbe2008, sec. 5.3]
reference  companion eigenvalues + sign scan + isolation (float64 only)            1..4
========== ======================================================================= ==================
"""

from __future__ import annotations

import numpy as np

from . import roots as _roots

__all__ = ["ROOT_METHODS", "check_root_method", "root_defines", "first_root"]

#: GPU root finders by name, with the polynomial degrees each handles.
ROOT_METHODS = {"analytic": (2, 3), "bracketed": (1, 2, 3, 4), "paper": (3, 4)}


def check_root_method(method, supported, *, degree: int | None = None) -> str:
    """Validate a ``roots`` option against the methods a program compiles.

    Parameters
    ----------
    method : str
    supported : sequence of str
        The program's methods (a subset of :data:`ROOT_METHODS`).
    degree : int, optional
        Degree of the polynomials solved; a method that cannot handle it is refused with the reason.

    Examples
    --------
    >>> check_root_method("paper", ("bracketed", "paper"), degree=4)
    'paper'
    >>> check_root_method("newton", ("bracketed", "paper"))
    Traceback (most recent call last):
    ...
    ValueError: roots must be one of 'bracketed', 'paper'; got 'newton'.
    """
    if method not in supported:
        raise ValueError(f"roots must be one of {', '.join(map(repr, supported))}; got {method!r}.")
    if degree is not None and degree not in ROOT_METHODS[method]:
        ok = [m for m in supported if degree in ROOT_METHODS[m]]
        raise ValueError(f"roots={method!r} does not solve degree-{degree} polynomials (it handles degrees "
                         f"{ROOT_METHODS[method]}); use one of {', '.join(map(repr, ok))}.")
    return method


def root_defines(method: str) -> dict:
    """The GLSL flags of a root method: exactly one of ``SV_ROOTS_ANALYTIC``, ``SV_ROOTS_BRACKETED``,
    ``SV_ROOTS_PAPER`` is set.

    >>> root_defines("paper")
    {'SV_ROOTS_ANALYTIC': False, 'SV_ROOTS_BRACKETED': False, 'SV_ROOTS_PAPER': True}
    """
    if method not in ROOT_METHODS:
        raise ValueError(f"roots must be one of {', '.join(map(repr, ROOT_METHODS))}; got {method!r}.")
    return {f"SV_ROOTS_{name.upper()}": name == method for name in ROOT_METHODS}


def first_root(c, method: str = "reference", iterations: int = 8) -> np.ndarray:
    """First root in [0, 1] of each Bernstein polynomial ``c`` (..., n + 1) by the named method, float64.

    The twins of the GLSL finders: ``"bracketed"`` is ``sv_first_root_bracketed``, ``"paper"`` is
    ``sv_first_root_newton4`` (quartics) or ``sv_first_root_newton3`` (cubics), ``"analytic"`` is
    ``sv_first_root_quadratic`` / ``sv_first_root_cubic``. NaN where there is none.

    >>> import numpy as np
    >>> c = np.array([[-1.0, -1.0, 1.0, 1.0]])  # a cubic crossing zero at 1/2
    >>> [round(float(first_root(c, m)[0]), 12) for m in ("reference", "analytic", "bracketed", "paper")]
    [0.5, 0.5, 0.5, 0.5]
    """
    c = np.asarray(c, dtype=np.float64)
    n = c.shape[-1] - 1
    if method == "reference":
        return _roots.first_root_reference(c)
    check_root_method(method, tuple(ROOT_METHODS), degree=n)
    if method == "analytic":
        return _roots.first_root_quadratic(c) if n == 2 else _roots.first_root_cubic(c)
    if method == "bracketed":
        return _roots.first_root_bracketed(c, iterations)
    if n == 3:
        return _roots.newton_three_starts(c, iterations)
    return _roots.newton_secure(c, iterations=iterations)

"""Roots on [0, 1] of univariate Bernstein-Bezier polynomials of degree <= 4.

Three methods:

* :func:`first_root_bracketed` -- the default GPU method (``sv_first_root_bracketed``, used by
  ``sv_first_root`` in ``glsl/lib/core/roots.glsl``), a line-by-line twin: bracketed Newton on the convex
  pieces between the inflection points, with a fixed iteration budget (:mod:`.bracketed`).
* :func:`newton_secure` -- the GPU method of [Reis2008, sec. V] (``sv_first_root_newton4``;
  ``sv_first_root`` with ``SV_ROOTS_PAPER`` defined), a line-by-line twin: Newton iteration from the
  "secure" starting points ``(0, w0, w1, 1)`` (end points and inflection points), accepting the smallest
  iterate in [0, 1] that passes a residual test whose constant splinevis derives from the float32
  rounding bound of de Casteljau's algorithm [MainarPena1999; Higham2002, sec. 3.4]. It often returns a
  later root than the first one (:mod:`.newton`, with the three-start variant of [Kalbe2008, sec. 5.3] for
  cubics, :func:`newton_three_starts`).
* :func:`roots_reference` -- a robust float64 reference that reports every root in [0, 1] (companion
  matrix eigenvalues, a sign-change scan with bisection, Newton polishing, merging of duplicates)
  (:mod:`.reference`).

Closed forms for quadratics and cubics (:func:`first_root_quadratic`, :func:`first_root_cubic`) are in
:mod:`.closed_form`; the float32 residual tolerance and the argument checks in :mod:`.tolerance`; the
twins of the GPU's Bernstein arithmetic (:func:`eval_deriv`, :func:`inflection_points`) in
:mod:`.bernstein`.

Coefficients are arrays ``(..., n + 1)``; ``n = c.shape[-1] - 1`` is the degree (0..4) and coefficient
``k`` multiplies ``B^n_k(t) = C(n, k) (1 - t)^(n - k) t^k`` (see :mod:`splinevis.bb.simplex`).

References
----------
.. [Reis2008] Reis et al. 2008, quartic terrain splines.
.. [Kalbe2008] Kalbe and Zeilfelder 2008, trivariate volume splines.
"""

from .bernstein import _eval_deriv as _eval_deriv, eval_deriv as eval_deriv, inflection_points as inflection_points
from .bracketed import MAX_BRACKET_ITERATIONS as MAX_BRACKET_ITERATIONS, first_root_bracketed as first_root_bracketed
from .closed_form import (
    CUBIC_POLISH as CUBIC_POLISH,
    first_root_cubic as first_root_cubic,
    first_root_quadratic as first_root_quadratic,
)
from .newton import newton_secure as newton_secure, newton_three_starts as newton_three_starts
from .reference import first_root_reference as first_root_reference, roots_reference as roots_reference
from .tolerance import EPS32 as EPS32, MAX_ROOT_DEGREE as MAX_ROOT_DEGREE, root_tolerance_k as root_tolerance_k

__all__ = [
    "first_root_quadratic",
    "MAX_ROOT_DEGREE",
    "EPS32",
    "root_tolerance_k",
    "eval_deriv",
    "inflection_points",
    "newton_secure",
    "first_root_bracketed",
    "MAX_BRACKET_ITERATIONS",
    "roots_reference",
    "first_root_reference",
    "first_root_cubic",
    "newton_three_starts",
    "CUBIC_POLISH",
]

"""Bernstein-Bezier form on simplices (:mod:`.simplex`) and root finding on [0, 1] (:mod:`.roots`)."""

from .roots import (
    EPS32 as EPS32,
    MAX_BRACKET_ITERATIONS as MAX_BRACKET_ITERATIONS,
    MAX_ROOT_DEGREE as MAX_ROOT_DEGREE,
    eval_deriv as eval_deriv,
    first_root_bracketed as first_root_bracketed,
    first_root_reference as first_root_reference,
    inflection_points as inflection_points,
    newton_secure as newton_secure,
    root_tolerance_k as root_tolerance_k,
    roots_reference as roots_reference,
)
from .simplex import (
    MAX_DEGREE as MAX_DEGREE,
    bernstein_basis as bernstein_basis,
    blossom as blossom,
    de_casteljau as de_casteljau,
    degree_of as degree_of,
    derivative as derivative,
    elevate as elevate,
    gradient as gradient,
    index_of as index_of,
    multi_indices as multi_indices,
    num_coefficients as num_coefficients,
    reparametrize as reparametrize,
    restrict_to_segment as restrict_to_segment,
    subdivide as subdivide,
)

__all__ = [
    "EPS32", "MAX_BRACKET_ITERATIONS", "MAX_DEGREE", "MAX_ROOT_DEGREE", "bernstein_basis", "blossom", "de_casteljau", "degree_of",
    "derivative", "elevate", "eval_deriv", "first_root_bracketed", "first_root_reference", "gradient", "index_of",
    "inflection_points", "multi_indices", "newton_secure", "num_coefficients", "reparametrize",
    "restrict_to_segment", "root_tolerance_k", "roots_reference", "subdivide",
]

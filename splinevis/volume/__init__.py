"""Trivariate splines of volume data on the type-6 tetrahedral partition [Kalbe2008, sec. 3-4]: the
quadratic super spline [Roessl2004; Nuernberger2005], the cubic C1 spline [SorokinaZeilfelder2007], the
trilinear baseline, and an approximation study.

See docs/volume-schemes.md for conventions, the derivations and what is verified.
"""

from .cubic import cubic_c1_spline
from .partition import NUM_TETS, barycentric, barycentric_matrices, locate, type6_tetrahedra
from .schemes import (
    SCHEMES,
    STENCIL,
    cube_coefficients,
    derive_weights,
    domain_points,
    edge_points,
    evaluate,
    evaluate_volume,
    inner_face_conditions,
    pad_volume,
    quadratic_super_spline,
    spline_coefficients,
    tet_weights,
)
from .trilinear import trilinear_interpolate

__all__ = ["NUM_TETS", "type6_tetrahedra", "locate", "barycentric", "barycentric_matrices", "quadratic_super_spline",
           "evaluate", "derive_weights", "domain_points", "edge_points", "inner_face_conditions", "SCHEMES", "STENCIL",
           "pad_volume", "tet_weights", "spline_coefficients", "cube_coefficients", "evaluate_volume",
           "cubic_c1_spline", "trilinear_interpolate"]

"""Trivariate splines of volume data on the type-6 tetrahedral partition (issue 4 groundwork).

See docs/volume-schemes.md for conventions, the derivation and what is verified.
"""

from .partition import NUM_TETS, barycentric, barycentric_matrices, locate, type6_tetrahedra
from .schemes import derive_weights, domain_points, edge_points, evaluate, inner_face_conditions, quadratic_super_spline

__all__ = ["NUM_TETS", "type6_tetrahedra", "locate", "barycentric", "barycentric_matrices", "quadratic_super_spline",
           "evaluate", "derive_weights", "domain_points", "edge_points", "inner_face_conditions"]

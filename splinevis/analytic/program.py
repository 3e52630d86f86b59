"""The GPU program of the analytic patch: a ProgramSpec for glsl/programs/analytic_patch.glsl."""

from __future__ import annotations

from .._validation import check_degree
from ..gl.spec import ProgramSpec
from .patch import QuarticTrianglePatch

__all__ = ["patch_program"]


def patch_program(patch: QuarticTrianglePatch, *, newton_iterations: int = 6) -> ProgramSpec:
    """Describe the ray-cast program of ``patch`` (proxy prism, coefficients and matrix as uniforms).

    ``newton_iterations`` (1..8) is the fixed Newton step count of lib/roots.glsl (paper 000: 5 hide
    visible artifacts, 6 reach full float precision).
    """
    if not isinstance(patch, QuarticTrianglePatch):
        raise TypeError(f"patch must be a QuarticTrianglePatch, got {type(patch).__name__}.")
    iterations = check_degree(newton_iterations, "newton_iterations", low=1, high=8)
    points, triangles = patch.proxy()
    m = patch.barycentric_matrix
    return ProgramSpec(
        name="analytic_patch",
        entry="programs/analytic_patch.glsl",
        points=points,
        triangles=triangles,
        uniforms={
            "sv_patch_b[]": patch.coefficients,
            "sv_patch_bary0": tuple(m[0]),
            "sv_patch_bary1": tuple(m[1]),
            "sv_patch_bary2": tuple(m[2]),
            "sv_patch_zrange": patch.zrange,
            "sv_newton_iterations": iterations,
            "sv_scalar_range": patch.zrange,
        },
    )

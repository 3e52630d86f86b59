"""The GPU program of the analytic patch: a ProgramSpec for glsl/programs/analytic_patch.glsl."""

from __future__ import annotations

import numpy as np

from .._validation import check_degree
from ..gl.spec import ProgramSpec
from .patch import QuarticTrianglePatch

__all__ = ["patch_program"]


def patch_program(patch: QuarticTrianglePatch, *, newton_iterations: int = 6,
                  coefficients_in: str = "uniform", roots: str = "bracketed") -> ProgramSpec:
    """Describe the ray-cast program of ``patch`` (proxy prism, coefficients and matrix as uniforms).

    ``newton_iterations`` (1..8) is the fixed step count of ``sv_first_root`` in lib/roots.glsl: per
    bracketed run of the default bracketed Newton on convex pieces (bracket <= 4^-N of a piece), or
    the Newton steps of paper 000's method with the define ``SV_ROOTS_PAPER_NEWTON`` (5 hide visible
    artifacts, 6 reach full float precision there). ``coefficients_in="texture"`` reads the
    coefficients from an RGBA32F table indexed by a per-vertex patch id instead of uniforms: the same
    image, through the plumbing large models need. ``roots="paper"`` compiles paper 000's four-start
    Newton iteration instead of the default bracketed Newton (for comparison).
    """
    from .._validation import check_choice

    check_choice(coefficients_in, "coefficients_in", {"uniform", "texture"})
    check_choice(roots, "roots", {"bracketed", "paper"})
    if not isinstance(patch, QuarticTrianglePatch):
        raise TypeError(f"patch must be a QuarticTrianglePatch, got {type(patch).__name__}.")
    iterations = check_degree(newton_iterations, "newton_iterations", low=1, high=8)
    points, triangles = patch.proxy()
    m = patch.barycentric_matrix
    extra = {"defines": {"SV_ROOTS_PAPER_NEWTON": roots == "paper"}}
    if coefficients_in == "texture":
        table = np.zeros((1, 4, 4), dtype=np.float32)
        table.reshape(-1)[:15] = patch.coefficients
        extra = dict(defines={"SV_PATCH_TEXTURE": True, "SV_ROOTS_PAPER_NEWTON": roots == "paper"}, textures={"sv_patch_coeffs": table},
                     attributes={"sv_patch_id": np.zeros(len(points), dtype=np.float32)})
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
        **extra,
    )

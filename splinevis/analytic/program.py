"""The analytic patch's spline program: a ray cast on a prism proxy (glsl/programs/analytic_patch.glsl).

Declares :data:`PROGRAM` for the registry (:mod:`splinevis.programs`): the GPU spec, the float64 twin
(:meth:`QuarticTrianglePatch.raycast`), the derived depth bound and the hard cases.
"""

from __future__ import annotations

import numpy as np

from .._validation import check_choice, check_degree
from ..bb.root_options import check_root_method, root_defines
from ..gl.contract import HardCase, SplineProgram
from ..gl.error_bounds import ray_depth_error_bound
from ..gl.proxies import pack_rgba32f
from ..gl.spec import ProgramSpec
from .patch import QuarticTrianglePatch

__all__ = ["patch_program", "patch_depth_bound", "PROGRAM"]

ROOTS = ("bracketed", "paper")


def patch_program(patch: QuarticTrianglePatch, style=None, *, newton_iterations: int = 6,
                  coefficients_in: str = "uniform", roots: str = "bracketed") -> ProgramSpec:
    """Describe the ray-cast program of ``patch`` (proxy prism, coefficients and matrix as uniforms).

    ``newton_iterations`` (1..8) is the fixed step count of ``sv_first_root`` in lib/core/roots.glsl: per
    bracketed run of the default bracketed Newton on convex pieces (bracket <= 4^-N of a piece), or
    the Newton steps of the four-start method of [Reis2008, sec. V] with ``roots="paper"`` (5 hide visible
    artifacts, 6 reach full float precision there). ``coefficients_in="texture"`` reads the
    coefficients from an RGBA32F table indexed by a per-vertex patch id instead of uniforms: the same
    image, through the plumbing large models need. ``style`` decides nothing here (the effects are
    compiled in by the injection).

    Examples
    --------
    >>> spec = patch_program(QuarticTrianglePatch.demo(), roots="paper")
    >>> spec.entry, spec.defines["SV_ROOTS_PAPER"], len(spec.points)
    ('programs/analytic_patch.glsl', True, 6)
    """
    check_choice(coefficients_in, "coefficients_in", {"uniform", "texture"})
    check_root_method(roots, ROOTS, degree=4)
    if not isinstance(patch, QuarticTrianglePatch):
        raise TypeError(f"patch must be a QuarticTrianglePatch, got {type(patch).__name__}.")
    iterations = check_degree(newton_iterations, "newton_iterations", low=1, high=8)
    points, triangles = patch.proxy()
    m = patch.barycentric_matrix
    extra = {"defines": root_defines(roots)}
    if coefficients_in == "texture":
        extra = dict(defines={"SV_PATCH_TEXTURE": True, **root_defines(roots)},
                     textures={"sv_patch_coeffs": pack_rgba32f(patch.coefficients)},
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


def patch_depth_bound(patch: QuarticTrianglePatch, matrix, origins, directions, t, *,
                      surface=None) -> np.ndarray:
    """Derived bound on |GPU - float64| window depth at hits ``origins + t directions``
    (:func:`splinevis.gl.error_bounds.ray_depth_error_bound`). The shader's rays start on the far side of
    the proxy (lib/core/raycast.glsl), so the coordinates it rounds are bounded by the proxy's extent. The bound
    depends on the hits' positions only: ``surface`` (the contract's hit parameters) is not read.

    Examples
    --------
    >>> patch = QuarticTrianglePatch.demo()
    >>> o, d = np.array([[0.0, 0.0, 3.0]]), np.array([[0.0, 0.0, -1.0]])
    >>> t = patch.raycast(o, d).t
    >>> bound = patch_depth_bound(patch, np.eye(4), o, d, t)  # identity camera: depth = (z + 1) / 2
    >>> bound.shape, bool(0.0 < bound[0] < 1e-5)  # a few float32 roundings of the depth
    ((1,), True)
    """
    p = np.asarray(origins) + np.asarray(t)[..., None] * np.asarray(directions)
    extent = np.abs(patch.vertices).max(axis=0)
    return ray_depth_error_bound(lambda q: patch.gradient(q), float(np.abs(patch.coefficients).max()), matrix,
                                 origins, directions, t, np.broadcast_to(extent, p[..., :2].shape),
                                 proxy_size=float(np.ptp(patch.vertices, axis=0).max() + np.ptp(patch.zrange)))


def _reference(patch, origins, directions, tmin=0.0, *, method="reference", iterations=6):
    return patch.raycast(origins, directions, tmin, method=method, iterations=iterations)


def hard_cases() -> list:
    """Views where a float32 ray cast of the patch is most likely to part from float64: the showcase's oblique
    view, rays grazing the patch 1 degree above the plane of its low edge, the camera below (the underside),
    the camera inside the proxy prism, and the paper's root finder.

    With the default (bracketed) root finder every case must agree exactly: no pixel hit on one side only
    (``max_disagree=0``) and every depth within the derived bound (``depth_fraction=1``). The paper's
    4-start Newton keeps the default 0.1 % of one-sided pixels: it misses some silhouette pixels, where the ray
    grazes the surface and the first root is nearly double (Newton converges linearly there and 8 float32
    steps need not pass the residual test); tests/test_inject.py asserts that those are GPU misses on the
    reference's silhouette only, and how many.

    >>> [(c.name, c.max_disagree, c.depth_fraction) for c in hard_cases()][::4]
    [('oblique', 0.0, 1.0), ('paper-newton', 0.001, 1.0)]
    """
    demo = QuarticTrianglePatch.demo
    oblique = [(2.5, -3.3, 2.4), (0.05, -0.1, 0.05), (0, 0, 1)]
    size = (400, 300)
    exact = dict(max_disagree=0.0, depth_fraction=1.0)
    return [
        HardCase("oblique", demo, oblique, size, min_hits=10_000 / 120_000, **exact),
        HardCase("grazing-1-degree", demo, [(-3.0, -0.2, 0.05 + 3.0 * np.tan(np.radians(1.0))), (0.0, 0.0, 0.05),
                                            (0, 0, 1)], size, min_hits=1_000 / 120_000, **exact),
        HardCase("underside", demo, [(0.6, -2.2, -1.6), (0.05, -0.1, 0.05), (0, 0, 1)], (320, 240), **exact),
        HardCase("camera-inside-prism", demo, [(0.0, -0.2, 0.2), (0.5, 0.6, 0.0), (0, 0, 1)], (320, 240),
                 clipping_range=(1e-3, 10.0), **exact),
        HardCase("paper-newton", demo, oblique, (320, 240), program_options={"roots": "paper"}, depth_fraction=1.0),
    ]


PROGRAM = SplineProgram(
    "analytic_patch", "raycast", QuarticTrianglePatch, patch_program, reference=_reference,
    depth_bound=patch_depth_bound, hard_cases=hard_cases, root_methods=ROOTS, newton_iterations=8,
    options=("coefficients_in", "roots"), description="one quartic BB triangle patch z = f(x, y), ray-cast on a prism")

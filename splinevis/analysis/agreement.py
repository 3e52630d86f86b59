"""GPU against float64, per pixel: hits, misses and window depths of any ray-cast spline program.

The model is rendered alone (unlit, no effects: depth does not depend on shading), the depth buffer is
read back, and every pixel's ray is cast in float64 by the program's twin (``reference`` of its
:class:`~splinevis.gl.contract.SplineProgram`, found in the registry) with the same camera matrix. Depth
differences are judged against the program's derived per-pixel ``depth_bound`` plus the depth change over the
rasterizer's sub-pixel snapping (:func:`splinevis.gl.error_bounds.subpixel_depth_slack`). Nothing here knows
a family: :func:`hard_case_agreement` runs any program's hard cases.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from ..gl.camera import pixel_rays, window_depth
from ..gl.error_bounds import subpixel_depth_slack

__all__ = ["depth_agreement", "reference_hits", "hard_case_agreement", "agreement_failures"]


def reference_hits(model, origins, directions, *, method="reference"):
    """Float64 ray cast of any registered model (its program's twin): a :class:`~splinevis.gl.contract.RayHits`.

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> patch = QuarticTrianglePatch(np.full(15, 0.5), [[0, 0], [1, 0], [0, 1]])  # the plane z = 0.5
    >>> hits = reference_hits(patch, np.array([[0.2, 0.2, 2.0]]), np.array([[0.0, 0.0, -1.0]]))
    >>> hits.t, hits.points
    (array([1.5]), array([[0.2, 0.2, 0.5]]))
    """
    from ..programs import program_for

    return program_for(model).raycast(model, origins, directions, 0.0, method=method)


def depth_agreement(model, camera_position, window_size=(400, 300), *, newton_iterations=None, plotter_hook=None,
                    program_options=None) -> dict:
    """Render ``model`` alone from ``camera_position`` and compare with the float64 reference.

    Returns a dict: ``pixels``, ``hit_disagree`` (pixels where exactly one side hits), ``leaks``
    (GPU misses at pixels whose reference hits and whose 8 neighbours all hit: cracks), ``both``,
    ``depth_error`` and ``depth_bound`` (over pixels where both hit), ``gpu_depth``,
    ``reference_depth``, ``matrix``.

    Examples
    --------
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> r = depth_agreement(QuarticTrianglePatch.demo(), [(2.5, -3.3, 2.4), (0.05, -0.1, 0.05), (0, 0, 1)], (64, 48))
    >>> r["pixels"], r["hit_disagree"], r["leaks"], bool(r["both"] > 500)
    (3072, 0, 0, True)
    >>> bool((r["depth_error"] <= r["depth_bound"]).all())  # every depth within the derived bound
    True
    """
    from ..plotting import Plotter
    from ..programs import program_for

    program = program_for(model)
    if program.reference is None or program.depth_bound is None:
        raise TypeError(f"program {program.name!r} ({program.kind}) has no float64 ray caster and depth bound: "
                        "per-pixel depth agreement applies to ray-cast programs.")
    w, h = window_size
    pl = Plotter(off_screen=True, window_size=window_size)
    pl.add_spline(model, lights=0, color=(1.0, 0.0, 0.0), newton_iterations=newton_iterations,
                  program_options=program_options)
    pl.camera_position = camera_position
    pl.reset_camera_clipping_range()
    if plotter_hook is not None:
        plotter_hook(pl)
    pl.screenshot()
    gpu = pl.depth_buffer()
    matrix = pl.camera_matrix()
    pl.close()
    o, d = pixel_rays(matrix, w, h)
    hits = program.raycast(model, o, d, 0.0)
    ref = window_depth(matrix, o + hits.t[..., None] * d)
    ref_hit = np.isfinite(ref) & (ref >= 0) & (ref <= 1)
    gpu_hit = gpu < 1.0
    both = gpu_hit & ref_hit
    interior = ndimage.binary_erosion(ref_hit, structure=np.ones((3, 3)), border_value=0)
    bound = program.depth_bound(model, matrix, o[both], d[both], hits.t[both], surface=hits.surface_at(both))
    bound = bound + subpixel_depth_slack(ref)[both]
    return {
        "pixels": w * h,
        "hit_disagree": int((gpu_hit != ref_hit).sum()),
        "leaks": int((interior & ~gpu_hit).sum()),
        "both": int(both.sum()),
        "depth_error": np.abs(gpu - ref)[both],
        "depth_bound": bound,
        "gpu_depth": gpu,
        "reference_depth": ref,
        "matrix": matrix,
    }


def hard_case_agreement(case) -> dict:
    """:func:`depth_agreement` of one :class:`~splinevis.gl.contract.HardCase` (camera, clipping range,
    options and window size as the case says).

    Examples
    --------
    >>> import dataclasses
    >>> from splinevis import programs
    >>> case = programs.get("analytic_patch").hard_cases()[1]
    >>> case.name
    'grazing-1-degree'
    >>> small = dataclasses.replace(case, window_size=(80, 60))
    >>> agreement_failures(hard_case_agreement(small), small)
    []
    """
    model = case.model()
    clip, scale = case.clipping_range, case.parallel_scale

    def hook(pl):
        if scale is not None:
            pl.camera.parallel_projection = True
            pl.camera.parallel_scale = scale
            pl.reset_camera_clipping_range()
        if clip is not None:
            pl.camera.clipping_range = clip

    return depth_agreement(model, case.camera_for(model), case.window_size, newton_iterations=case.newton_iterations,
                           plotter_hook=hook, program_options=case.program_options)


def agreement_failures(r: dict, case) -> list:
    """What breaks the case's limits (empty when it passes): too few hits, any leak (a crack: a GPU miss
    whose reference and all 8 neighbours hit), too many pixels where exactly one side hits, too few depths
    within the derived bound.

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.gl.contract import HardCase
    >>> case = HardCase("example", None, None)  # default limits: 2 % hits, 0.1 % one-sided, 99.9 % within
    >>> r = {"pixels": 1000, "both": 500, "leaks": 0, "hit_disagree": 3,
    ...      "depth_error": np.array([1e-7, 3e-7]), "depth_bound": np.array([2e-7, 2e-7])}
    >>> for failure in agreement_failures(r, case):
    ...     print(failure)
    3 pixels hit on one side only (> 0.1%)
    50.0000% of depths within the bound (< 99.9%; worst 1.5 x bound)
    """
    out = []
    if r["both"] < case.min_hits * r["pixels"]:
        out.append(f"only {r['both']} of {r['pixels']} pixels hit on both sides (< {case.min_hits:.1%})")
    if r["leaks"]:
        out.append(f"{r['leaks']} background pixels leak through the surface")
    if r["hit_disagree"] > case.max_disagree * r["pixels"]:
        out.append(f"{r['hit_disagree']} pixels hit on one side only (> {case.max_disagree:.1%})")
    if r["both"]:
        within = float(np.mean(r["depth_error"] <= r["depth_bound"]))
        if within < case.depth_fraction:
            worst = float(np.max(r["depth_error"] / r["depth_bound"]))
            out.append(f"{within:.4%} of depths within the bound (< {case.depth_fraction:.1%}; worst {worst:.3g} x bound)")
    return out

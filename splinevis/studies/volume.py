"""The volume study (``splinevis study volume --out DIR [--quick]``): what accuracy costs in time for
isosurfaces of volume data, side by side with what users use today ([Kalbe2008]).

Writes ``DIR/volume.json``, ``DIR/volume.md`` (every table) and figures:

1. **Approximation** (``approximation.png``): value and gradient errors of the trilinear, quadratic and
   cubic reconstructions on n^3 samples of Marschner-Lobb and of a smooth field (the Gaussian blob), from
   :func:`splinevis.volume.approximation.approximation_table` (max errors over 20,000 random interior
   points, observed orders between sizes).
1b. **Data fidelity** (``fidelity.png``): value and gradient errors and gradient angles of trilinear, central
   differences (what VTK shades with), the paper's splines and the prefiltered and interpolating splines
   (:mod:`splinevis.volume.prefilter`) side by side, inner region and full box, n = 33, 65, 129
   (:func:`splinevis.studies.volume_accuracy.fidelity_rows`).
2. **Accuracy vs time** (``pareto.png``): the isosurface of a sampled torus distance field (exact ray hits
   exist) in one camera and window. Per pixel against the exact torus: coverage mismatch (pixels covered
   by the method but not by the exact surface or vice versa), hit-position error (distance of the shown
   point to the exact surface, in grid spacings h) and normal-angle error (degrees, median and 95th
   percentile over the pixels both cover), and the median frame time (:func:`splinevis.analysis.timing.frame_times`).

   * marching cubes (scikit-image, VTK flying edges) at upsample 1..4, smooth-shaded: coverage from the
     depth buffer, the hit point is the depth buffer unprojected, the normal the mesh's barycentric
     interpolation of its vertex normals at that point (what Gouraud/Phong interpolation shows);
   * VTK's GPU isosurface ray caster (trilinear) at several sample distances: it writes no depth, so
     coverage comes from the image against a black background and there is no position error; normals
     from a lighting trick (six renders with one white directional light, ambient 0, diffuse 1, specular
     0, along x, y, z and the diagonals x+y, x+z, y+z: VTK lights volumes two-sided, so each render gives
     ``|n . L|``; the axis renders give the components' magnitudes, the diagonal ones their relative
     signs). The 8-bit quantisation of those renders bounds what can be measured; the floor, the same
     reconstruction applied to the exact normals quantised to 8 bits, is reported with every VTK row;
   * the quadratic and cubic splines (:meth:`splinevis.Plotter.add_isosurface`) at several root methods,
     iteration counts and both coefficient encodings: coverage from the GPU's depth buffer; hit points and
     normals from the program's float64 twin (:mod:`splinevis.volume.raycast`) at the same pixels, method
     and iteration count (tests prove GPU depth == twin within a derived bound with no disagreeing pixels);
     the number of pixels where the GPU's coverage and the twin's differ is reported.

   Normal angles are orientation-free (``arccos |n . n_exact|``): VTK's volume normals carry no sign.
3. **Memory and preprocessing** per volume size (Marschner-Lobb at 64^3, 128^3, 256^3) in the layout of
   [Kalbe2008, Table 1] (bounding geometry, data texture vs all coefficients vs determining set, octree,
   seconds for VolumeSpline + octree + relevant cubes + program spec), and the time of a second isovalue
   (the octree is reused). The paper's numbers are only in a separate table labelled "paper".
4. **Side by side** (``side_by_side.png``): one close-up of Marschner-Lobb at 41^3: marching cubes 1x,
   VTK's trilinear ray caster, quadratic and cubic splines; second row reflection lines from the same GLSL
   on the splines and on the mesh's interpolated normals (VTK's volume mapper takes no shader effects: plain
   shading again).

If the cubic scheme is not available the study says so (``result["cubic"]``, the markdown and stderr)
and runs the quadratic only.

This module runs the study and writes its report; the measurements of sections 1 and 2 are in
:mod:`splinevis.studies.volume_accuracy`, section 3 in :mod:`splinevis.studies.volume_memory`, the figures
in :mod:`splinevis.studies.volume_figures` and the table, JSON and figure helpers in
:mod:`splinevis.studies.report`. Their public names are importable from here too.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from .report import clean, log, md_table, write_json
from .volume_accuracy import (CAMERA, CLIP, QUICK_WINDOW, WINDOW, Reference, accuracy_vs_time, approximation_rows,
                              fidelity_rows,
                              exact_reference, measure_mesh, measure_spline, measure_vtk, normals_from_two_sided,
                              spline_configs, unproject)
from .volume_figures import ML_CAMERA, approximation_figure, fidelity_figure, pareto_figure, side_by_side_figure
from .volume_memory import PAPER_TABLE_1, memory_markdown, memory_rows

__all__ = ["run_volume_study", "cubic_status", "exact_reference", "measure_spline", "measure_mesh", "measure_vtk",
           "approximation_rows", "memory_rows", "unproject", "PAPER_TABLE_1",
           # also here, from the modules that define them
           "WINDOW", "QUICK_WINDOW", "CAMERA", "CLIP", "ML_CAMERA", "Reference", "normals_from_two_sided",
           "spline_configs", "accuracy_vs_time", "approximation_figure", "pareto_figure", "side_by_side_figure"]


def cubic_status() -> tuple:
    """``(available, note)``: whether the cubic scheme builds and evaluates here.

    Examples
    --------
    >>> from splinevis.studies.volume import cubic_status
    >>> cubic_status()
    (True, 'cubic scheme available')
    """
    try:
        from datasets_synthetic.volumes import sphere_distance
        from ..volume.model import VolumeSpline

        s = VolumeSpline(sphere_distance().sample(6), "cubic")
        s.evaluate([[0.1, 0.2, 0.3]], gradient=True)
        return True, "cubic scheme available"
    except (NotImplementedError, ImportError, AttributeError, ValueError) as exc:
        return False, f"cubic scheme NOT available ({type(exc).__name__}: {exc}); the study ran the quadratic only"


def _markdown(result) -> str:
    md = ["# Volume study: what accuracy costs in time ([Kalbe2008])\n",
          f"Mode: {'quick' if result['quick'] else 'full'}; {result['cubic']['note']}; "
          f"{result['seconds']:.0f} s; load average (1/5/15 min) at start "
          f"{'/'.join(f'{v:.1f}' for v in result.get('machine', {}).get('loadavg_1_5_15_at_start', []))}, at end "
          f"{'/'.join(f'{v:.1f}' for v in result.get('machine', {}).get('loadavg_1_5_15_at_end', []))} "
          "(frame times are wall-clock on a shared 2-core machine). All numbers measured in this run on Mesa llvmpipe (2 CPU cores, no GPU) "
          "unless the column or table says \"paper\".\n"]
    md.append("## 1. Approximation (max errors over 20,000 random interior points; order = observed vs previous size)\n")
    md.append(md_table(result["approximation"], [
        ("field", "field", "s"), ("scheme", "scheme", "s"), ("n", "n", "s"), ("h", "h", "e"),
        ("value max", "value_max", "e"), ("order", "order_value_max", "f2"), ("gradient max", "gradient_max", "e"),
        ("order", "order_gradient_max", "f2"), ("gradient rms", "gradient_rms", "e")]))
    if result.get("fidelity"):
        n = max(r["n"] for r in result["fidelity"])
        md.append(f"\n## 1b. Data fidelity side by side (n = {n}; 20,000 random points per region; inner: 2 cells of the "
                  "coarsest grid from the boundary; full: the whole sampled box, a quarter of the points on its faces)\n")
        md.append("Methods: `trilinear` (values and the exact gradient of the trilinear interpolant), `central-differences` "
                  "(trilinear values, gradients trilinearly interpolated from central differences: what VTK shades with), "
                  "the paper's splines (`quadratic`, `cubic`: linear padding), and `scheme+prefilter/padding` "
                  "(splinevis.volume.prefilter: `local` reproduces quadratics, `interpolate` interpolates the samples). "
                  "Angles between the reconstructed and the true gradient, degrees. Orders against the previous size.\n")
        md.append(md_table([r for r in result["fidelity"] if r["n"] == n], [
            ("field", "field", "s"), ("region", "region", "s"), ("method", "scheme", "s"),
            ("value rms", "value_rms", "e"), ("value max", "value_max", "e"), ("order", "order_value_max", "f2"),
            ("gradient rms", "gradient_rms", "e"), ("gradient max", "gradient_max", "e"),
            ("order", "order_gradient_max", "f2"), ("angle mean °", "angle_mean", "e"),
            ("angle median °", "angle_median", "e"), ("angle rms °", "angle_rms", "e")]))
    s = result["accuracy_setup"]
    md.append(f"\n## 2. Accuracy vs time ({s['field']}, {s['grid']} samples, h = {s['h']:.4f}, "
              f"{s['window'][0]}x{s['window'][1]} window, {s['pixels_exact']} exact pixels; a pixel is "
              f"{s['pixel_footprint_h']:.3f} h wide at the surface)\n")
    md.append("Errors per pixel against the exact torus. Coverage mismatch: pixels covered by exactly one of the "
              "method and the exact surface. Position: distance of the shown point to the torus in grid spacings "
              "(meshes: depth buffer unprojected; splines: float64 twin of the GPU program at the same pixels; VTK's "
              "volume writes no depth: none). Normals: orientation-free angle to the exact normal (meshes: "
              "interpolated vertex normals at the shown point; splines: twin gradient; VTK: lighting trick, see "
              "the floor column). Frame time: median of the repeats after two warm-up frames.\n")
    md.append(md_table(result["accuracy_vs_time"], [
        ("method", "method", "s"), ("config", "config", "s"), ("triangles / tets", "elements", "int"),
        ("frame median ms", "frame_median_ms", "f1"), ("coverage mismatch px", "coverage_mismatch", "int"),
        ("position median h", "position_err_median_h", "e"), ("position p95 h", "position_err_p95_h", "e"),
        ("normal median °", "normal_err_median_deg", "e"), ("normal p95 °", "normal_err_p95_deg", "e"),
        ("VTK read-out floor median/p95 °", "floor", "s"), ("GPU vs twin coverage px", "gpu_twin_coverage_disagree", "int")]))
    md.extend(memory_markdown(result["memory"]))
    md.append("\n## 4. Figures\n\n* `approximation.png` - error vs h (log-log) with slopes\n"
              "* `fidelity.png` - value RMS and mean gradient angle of every method at the finest grid\n"
              "* `pareto.png` - normal error and coverage mismatch vs frame time\n"
              "* `side_by_side.png` - Marschner-Lobb 41^3 close-up: MC 1x | VTK trilinear | quadratic | cubic; "
              "row 2 reflection lines (splines and the mesh; VTK's volume: plain shading)\n")
    return "\n".join(md)


def run_volume_study(out_dir, *, quick=False, progress=True) -> dict:
    """Run the study; returns the dict also written to ``out_dir/volume.json``.

    Parameters
    ----------
    out_dir : str or Path
        Created if missing; receives ``volume.json``, ``volume.md`` and the figures.
    quick : bool, optional
        Smaller sizes, windows and fewer configurations (a few minutes).
    progress : bool, optional
        Progress bars on stderr.

    Returns
    -------
    dict
        NaN-free (``None`` instead), as written to ``volume.json``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    cubic, note = cubic_status()
    log("volume", note)
    schemes = ("trilinear", "quadratic", "cubic") if cubic else ("trilinear", "quadratic")
    result = {"quick": quick, "cubic": {"available": cubic, "note": note},
              "machine": {"loadavg_1_5_15_at_start": list(os.getloadavg())}}
    result["approximation"] = approximation_rows(sizes=(16, 32, 64) if quick else (16, 32, 64, 128), schemes=schemes,
                                                 progress=progress)
    approximation_figure(result["approximation"], out / "approximation.png")
    result["fidelity"] = fidelity_rows(sizes=(33, 65) if quick else (33, 65, 129), progress=progress)
    fidelity_figure(result["fidelity"], out / "fidelity.png")
    rows, setup = accuracy_vs_time(quick=quick, cubic=cubic, progress=progress)
    for r in rows:
        if r.get("quantisation_floor_median_deg") is not None:
            r["floor"] = f"{r['quantisation_floor_median_deg']:.2f} / {r['quantisation_floor_p95_deg']:.2f}"
    result["accuracy_vs_time"], result["accuracy_setup"] = rows, setup
    pareto_figure(rows, setup, out / "pareto.png")
    result["memory"] = memory_rows(sizes=(64, 128) if quick else (64, 128, 256),
                                   schemes=("quadratic", "cubic") if cubic else ("quadratic",), progress=progress)
    result["paper_table_1"] = PAPER_TABLE_1
    result["side_by_side_coverage"] = side_by_side_figure(out / "side_by_side.png", n=41, cubic=cubic)
    result["seconds"] = time.perf_counter() - t_start
    result["machine"]["loadavg_1_5_15_at_end"] = list(os.getloadavg())
    result = clean(result)
    (out / "volume.md").write_text(_markdown(result))
    write_json(out / "volume.json", result)
    return result

"""The volume study (``splinevis study volume --out DIR [--quick]``): what accuracy costs in time for
isosurfaces of volume data, side by side with what users use today (paper 003, Kalbe & Zeilfelder 2008).

Writes ``DIR/volume.json``, ``DIR/volume.md`` (every table) and figures:

1. **Approximation** (``approximation.png``): value and gradient errors of the trilinear, quadratic and
   cubic reconstructions on n^3 samples of Marschner-Lobb and of a smooth field (the Gaussian blob), from
   :func:`splinevis.volume.approximation.approximation_table` (max errors over 20,000 random interior
   points, observed orders between sizes).
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
     normals from the float64 twin of the GPU program
     (:func:`splinevis.volume.raycast.raycast_isosurface`) at the same pixels, method and iteration count
     (tests prove GPU depth == twin within a derived bound with no disagreeing pixels); the number of
     pixels where the GPU's coverage and the twin's differ is reported.

   Normal angles are orientation-free (``arccos |n . n_exact|``): VTK's volume normals carry no sign.
3. **Memory and preprocessing** per volume size (Marschner-Lobb at 64^3, 128^3, 256^3) in the layout of
   the paper's Table 1 (bounding geometry, data texture vs all coefficients vs determining set, octree,
   seconds for VolumeSpline + octree + relevant cubes + program spec), and the time of a second isovalue
   (the octree is reused). The paper's numbers are only in a separate table labelled "paper".
4. **Side by side** (``side_by_side.png``): one close-up of Marschner-Lobb at 41^3: marching cubes 1x,
   VTK's trilinear ray caster, quadratic and cubic splines; second row reflection lines from the same GLSL
   on the splines and on the mesh's interpolated normals (VTK's volume mapper takes no shader effects: plain
   shading again).

If the cubic scheme is not available the study says so (``result["cubic"]``, the markdown and stderr)
and runs the quadratic only.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from .terrain import _fmt, _md_table

__all__ = ["run_volume_study", "cubic_status", "exact_reference", "measure_spline", "measure_mesh", "measure_vtk",
           "approximation_rows", "memory_rows", "unproject", "PAPER_TABLE_1"]

WINDOW = (400, 300)
QUICK_WINDOW = (200, 150)
CAMERA = [(1.5, -2.0, 1.6), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
CLIP = (1.0, 6.0)
#: Close-up of Marschner-Lobb (side-by-side figure).
ML_CAMERA = [(0.55, -0.95, 0.75), (0.05, -0.05, -0.05), (0.0, 0.0, 1.0)]

#: Paper 003, Table 1 (text extraction; columns read in order): dataset, voxels, isovalue rho, #cubes,
#: #patches (tetrahedra), memory MB of D2 (quadratic determining set), D3 (cubic), bounding geometry,
#: preprocessing seconds of the octree, QSS (quadratic) and S31 (cubic), frames per second on a G80 at
#: 1280x1024 for QSS and S31. Only ever shown in tables labelled "paper".
PAPER_TABLE_1 = [
    {"dataset": "neghip", "voxels": "64^3", "rho": 0.40, "cubes": 1.0e4, "patches": 1.17e5, "D2_MB": 0.77, "D3_MB": 2.16,
     "geometry_MB": 0.48, "octree_s": 0.05, "QSS_s": 0.2, "S31_s": 0.4, "QSS_fps": "40-60", "S31_fps": "20-34"},
    {"dataset": "dragon", "voxels": "200x158x121", "rho": 0.50, "cubes": 5.0e4, "patches": 5.84e5, "D2_MB": 3.84,
     "D3_MB": 10.77, "geometry_MB": 2.41, "octree_s": 0.17, "QSS_s": 1.2, "S31_s": 1.5, "QSS_fps": "20-40", "S31_fps": "14-30"},
    {"dataset": "aneurism", "voxels": "256^3", "rho": 0.40, "cubes": 7.6e4, "patches": 8.53e5, "D2_MB": 5.79,
     "D3_MB": 16.20, "geometry_MB": 2.95, "octree_s": 0.60, "QSS_s": 2.0, "S31_s": 2.5, "QSS_fps": "15-22", "S31_fps": "10-18"},
    {"dataset": "lobster", "voxels": "301x324x56", "rho": 0.14, "cubes": 1.5e5, "patches": 1.70e6, "D2_MB": 11.20,
     "D3_MB": 31.35, "geometry_MB": 7.00, "octree_s": 1.00, "QSS_s": 3.3, "S31_s": 4.1, "QSS_fps": "7-15", "S31_fps": "4-9"},
    {"dataset": "foot", "voxels": "256^3", "rho": 0.40, "cubes": 3.5e5, "patches": 4.17e6, "D2_MB": 27.03,
     "D3_MB": 75.70, "geometry_MB": 16.83, "octree_s": 1.30, "QSS_s": 6.6, "S31_s": 8.0, "QSS_fps": "4-12", "S31_fps": "2.7-8"},
    {"dataset": "bonsai", "voxels": "256^3", "rho": 0.14, "cubes": 5.1e5, "patches": 6.18e6, "D2_MB": 38.90,
     "D3_MB": 108.93, "geometry_MB": 25.27, "octree_s": 1.30, "QSS_s": 13.8, "S31_s": 16.0, "QSS_fps": "2.5-12", "S31_fps": "1.5-8"},
]


def _log(msg):
    print(f"[volume study] {msg}", file=sys.stderr, flush=True)


def cubic_status() -> tuple:
    """``(available, note)``: whether the cubic scheme builds and evaluates here."""
    try:
        from datasets_synthetic.volumes import sphere_distance
        from ..volume.model import VolumeSpline

        s = VolumeSpline(sphere_distance().sample(6), "cubic")
        s.evaluate([[0.1, 0.2, 0.3]], gradient=True)
        return True, "cubic scheme available"
    except (NotImplementedError, ImportError, AttributeError, ValueError) as exc:
        return False, f"cubic scheme NOT available ({type(exc).__name__}: {exc}); the study ran the quadratic only"


def _clean(obj):
    """JSON without NaN/inf (null instead) and with plain Python numbers."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


# ------------------------------------------------------------------------------------------------- 1
def approximation_rows(sizes=(16, 32, 64, 128), schemes=("trilinear", "quadratic", "cubic"), n_points=20000, progress=True):
    """Approximation table rows (with ``field``) on Marschner-Lobb and the Gaussian blob."""
    from tqdm import tqdm

    from datasets_synthetic.volumes import blob, marschner_lobb
    from ..volume.approximation import approximation_table

    rows = []
    for field in tqdm([marschner_lobb(), blob()], desc="approximation", disable=not progress):
        for r in approximation_table(field, sizes=sizes, schemes=schemes, n_points=n_points):
            rows.append({"field": field.name, **r})
    return rows


def approximation_figure(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fields = sorted({r["field"] for r in rows})
    fig, axes = plt.subplots(1, 2 * len(fields), figsize=(4.2 * 2 * len(fields), 4))
    for fi, name in enumerate(fields):
        for ki, (key, label) in enumerate((("value_max", "max value error"), ("gradient_max", "max gradient error"))):
            ax = axes[2 * fi + ki]
            for s in ("trilinear", "quadratic", "cubic"):
                rs = [r for r in rows if r["field"] == name and r["scheme"] == s]
                if not rs:
                    continue
                h = [r["h"] for r in rs]
                e = [r[key] for r in rs]
                slope = math.log(e[-2] / e[-1]) / math.log(h[-2] / h[-1]) if len(rs) > 1 else float("nan")
                ax.loglog(h, e, "-o", label=f"{s} (slope {slope:.2f})")
            ax.set_xlabel("grid spacing h")
            ax.set_title(f"{name}: {label}", fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8, title="slope between the two finest", title_fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------- 2
def _set_camera(pl, camera=CAMERA, clip=CLIP):
    pl.camera_position = camera
    pl.camera.clipping_range = clip


def unproject(matrix, depth):
    """World points (H, W, 3) of window depths (H, W) (row 0 at the top); NaN where depth >= 1."""
    depth = np.asarray(depth, dtype=np.float64)
    h, w = depth.shape
    inv = np.linalg.inv(np.asarray(matrix, dtype=np.float64))
    x = 2.0 * (np.arange(w) + 0.5) / w - 1.0
    y = 1.0 - 2.0 * (np.arange(h) + 0.5) / h
    xx, yy = np.meshgrid(x, y)
    ndc = np.stack([xx, yy, 2.0 * depth - 1.0, np.ones_like(xx)], axis=-1)
    p = ndc @ inv.T
    p = p[..., :3] / p[..., 3:4]
    p[depth >= 1.0] = np.nan
    return p


class Reference:
    """The exact surface per pixel: rays, exact hit parameter, coverage, hit points and normals."""

    def __init__(self, field, grid, window, matrix):
        from ..analysis.rays import pixel_rays

        self.field, self.grid, self.window, self.matrix = field, grid, tuple(window), matrix
        self.h = float(max(grid.spacing))
        o, d = pixel_rays(matrix, *window)
        self.o, self.d = o, d
        t = field.ray_hit(o.reshape(-1, 3), d.reshape(-1, 3)).reshape(o.shape[:2])
        self.t = t
        self.covered = np.isfinite(t)
        self.points = o + np.where(self.covered, t, 0.0)[..., None] * d
        self.normals = field.normal(self.points)
        # a pixel's width at the surface (world): the neighbouring pixel's ray at the same ray parameter
        c = self.covered[:, :-1]
        tc = np.where(c, t[:, :-1], 0.0)[..., None]
        step = np.linalg.norm((o[:, 1:] - o[:, :-1]) + tc * (d[:, 1:] - d[:, :-1]), axis=-1)[c]
        self.pixel_size = float(np.median(step)) if step.size else 0.0


def exact_reference(field, grid, window=WINDOW, camera=CAMERA, clip=CLIP) -> Reference:
    """The study camera's exact per-pixel reference of ``field``'s isosurface (needs ``field.ray_hit``)."""
    import pyvista as pv

    from ..plotting import Plotter

    pl = Plotter(off_screen=True, window_size=window)
    pl.add_mesh(pv.Sphere(radius=0.1))  # any actor; only the camera matters
    _set_camera(pl, camera, clip)
    matrix = pl.camera_matrix()
    pl.close()
    return Reference(field, grid, window, matrix)


def _angles(a, b):
    """Orientation-free angles (degrees) between rows of a and b."""
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    return np.degrees(np.arccos(np.clip(np.abs(np.einsum("...i,...i->...", a, b)), 0.0, 1.0)))


def _errors(ref: Reference, covered, points=None, normals=None) -> dict:
    """Coverage mismatch, position error (grid spacings) and normal error (degrees) against ``ref``."""
    out = {"pixels_exact": int(ref.covered.sum()), "pixels_shown": int(covered.sum()),
           "coverage_missing": int((ref.covered & ~covered).sum()), "coverage_extra": int((~ref.covered & covered).sum())}
    out["coverage_mismatch"] = out["coverage_missing"] + out["coverage_extra"]
    out["coverage_mismatch_rel"] = out["coverage_mismatch"] / max(out["pixels_exact"], 1)
    both = ref.covered & covered
    if points is not None:
        ok = both & np.isfinite(points).all(axis=-1)
        p = points[ok]
        dist = np.linalg.norm(p - ref.field.closest_point(p), axis=1) / ref.h if len(p) else np.zeros(0)
        out.update(position_err_median_h=float(np.median(dist)) if dist.size else None,
                   position_err_p95_h=float(np.percentile(dist, 95)) if dist.size else None,
                   position_err_max_h=float(dist.max()) if dist.size else None)
    else:
        out.update(position_err_median_h=None, position_err_p95_h=None, position_err_max_h=None)
    if normals is not None:
        ok = both & np.isfinite(normals).all(axis=-1) & (np.linalg.norm(np.nan_to_num(normals), axis=-1) > 0)
        # exact normal at the shown point where there is one (distance fields: the closest surface point's)
        at = points if points is not None else ref.points
        exact = ref.field.normal(np.where(np.isfinite(at), at, 0.0)[ok])
        ang = _angles(normals[ok], exact) if ok.any() else np.zeros(0)
        out.update(normal_err_median_deg=float(np.median(ang)) if ang.size else None,
                   normal_err_p95_deg=float(np.percentile(ang, 95)) if ang.size else None,
                   normal_pixels=int(ang.size))
    else:
        out.update(normal_err_median_deg=None, normal_err_p95_deg=None, normal_pixels=0)
    return out


def _timed(pl, repeats):
    from ..analysis.timing import frame_times

    r = frame_times(pl, repeats)
    return {"frame_min_ms": r["min_ms"], "frame_median_ms": r["median_ms"], "repeats": r["repeats"]}


def measure_spline(ref: Reference, spline, *, roots=None, iterations=2, encoding="data", proxy="blocks",
                   repeats=3) -> dict:
    """One spline configuration: GPU frame time and coverage; positions and normals from the float64 twin."""
    from ..plotting import Plotter
    from ..volume.program import Isosurface
    from ..volume.raycast import raycast_isosurface

    cubic = spline.degree == 3
    roots = roots or "analytic"
    iso = Isosurface(spline, ref.field.isovalue)
    t0 = time.perf_counter()
    rel = iso.relevant
    pre = time.perf_counter() - t0
    pl = Plotter(off_screen=True, window_size=ref.window)
    pl.add_spline(iso, lights=1, newton_iterations=iterations,
                  program_options={"encoding": encoding, "roots": roots, "proxy": proxy})
    _set_camera(pl)
    timing = _timed(pl, repeats)
    gpu_cov = pl.depth_buffer() < 1.0
    pl.close()
    t, g = raycast_isosurface(iso, ref.o.reshape(-1, 3), ref.d.reshape(-1, 3), method=roots, iterations=iterations)
    t = t.reshape(ref.window[::-1])
    twin_cov = np.isfinite(t)
    points = ref.o + np.where(twin_cov, t, np.nan)[..., None] * ref.d
    normals = g.reshape(points.shape)
    row = {"kind": f"spline {spline.scheme}", "method": f"{spline.scheme} spline",
           "config": f"{proxy}, {encoding}, {roots}" + ("" if roots == "analytic" else f", {iterations} it."),
           "scheme": spline.scheme, "encoding": encoding, "roots": roots, "proxy": proxy,
           "iterations": None if roots == "analytic" else iterations, "elements": int(rel.num_tets),
           "relevant_cubes": int(len(rel.cubes)), "relevant_seconds": pre, **timing,
           "gpu_twin_coverage_disagree": int((gpu_cov != twin_cov).sum())}
    row.update(_errors(ref, gpu_cov, points, normals))
    return row


def _mesh_normals_at(mesh, points):
    """Barycentric interpolation of the mesh's point normals at (n, 3) points on (or next to) its triangles."""
    cells, closest = mesh.find_closest_cell(points, return_closest_point=True)
    tri = mesh.faces.reshape(-1, 4)[:, 1:][cells]
    a, b, c = (mesh.points[tri[:, i]] for i in range(3))
    v0, v1, v2 = b - a, c - a, closest - a
    d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
    d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
    den = d00 * d11 - d01 * d01
    den = np.where(den == 0, 1.0, den)
    lb = (d11 * d20 - d01 * d21) / den
    lc = (d00 * d21 - d01 * d20) / den
    la = 1.0 - lb - lc
    nrm = np.asarray(mesh.point_data["Normals"])
    return la[:, None] * nrm[tri[:, 0]] + lb[:, None] * nrm[tri[:, 1]] + lc[:, None] * nrm[tri[:, 2]]


def measure_mesh(ref: Reference, *, method="flying_edges", upsample=1, repeats=3) -> dict:
    """Marching cubes mesh, smooth-shaded: frame time, coverage and depth from the GPU, interpolated normals."""
    from ..plotting import Plotter
    from ..volume.baselines import marching_cubes_mesh

    mesh = marching_cubes_mesh(ref.grid, ref.field.isovalue, method=method, upsample=upsample)
    pl = Plotter(off_screen=True, window_size=ref.window)
    pl.add_mesh(mesh, color="tan", smooth_shading=True)
    _set_camera(pl)
    timing = _timed(pl, repeats)
    depth = pl.depth_buffer()
    pl.close()
    covered = depth < 1.0
    points = unproject(ref.matrix, depth)
    normals = np.full(points.shape, np.nan)
    if covered.any():
        normals[covered] = _mesh_normals_at(mesh, points[covered])
    row = {"kind": f"marching cubes ({method})", "method": f"MC {method}", "config": f"upsample {upsample}x",
           "upsample": upsample, "elements": int(mesh.n_cells),
           "build_seconds": float(mesh.field_data["total_seconds"][0]), **timing}
    row.update(_errors(ref, covered, points, normals))
    return row


#: Light directions of the normal-recovery trick: three axes, then x+y, x+z, y+z.
_LIGHTS = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, 0, 1], [0, 1, 1]], dtype=np.float64)
_LIGHTS = _LIGHTS / np.linalg.norm(_LIGHTS, axis=1, keepdims=True)
_SIGNS = np.array([[1, sy, sz] for sy in (1, -1) for sz in (1, -1)], dtype=np.float64)


def normals_from_two_sided(intensity):
    """Normals (n, 3) from two-sided diffuse intensities ``|n . L|`` (n, 6) under :data:`_LIGHTS`: the axis
    intensities are the magnitudes; the sign pattern (x taken positive) best explaining the diagonal ones
    is chosen."""
    mag = intensity[:, :3]
    cand = mag[:, None, :] * _SIGNS[None]  # (n, 4, 3)
    pred = np.abs(cand @ _LIGHTS[3:].T)  # (n, 4, 3)
    best = np.argmin(((pred - intensity[:, None, 3:]) ** 2).sum(-1), axis=1)
    return cand[np.arange(len(mag)), best]


def measure_vtk(ref: Reference, *, sample_distance=None, repeats=3) -> dict:
    """VTK's GPU isosurface ray caster: frame time, coverage from the image, normals by the lighting trick."""
    import pyvista as pv

    from ..plotting import Plotter
    from ..volume.baselines import add_vtk_isosurface

    def scene():
        pl = Plotter(off_screen=True, window_size=ref.window)
        pl.set_background("black")
        add_vtk_isosurface(pl, ref.grid, ref.field.isovalue, sample_distance=sample_distance, color=(1.0, 1.0, 1.0),
                           ambient=0.0, diffuse=1.0, specular=0.0)
        _set_camera(pl)
        return pl

    pl = scene()
    timing = _timed(pl, repeats)
    pl.close()
    imgs = []
    for L in _LIGHTS:
        pl = scene()
        pl.remove_all_lights()
        pl.add_light(pv.Light(position=tuple(L), focal_point=(0.0, 0.0, 0.0), light_type="scene light", intensity=1.0))
        imgs.append(pl.screenshot().astype(np.float64)[..., 0] / 255.0)
        pl.close()
    I = np.stack(imgs, axis=-1)
    # every visible normal has some axis component >= 1/sqrt(3): a covered pixel is non-black in an axis render
    covered = I[..., :3].max(axis=-1) > 0
    normals = np.full(ref.points.shape, np.nan)
    normals[covered] = normals_from_two_sided(I[covered])
    # the floor: the same reconstruction from the exact normals, quantised to 8 bits
    ex = ref.normals[ref.covered]
    q = np.round(np.abs(ex @ _LIGHTS.T) * 255.0) / 255.0
    floor = _angles(normals_from_two_sided(q), ex)
    sd = sample_distance
    row = {"kind": "VTK GPU ray caster (trilinear)", "method": "VTK volume",
           "config": "auto sample distance" if sd is None else f"sample distance h/{ref.h / sd:.3g}",
           "sample_distance": sd, "sample_distance_h": None if sd is None else sd / ref.h, "elements": None, **timing,
           "quantisation_floor_median_deg": float(np.median(floor)), "quantisation_floor_p95_deg": float(np.percentile(floor, 95))}
    row.update(_errors(ref, covered, None, normals))
    return row


def spline_configs(quick, cubic):
    """(scheme, encoding, roots, iterations, proxy) of the measured spline programs. Paper 003's Newton
    (``"paper"``) exists for the cubic only: the paper solves quadratics in closed form."""
    q = [("quadratic", "data", "analytic", 1, "blocks"), ("quadratic", "coefficients", "analytic", 1, "blocks"),
         ("quadratic", "data", "analytic", 1, "cubes")]
    c = [("cubic", "data", "analytic", 1, "blocks"), ("cubic", "determining", "analytic", 1, "blocks"),
         ("cubic", "data", "paper", 5, "blocks"),
         ("cubic", "data", "bracketed", 2, "blocks")]
    if not quick:
        q += [("quadratic", "data", "bracketed", 2, "blocks"), ("quadratic", "data", "bracketed", 4, "blocks")]
        c += [("cubic", "data", "paper", 2, "blocks"), ("cubic", "data", "paper", 8, "blocks"),
              ("cubic", "data", "bracketed", 4, "blocks"), ("cubic", "coefficients", "analytic", 1, "blocks"),
              ("cubic", "data", "analytic", 1, "cubes")]
    return q + (c if cubic else [])


def accuracy_vs_time(*, quick=False, cubic=True, repeats=None, n=None, progress=True):
    """Rows of every method on the sampled torus (see the module docstring); and the set-up."""
    from tqdm import tqdm

    from datasets_synthetic.volumes import torus_distance
    from ..volume.model import VolumeSpline

    field = torus_distance()
    n = n or (24 if quick else 32)
    repeats = repeats or (2 if quick else 3)
    window = QUICK_WINDOW if quick else WINDOW
    grid = field.sample(n)
    ref = exact_reference(field, grid, window)
    jobs = [("mesh", m, u) for m in ("skimage", "flying_edges") for u in ((1, 2, 4) if quick else (1, 2, 3, 4))]
    jobs += [("vtk", f, None) for f in ((2, 8) if quick else (1, 2, 4, 10))]
    jobs += [("spline",) + c for c in spline_configs(quick, cubic)]
    splines = {}
    rows = []
    for job in tqdm(jobs, desc="accuracy vs time", disable=not progress):
        if job[0] == "mesh":
            rows.append(measure_mesh(ref, method=job[1], upsample=job[2], repeats=repeats))
        elif job[0] == "vtk":
            rows.append(measure_vtk(ref, sample_distance=ref.h / job[1], repeats=repeats))
        else:
            _, scheme, enc, roots, k, proxy = job
            if scheme not in splines:
                splines[scheme] = VolumeSpline(grid, scheme)
            rows.append(measure_spline(ref, splines[scheme], roots=roots, iterations=k, encoding=enc, proxy=proxy,
                                       repeats=repeats))
    setup = {"field": f"torus distance R={field.R}, r={field.r}, isovalue {field.isovalue}", "grid": f"{n}^3",
             "h": ref.h, "window": list(window), "camera": CAMERA, "clipping_range": list(CLIP), "repeats": repeats,
             "pixels_exact": int(ref.covered.sum()), "pixel_footprint_world": ref.pixel_size,
             "pixel_footprint_h": ref.pixel_size / ref.h}
    return rows, setup


def _short(r):
    if r["method"].startswith("MC"):
        return f"{r['upsample']}x"
    if r["method"] == "VTK volume":
        return r["config"].replace("sample distance ", "")
    return (("" if r.get("proxy", "blocks") == "blocks" else "cubes ") + {"data": "D", "coefficients": "C"}.get(r["encoding"], "S") + "/"
            + r["roots"][:2] + ("" if r["iterations"] is None else str(r["iterations"])))


def pareto_figure(rows, setup, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(14, 5.5))
    styles = {"MC skimage": ("k", "o"), "MC flying_edges": ("0.5", "s"), "VTK volume": ("tab:green", "^"),
              "quadratic spline": ("tab:blue", "D"), "cubic spline": ("tab:red", "v")}
    for key, (ykey, ylabel) in enumerate((("normal_err_median_deg", "median normal error (degrees)"),
                                          ("coverage_mismatch", "coverage mismatch (pixels) + 1"))):
        ax = axes[key]
        for method, (col, mk) in styles.items():
            rs = [r for r in rows if r["method"] == method and r.get(ykey) is not None]
            if not rs:
                continue
            xs = [r["frame_median_ms"] for r in rs]
            ys = [r[ykey] + (1 if ykey == "coverage_mismatch" else 0) for r in rs]
            if method.startswith("MC") or method == "VTK volume":
                ax.plot(xs, ys, "-", color=col, marker=mk, label=method)
            else:
                ax.plot(xs, ys, linestyle="none", color=col, marker=mk, label=method)
            for i, (r, x, y) in enumerate(zip(rs, xs, ys)):
                ax.annotate(_short(r), (x, y), fontsize=6, xytext=(4, 6 - 7 * (i % 3)), textcoords="offset points")
        if ykey == "normal_err_median_deg":
            fl = [r["quantisation_floor_median_deg"] for r in rows if r.get("quantisation_floor_median_deg") is not None]
            if fl:
                ax.axhline(max(fl), color="tab:green", ls=":", lw=1, label="VTK normal read-out floor (8 bit)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"frame time, median ms ({setup['window'][0]}x{setup['window'][1]}, llvmpipe, 2 cores)")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"Accuracy vs time: {setup['field']}, {setup['grid']} samples (h = {setup['h']:.4f});\nspline labels: "
                 "D/C/S = data texture / coefficient table / determining set, an = closed form, br = bracketed, pa = paper's Newton + iterations",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------- 3
def memory_rows(sizes=(64, 128, 256), schemes=("quadratic", "cubic"), progress=True):
    """Memory and preprocessing per Marschner-Lobb volume size and scheme (isovalue 0.5, then 0.45)."""
    from tqdm import tqdm

    from datasets_synthetic.volumes import marschner_lobb
    from ..volume.model import VolumeSpline
    from ..volume.program import Isosurface, isosurface_program, memory_report

    field = marschner_lobb()
    rows = []
    for n in tqdm(sizes, desc="memory / preprocessing", disable=not progress):
        grid = field.sample(n)
        for scheme in schemes:
            t0 = time.perf_counter()
            s = VolumeSpline(grid, scheme)
            t1 = time.perf_counter()
            s.octree
            t2 = time.perf_counter()
            rel = s.relevant(field.isovalue)
            t3 = time.perf_counter()
            isosurface_program(Isosurface(s, field.isovalue, rel))
            t4 = time.perf_counter()
            rel2 = s.relevant(field.isovalue - 0.05)
            t5 = time.perf_counter()
            isosurface_program(Isosurface(s, field.isovalue - 0.05, rel2))
            t6 = time.perf_counter()
            mem = memory_report(s, rel)
            mb = {k.replace("_bytes", "_MB"): v / 2**20 for k, v in mem.items() if k.endswith("_bytes")}
            rows.append({"volume": f"{n}^3", "n": n, "scheme": scheme, "isovalue": field.isovalue,
                         "relevant_cubes": mem["relevant_cubes"], "relevant_tets": mem["relevant_tets"],
                         "octree_candidates": int(rel.candidates), **mb,
                         "spline_s": t1 - t0, "octree_s": t2 - t1, "relevant_s": t3 - t2, "program_s": t4 - t3,
                         "preprocessing_s": t4 - t0, "second_isovalue": field.isovalue - 0.05,
                         "second_isovalue_s": t6 - t4, "second_isovalue_cubes": int(len(rel2.cubes)),
                         "second_vs_first": (t6 - t4) / (t4 - t0)})
            del s
    return rows


# ------------------------------------------------------------------------------------------------- 4
def side_by_side_figure(path, *, n=41, cubic=True, window=(420, 330)):
    """Marching cubes 1x | VTK ray caster (trilinear) | quadratic | cubic on Marschner-Lobb n^3, close-up;
    row 1 shading, row 2 reflection lines (splines and the mesh, same GLSL; VTK's volume mapper shows plain
    shading again)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from datasets_synthetic.volumes import marschner_lobb
    from ..plotting import Plotter
    from ..gl.mesh_effects import add_mesh_with_reflection_lines
    from ..volume.baselines import add_vtk_isosurface, marching_cubes_mesh
    from ..volume.model import VolumeSpline

    field = marschner_lobb()
    grid = field.sample(n)
    iso = field.isovalue
    cols = [("marching cubes 1x (flying edges)", "mc"), ("VTK ray caster (trilinear)", "vtk"), ("quadratic spline", "quadratic")]
    if cubic:
        cols.append(("cubic spline", "cubic"))
    fig, axes = plt.subplots(2, len(cols), figsize=(3.6 * len(cols), 6.2))
    shots = {}
    for ci, (title, kind) in enumerate(cols):
        for ri, lines in enumerate((False, True)):
            pl = Plotter(off_screen=True, window_size=window)
            pl.set_background("white")
            if kind == "mc" and lines:
                # the same reflection-line GLSL on the mesh's interpolated vertex normals
                add_mesh_with_reflection_lines(pl, marching_cubes_mesh(grid, iso, method="flying_edges"), 12)
            elif kind == "mc":
                pl.add_mesh(marching_cubes_mesh(grid, iso, method="flying_edges"), color="tan", smooth_shading=True)
            elif kind == "vtk":
                add_vtk_isosurface(pl, grid, iso, sample_distance=grid.spacing[0] / 4, color=(0.82, 0.71, 0.55))
            else:
                style = dict(lights=1, reflection_lines=12) if lines else dict(lights=1)
                pl.add_isosurface(VolumeSpline(grid, kind), iso, newton_iterations=4, **style)
            _set_camera(pl, ML_CAMERA, (0.05, 5.0))
            img = pl.screenshot()
            pl.close()
            shots[(kind, lines)] = img
            ax = axes[ri, ci]
            ax.imshow(img)
            ax.set_axis_off()
            if ri == 0:
                ax.set_title(title, fontsize=10)
            elif kind == "vtk":
                ax.set_title("(VTK's volume mapper takes no shader\neffects: plain shading)", fontsize=8)
            else:
                ax.set_title("reflection lines (12)", fontsize=9)
    fig.suptitle(f"Marschner-Lobb, {n}^3 samples, isovalue {iso}: the same close-up")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return {f"{k}{' lines' if l else ''}": float((np.abs(v.astype(int) - 255).sum(-1) > 30).mean()) for (k, l), v in shots.items()}


# ------------------------------------------------------------------------------------------------- report
def _markdown(result) -> str:
    md = ["# Volume study: what accuracy costs in time (issue 4, paper 003)\n",
          f"Mode: {'quick' if result['quick'] else 'full'}; {result['cubic']['note']}; "
          f"{result['seconds']:.0f} s; load average (1/5/15 min) at start "
          f"{'/'.join(f'{v:.1f}' for v in result.get('machine', {}).get('loadavg_1_5_15_at_start', []))}, at end "
          f"{'/'.join(f'{v:.1f}' for v in result.get('machine', {}).get('loadavg_1_5_15_at_end', []))} "
          "(frame times are wall-clock on a shared 2-core machine). All numbers measured in this run on Mesa llvmpipe (2 CPU cores, no GPU) "
          "unless the column or table says \"paper\".\n"]
    md.append("## 1. Approximation (max errors over 20,000 random interior points; order = observed vs previous size)\n")
    md.append(_md_table(result["approximation"], [
        ("field", "field", "s"), ("scheme", "scheme", "s"), ("n", "n", "s"), ("h", "h", "e"),
        ("value max", "value_max", "e"), ("order", "order_value_max", "f2"), ("gradient max", "gradient_max", "e"),
        ("order", "order_gradient_max", "f2"), ("gradient rms", "gradient_rms", "e")], _fmt))
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
    md.append(_md_table(result["accuracy_vs_time"], [
        ("method", "method", "s"), ("config", "config", "s"), ("triangles / tets", "elements", "int"),
        ("frame median ms", "frame_median_ms", "f1"), ("coverage mismatch px", "coverage_mismatch", "int"),
        ("position median h", "position_err_median_h", "e"), ("position p95 h", "position_err_p95_h", "e"),
        ("normal median °", "normal_err_median_deg", "e"), ("normal p95 °", "normal_err_p95_deg", "e"),
        ("VTK read-out floor median/p95 °", "floor", "s"), ("GPU vs twin coverage px", "gpu_twin_coverage_disagree", "int")],
        _fmt))
    md.append("\n## 3. Memory and preprocessing (Marschner-Lobb, isovalue 0.5; layout of the paper's Table 1)\n")
    md.append(_md_table(result["memory"], [
        ("volume", "volume", "s"), ("scheme", "scheme", "s"), ("cubes", "relevant_cubes", "int"),
        ("tets", "relevant_tets", "int"), ("geometry MB (blocks)", "geometry_MB", "f2"),
        ("geometry MB (cube proxies)", "geometry_cubes_MB", "f2"), ("data texture MB", "data_texture_MB", "f2"),
        ("determining set MB", "determining_set_MB", "f2"), ("all coefficients MB", "all_coefficients_MB", "f2"),
        ("coef. table MB", "coefficient_table_MB", "f2"), ("octree MB", "octree_MB", "f2"),
        ("spline s", "spline_s", "f2"), ("octree s", "octree_s", "f2"), ("relevant s", "relevant_s", "f2"),
        ("program s", "program_s", "f2"), ("preprocessing s", "preprocessing_s", "f2"),
        ("2nd isovalue s", "second_isovalue_s", "f2")], _fmt))
    big = [r for r in result["memory"] if r["n"] == 256]
    if big:
        md.append("\nGoal: 256^3 preprocessing for one isovalue <= 5 s: " + ", ".join(
            f"{r['scheme']} {r['preprocessing_s']:.2f} s ({'met' if r['preprocessing_s'] <= 5 else 'NOT met'})" for r in big) + ".\n")
    md.append("\n### paper (Kalbe & Zeilfelder 2008, Table 1, NVIDIA 8800 Ultra, 1280x1024; real data sets, not ours)\n")
    md.append(_md_table(PAPER_TABLE_1, [
        ("paper dataset", "dataset", "s"), ("voxels", "voxels", "s"), ("rho", "rho", "f2"), ("cubes", "cubes", "e"),
        ("patches", "patches", "e"), ("D2 MB", "D2_MB", "f2"), ("D3 MB", "D3_MB", "f2"), ("geometry MB", "geometry_MB", "f2"),
        ("octree s", "octree_s", "f2"), ("QSS s", "QSS_s", "f1"), ("S31 s", "S31_s", "f1"), ("QSS fps", "QSS_fps", "s"),
        ("S31 fps", "S31_fps", "s")], _fmt))
    md.append("\nD2/D3 = the paper's determining sets (20 resp. 56 floats per cube) = our \"determining set MB\"; our "
              "default encoding uploads the data texture (1 float per sample) instead.\n")
    md.append("\n## 4. Figures\n\n* `approximation.png` - error vs h (log-log) with slopes\n"
              "* `pareto.png` - normal error and coverage mismatch vs frame time\n"
              "* `side_by_side.png` - Marschner-Lobb 41^3 close-up: MC 1x | VTK trilinear | quadratic | cubic; "
              "row 2 reflection lines (splines and the mesh; VTK's volume: plain shading)\n")
    return "\n".join(md)


def run_volume_study(out_dir, *, quick=False, progress=True) -> dict:
    """Run the study; returns the dict also written to ``out_dir/volume.json``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    cubic, note = cubic_status()
    _log(note)
    schemes = ("trilinear", "quadratic", "cubic") if cubic else ("trilinear", "quadratic")
    result = {"quick": quick, "cubic": {"available": cubic, "note": note},
              "machine": {"loadavg_1_5_15_at_start": list(os.getloadavg())}}
    result["approximation"] = approximation_rows(sizes=(16, 32, 64) if quick else (16, 32, 64, 128), schemes=schemes,
                                                 progress=progress)
    approximation_figure(result["approximation"], out / "approximation.png")
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
    result = _clean(result)
    (out / "volume.md").write_text(_markdown(result))
    (out / "volume.json").write_text(json.dumps(result, indent=2, allow_nan=False))
    return result

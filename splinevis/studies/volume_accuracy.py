"""What each method of the volume study gets right, measured: the approximation errors of the trilinear,
quadratic and cubic reconstructions, and the per-pixel errors of every renderer of an isosurface against
the exact surface, with its frame time (sections 1 and 2 of :mod:`splinevis.studies.volume`, whose
docstring says how each method is measured).

The scene is a sampled distance field with exact ray hits (the torus); :class:`Reference` holds the exact
surface per pixel, ``measure_*`` one configuration of a method each, :func:`accuracy_vs_time` the sweep.
"""

from __future__ import annotations

import time

import numpy as np

from .report import error_summary, progress_bar, timed

__all__ = ["WINDOW", "QUICK_WINDOW", "CAMERA", "CLIP", "approximation_rows", "fidelity_rows", "set_camera", "unproject", "Reference",
           "exact_reference", "measure_spline", "measure_mesh", "measure_vtk", "normals_from_two_sided",
           "spline_configs", "accuracy_vs_time"]

WINDOW = (400, 300)
QUICK_WINDOW = (200, 150)
CAMERA = [(1.5, -2.0, 1.6), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
CLIP = (1.0, 6.0)


# ------------------------------------------------------------------------------------------ approximation
def approximation_rows(sizes=(16, 32, 64, 128), schemes=("trilinear", "quadratic", "cubic"), n_points=20000, progress=True):
    """Approximation table rows (with ``field``) on Marschner-Lobb and the Gaussian blob.

    Examples
    --------
    >>> from splinevis.studies.volume_accuracy import approximation_rows
    >>> rows = approximation_rows(sizes=(8, 16), schemes=("trilinear",), n_points=1000, progress=False)
    >>> [(r["field"], r["n"]) for r in rows]
    [('marschner_lobb', 8), ('marschner_lobb', 16), ('blob', 8), ('blob', 16)]
    >>> round(rows[-1]["order_value_max"], 1)  # observed order on the smooth blob, heading for 2
    1.8
    """
    from datasets_synthetic.volumes import blob, marschner_lobb
    from ..volume.approximation import approximation_table

    rows = []
    for field in progress_bar([marschner_lobb(), blob()], "approximation", enabled=progress):
        for r in approximation_table(field, sizes=sizes, schemes=schemes, n_points=n_points):
            rows.append({"field": field.name, **r})
    return rows


# ------------------------------------------------------------------------------------------ the exact surface
def fidelity_rows(sizes=(33, 65, 129), methods=None, n_points=20000, progress=True):
    """Data fidelity side by side: value and gradient errors (and gradient angles) of trilinear interpolation,
    central differences (what VTK shades with), the paper's splines and the prefiltered ones
    (:data:`splinevis.volume.approximation.FIDELITY_METHODS`) on Marschner-Lobb and the Gaussian blob, in the
    inner region and the full sampled box (``region`` key).

    Examples
    --------
    >>> rows = fidelity_rows(sizes=(9, 17), methods=("trilinear", "quadratic+local/quadratic"), n_points=500,
    ...                      progress=False)
    >>> sorted({(r["field"], r["region"]) for r in rows})[:2], len(rows)
    ([('blob', 'full'), ('blob', 'inner')], 16)
    """
    from datasets_synthetic.volumes import blob, marschner_lobb
    from ..volume.approximation import FIDELITY_METHODS, approximation_table

    methods = tuple(methods or FIDELITY_METHODS)
    rows = []
    jobs = [(f, region) for f in (marschner_lobb(), blob()) for region in ("inner", "full")]
    for field, region in progress_bar(jobs, "data fidelity", enabled=progress):
        for r in approximation_table(field, sizes=sizes, schemes=methods, n_points=n_points, region=region):
            rows.append({"field": field.name, **r})
    return rows


def set_camera(pl, camera=CAMERA, clip=CLIP):
    """Put the study camera (or ``camera``) on a plotter, with a fixed clipping range.

    Examples
    --------
    >>> from splinevis.plotting import Plotter
    >>> from splinevis.studies.volume_accuracy import set_camera
    >>> pl = Plotter(off_screen=True, window_size=(32, 24))
    >>> set_camera(pl)
    >>> pl.camera.position, pl.camera.focal_point, pl.camera.clipping_range
    ((1.5, -2.0, 1.6), (0.0, 0.0, 0.0), (1.0, 6.0))
    >>> pl.close()
    """
    pl.camera_position = camera
    pl.camera.clipping_range = clip


def unproject(matrix, depth):
    """World points (H, W, 3) of window depths (H, W) (row 0 at the top); NaN where depth >= 1.

    Examples
    --------
    With the identity matrix world coordinates are normalized device coordinates (depth 0 is the near
    plane z = -1, depth 1 the far plane: background):

    >>> import numpy as np
    >>> from splinevis.studies.volume_accuracy import unproject
    >>> unproject(np.eye(4), [[0.5, 1.0], [0.0, 0.5]])
    array([[[-0.5,  0.5,  0. ],
            [ nan,  nan,  nan]],
    <BLANKLINE>
           [[-0.5, -0.5, -1. ],
            [ 0.5, -0.5,  0. ]]])
    """
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
    """The exact surface per pixel: rays, exact hit parameter, coverage, hit points and normals.

    Parameters
    ----------
    field : AnalyticField
        With ``ray_hit`` (exact ray hits), ``normal`` and ``closest_point``, such as the torus.
    grid : VolumeGrid
        The samples the methods see; its spacing ``h`` is the unit of the position errors.
    window : (W, H)
    matrix : (4, 4) array_like
        The camera's world-to-clip matrix (:meth:`splinevis.Plotter.camera_matrix`).

    Examples
    --------
    With the identity matrix the rays run along z, down the axis of the torus: the covered pixels form a
    ring.

    >>> import numpy as np
    >>> from datasets_synthetic.volumes import torus_distance
    >>> from splinevis.studies.volume_accuracy import Reference
    >>> field = torus_distance()  # R = 0.6, r = 0.25 about the z axis
    >>> ref = Reference(field, field.sample(8), (8, 8), np.eye(4))
    >>> ref.covered.astype(int)
    array([[0, 0, 0, 0, 0, 0, 0, 0],
           [0, 0, 1, 1, 1, 1, 0, 0],
           [0, 1, 1, 1, 1, 1, 1, 0],
           [0, 1, 1, 0, 0, 1, 1, 0],
           [0, 1, 1, 0, 0, 1, 1, 0],
           [0, 1, 1, 1, 1, 1, 1, 0],
           [0, 0, 1, 1, 1, 1, 0, 0],
           [0, 0, 0, 0, 0, 0, 0, 0]])
    >>> bool(np.abs(field.value(ref.points[ref.covered])).max() < 1e-12)  # the hits are on the torus
    True
    >>> ref.h == 2 / 7  # 8 samples across [-1, 1]
    True
    """

    def __init__(self, field, grid, window, matrix):
        from ..gl.camera import pixel_rays

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
    """The study camera's exact per-pixel reference of ``field``'s isosurface (needs ``field.ray_hit``).

    Examples
    --------
    >>> from datasets_synthetic.volumes import torus_distance
    >>> from splinevis.studies.volume_accuracy import exact_reference
    >>> field = torus_distance()
    >>> ref = exact_reference(field, field.sample(8), window=(32, 24))
    >>> ref.covered.shape, int(ref.covered.sum())  # (H, W) and the pixels the exact torus covers
    ((24, 32), 356)
    """
    import pyvista as pv

    from ..plotting import Plotter

    pl = Plotter(off_screen=True, window_size=window)
    pl.add_mesh(pv.Sphere(radius=0.1))  # any actor; only the camera matters
    set_camera(pl, camera, clip)
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
    dist = np.zeros(0)
    if points is not None:
        ok = both & np.isfinite(points).all(axis=-1)
        p = points[ok]
        if len(p):
            dist = np.linalg.norm(p - ref.field.closest_point(p), axis=1) / ref.h
    out.update(error_summary(dist, "position", "h"))
    ang = np.zeros(0)
    if normals is not None:
        ok = both & np.isfinite(normals).all(axis=-1) & (np.linalg.norm(np.nan_to_num(normals), axis=-1) > 0)
        # exact normal at the shown point where there is one (distance fields: the closest surface point's)
        at = points if points is not None else ref.points
        exact = ref.field.normal(np.where(np.isfinite(at), at, 0.0)[ok])
        if ok.any():
            ang = _angles(normals[ok], exact)
    out.update(error_summary(ang, "normal", "deg", stats=("median", "p95")), normal_pixels=int(ang.size))
    return out


# ------------------------------------------------------------------------------------------ the methods
def measure_spline(ref: Reference, spline, *, roots=None, iterations=2, encoding="data", proxy="blocks",
                   repeats=3) -> dict:
    """One spline configuration: GPU frame time and coverage; positions and normals from the float64 twin.

    Examples
    --------
    >>> from datasets_synthetic.volumes import torus_distance
    >>> from splinevis.studies.volume_accuracy import exact_reference, measure_spline
    >>> from splinevis.volume.model import VolumeSpline
    >>> field = torus_distance()
    >>> grid = field.sample(8)
    >>> ref = exact_reference(field, grid, window=(32, 24))
    >>> row = measure_spline(ref, VolumeSpline(grid, "quadratic"), repeats=1)
    >>> row["method"], row["config"], row["elements"]
    ('quadratic spline', 'blocks, data, analytic', 800)
    >>> row["gpu_twin_coverage_disagree"]  # the GPU covers exactly the pixels its float64 twin hits
    0
    """
    from ..plotting import Plotter
    from ..programs import program_for
    from ..volume.isosurface import Isosurface

    roots = roots or "analytic"
    iso = Isosurface(spline, ref.field.isovalue)
    t0 = time.perf_counter()
    rel = iso.relevant
    pre = time.perf_counter() - t0
    pl = Plotter(off_screen=True, window_size=ref.window)
    pl.add_spline(iso, lights=1, newton_iterations=iterations,
                  program_options={"encoding": encoding, "roots": roots, "proxy": proxy})
    set_camera(pl)
    timing = timed(pl, repeats)
    gpu_cov = pl.depth_buffer() < 1.0
    pl.close()
    hits = program_for(iso).raycast(iso, ref.o, ref.d, method=roots, iterations=iterations)
    twin_cov = hits.hit
    points = ref.o + np.where(twin_cov, hits.t, np.nan)[..., None] * ref.d
    normals = hits.normals
    variant = "" if getattr(spline, "prefilter", "none") == "none" and getattr(spline, "padding", "linear") == "linear" \
        else f" ({spline.prefilter} prefilter, {spline.padding} padding)"
    row = {"kind": f"spline {spline.scheme}", "method": f"{spline.scheme} spline{variant}",
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
    """Marching cubes mesh, smooth-shaded: frame time, coverage and depth from the GPU, interpolated normals.

    Examples
    --------
    >>> from datasets_synthetic.volumes import torus_distance
    >>> from splinevis.studies.volume_accuracy import exact_reference, measure_mesh
    >>> field = torus_distance()
    >>> ref = exact_reference(field, field.sample(8), window=(32, 24))
    >>> row = measure_mesh(ref, upsample=1, repeats=1)
    >>> row["method"], row["config"], row["elements"]
    ('MC flying_edges', 'upsample 1x', 208)
    >>> row["pixels_exact"], row["position_err_median_h"] < 0.5  # shown points within half a grid spacing
    (356, True)
    """
    from ..plotting import Plotter
    from ..volume.baselines import marching_cubes_mesh

    mesh = marching_cubes_mesh(ref.grid, ref.field.isovalue, method=method, upsample=upsample)
    pl = Plotter(off_screen=True, window_size=ref.window)
    pl.add_mesh(mesh, color="tan", smooth_shading=True)
    set_camera(pl)
    timing = timed(pl, repeats)
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
    is chosen.

    Examples
    --------
    Two unit normals, lit from the three axes and the three diagonals (the first comes back with x
    positive: VTK's two-sided lighting cannot tell a normal from its opposite):

    >>> import numpy as np
    >>> from splinevis.studies.volume_accuracy import normals_from_two_sided
    >>> lights = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, 0, 1], [0, 1, 1]])
    >>> lights = lights / np.linalg.norm(lights, axis=1, keepdims=True)
    >>> normals = np.array([[-0.6, 0.8, 0.0], [0.48, 0.6, -0.64]])
    >>> normals_from_two_sided(np.abs(normals @ lights.T))
    array([[ 0.6 , -0.8 ,  0.  ],
           [ 0.48,  0.6 , -0.64]])
    """
    mag = intensity[:, :3]
    cand = mag[:, None, :] * _SIGNS[None]  # (n, 4, 3)
    pred = np.abs(cand @ _LIGHTS[3:].T)  # (n, 4, 3)
    best = np.argmin(((pred - intensity[:, None, 3:]) ** 2).sum(-1), axis=1)
    return cand[np.arange(len(mag)), best]


def measure_vtk(ref: Reference, *, sample_distance=None, repeats=3) -> dict:
    """VTK's GPU isosurface ray caster: frame time, coverage from the image, normals by the lighting trick.

    Examples
    --------
    VTK's volume rendering writes no depth: coverage and normals are measured, positions are not.

    >>> from datasets_synthetic.volumes import torus_distance
    >>> from splinevis.studies.volume_accuracy import exact_reference, measure_vtk
    >>> field = torus_distance()
    >>> ref = exact_reference(field, field.sample(8), window=(32, 24))
    >>> row = measure_vtk(ref, sample_distance=ref.h / 4, repeats=1)
    >>> row["method"], row["config"], row["position_err_median_h"]
    ('VTK volume', 'sample distance h/4', None)
    >>> row["quantisation_floor_median_deg"] < 1.0  # what 8-bit renders allow to measure of the normals
    True
    """
    import pyvista as pv

    from ..plotting import Plotter
    from ..volume.baselines import add_vtk_isosurface

    def scene():
        pl = Plotter(off_screen=True, window_size=ref.window)
        pl.set_background("black")
        add_vtk_isosurface(pl, ref.grid, ref.field.isovalue, sample_distance=sample_distance, color=(1.0, 1.0, 1.0),
                           ambient=0.0, diffuse=1.0, specular=0.0)
        set_camera(pl)
        return pl

    pl = scene()
    timing = timed(pl, repeats)
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


# ------------------------------------------------------------------------------------------ the sweep
def spline_configs(quick, cubic):
    """(method, encoding, roots, iterations, proxy) of the measured spline programs; a method is a scheme or a
    prefiltered spline (:func:`splinevis.volume.approximation.parse_method`). The Newton iteration
    of [Kalbe2008] (``"paper"``) exists for the cubic only: the paper solves quadratics in closed form.

    Examples
    --------
    >>> from splinevis.studies.volume_accuracy import spline_configs
    >>> spline_configs(quick=True, cubic=False)
    [('quadratic', 'data', 'analytic', 1, 'blocks'), ('quadratic', 'coefficients', 'analytic', 1, 'blocks'),
     ('quadratic', 'data', 'analytic', 1, 'cubes'), ('quadratic+local/quadratic', 'data', 'analytic', 1, 'blocks')]
    >>> len(spline_configs(quick=True, cubic=True)), len(spline_configs(quick=False, cubic=True))
    (9, 17)
    """
    q = [("quadratic", "data", "analytic", 1, "blocks"), ("quadratic", "coefficients", "analytic", 1, "blocks"),
         ("quadratic", "data", "analytic", 1, "cubes")]
    c = [("cubic", "data", "analytic", 1, "blocks"), ("cubic", "determining", "analytic", 1, "blocks"),
         ("cubic", "data", "paper", 5, "blocks"),
         ("cubic", "data", "bracketed", 2, "blocks")]
    # the prefiltered splines (data fidelity, splinevis.volume.prefilter): does it change where the spline wins?
    q += [("quadratic+local/quadratic", "data", "analytic", 1, "blocks")]
    c += [("cubic+local/quadratic", "data", "analytic", 1, "blocks")]
    if not quick:
        q += [("quadratic", "data", "bracketed", 2, "blocks"), ("quadratic", "data", "bracketed", 4, "blocks")]
        c += [("cubic+interpolate/cubic", "data", "analytic", 1, "blocks")]
        c += [("cubic", "data", "paper", 2, "blocks"), ("cubic", "data", "paper", 8, "blocks"),
              ("cubic", "data", "bracketed", 4, "blocks"), ("cubic", "coefficients", "analytic", 1, "blocks"),
              ("cubic", "data", "analytic", 1, "cubes")]
    return q + (c if cubic else [])


def accuracy_vs_time(*, quick=False, cubic=True, repeats=None, n=None, progress=True):
    """Rows of every method on the sampled torus (see :mod:`splinevis.studies.volume`); and the set-up."""
    from datasets_synthetic.volumes import torus_distance
    from ..volume.approximation import parse_method
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
    for job in progress_bar(jobs, "accuracy vs time", enabled=progress):
        if job[0] == "mesh":
            rows.append(measure_mesh(ref, method=job[1], upsample=job[2], repeats=repeats))
        elif job[0] == "vtk":
            rows.append(measure_vtk(ref, sample_distance=ref.h / job[1], repeats=repeats))
        else:
            _, scheme, enc, roots, k, proxy = job
            if scheme not in splines:
                spec = parse_method(scheme)
                splines[scheme] = VolumeSpline(grid, spec["scheme"], prefilter=spec["prefilter"], padding=spec["padding"])
            rows.append(measure_spline(ref, splines[scheme], roots=roots, iterations=k, encoding=enc, proxy=proxy,
                                       repeats=repeats))
    setup = {"field": f"torus distance R={field.R}, r={field.r}, isovalue {field.isovalue}", "grid": f"{n}^3",
             "h": ref.h, "window": list(window), "camera": CAMERA, "clipping_range": list(CLIP), "repeats": repeats,
             "pixels_exact": int(ref.covered.sum()), "pixel_footprint_world": ref.pixel_size,
             "pixel_footprint_h": ref.pixel_size / ref.h}
    return rows, setup

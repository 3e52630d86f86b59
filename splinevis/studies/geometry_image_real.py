"""Section (g) of the geometry-image study: smooth geometry images [Losasso2003] of real meshes (scans, a statue,
characters, a CAD part) against the Loop [Loop1987] and Catmull-Clark [CatmullClark1978] subdivisions of the same
meshes at equal triangle counts.

**Data.** The closed genus-0 meshes of :data:`DEV_MESHES`, read from :func:`mesh_data_dir` (the data folder beside
the repository, ``../shared/data/meshes``, or ``$SPLINEVIS_MESH_DATA``). It is not part of the repository: when it
is absent the section says so and is skipped; a missing file is listed and skipped.

**Per mesh** (one row of each table, one figure):

* the build (:func:`splinevis.geometry_image.build.geometry_image_from_mesh`, ``n="auto"`` by default): triangles
  in, the image size chosen and the Hausdorff distance of every size tried, the parametrization's stretch, the
  two-sided Hausdorff and RMS distance of the limit surface (two levels finer than level 0) to the input, the
  folded share of those limit triangles and the seconds of every stage, all from its
  :class:`~splinevis.geometry_image.build.BuildReport`;
* at equal triangle counts: the geometry image at the drawn ``level`` (3, what
  :meth:`~splinevis.plotting.Plotter.add_geometry_image` and ``splinevis check`` draw; float64 twin) against the
  MeshLab Loop and Catmull-Clark subdivisions of the input (:mod:`.geometry_image_compare`) whose triangle
  counts are nearest in ratio (:func:`matched_steps`: Loop multiplies by 4 per step, so its nearest count is
  within a factor 2; Catmull-Clark's first step gives 6 triangles per input triangle, then 4 per step, so it is
  within 2 unless the image has fewer than 3 per input triangle). Each drawn mesh is measured by
  :func:`measure_drawn`: Hausdorff distance (symmetric, its vertices to the input and the input's vertices and
  centroids to it), mean distance (area-weighted, its vertices to the input), the normal error, triangles facing
  against the normals they are lit with (for the image: away from the four cut vertices, whose own triangles
  are counted apart, as the check does) and the seconds it took to make (the image: the twin's subdivision; the
  others: MeshLab).
* A figure ``geometry-image_real_<mesh>.png``: the input, Loop, Catmull-Clark and the geometry image with the
  same reflection lines (:func:`splinevis.gl.mesh_effects.add_mesh_with_effects`, the GLSL the spline programs
  use, on the interpolated vertex normals; the image's are its exact normals) from the same camera.

**The normal-error reference.** A scan has no exact surface. The reference is the input's own smooth-shading
normal field: the area-weighted vertex normals of the input, interpolated barycentrically at the point of the
input closest to the measured vertex. Why this one: it depends on the input only (not on Loop, Catmull-Clark or
the image, none of which converges to it, so none is favoured, where the limit normals of a finely
Loop-subdivided input would make Loop's error vanish by construction); it is what the input looks like drawn
with smooth shading, so the error says how far each smooth surface changes the input's shading. The angles are
averaged over the drawn surface's area (each vertex weighs a third of its triangles' area), so the grid of the
image and the input-shaped triangles of the subdivisions are compared per area, not per vertex.

**What the numbers can say**: at equal triangles, which surface stays closer to the input and shades like it;
where the image folds (a fold shows as a normal error near 180 degrees). **What they cannot say**: which is
closer to the scanned object (the input is a sample with noise and facets); the reference field is only C0 (it
kinks across every input edge), so no smooth surface reaches zero, and on a CAD part with sharp creases
(fandisk) the errors are dominated by how each surface rounds the creases the input's shading smears over one
triangle; where a surface moved away from the input (Loop shrinks convex parts), its normals are compared with
the input's at the closest point, which mixes distance into the angle. The vertex-sampled Hausdorff distance
can miss up to the longest drawn edge (reported as ``edge_max``: the distance function is 1-Lipschitz).

``quick`` runs of the study skip this section (building the smallest mesh alone takes longer than the rest of a
quick run); the full run builds all seven, about 20 to 40 minutes on this machine (2 cores, llvmpipe).

Why our own code: the subdivisions are MeshLab's, the distances libigl's; this module only runs and measures.
"""

from __future__ import annotations

import os
import pickle
import time
import warnings
from pathlib import Path

import numpy as np

from .._reproducible import weighted_quantile
from .report import log, md_table, progress_bar

__all__ = ["DEV_MESHES", "mesh_data_dir", "matched_steps", "measure_drawn", "real_mesh_section",
           "real_mesh_markdown"]

#: The closed genus-0 meshes of the data folder the section builds (the others there are open or of higher genus).
DEV_MESHES = ("armadillo", "beast", "cheburashka", "decimated-max", "elephant", "fandisk", "nefertiti")

#: Per mesh: direction from the centre to the camera and up (the mesh's frame), reflection-line stripes; other
#: meshes get :data:`DEFAULT_VIEW`. Scans show their facets and noise in the lines: fewer stripes.
VIEWS = {"armadillo": ((0.45, 0.15, 1.0), (0, 1, 0), 4), "beast": ((0.35, 0.1, 1.0), (0, 1, 0), 4),
         "cheburashka": ((0.45, 0.1, 1.0), (0, 1, 0), 6), "decimated-max": ((-0.6, 0.1, -1.0), (0, 1, 0), 6),
         "elephant": ((0.6, 0.2, 1.0), (0, 1, 0), 6), "fandisk": ((0.6, -1.0, -0.4), (0, 0, 1), 12),
         "nefertiti": ((0.7, -1.0, 0.2), (0, 0, 1), 4)}
DEFAULT_VIEW = ((1.0, -1.3, 0.8), (0, 0, 1), 8)


def mesh_data_dir() -> Path:
    """The folder of real meshes: ``$SPLINEVIS_MESH_DATA``, else ``shared/data/meshes`` beside the repository.

    >>> mesh_data_dir().name
    'meshes'
    """
    env = os.environ.get("SPLINEVIS_MESH_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[2].parent / "shared" / "data" / "meshes"


def _shown(path: Path) -> str:
    """``path`` relative to the repository when it can be (results are committed: no machine paths)."""
    root = Path(__file__).resolve().parents[2]
    try:
        return os.path.relpath(Path(path).resolve(), root)
    except ValueError:  # another drive
        return Path(path).name


def matched_steps(triangles_in: int, target: int) -> dict:
    """Loop and Catmull-Clark steps whose triangle counts are nearest ``target`` in ratio: Loop gives
    ``T 4^k`` triangles (``k >= 0``, 0 the input itself), Catmull-Clark (triangulated) ``6 T 4^(k-1)`` (``k >= 1``).
    Returns ``{"loop": (k, triangles), "catmull_clark": (k, triangles)}``.

    >>> matched_steps(10540, 2 * 512 ** 2)  # a 129 x 129 image at level 2 against a 10,540-triangle mesh
    {'loop': (3, 674560), 'catmull_clark': (3, 1011840)}
    """
    T, target = int(triangles_in), float(target)

    def best(count, first):
        k = first
        while abs(np.log(count(k + 1) / target)) < abs(np.log(count(k) / target)):
            k += 1
        return k, int(count(k))

    return {"loop": best(lambda k: T * 4 ** k, 0), "catmull_clark": best(lambda k: 6 * T * 4 ** (k - 1), 1)}


def _vertex_areas(P, T):
    area = 0.5 * np.linalg.norm(np.cross(P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]]), axis=1)
    w = np.zeros(len(P))
    for j in range(3):
        np.add.at(w, T[:, j], area / 3.0)
    return w


def _area_vertex_normals(V, F):
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])  # length: twice the area
    N = np.zeros_like(V)
    for j in range(3):
        np.add.at(N, F[:, j], fn)
    return N / np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)


def _reference_normals(V, F, NV, face, X):
    """The input's area-weighted vertex normals ``NV`` interpolated barycentrically at the points ``X`` on the
    triangles ``face`` (module docstring)."""
    A, B, C = V[F[face, 0]], V[F[face, 1]], V[F[face, 2]]
    e0, e1, e2 = B - A, C - A, X - A
    d00, d01, d11 = (np.einsum("ij,ij->i", a, b) for a, b in ((e0, e0), (e0, e1), (e1, e1)))
    d20, d21 = np.einsum("ij,ij->i", e2, e0), np.einsum("ij,ij->i", e2, e1)
    den = d00 * d11 - d01 * d01
    ok = den > 1e-30 * np.maximum(d00 * d11, 1e-300)
    den = np.where(ok, den, 1.0)
    v = np.where(ok, (d11 * d20 - d01 * d21) / den, 1.0 / 3.0)
    w = np.where(ok, (d00 * d21 - d01 * d20) / den, 1.0 / 3.0)
    bary = np.clip(np.column_stack([1.0 - v - w, v, w]), 0.0, 1.0)
    N = np.einsum("ij,ijk->ik", bary, NV[F[face]])
    return N / np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)


def measure_drawn(P, T, N, V, F, *, skip_folded=None) -> dict:
    """A drawn mesh (points ``P``, triangles ``T``, the normals ``N`` it is lit with) against the input ``(V, F)``
    (module docstring): ``hausdorff`` (symmetric) and ``mean`` (area-weighted, drawn to input) in units of the
    input's bounding-box diagonal, ``edge_max`` (longest drawn edge, same unit), ``normal_rms_deg`` /
    ``normal_p99_deg`` (area-weighted) and ``normal_max_deg`` against the input's interpolated vertex normals at
    the closest point, ``folded`` triangles facing against the sum of their corners' normals (those with a
    vertex in ``skip_folded`` counted apart as ``folded_skipped``) and ``triangles``.

    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> s = sphere_mesh(level=2); V = np.asarray(s.points); F = s.faces.reshape(-1, 4)[:, 1:]
    >>> m = measure_drawn(V, F, _area_vertex_normals(V, F), V, F)  # the input against itself: zero up to rounding
    >>> # (arccos near 1 turns a rounding error of 1e-16 into sqrt(2e-16) rad, about 1e-6 degrees)
    >>> m["hausdorff"] < 1e-12, m["mean"] < 1e-12, m["normal_max_deg"] < 1e-5, m["folded"], m["triangles"]
    (True, True, True, 0, 320)
    """
    import igl

    P = np.ascontiguousarray(P, dtype=np.float64)
    T = np.ascontiguousarray(T, dtype=np.int64)
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    sq, face, X = igl.point_mesh_squared_distance(P, V, F)
    to_input = np.sqrt(sq) / diag
    samples = np.vstack([V, V[F].mean(axis=1)])
    from_input = np.sqrt(igl.point_mesh_squared_distance(samples, P, T)[0]) / diag
    w = _vertex_areas(P, T)
    ref = _reference_normals(V, F, _area_vertex_normals(V, F), face, X)
    n = np.asarray(N, dtype=np.float64)
    n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", n, ref), -1.0, 1.0)))
    orient = np.cross(P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]])
    folded = np.einsum("ij,ij->i", orient, n[T].sum(axis=1)) < 0.0
    skipped = np.isin(T, skip_folded).any(axis=1) if skip_folded is not None else np.zeros(len(T), bool)
    edges = np.concatenate([P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 1]], P[T[:, 0]] - P[T[:, 2]]])
    return {"triangles": int(len(T)), "hausdorff": float(max(to_input.max(), from_input.max())),
            "to_input_max": float(to_input.max()), "from_input_max": float(from_input.max()),
            "mean": float(np.average(to_input, weights=w)), "edge_max": float(np.linalg.norm(edges, axis=1).max()) / diag,
            "normal_rms_deg": float(np.sqrt(np.average(angle ** 2, weights=w))),
            "normal_p99_deg": weighted_quantile(angle, w, 0.99), "normal_max_deg": float(angle.max()),
            "folded": int((folded & ~skipped).sum()), "folded_skipped": int((folded & skipped).sum())}


def _camera(name, V):
    """``(position, focal point, up)`` framing the input's points in the 30 degree view: every panel of a mesh
    shares it (square panels)."""
    direction, up, _ = VIEWS.get(name, DEFAULT_VIEW)
    d = np.asarray(direction, dtype=np.float64)
    d /= np.linalg.norm(d)
    right = np.cross(-d, np.asarray(up, dtype=np.float64))
    right /= np.linalg.norm(right)
    true_up = np.cross(right, -d)
    centre = 0.5 * (V.min(axis=0) + V.max(axis=0))
    X = V - centre
    # a point at depth z (towards the camera) and offsets x, y across is inside the frustum when
    # (distance - z) tan 15 >= max(|x|, |y|); a 4 % margin
    half = np.maximum(np.abs(X @ right), np.abs(X @ true_up))
    distance = float((X @ d + 1.04 * half / np.tan(np.radians(15.0))).max())
    return [tuple(centre + distance * d), tuple(centre), tuple(float(u) for u in true_up)]


def _style(name, camera):
    from ..effects import Style

    return Style(lights=1, color=(0.93, 0.93, 0.93), reflection_lines=VIEWS.get(name, DEFAULT_VIEW)[2],
                 reflection_axis=tuple(camera[2]), ambient=0.3, diffuse=0.7)


def _shot(add, camera, size):
    """A screenshot from exactly ``camera`` (no zoom to the actor: the panels of one mesh line up)."""
    import splinevis

    pl = splinevis.Plotter(off_screen=True, window_size=size)
    pl.set_background("white")
    add(pl)
    pl.camera_position = camera
    pl.renderer.ResetCameraClippingRange()
    image = pl.screenshot()
    pl.close()
    return image


def _polydata(P, T, N):
    import pyvista as pv

    mesh = pv.PolyData(np.asarray(P, dtype=np.float64), faces=pv.CellArray.from_regular_cells(np.asarray(T)))
    mesh.point_data["Normals"] = np.asarray(N, dtype=np.float64)
    mesh.point_data.active_normals_name = "Normals"
    return mesh


def _build_here(path, n):
    """The build of :func:`_build`, in this process."""
    from ..geometry_image.build import geometry_image_from_mesh
    from ..geometry_image.repair import prepare_mesh

    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh, repairs = prepare_mesh(path, path.name)
        image, report = geometry_image_from_mesh(mesh, n, name=path.name)
    return mesh, image, report, time.perf_counter() - t0, list(repairs) + [str(w.message) for w in caught]


def _build(path, n, cache_dir):
    """``(repaired mesh, image, report, seconds, warnings)``, built in a new process (spawned, one at a time), so
    that the report's peak memory (``BuildReport.memory_mb``) is this build's and not the study's process's,
    which holds the meshes and pictures of the meshes before; pickled in ``cache_dir`` (keyed by the file's name,
    size and time and ``n``) when one is given."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    key = None
    if cache_dir is not None:
        st = path.stat()
        key = Path(cache_dir) / f"{path.stem}-{st.st_size}-{int(st.st_mtime)}-{n}.pkl"
        if key.exists():
            with open(key, "rb") as f:
                return pickle.load(f)
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        out = pool.submit(_build_here, path, n).result()
    if key is not None:
        key.parent.mkdir(parents=True, exist_ok=True)
        with open(key, "wb") as f:
            pickle.dump(out, f)
    return out


def _defect_shot(image, V, F, camera, size, level: int = 2):
    """The input in grey with the geometry image's folds (centroids of the folded limit triangles, blue) and
    inside-out limit points (red) on it (:func:`splinevis.geometry_image.measure.defect_points`, on the level the
    build measures), as a titled shot for the figure row."""
    import pyvista as pv

    from ..geometry_image.build import limit_mesh_arrays
    from ..geometry_image.measure import defect_points

    P, N, T = limit_mesh_arrays(image, level)
    where = defect_points(P, N, T, V, F)
    del P, N, T

    def add(pl):
        pl.add_mesh(pv.PolyData(V, faces=pv.CellArray.from_regular_cells(F)), color=(0.85, 0.85, 0.85))
        for key, color in (("folded", "blue"), ("inside_out", "red")):
            if len(where[key]):
                pl.add_mesh(pv.PolyData(where[key]), color=color, point_size=3, render_points_as_spheres=False)

    return (f"folds: {len(where['folded']):,} (blue), inside out: {len(where['inside_out']):,} (red), level {level}",
            _shot(add, camera, size))


def _one_mesh(path, out, *, n, level, figure, size, cache_dir):
    from ..geometry_image.image import cut_vertices
    from ..geometry_image.program import surface_arrays
    from ..geometry_image.subdivision import grid_faces
    from ..gl.mesh_effects import add_mesh_with_effects
    from .geometry_image_compare import catmull_clark_meshlab, loop_meshlab, vertex_normals

    name = path.stem
    mesh, image, report, build_s, notes = _build(path, n, cache_dir)
    V = np.asarray(mesh.points, dtype=np.float64)
    F = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
    M2 = 2 * ((report.n - 1) * 4) ** 2  # the limit triangles the build measured (two levels finer than 0)
    s = report.seconds
    build = {"mesh": name, "triangles_in": report.triangles, "vertices_in": report.vertices, "n": report.n,
             "sizes_tried": {str(k): v for k, v in report.distance.get("sizes_tried", {}).items()},
             "stretch_l2": report.stretch.get("l2"), "stretch_max": report.stretch.get("l2_max"),
             "anisotropy_median": report.stretch.get("anisotropy_median"),
             "anisotropy_p95": report.stretch.get("anisotropy_p95"),
             "flipped": report.stretch.get("flipped"), "hausdorff": report.distance.get("hausdorff"),
             "rms": report.distance.get("rms"), "folded_fraction": report.folded,
             "folded_limit": int(round(report.folded * M2)) if np.isfinite(report.folded) else None,
             "limit_triangles": M2, "folds_level4": report.folds.get("fraction"),
             "reversed": report.folds.get("reversed"), "memory_mb": report.memory_mb,
             **{f"{k.replace('/', '_')}_s": v for k, v in s.items()},
             "total_s": build_s, "warnings": notes}
    build["tried"] = ", ".join(f"{k}: {100 * v:.2g} %" for k, v in build["sizes_tried"].items()) or str(report.n)
    camera = _camera(name, V)
    style = _style(name, camera)
    shots = []
    if figure:
        shots.append((f"input, {len(F):,} triangles", _shot(
            lambda pl: add_mesh_with_effects(pl, _polydata(V, F, vertex_normals(V, F)), style), camera, size)))

    t0 = time.perf_counter()
    P, N, _ = surface_arrays(image, level, backend="numpy")
    seconds = time.perf_counter() - t0
    M = P.shape[0]
    T = grid_faces(M)
    cut = cut_vertices(M) @ np.array([M, 1]) if level >= 0 else None
    gi = {"mesh": name, "method": "geometry image", "step": f"n={image.n} level {level:g}", "seconds": seconds,
          **measure_drawn(P.reshape(-1, 3), T, N.reshape(-1, 3), V, F, skip_folded=cut)}
    gi["ratio"] = 1.0
    del P, N, T
    rows = [gi]
    steps = matched_steps(len(F), gi["triangles"])
    for method, fn, key in (("Loop (MeshLab)", loop_meshlab, "loop"),
                            ("Catmull-Clark (MeshLab)", catmull_clark_meshlab, "catmull_clark")):
        k = steps[key][0]
        t0 = time.perf_counter()
        Vs, Fs = fn(V, F, k)
        sub_s = time.perf_counter() - t0
        Ns = vertex_normals(Vs, Fs)
        row = {"mesh": name, "method": method, "step": f"{k} step{'s' * (k != 1)}", "seconds": sub_s,
               **measure_drawn(Vs, Fs, Ns, V, F)}
        row["ratio"] = row["triangles"] / gi["triangles"]
        rows.append(row)
        if figure:
            drawn = _polydata(Vs, Fs, Ns)
            shots.append((f"{method.split(' (')[0]} {k}, {len(Fs):,} triangles",
                           _shot(lambda pl, m=drawn: add_mesh_with_effects(pl, m, style), camera, size)))
            del drawn
        del Vs, Fs, Ns  # the next subdivision may be as large: free this one first
    figure_name = None
    if figure:
        from .geometry_image_figures import reflection_row_figure

        shots.append((f"geometry image {image.n}x{image.n}, level {level:g}, {gi['triangles']:,} triangles",
                      _shot(lambda pl: pl.add_geometry_image(image, style, level=level), camera, size)))
        shots.append(_defect_shot(image, V, F, camera, size))
        figure_name = reflection_row_figure(
            out / f"geometry-image_real_{name}.png", shots,
            f"{name}: reflection lines ({style.reflection_lines} stripes) on the input's vertex normals, its Loop and "
            f"Catmull-Clark subdivisions and the geometry image's exact normals, same camera; last: where the "
            f"image folds and is inside out").name
    return build, rows, figure_name


def real_mesh_section(out_dir, *, data_dir=None, names=DEV_MESHES, n="auto", level: float = 3.0,
                      figures: bool = True, size=(440, 440), progress: bool = True, cache_dir=None) -> dict:
    """Section (g) (module docstring) on the meshes ``names`` (``<name>.obj``, or any extension pyvista reads) of
    ``data_dir`` (default :func:`mesh_data_dir`); figures into ``out_dir``. Returns ``{"data", "available",
    "build": rows, "equal_triangles": rows, "figures", "missing", "level", "note"}``. ``cache_dir``: pickles of
    the built images (development; the study builds every time).

    >>> import tempfile
    >>> real_mesh_section(tempfile.mkdtemp(), data_dir="no such folder", progress=False)["available"]
    False
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    data = Path(data_dir) if data_dir is not None else mesh_data_dir()
    result = {"data": _shown(data), "available": data.is_dir(), "level": float(level), "build": [],
              "equal_triangles": [], "figures": [], "missing": []}
    if not result["available"]:
        result["note"] = (f"the data folder {result['data']} is not there (set SPLINEVIS_MESH_DATA): section "
                          "skipped.")
        return result
    paths = []
    for name in names:
        found = sorted(p for p in data.glob(f"{name}.*") if p.is_file())
        if found:
            paths.append(found[0])
        else:
            result["missing"].append(name)
    for path in progress_bar(paths, "geometry-image: real meshes", enabled=progress):
        log("geometry-image", f"(g) {path.name}")
        build, rows, figure = _one_mesh(path, out, n=n, level=level, figure=figures, size=size, cache_dir=cache_dir)
        result["build"].append(build)
        result["equal_triangles"] += rows
        if figure:
            result["figures"].append(figure)
    result["note"] = f"{len(paths)} mesh{'es' * (len(paths) != 1)} from {result['data']}" + (
        f"; not found: {', '.join(result['missing'])}" if result["missing"] else "")
    return result


def real_mesh_markdown(section) -> str:
    """The section's markdown: the build table, the equal-triangles table, the figures, the reference.

    >>> print(real_mesh_markdown({"available": False, "note": "no data: section skipped."}), end="")
    <BLANKLINE>
    ## (g) Real meshes
    <BLANKLINE>
    Skipped: no data: section skipped.
    """
    md = ["\n## (g) Real meshes\n\n"]
    if section.get("skipped") or not section.get("available"):
        md.append(f"Skipped: {section.get('note', '')}\n")
        return "".join(md)
    lv = section["level"]
    md.append(f"{section['note']}. Distances in units of the input's bounding-box diagonal. Build: "
              "`geometry_image_from_mesh(path)` with its defaults; Hausdorff and RMS of the limit surface two "
              "levels finer than level 0 against the input, both ways (its report); folded: those limit "
              "triangles facing against their corners' normals; folds level 4 and inside out: the shares the check "
              "judges (thresholds 1e-4 and 1e-3); anisotropy: sigma_1 / sigma_2 of the spherical map's triangles "
              "(how much longer one way than the other a square of the sphere comes out on the mesh), area-weighted "
              "median and 95th percentile; peak MB: the peak resident memory of the build, each in a process of its own "
              "(Python and the libraries included).\n\n")
    md.append(md_table(section["build"], [
        ("mesh", "mesh", "s"), ("triangles in", "triangles_in", "int"), ("n", "n", "s"),
        ("Hausdorff per n tried", "tried", "s"), ("stretch L2", "stretch_l2", "f2"),
        ("stretch max", "stretch_max", "f2"), ("anisotropy median", "anisotropy_median", "f2"),
        ("anisotropy p95", "anisotropy_p95", "f2"), ("flipped", "flipped", "s"), ("Hausdorff", "hausdorff", "e"),
        ("RMS", "rms", "e"), ("folded", "folded_limit", "int"), ("of limit triangles", "limit_triangles", "int"),
        ("folds level 4 (check)", "folds_level4", "e"), ("inside out (check)", "reversed", "e"),
        ("parametrize s", "parametrize_s", "f1"), ("sample s", "sample_s", "f1"), ("fit s", "fit_s", "f1"),
        ("measure s", "measure_s", "f1"), ("total s", "total_s", "f1"), ("peak MB", "memory_mb", "int")]))
    md.append(f"\nAt equal triangle counts: the image at level {lv:g} (the float64 twin of what is drawn) against "
              "the MeshLab subdivisions of the input nearest in triangles (ratio to the image's). Hausdorff: "
              "symmetric; mean: area-weighted, drawn to input. Normal error: each drawn vertex's normal (the "
              "image's exact one, the subdivisions' averaged ones) against the input's area-weighted vertex normals "
              "interpolated at the closest input point, area-weighted RMS and 99th percentile, and the largest. "
              "Folded: triangles facing against their corners' normals (the image's at its four cut vertices "
              "not counted). Seconds: making the drawn mesh (the twin's subdivision; MeshLab).\n\n")
    md.append(md_table(section["equal_triangles"], [
        ("mesh", "mesh", "s"), ("method", "method", "s"), ("step", "step", "s"), ("triangles", "triangles", "int"),
        ("ratio", "ratio", "f2"), ("Hausdorff", "hausdorff", "e"), ("mean", "mean", "e"),
        ("normal RMS", "normal_rms_deg", "f2"), ("normal p99", "normal_p99_deg", "f2"),
        ("normal max", "normal_max_deg", "f1"), ("folded", "folded", "int"), ("s", "seconds", "f1")]))
    md.append("\nThe reference has no exact surface behind it: it is the input's own smooth shading, C0 across "
              "every input edge, so no smooth surface reaches zero, and on a CAD part with sharp creases the "
              "errors measure how each surface rounds them. The numbers compare the three surfaces with the "
              "input, not with the scanned object (module docstring of "
              "`splinevis.studies.geometry_image_real`).\n")
    warned = [b for b in section["build"] if b["warnings"]]
    if warned:
        md.append("\nBuild warnings:\n\n" + "".join(f"- {b['mesh']}: " + "; ".join(b["warnings"]) + "\n"
                                                   for b in warned))
    for f in section["figures"]:
        md.append(f"\n![{f}]({f})\n")
    return "".join(md)

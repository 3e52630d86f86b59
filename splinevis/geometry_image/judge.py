"""What ``splinevis check`` does with a closed triangle mesh (family ``"mesh"``): the smooth geometry image
[Losasso2003] drawn beside the mesh itself.

* **read**: OBJ, PLY, STL and VTP with pyvista; OFF with libigl (VTK has no OFF reader). The faces are then put
  in the form a spherical parametrization [PraunHoppe2003] needs, and every change is a WARN finding saying what
  was done: points at exactly the same position are welded into one vertex (VTK's OBJ reader gives every face
  corner its own point when the file has texture coordinates or normals, so the mesh arrives as a soup of
  separate faces), points no face uses are dropped, and polygons are triangulated. Each polygon is split into
  a fan whose diagonals are not edges of the mesh already: a fixed fan can make a closed quad mesh
  non-manifold (two quads sharing two sides, as in ``beast.obj``, each cut along the same diagonal, make one
  triangle twice); among the fans that qualify, the one with the shortest diagonals.
* **build**: the program's ``model_from`` (:func:`.program.model_from`, what
  :meth:`splinevis.plotting.Plotter.add_geometry_image` does), options ``n`` (samples per side, default "auto": :data:`.build.AUTO_SIZES`) and
  ``fairness`` (default "auto": :data:`.build.AUTO_FAIRNESS`). A mesh that is not a closed, connected, oriented genus-0 2-manifold raises
  :class:`splinevis.errors.MeshTopologyError` naming the check that failed; it is not caught (``run.py``
  makes it the FAIL).
* **add**: ``Plotter.add_geometry_image`` with its defaults (option ``level``, default 3).
* **baseline**: the input mesh (after the repairs above), in the same coordinates as the geometry image.
* **accuracy**: the limit surface is subdivided ``measure_level`` times (default: one level finer than drawn,
  so the triangles' chord error is a quarter of the drawn mesh's) and compared with the input mesh by
  :func:`.measure.surface_distance`: the symmetric Hausdorff distance and the RMS, in units of the input's
  bounding-box diagonal. Folds: ``folded_triangles`` counts the limit triangles whose orientation points
  against the exact normals at their corners (:func:`.build.folded_fraction`), the creases where the surface
  folds over. The triangles at the four cut vertices are counted apart (``cut_vertex_folded``): the tangents
  vanish there, and the triangles touching a cut vertex often flip at every level on an image that does not
  fold (one to three on the real meshes tried). Where the surface bends sharply within one triangle (strongly stretched parts of the image), the triangles
  of a coarse level flip although the surface does not fold; a finer level removes them (on ``elephant.obj``
  700 at level 3, 30 at level 4, none at level 5). The count on the measured level judges the surface, and the
  count on the drawn level (``drawn_folded``, the same limit points subsampled) judges what is drawn.
  These creases do not measure how much of the surface is folded, and they miss folds: a 5 x 5 block of the
  17 x 17 image of a star blob turned over (its columns reversed) moves the surface by 8 % of the diagonal and
  flips no triangle at level 4, since inside the block the normals turn with the triangles. ``reversed_fraction``
  measures the folded area instead: the fraction of the limit points (on the level-2 grid, each standing for
  an equal share of the image) whose exact normal is more than 120 degrees from the outward normal of the
  input triangle closest to them. A fold's middle sheet faces backwards (turned-over block: 6 % of the points),
  while the blob's own geometry image has none. Where the input itself folds back (a triangle more than
  120 degrees from a neighbour, as 103 of ``decimated-max.obj``'s are), its closest-triangle normal
  means nothing, and those points are not judged (``input_folded_faces`` counts such triangles).

Thresholds (:data:`THRESHOLDS`) are in pixels of the check's own views. ``run.py`` draws at
``WINDOW = (400, 300)`` with VTK's default camera, which fits the bounding sphere (diameter = the diagonal)
into the 30 degree view: the 300 pixel height spans ``diagonal / cos 15 deg``, so 1 % of the diagonal is
2.9 pixels in the default view and 8.7 in the 3x close-up.

* Hausdorff above 0.5 % of the diagonal: WARN. Somewhere the surface departs from the mesh by 1.5 pixels in
  the default view and 4 in the close-up, so a user comparing the two pictures can see it.
* Hausdorff above 3 %: FAIL. That is 9 pixels in the default view: the outline is a different shape.
* Any folded limit triangle: WARN. A fold is a visible shading defect (a crease that catches the light
  wrongly) wherever the camera comes close. Folded triangles on the drawn level only: WARN too, because
  they are drawn facing against the normals they are lit with.
* Folded limit triangles above 1e-4 of all: FAIL. The threshold is :data:`.build.FOLDED_WARNING`, the one the
  build warns at (the build counts the same way on the same level, :data:`.build.FOLD_LEVEL`). A fold's crease
  flips a handful of triangles at any level (0 to 20 for a 5 x 5 block of a 17 x 17 image turned over, at
  levels 1 to 4), and a ripple crossing one control cell flips about one row of its ``16 x 16`` level-4 quads,
  ~32 triangles. So 1e-4 of the ``2 (16 (n - 1))^2`` level-4 triangles is ``1.6e-3 (n - 1)^2`` cells crossed,
  about a hundred of the 65,536 cells of a 257 x 257 image: a few short ripples in a few places, each a
  shading defect seen close up (WARN), while at 1e-3 (the former threshold) a thousand cells ripple, scattered
  over the whole of a limb. The check reports the build's own count beside its own (every triangle, the cut
  vertices' included, on the build's level 2, where a coarse triangle across a sharp bend flips without a fold:
  an upper bound).
* Normals reversed at more than 1e-3 of the surface: FAIL. That is four control cells of a 65 x 65 image
  (4 / 64^2) turned inside out, a patch several pixels across shaded from behind. Any reversed point: WARN.

Why our own code: the distances are libigl's (through :mod:`.measure`), the checks and fits the geometry image's
own; this module only reads, repairs with a report, and judges.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._boxes import box_distance2
from ..check.judge import FamilyJudge, Finding
from .build import FOLDED_WARNING, REVERSED_WARNING

__all__ = ["JUDGE"]

#: Option defaults: ``n`` and ``fairness`` of the build, ``level`` drawn, ``measure_level`` (None: ``level`` + 1).
DEFAULTS = {"n": "auto", "fairness": "auto", "level": 3.0, "measure_level": None}

#: Verdict thresholds (module docstring): distances in units of the input's bounding-box diagonal.
THRESHOLDS = {"hausdorff_warn": 0.005, "hausdorff_fail": 0.03, "folded_fail": FOLDED_WARNING, "reversed_fail": REVERSED_WARNING}

#: The level whose limit points the reversed normals are counted on (module docstring).
REVERSED_LEVEL = 2

#: The level of the build's own fold count (``levels_finer`` of :func:`.build.geometry_image_from_mesh`),
#: reported beside the check's.
BUILD_FOLD_LEVEL = 2

#: The distance from the input mesh's samples to the limit triangles is searched tile by tile among the triangles
#: that can be nearest (:func:`_nearest_in_tile`): blocks of ``PRUNE_CELLS`` x ``PRUNE_CELLS`` limit cells, within
#: ``PRUNE_REACH`` (share of the diagonal) of a sample. A sample farther than that from every tile is measured
#: against every triangle afterwards (the Hausdorff distance then fails the check anyway).
PRUNE_CELLS = 4
PRUNE_REACH = 0.05



@dataclass(frozen=True, eq=False)
class MeshData:
    """What the reader gives the other stages: the repaired triangle mesh and its name for messages."""

    mesh: object  # pyvista.PolyData of triangles
    name: str


def _fairness(value):
    return value if isinstance(value, str) else float(value)


def _option(options, key):
    value = (options or {}).get(key)
    return DEFAULTS[key] if value is None else value


# ---------------------------------------------------------------------------------------------------- read


def _read(path, options, findings) -> MeshData:
    """Read ``path`` and repair it into one triangle mesh, each repair a WARN finding
    (:func:`.repair.prepare_mesh`)."""
    from .repair import prepare_mesh

    mesh, repairs = prepare_mesh(Path(path), Path(path).name)
    findings.extend(Finding("WARN", r) for r in repairs)
    return MeshData(mesh, Path(path).name)


# ---------------------------------------------------------------------------------------------------- build, draw


def _build(data: MeshData, options, findings):
    from ..programs import get

    n = _option(options, "n")
    n = n if n == "auto" else int(n)
    return get("geometry_image").model_from(data.mesh, n, fairness=_fairness(_option(options, "fairness")),
                                            name=data.name)


def _baseline(data: MeshData, model, options, findings):
    return data.mesh


def _add(plotter, model, options):
    return plotter.add_geometry_image(model, level=float(_option(options, "level")), **options.get("style", {}))


# ---------------------------------------------------------------------------------------------------- accuracy


def _measure_level(options) -> int:
    level = _option(options, "measure_level")
    if level is None:
        level = max(math.floor(float(_option(options, "level"))) + 1, 0)
    level = int(level)
    if not 0 <= level <= 6:
        raise ValueError(f"measure_level must be in 0..6, got {level}.")
    return level


def _input_arrays(mesh):
    V = np.ascontiguousarray(mesh.points, dtype=np.float64)
    F = np.ascontiguousarray(np.asarray(mesh.faces).reshape(-1, 4)[:, 1:], dtype=np.int64)
    return V, F


def surface_measures(model, mesh, measure_level: int, drawn_level: int | None = None, *, cells: int | None = None) -> dict:
    """The accuracy figures of the geometry image ``model`` against the triangle mesh ``mesh`` (module docstring),
    the limit surface subdivided ``measure_level`` times; folds also on the drawn level ``drawn_level`` (at most
    ``measure_level``; None: ``measure_level - 1``), the same limit points subsampled.

    The limit surface is made tile by tile (:func:`.tiles.limit_tiles`, ``cells`` control cells a side, by
    default :data:`.tiles.TILE_CELLS`), so a 257 x 257 image at level 4 (33 million triangles, about 12 GB
    whole) is measured in blocks of a million points: the distances of :func:`.measure.surface_distance` (each
    limit point and triangle centroid to the mesh, maximum and sum of squares over the tiles; each mesh sample to
    the nearest limit triangle in a second pass over the tiles, searched only where it can be,
    :func:`_from_reference`), the fold counts of :func:`.build.fold_counts` and
    :func:`.build.folded_fraction` (:func:`.tiles.fold_counts_tiled`) and the reversed points
    (:func:`.measure.reversed_normals` on the level-:data:`REVERSED_LEVEL` points, the cut vertices left out),
    each the whole level's (the RMS up to the order of its sum).

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import star_blob
    >>> from splinevis.geometry_image.program import model_from
    >>> blob = star_blob(level=2)
    >>> m = surface_measures(model_from(blob, 17), blob, 2)
    >>> m["limit_triangles"], m["folded_triangles"], m["drawn_folded"], bool(m["hausdorff"] < 0.03)
    (8192, 0, 0, True)
    """
    import igl

    from .image import cut_vertices
    from .measure import reversed_normals
    from .subdivision import grid_faces
    from .tiles import TILE_CELLS, count_folds, fold_counts_tiled, limit_tiles

    V, F = _input_arrays(mesh)
    L = int(measure_level)
    cells = TILE_CELLS if cells is None else int(cells)
    control = model.control
    M = (1 << L) * (int(model.n) - 1) + 1
    diagonal = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    if not diagonal > 0:
        raise ValueError("the reference mesh has a zero bounding box: nothing to measure distances in.")
    tree = igl.AABB()
    tree.init(V, F)
    ref_samples = np.vstack([V, V[F].mean(axis=1)])
    corners = []  # every 2^(L - 2)-th limit point: vertices of the triangles, bounds for the other direction
    ustep = 1 << max(L - 2, 0)
    to_max, to_sq, to_count = 0.0, 0.0, 0
    drawn = max(L - 1, 0) if drawn_level is None else min(int(drawn_level), L)
    bl = min(BUILD_FOLD_LEVEL, L)
    steps = {"measured": 1, "drawn": 1 << (L - drawn), "build": 1 << (L - bl)}
    counts = {k: [] for k in steps}
    rstep = 1 << max(L - REVERSED_LEVEL, 0)
    cuts = cut_vertices(M)
    rev = {"reversed_points": 0, "reversed_grid_points": 0, "input_folded_faces": 0}
    for r, c, p, nrm in limit_tiles(control, L, cells):
        k = len(p)
        for key, step in steps.items():
            counts[key].append(count_folds(p, nrm, step))
        own = np.ones((k, k), dtype=bool)  # the last row and column belong to the next tile (if there is one)
        own[-1, :] = r + k == M
        own[:, -1] &= c + k == M
        faces = grid_faces(k)
        Vt = p.reshape(-1, 3)
        d2 = tree.squared_distance(V, F, np.vstack([Vt[own.ravel()], Vt[faces].mean(axis=1)]))[0]
        a = np.sqrt(d2) / diagonal
        to_max, to_sq, to_count = max(to_max, float(a.max())), to_sq + float((a * a).sum()), to_count + a.size
        corners.append(p[::ustep, ::ustep].reshape(-1, 3))
        grid = np.zeros((k, k), dtype=bool)  # the reversed normals: the level-REVERSED_LEVEL points
        grid[::rstep, ::rstep] = True
        grid &= own
        for vr, vc in cuts:
            if r <= vr < r + k and c <= vc < c + k:
                grid[vr - r, vc - c] = False
        idx = np.flatnonzero(grid.ravel())
        if idx.size:
            closest = tree.squared_distance(V, F, np.ascontiguousarray(Vt[idx]))[1]
            part = reversed_normals(nrm.reshape(-1, 3)[idx], closest, V, F)
            for key in ("reversed_points", "reversed_grid_points"):
                rev[key] += part[key]
            rev["input_folded_faces"] = part["input_folded_faces"]
    from_ref = _from_reference(ref_samples, np.vstack(corners), control, L, cells, (PRUNE_REACH * diagonal) ** 2)
    b = np.sqrt(from_ref) / diagonal
    out = {"hausdorff": max(to_max, float(b.max())), "to_reference": to_max, "from_reference": float(b.max()),
           "rms": float(np.sqrt((to_sq + float((b * b).sum())) / (to_count + b.size))), "diagonal": diagonal}
    T = 2 * (M - 1) ** 2
    folded, at_cut = fold_counts_tiled(control, L, cells, step=1, tiles=counts["measured"])
    out.update(measure_level=L, limit_triangles=T, folded_triangles=folded, folded_fraction=folded / T,
               cut_vertex_folded=at_cut)
    out.update(drawn_level=drawn, drawn_folded=fold_counts_tiled(control, L, cells, step=steps["drawn"],
                                                                 tiles=counts["drawn"])[0])
    # the build's own count (BuildReport.folded): every triangle, the cut vertices' included, on its level
    fb, ab = fold_counts_tiled(control, L, cells, step=steps["build"], tiles=counts["build"])
    out.update(build_fold_level=bl, build_folded_fraction=(fb + ab) / (2 * ((M - 1) // steps["build"]) ** 2))
    rev["reversed_fraction"] = rev["reversed_points"] / max(rev["reversed_grid_points"], 1)
    out.update(rev)
    out.update(input_vertices=int(len(V)), input_triangles=int(len(F)), n=int(model.n))
    return out


def _from_reference(samples, corners, control, level, cells, reach2):
    """Squared distances of the input mesh's ``samples`` to the limit triangles of ``control`` at ``level``,
    libigl's (``surface_measures``' other direction, measured in a second pass over the tiles): each sample is
    first bounded by its distance to the nearest of ``corners`` (limit points, so vertices of the triangles: a
    scipy k-d tree), then each tile is searched only where it can be nearer (:func:`_nearest_in_tile`); a sample
    farther than ``sqrt(reach2)`` from every tile is measured against every triangle. The bounds only choose
    where to search, with a margin for the rounding of the distances compared (``64 u`` times the largest
    coordinate): every distance returned is libigl's to a triangle."""
    import igl
    from scipy.spatial import cKDTree

    from .subdivision import grid_faces
    from .tiles import limit_tiles

    slack = 64 * np.finfo(np.float64).eps * max(float(np.abs(samples).max()), float(np.abs(corners).max()))
    bound = cKDTree(corners).query(samples)[0]
    best = np.full(len(samples), np.inf)
    reach = float(np.sqrt(reach2))
    for _, _, p, _ in limit_tiles(control, level, cells):
        _nearest_in_tile(samples, best, bound, p, reach, slack)
    far = np.flatnonzero(best > reach2)
    if far.size:
        for _, _, p, _ in limit_tiles(control, level, cells):
            best[far] = np.minimum(best[far], igl.point_mesh_squared_distance(
                np.ascontiguousarray(samples[far]), p.reshape(-1, 3), grid_faces(len(p)))[0])
    return best


def _nearest_in_tile(samples, best, bound, points, reach, slack):
    """Lower ``best`` (squared distances of ``samples`` to the limit triangles, the least libigl found so far) to
    the least over the triangles of one tile, ``points`` ``(k, k, 3)`` (:func:`.subdivision.grid_faces`'s
    triangles), wherever that is within ``r = min(bound, sqrt(best), reach) + slack`` (``bound``: at least the
    distance to the nearest triangle, :func:`_from_reference`).

    Exact, with a fraction of the tile's triangles: a triangle within ``r`` lies in a block of
    :data:`PRUNE_CELLS` x :data:`PRUNE_CELLS` cells whose bounding box is within ``r``. Only samples whose
    distance to the tile's box is at most ``r`` are searched, each among the blocks whose boxes are within its
    ``r`` (found by a ball query on the blocks' centres, radius ``r`` plus the half diagonal of all but the
    0.1 % largest blocks, which are tested against every sample), with libigl's AABB tree on the union of those
    blocks' triangles. The nearest triangle is within ``r`` of its sample in its tile, so it is searched there.
    Measured on a 513 x 513 image of beast.obj at level 4 (2.1 million triangles a tile): 17 % of the triangles
    searched; the figures of :func:`surface_measures` equal, bit for bit, those of every tile's whole tree.
    """
    import igl
    from scipy.spatial import cKDTree

    from .subdivision import grid_faces

    k = points.shape[0]
    flat = points.reshape(-1, 3)
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    radius = np.minimum(np.minimum(bound, np.sqrt(best)), reach) + slack
    cand = np.flatnonzero(box_distance2(samples, lo, hi) <= radius * radius)
    if not cand.size:
        return
    q = samples[cand]
    r = radius[cand]
    # the cells' boxes, then those of blocks of PRUNE_CELLS x PRUNE_CELLS cells (the last ones may be smaller)
    corners = (points[:-1, :-1], points[:-1, 1:], points[1:, :-1], points[1:, 1:])
    clo, chi = np.minimum.reduce(corners), np.maximum.reduce(corners)
    b = PRUNE_CELLS
    nb = -(-(k - 1) // b)
    extra = ((0, nb * b - (k - 1)), (0, nb * b - (k - 1)), (0, 0))
    blo = np.pad(clo, extra, mode="edge").reshape(nb, b, nb, b, 3).min(axis=(1, 3)).reshape(-1, 3)
    bhi = np.pad(chi, extra, mode="edge").reshape(nb, b, nb, b, 3).max(axis=(1, 3)).reshape(-1, 3)
    centre = 0.5 * (blo + bhi)
    half = np.linalg.norm(0.5 * (bhi - blo), axis=1)
    # a ball query on the centres of all but the largest blocks (radius r plus their largest half diagonal,
    # and the slack), the largest ones (strongly stretched parts of the image) against every sample
    cut = float(np.sort(half)[int(0.999 * (half.size - 1))])
    small = np.flatnonzero(half <= cut)
    large = np.flatnonzero(half > cut)
    hits = cKDTree(centre[small]).query_ball_point(q, r + cut + slack)
    owner = np.repeat(np.arange(len(q)), [len(h) for h in hits])
    block = small[np.concatenate([np.asarray(h, dtype=np.int64) for h in hits])] if owner.size else owner
    owner = np.concatenate([owner, np.repeat(np.arange(len(q)), large.size)])
    block = np.concatenate([block, np.tile(large, len(q))])
    near = box_distance2(q[owner], blo[block], bhi[block]) <= r[owner] * r[owner]
    chosen = np.unique(block[near])
    if not chosen.size:
        return
    # the cells of the chosen blocks, then their two triangles each
    rows = (np.divmod(chosen, nb)[0] * b)[:, None, None] + np.arange(b)[None, :, None]
    cols = (np.divmod(chosen, nb)[1] * b)[:, None, None] + np.arange(b)[None, None, :]
    rows, cols = np.broadcast_arrays(rows, cols)
    inside = (rows < k - 1) & (cols < k - 1)
    cells = np.sort(rows[inside] * (k - 1) + cols[inside])
    faces = grid_faces(k)[np.stack([2 * cells, 2 * cells + 1], axis=1).ravel()]
    d2 = igl.point_mesh_squared_distance(np.ascontiguousarray(q), flat, faces)[0]
    best[cand] = np.minimum(best[cand], d2)


def _pixels(fraction: float) -> str:
    from ..check.run import CLOSE_UP_ZOOM, WINDOW

    default = fraction * WINDOW[1] * math.cos(math.radians(15.0))
    return f"{default:.1f} px in the default view, {default * CLOSE_UP_ZOOM:.1f} px in the close-up"


def _accuracy(path, data: MeshData, model, baseline, options, findings) -> dict:
    m = surface_measures(model, data.mesh, _measure_level(options),
                         min(math.floor(float(_option(options, "level"))), _measure_level(options)))
    t = THRESHOLDS
    h, rms = m["hausdorff"], m["rms"]
    what = (f"the smooth surface (limit at level {m['measure_level']}, {m['n']} x {m['n']} image) is within "
            f"{100 * h:.2f} % of the bounding-box diagonal of the input mesh ({_pixels(h)}; Hausdorff, RMS "
            f"{100 * rms:.3f} %)")
    if h > t["hausdorff_fail"]:
        findings.append(Finding("FAIL", f"{what}: more than {100 * t['hausdorff_fail']:g} %, a different shape"))
    elif h > t["hausdorff_warn"]:
        findings.append(Finding("WARN", f"{what}: more than {100 * t['hausdorff_warn']:g} %, visible in a close-up"))
    else:
        findings.append(Finding("PASS", what))

    folds, frac, rev = m["folded_triangles"], m["folded_fraction"], m["reversed_fraction"]
    fold = (f"{folds:,} of the {m['limit_triangles']:,} limit triangles at level {m['measure_level']} turn against "
            f"the surface normals at their corners ({100 * frac:.3g} %; not counting {m['cut_vertex_folded']} at the "
            f"cut vertices; the build's count, every triangle at level {m['build_fold_level']}: "
            f"{100 * m['build_folded_fraction']:.3g} %), and "
            f"the normals point into the mesh at {m['reversed_points']:,} of {m['reversed_grid_points']:,} limit "
            f"points ({100 * rev:.3g} % of the surface)")
    note = ""
    if m["input_folded_faces"]:
        note = (f" ({m['input_folded_faces']:,} triangles of the input fold back more than 120 degrees against a "
                "neighbour; limit points closest to them are not judged)")
    if frac > t["folded_fail"] or rev > t["reversed_fail"]:
        why = [f"folds along more than {100 * t['folded_fail']:g} % of the limit triangles"] * (frac > t["folded_fail"])
        why += [f"inside out over more than {100 * t['reversed_fail']:g} % of the surface"] * (rev > t["reversed_fail"])
        findings.append(Finding("FAIL", f"{fold}: {' and '.join(why)}, a visible defect{note}"))
    elif folds or m["reversed_points"]:
        findings.append(Finding("WARN", f"{fold}: the surface folds over there, a shading defect seen close up{note}"))
    elif m["drawn_folded"]:
        findings.append(Finding("WARN", f"the drawn mesh (level {m['drawn_level']}) has {m['drawn_folded']:,} "
                                        "triangles turned against the normals they are lit with, where the surface "
                                        "bends more within a triangle than the triangle can follow; "
                                        f"the limit surface has no fold ({fold}){note}"))
    else:
        findings.append(Finding("PASS", f"no folds: {fold}{note}"))
    return m


JUDGE = FamilyJudge(
    family="mesh", baseline_name="input mesh", read=_read, build=_build, baseline=_baseline, accuracy=_accuracy,
    add=_add, description="a closed genus-0 triangle mesh as a smooth geometry image [Losasso2003]",
    extra={"defaults": DEFAULTS, "thresholds": THRESHOLDS})

"""From a closed triangle mesh to a smooth geometry image, stage by stage [Losasso2003, sec. 4]:

1. **check** the mesh is a closed, oriented, connected genus-0 manifold (:func:`.validate.check_genus0`);
2. **parametrize** it on the unit sphere (:func:`.sphere.spherical_parametrization`), bijectively;
3. **sample** it on the octahedral grid, ``oversample`` times finer than the image: each grid point's direction
   (:func:`.image.octahedral_to_sphere`) is located in the spherical triangulation and mapped back to the mesh
   (:func:`.sphere.surface_points`), then moved along the mesh so that the grid is a smooth function of the
   image coordinates (:mod:`.regularize`; the spherical map's kinks at mesh edges made the fit ripple);
4. **fit** the bicubic control image with fairness (:func:`.fit.fit_geometry_image`);
5. **measure** the fitted surface against the mesh, both ways, in units of the mesh's bounding-box diagonal
   (:func:`.measure.surface_distance` on the limit points ``levels_finer`` subdivision levels down).

:func:`geometry_image_from_mesh` returns the :class:`~.model.GeometryImage` and a :class:`BuildReport` with the
time of every stage, the parametrization's stretch and the distances.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from .auto import (AUTO_FAIRNESS, AUTO_FAIRNESS_HAUSDORFF, AUTO_HAUSDORFF, AUTO_SIZES, ESCALATE_INVERSE, ESCALATE_MAX,
                   FOLDED_WARNING, REVERSED_WARNING, _badness, _escalation_words, _guard_words, _next_size, _prefer,
                   auto_oversample)
from .fit import fit_geometry_image
from .hierarchy import LEVEL_INVERSE
from .measure import folded_triangles, reversed_normals, surface_distance
from .model import GeometryImage
from .regularize import SIGMA_CELLS, smooth_samples, smoothing_steps

__all__ = ["BuildReport", "geometry_image_from_mesh", "limit_mesh_arrays", "folded_fraction", "fold_counts",
           "FOLDED_WARNING", "REVERSED_WARNING", "FOLD_LEVEL", "AUTO_SIZES", "AUTO_HAUSDORFF", "auto_oversample"]


@dataclass(frozen=True, eq=False)
class BuildReport:
    """What building a geometry image from a mesh took and how close it came.

    Attributes
    ----------
    name : str
    vertices, triangles : int
        Of the input mesh.
    n : int
        Samples per side of the image.
    fairness : float
    seconds : dict
        Per stage: ``check``, ``parametrize`` (and the parametrization's own stages as ``parametrize/...``),
        ``orient``, ``sample``, ``fit``, ``measure``.
    stretch : dict
        The spherical parametrization's stretch (:class:`.sphere.SphericalMap`), ``"flipped"`` its flipped
        triangles and, when the build parametrized the mesh itself, ``"level_inverse"`` the inverse-stretch weight
        of the map kept (:data:`ESCALATE_INVERSE` if the finer image from a second coarse-to-fine map was kept).
    distance : dict
        :func:`.measure.surface_distance` of the fitted surface to the mesh (``hausdorff``, ``rms``, ...), in
        units of the mesh's bounding-box diagonal; empty when not measured.
    fit_rms : float
        The fit's residual at its samples (diagonal units).
    orientation : (3, 3) ndarray
        The rotation of the sphere the mesh was sampled through.
    folded : float
        The build's own count: fraction of the triangles of the limit mesh it measures the distance on
        (``levels_finer`` levels down) that face against the surface normals at their corners
        (:func:`folded_fraction`, the cut vertices' triangles included); NaN when not measured. A coarse level
        overstates the folds: a triangle across which the surface bends sharply flips without a fold.
    folds : dict
        The check's count (:mod:`.judge`), measured the same way: ``{"level", "triangles", "folded",
        "fraction", "at_cut"}`` of the limit mesh :data:`FOLD_LEVEL` levels down (:func:`fold_counts`:
        neighbouring limit points whose normals and triangle turn apart, the triangles at the four cut vertices
        counted apart in ``at_cut``), and ``"reversed"``, the share of level-``levels_finer`` limit points whose
        normal points into the mesh (:func:`.measure.reversed_normals`); empty when not measured.
        :data:`FOLDED_WARNING` applies to ``fraction``, :data:`REVERSED_WARNING` to ``reversed``; with
        ``fairness="auto"``, ``"fairness_tried"`` and ``"reversed_tried"`` list each weight's figures;
        ``"escalation_tried"`` (``n="auto"``, :data:`ESCALATE_INVERSE`) the folded and inside-out fractions and the
        distance of the first image and of the finer one from the second parametrization.
    memory_mb : float
        The peak resident memory of the process while the build ran, in MB (:class:`splinevis.analysis.memory.
        PeakMemory`, sampled every 5 ms): what the build needs, with what the process held before (the
        difference would read 0 where the build reuses memory freed earlier in the process).
    repairs : tuple of str
        What was done to the input to make it one closed triangle mesh (:func:`.repair.prepare_mesh`: welding,
        triangulating, dropping unused points); each also a warning.

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import ellipsoid_mesh
    >>> gi, report = geometry_image_from_mesh(ellipsoid_mesh(level=2), n=17)
    >>> report.n, sorted(report.seconds)[:3], bool(report.distance["hausdorff"] < 0.03)
    (17, ['check', 'fit', 'measure'], True)
    """

    name: str
    vertices: int
    triangles: int
    n: int
    fairness: float
    seconds: dict = field(default_factory=dict)
    stretch: dict = field(default_factory=dict)
    distance: dict = field(default_factory=dict)
    fit_rms: float = float("nan")
    folded: float = float("nan")
    orientation: np.ndarray = field(default_factory=lambda: np.eye(3))
    repairs: tuple = ()
    folds: dict = field(default_factory=dict)
    memory_mb: float = float("nan")


#: The subdivision level folds are counted on, by the build and the check alike: the check draws level 3 and
#: measures one level finer (:mod:`.judge`).
FOLD_LEVEL = 4


def folded_fraction(points, normals, faces) -> float:
    """Fraction of triangles whose orientation (``(b - a) x (c - a)``) points against the sum of the unit normals
    at their corners: where a fitted surface ripples so much that it folds over (degenerate triangles, e.g. at
    the cut vertices, do not count).

    >>> import numpy as np
    >>> P = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]); up = np.tile([0.0, 0, 1], (3, 1))
    >>> folded_fraction(P, up, np.array([[0, 1, 2]])), folded_fraction(P, -up, np.array([[0, 1, 2]]))
    (0.0, 1.0)
    """
    return float(folded_triangles(points, normals, faces).mean())


def fold_counts(points, normals) -> tuple:
    """``(folded, at_cut)``: how many triangles of the ``M x M`` grid of limit ``points`` with unit ``normals``
    (both ``(M, M, 3)``; triangles as :func:`.subdivision.grid_faces` makes them) face against the sum of the
    normals at their corners, away from the four cut vertices and touching one of them. The same test as
    :func:`folded_fraction`, on the grid's slices instead of an index array (a level-4 grid of a 257 x 257
    image has 33 million triangles); the triangles at the cut vertices, where the tangents vanish, are
    counted apart (:mod:`.judge`).

    >>> import numpy as np
    >>> i, j = np.mgrid[0:9, 0:9].astype(float)
    >>> P = np.stack([j, i, 0.0 * i], axis=2); up = np.broadcast_to([0.0, 0.0, 1.0], P.shape)
    >>> fold_counts(P, up), fold_counts(P, -up)  # a flat 9 x 9 grid: its 128 triangles all fold when lit from below
    ((0, 0), (116, 12))
    """
    from .image import cut_vertices

    P, N = np.asarray(points), np.asarray(normals)
    M = P.shape[0]
    folded = 0
    for rows in range(0, M - 1, 512):  # in bands of rows: the cross products of a band at a time
        r = slice(rows, min(rows + 512, M - 1))
        r1 = slice(rows + 1, min(rows + 513, M))
        a, b, c, d = P[r, :-1], P[r, 1:], P[r1, :-1], P[r1, 1:]
        na, nb, nc, nd = N[r, :-1], N[r, 1:], N[r1, :-1], N[r1, 1:]
        up = np.einsum("ijk,ijk->ij", np.cross(b - a, d - a), na + nb + nd) < 0.0  # (00, 01, 11)
        lo = np.einsum("ijk,ijk->ij", np.cross(d - a, c - a), na + nd + nc) < 0.0  # (00, 11, 10)
        folded += int(up.sum() + lo.sum())
    at_cut = 0
    for vr, vc in cut_vertices(M):  # the up-to-six triangles around each cut vertex
        for cr in (vr - 1, vr):
            for cc in (vc - 1, vc):
                if not (0 <= cr < M - 1 and 0 <= cc < M - 1):
                    continue
                a, b, c, d = P[cr, cc], P[cr, cc + 1], P[cr + 1, cc], P[cr + 1, cc + 1]
                na, nb, nc, nd = N[cr, cc], N[cr, cc + 1], N[cr + 1, cc], N[cr + 1, cc + 1]
                corners_up = {(cr, cc), (cr, cc + 1), (cr + 1, cc + 1)}
                corners_lo = {(cr, cc), (cr + 1, cc + 1), (cr + 1, cc)}
                if (vr, vc) in corners_up and np.cross(b - a, d - a) @ (na + nb + nd) < 0.0:
                    at_cut += 1
                if (vr, vc) in corners_lo and np.cross(d - a, c - a) @ (na + nd + nc) < 0.0:
                    at_cut += 1
    return folded - at_cut, at_cut


def limit_mesh_arrays(image: GeometryImage, level: int):
    """Limit points, unit normals and triangles of ``image`` subdivided ``level`` times, float64 (the twin):
    ``(points (M*M, 3), normals (M*M, 3), faces (T, 3))``, ``M = 2^level (n - 1) + 1``.

    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(5)), constrain=True)
    >>> [a.shape for a in limit_mesh_arrays(gi, 1)]
    [(81, 3), (81, 3), (128, 3)]
    """
    from .subdivision import grid_faces, subdivide

    sub = subdivide(image.control, int(level))
    M = sub.p.shape[0]
    return sub.p.reshape(-1, 3), sub.n.reshape(-1, 3), grid_faces(M)


def _fold_measure(image, n: int) -> dict:
    """The check's fold count (:func:`fold_counts` on level :data:`FOLD_LEVEL`) of ``image``, tile by tile
    (:func:`.tiles.fold_counts_tiled`: the same count; a 257 x 257 image's level 4 held about 12 GB whole)."""
    import os

    from .tiles import fold_counts_tiled

    count, at_cut = fold_counts_tiled(image.control, FOLD_LEVEL, workers=min(os.cpu_count() or 1, 4))
    triangles = 2 * (2 ** FOLD_LEVEL * (int(n) - 1)) ** 2
    return {"level": FOLD_LEVEL, "triangles": triangles, "folded": count, "fraction": count / triangles,
            "at_cut": at_cut}


def _near(image, levels_finer: int, smap) -> tuple:
    """``(distance, reversed, folded)`` of a fitted ``image`` against the mesh of ``smap``, all on the limit mesh
    ``levels_finer`` levels down: the report's distance (:func:`.measure.surface_distance`), the share of limit
    points that are inside out (:func:`.measure.reversed_normals`) and the build's own fold share
    (:func:`folded_fraction`)."""
    P, N, F = limit_mesh_arrays(image, levels_finer)
    distance = surface_distance(P, F, smap.points, smap.faces, closest=True)
    reversed_ = reversed_normals(N, distance.pop("closest_face"), smap.points, smap.faces)
    return distance, reversed_["reversed_fraction"], folded_fraction(P, N, F)


def _measured(image, n: int, levels_finer: int, smap) -> tuple:
    """``(distance, folds, folded)`` of a fitted ``image``: :func:`_near`, the inside-out share put with the check's
    folds (:func:`_fold_measure`)."""
    distance, reversed_, folded = _near(image, levels_finer, smap)
    return distance, dict(_fold_measure(image, n), reversed=reversed_), folded


def geometry_image_from_mesh(mesh, n="auto", *, fairness="auto", oversample="auto",
                             name: str = "mesh", measure: bool = True, levels_finer: int = 2, progress: bool = False,
                             parametrization_options: dict | None = None, orientation="auto", sphere_map=None,
                             smoothing: float = SIGMA_CELLS, turn_guard="auto"):
    """Build an ``n x n`` smooth geometry image of the closed genus-0 ``mesh`` (module docstring).

    Parameters
    ----------
    mesh : pyvista.PolyData or str or path
        Triangles; a file name is read with ``pyvista.read``.
    n : int or "auto"
        Samples per side, odd; ``2^k + 1`` for levels of detail down to the octahedron. ``"auto"`` (default):
        the first of :data:`AUTO_SIZES` whose limit surface is within :data:`AUTO_HAUSDORFF` of the diagonal of
        the mesh (measured; ``distance["sizes_tried"]`` lists each size's distance), with a warning when the
        largest is not; an image that still folds is built again, twice as fine (and again while the last one
        still folds, up to :data:`ESCALATE_MAX`), from a parametrization nearer conformal
        (:data:`ESCALATE_INVERSE`; from the same map where it came from the Tutte start, which the weight does
        not change; not when ``sphere_map`` or ``parametrization_options["level_inverse"]`` is given).
    fairness : float or "auto"
        The fit's fairness weight (:func:`.fit.fit_geometry_image`): 0.1 suppresses the ripples a faceted input
        leaves in the normals (measured in the geometry-image study) at a small cost in distance. ``"auto"``
        (default): 0.1 (sizes are chosen with it), then the next of :data:`AUTO_FAIRNESS` while the image folds
        or is inside out (:func:`_badness` above 1), as long as the surface stays within
        :data:`AUTO_FAIRNESS_HAUSDORFF` of the mesh; the fit least past those thresholds is kept
        (``folds["fairness_tried"]`` lists each weight's fold fraction and distance, ``folds["reversed_tried"]``
        its inside-out fraction).
    oversample : int or "auto"
        Mesh samples per control point and direction; ``"auto"`` (:func:`auto_oversample`) as few as resolve
        both the image and the mesh.
    name : str
        How errors and the report call the mesh.
    measure : bool
        Measure the distance to the mesh (costs about as much as the fit).
    levels_finer : int
        Subdivision levels of the fitted surface used for measuring.
    progress : bool
        Progress bars on the long stages.
    parametrization_options : dict, optional
        Passed to :func:`.sphere.spherical_parametrization`.
    sphere_map : SphericalMap, optional
        This mesh's spherical parametrization, already made (:func:`.sphere.spherical_parametrization`): it is
        used instead of parametrizing again (its stage times are then not in the report).
    smoothing : float
        Width, in control cells, over which the samples are moved along the mesh before the fit so that the
        parametrization the fit sees is smooth (:mod:`.regularize`: on the nefertiti scan 12,747 -> 1,062
        folded limit triangles at level 3); 0 samples the spherical map as it is.
    turn_guard : bool or "auto"
        Whether the smoothing holds back the samples where the surface turns by more than 45 degrees within a
        grid step (:func:`.regularize.smooth_samples`). ``"auto"`` (default): held back; when the image then
        folds or is inside out (:func:`_badness` above 1), the samples are smoothed again without the guard and
        that fit is kept if it is less past the thresholds and no farther from the mesh than
        ``max(AUTO_FAIRNESS_HAUSDORFF, the guarded fit's distance)`` (:func:`_prefer`); fairness is then raised
        from the fit kept (``folds["turn_guard_tried"]`` lists both: fold
        fraction, inside-out fraction, Hausdorff). Measured on the nefertiti scan (n = 257, fairness 0.1): with
        the guard 0.0038 % folds, 0.31 % inside out, Hausdorff 0.26 %; without it 0.0023 %, 0.061 %, 0.42 %: the
        ripples along the headdress's groove, where the samples held back left kinks in the grid, are gone.
    orientation : "auto", None or (3, 3) array
        The rotation of the sphere under the octahedron: ``"auto"`` picks the one that samples the most compressed
        part of the mesh best (:func:`.orient.best_orientation`), None keeps the parametrization's own.

    Returns
    -------
    (GeometryImage, BuildReport)

    Raises
    ------
    splinevis.errors.MeshTopologyError
        The mesh is not a closed genus-0 manifold (which check failed, where).

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import star_blob
    >>> gi, report = geometry_image_from_mesh(star_blob(level=2), n=17, name="blob")
    >>> gi.n, report.triangles, report.stretch["flipped"] if "flipped" in report.stretch else 0
    (17, 320, 0)
    """
    from ..analysis.memory import PeakMemory

    with PeakMemory() as memory:
        image, report = _build(mesh, n, fairness, oversample, name, measure, levels_finer, progress,
                               parametrization_options, orientation, sphere_map, smoothing, turn_guard)
    return image, replace(report, memory_mb=round(memory.peak_mb, 1))


def _build(mesh, n, fairness, oversample, name, measure, levels_finer, progress, parametrization_options,
           orientation, sphere_map, smoothing, turn_guard):
    """:func:`geometry_image_from_mesh` without the memory sampling (its warnings point at the caller's caller)."""
    import pyvista as pv

    from .repair import prepare_mesh
    from .validate import check_genus0

    if not (turn_guard is True or turn_guard is False or (isinstance(turn_guard, str) and turn_guard == "auto")):
        raise ValueError(f"turn_guard must be True, False or 'auto', got {turn_guard!r}.")
    if not isinstance(mesh, pv.DataSet):
        name = str(mesh) if name == "mesh" else name
    mesh, repairs = prepare_mesh(mesh, name)
    if repairs:
        import warnings

        warnings.warn(f"{name}: " + "; ".join(repairs), stacklevel=3)
    seconds = {}
    t0 = time.perf_counter()
    info = check_genus0(mesh, name)
    seconds["check"] = time.perf_counter() - t0

    if sphere_map is None:
        smap = _parametrize(mesh, name, progress, parametrization_options or {}, seconds)
    else:
        smap = sphere_map
        if smap.points.shape != (info["vertices"], 3) or not np.array_equal(smap.points, np.asarray(mesh.points)):
            raise ValueError(f"sphere_map is not a parametrization of {name}: its points differ from the mesh's.")
    R = _orientation(orientation, smap, seconds)

    sizes = AUTO_SIZES if isinstance(n, str) and n == "auto" else (int(n),)
    if isinstance(n, str) and n != "auto":
        raise ValueError(f"n must be 'auto' or an odd sample count, got {n!r}.")
    auto_fairness = isinstance(fairness, str)
    if auto_fairness and fairness != "auto":
        raise ValueError(f"fairness must be 'auto' or a number >= 0, got {fairness!r}.")
    fairness = AUTO_FAIRNESS[0] if auto_fairness else float(fairness)
    measure = measure or len(sizes) > 1 or auto_fairness
    settings = dict(fairness=fairness, auto_fairness=auto_fairness, oversample=oversample, measure=measure,
                    levels_finer=levels_finer, smoothing=smoothing, turn_guard=turn_guard,
                    vertices=info["vertices"], seconds=seconds)
    got = _image_from_map(smap, R, sizes, **settings)
    inverse = (parametrization_options or {}).get("level_inverse")
    if len(sizes) > 1 and sphere_map is None and inverse is None and got.n < ESCALATE_MAX and _badness(got.folds) > 1:
        # the inverse weight acts on the coarse-to-fine start's levels only: a Tutte start would come out the same
        inverse2 = ESCALATE_INVERSE if smap.start == "coarse to fine" else LEVEL_INVERSE
        smap2, R2 = smap, got.orientation
        if inverse2 != LEVEL_INVERSE:
            smap2 = _parametrize(mesh, name, progress, dict(parametrization_options or {}, level_inverse=inverse2),
                                 seconds)
            R2 = _orientation(orientation, smap2, seconds)
        tried_e = {f"n = {got.n}, level_inverse {LEVEL_INVERSE:g}": _escalation_entry(got)}
        sizes_tried = dict(got.distance.get("sizes_tried", {}))
        last = got
        while last.n < ESCALATE_MAX and _badness(last.folds) > 1:  # twice as fine while the last one still folds
            n2 = min(2 * (last.n - 1) + 1, ESCALATE_MAX)
            last = _image_from_map(smap2, R2, (n2,), **settings)
            sizes_tried[n2] = float(last.distance["hausdorff"])
            last.distance["sizes_tried"] = dict(sizes_tried)
            tried_e[f"n = {n2}, level_inverse {inverse2:g}"] = _escalation_entry(last)
            if _prefer(last.folds, last.distance["hausdorff"], got.folds, got.distance["hausdorff"]):
                got, smap, inverse = last, smap2, inverse2
        got.folds["escalation_tried"] = tried_e
    fit, n, fairness, distance, folds, folded = got.fit, got.n, got.fairness, got.distance, got.folds, got.folded
    if measure and _badness(folds) > 1.0:
        import warnings

        warnings.warn(f"the geometry image of {name} folds over in {100 * folds['fraction']:.2g}% of its limit "
                      f"triangles at level {FOLD_LEVEL} ({100 * folded:.2g}% at level {levels_finer}) and is "
                      f"inside out at {100 * folds['reversed']:.2g}% of its limit points: the "
                      f"spherical parametrization (stretch {smap.stretch.get('l2', float('nan')):.3g}, largest "
                      f"{smap.stretch.get('l2_max', float('nan')):.3g}; anisotropy median "
                      f"{smap.stretch.get('anisotropy_median', float('nan')):.3g}, 95th percentile "
                      f"{smap.stretch.get('anisotropy_p95', float('nan')):.3g}) undersamples part of the mesh "
                      "(the folds sit where a square of the sphere comes out longest one way on the mesh); "
                      + _escalation_words(folds.get("escalation_tried", {}))
                      + _guard_words(folds.get("turn_guard_tried", {}))
                      + ("fairness tried (folds, distance): " + ", ".join(
                          f"{f:g}: " + ("folds not counted" if a != a else f"{100 * a:.2g}%") + f", {100 * b:.2g}%"
                          for f, (a, b) in folds["fairness_tried"].items())
                         + f"; kept {fairness:g} (" + (
                             f"a stronger one moves the surface more than {100 * AUTO_FAIRNESS_HAUSDORFF:g}% of "
                             "the diagonal from the mesh)." if list(folds["fairness_tried"].values())[-1][1]
                             > AUTO_FAIRNESS_HAUSDORFF else "the fewest folds of the weights tried).")
                         if auto_fairness else "a larger n or fairness reduces the ripples.")
                      + (" The sphere's rotation under the octahedron decides where the folds fall as well: with "
                         "orientation=None (the map's own) or another rotation matrix their share can change "
                         "several-fold (4.5x and 15x between rotations on two scans, docs/geometry_images.md)."
                         if isinstance(orientation, str) else ""), stacklevel=3)
    if measure and len(sizes) > 1 and distance["hausdorff"] > AUTO_HAUSDORFF:
        import warnings

        warnings.warn(_distance_words(name, n, fairness, distance["hausdorff"], folds.get("fairness_tried", {})),
                      stacklevel=3)
    stretch = dict(smap.stretch)
    stretch["flipped"] = int(smap.flipped)
    if sphere_map is None:
        stretch["level_inverse"] = float(LEVEL_INVERSE if inverse is None else inverse)
    report = BuildReport(name, int(info["vertices"]), int(info["triangles"]), int(n), float(fairness), seconds,
                         stretch, distance, fit.rms, folded, got.orientation, tuple(repairs), folds)
    return fit.image, report


def _distance_words(name, n, fairness, hausdorff, fairness_tried) -> str:
    """The warning of an ``n="auto"`` image farther than :data:`AUTO_HAUSDORFF` from the mesh: what put it there,
    the fairness kept against folds (its first weight's fit was within the goal) or the resolution.

    >>> print(_distance_words("bent", 129, 3.0, 0.00501, {0.1: (4e-6, 0.0011), 3.0: (1e-6, 0.00501)}))
    the geometry image of bent stays 0.5% of the diagonal from the mesh at n = 129 (goal 0.5%): fairness 3, kept against its folds, smooths it that far (at fairness 0.1: 0.11%).
    """
    words = f"the geometry image of {name} stays {100 * hausdorff:.2g}% of the diagonal from the mesh at n = {n} " \
            f"(goal {100 * AUTO_HAUSDORFF:g}%): "
    first = fairness_tried.get(AUTO_FAIRNESS[0])
    if fairness != AUTO_FAIRNESS[0] and first is not None and first[1] <= AUTO_HAUSDORFF:
        return words + (f"fairness {fairness:g}, kept against its folds, smooths it that far (at fairness "
                        f"{AUTO_FAIRNESS[0]:g}: {100 * first[1]:.2g}%).")
    return words + "detail finer than the image resolves (fingers, thin ears) is smoothed away."


def _escalation_entry(built) -> tuple:
    """(folds, inside out, Hausdorff distance) of one image of the escalation (``folds["escalation_tried"]``)."""
    return built.folds["fraction"], built.folds["reversed"], float(built.distance["hausdorff"])


def _parametrize(mesh, name, progress, options, seconds):
    """:func:`.sphere.spherical_parametrization` of ``mesh``, its seconds (and its stages') added to ``seconds``."""
    from .sphere import spherical_parametrization

    t0 = time.perf_counter()
    smap = spherical_parametrization(mesh, name=name, progress=progress, **options)
    seconds["parametrize"] = seconds.get("parametrize", 0.0) + time.perf_counter() - t0
    for stage, s in smap.timings.items():
        seconds[f"parametrize/{stage}"] = seconds.get(f"parametrize/{stage}", 0.0) + float(s)
    return smap


def _orientation(orientation, smap, seconds) -> np.ndarray:
    """The rotation of the sphere under the octahedron (``orientation`` of :func:`geometry_image_from_mesh`) for
    the map ``smap``; its seconds added to ``seconds["orient"]``."""
    t0 = time.perf_counter()
    if isinstance(orientation, str) and orientation == "auto":
        from .orient import best_orientation

        R, _ = best_orientation(smap)
    elif orientation is None:
        R = np.eye(3)
    else:
        R = np.asarray(orientation, dtype=np.float64)
        if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
            raise ValueError(f"orientation must be 'auto', None or a 3x3 rotation matrix, got {orientation!r}.")
    seconds["orient"] = seconds.get("orient", 0.0) + time.perf_counter() - t0
    return R


@dataclass
class _Built:
    """One image made from one spherical map (:func:`_image_from_map`): the fit kept, its size and fairness, the
    report's distance, the check's folds and the build's own fold share, and the sphere's rotation."""
    fit: object
    n: int
    fairness: float
    distance: dict
    folds: dict
    folded: float
    orientation: np.ndarray


def _image_from_map(smap, R, sizes, *, fairness, auto_fairness, oversample, measure, levels_finer, smoothing,
                    turn_guard, vertices, seconds) -> _Built:
    """Stages 3-5 of the module docstring on the spherical map ``smap`` rotated by ``R``: the first of ``sizes``
    close enough to the mesh (:func:`_next_size`), then, with ``turn_guard="auto"`` and ``auto_fairness``, the
    fits of :func:`geometry_image_from_mesh`'s ``turn_guard`` and ``fairness`` (the one least past the thresholds
    kept). Stage seconds are added to ``seconds``."""
    from .._reproducible import mat
    from .image import image_uv, octahedral_to_sphere
    from .sphere import locate

    tried = {}
    index = 0
    while index < len(sizes):
        n = sizes[index]
        t0 = time.perf_counter()
        k = auto_oversample(n, vertices) if isinstance(oversample, str) and oversample == "auto" else oversample
        M = int(k) * (int(n) - 1) + 1
        # the image's direction d samples the parametrization at R^T d: the sphere rotated by R under the octahedron
        face, bary = locate(smap, mat(octahedral_to_sphere(image_uv(M)).reshape(-1, 3), R))
        raw = np.einsum("ni,nij->nj", bary, smap.points[smap.faces[face]]).reshape(M, M, 3)
        samples = raw
        seconds["sample"] = seconds.get("sample", 0.0) + time.perf_counter() - t0
        if smoothing > 0:
            t0 = time.perf_counter()
            samples, _ = smooth_samples(smap.points, smap.faces, raw, face, smoothing_steps(k, smoothing),
                                        turn_guard=turn_guard is not False)
            seconds["smooth"] = seconds.get("smooth", 0.0) + time.perf_counter() - t0

        t0 = time.perf_counter()
        fit = fit_geometry_image(None, n, fairness=fairness, oversample=k, samples=samples)
        seconds["fit"] = seconds.get("fit", 0.0) + time.perf_counter() - t0

        distance, folded = {}, float("nan")
        if measure:
            t0 = time.perf_counter()
            distance, reversed_, folded = _near(fit.image, levels_finer, smap)
            seconds["measure"] = seconds.get("measure", 0.0) + time.perf_counter() - t0
            tried[int(n)] = float(distance["hausdorff"])
            if distance["hausdorff"] <= AUTO_HAUSDORFF:
                break
        index = _next_size(index, sizes, tried)
    if len(sizes) > 1:
        distance["sizes_tried"] = tried
    folds = {}
    if measure:
        t0 = time.perf_counter()
        folds = dict(_fold_measure(fit.image, n), reversed=reversed_)
        seconds["measure"] = seconds.get("measure", 0.0) + time.perf_counter() - t0
        if isinstance(turn_guard, str) and smoothing > 0:
            tried_g = {"turn guard": (folds["fraction"], folds["reversed"], float(distance["hausdorff"]))}
            if _badness(folds) > 1.0:
                t0 = time.perf_counter()
                loose, _ = smooth_samples(smap.points, smap.faces, raw, face, smoothing_steps(k, smoothing),
                                          turn_guard=False)
                seconds["smooth"] += time.perf_counter() - t0
                t0 = time.perf_counter()
                fit2 = fit_geometry_image(None, n, fairness=fairness, oversample=k, samples=loose)
                seconds["fit"] += time.perf_counter() - t0
                t0 = time.perf_counter()
                distance2, folds2, folded2 = _measured(fit2.image, n, levels_finer, smap)
                seconds["measure"] += time.perf_counter() - t0
                tried_g["no turn guard"] = (folds2["fraction"], folds2["reversed"], float(distance2["hausdorff"]))
                if _prefer(folds2, distance2["hausdorff"], folds, distance["hausdorff"]):
                    fit, folds, folded, samples = fit2, folds2, folded2, loose
                    distance = dict(distance2, **({"sizes_tried": tried} if len(sizes) > 1 else {}))
        if auto_fairness:
            tried_f = {fairness: (folds["fraction"], float(distance["hausdorff"]))}
            reversed_tried = {fairness: folds["reversed"]}
            for stronger in AUTO_FAIRNESS[1:]:
                if _badness(folds) <= 1.0:
                    break
                t0 = time.perf_counter()
                fit2 = fit_geometry_image(None, n, fairness=stronger, oversample=k, samples=samples)
                seconds["fit"] += time.perf_counter() - t0
                t0 = time.perf_counter()
                P, N, F = limit_mesh_arrays(fit2.image, levels_finer)
                distance2 = surface_distance(P, F, smap.points, smap.faces, closest=True)
                closest = distance2.pop("closest_face")
                if distance2["hausdorff"] > AUTO_FAIRNESS_HAUSDORFF:  # smoothed too far from the mesh: keep the
                    seconds["measure"] += time.perf_counter() - t0  # last fit that was close enough (its folds
                    tried_f[stronger] = (float("nan"), float(distance2["hausdorff"]))  # are not counted: no use)
                    break
                folds2 = dict(_fold_measure(fit2.image, n),
                              reversed=reversed_normals(N, closest, smap.points, smap.faces)["reversed_fraction"])
                seconds["measure"] += time.perf_counter() - t0
                tried_f[stronger] = (folds2["fraction"], float(distance2["hausdorff"]))
                reversed_tried[stronger] = folds2["reversed"]
                if _badness(folds2) < _badness(folds):
                    fit, folds, fairness = fit2, folds2, stronger
                    distance = dict(distance2, **({"sizes_tried": tried} if len(sizes) > 1 else {}))
                    folded = folded_fraction(P, N, F)
            folds["fairness_tried"] = tried_f
            folds["reversed_tried"] = reversed_tried
        if isinstance(turn_guard, str) and smoothing > 0:
            folds["turn_guard_tried"] = tried_g
    return _Built(fit, int(n), float(fairness), distance, folds, folded, R)

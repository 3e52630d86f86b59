"""What the ``"auto"`` settings of :func:`.build.geometry_image_from_mesh` decide, and the thresholds they aim at:
the image sizes tried (``n="auto"``) and when a size is skipped, the fairness weights (``fairness="auto"``), which
of two fits is kept (``turn_guard="auto"``, the finer image from the second parametrization), the samples per
control interval (``oversample="auto"``) and the warnings' account of what was tried. Every constant has what it
was measured to do on the real meshes beside it.

:mod:`.build` imports these names and reads its own bindings of them: a test that changes a setting for the build
sets it on :mod:`.build` (what :func:`_prefer` and :func:`_next_size` read stays here).
"""

from __future__ import annotations

import numpy as np

__all__ = ["FOLDED_WARNING", "REVERSED_WARNING", "AUTO_SIZES", "AUTO_HAUSDORFF", "AUTO_FAIRNESS",
           "AUTO_FAIRNESS_HAUSDORFF", "ESCALATE_INVERSE", "ESCALATE_MAX", "auto_oversample"]

#: Above this fraction of folded limit triangles on level :data:`.build.FOLD_LEVEL` (the check's count, away from the
#: cut vertices), :func:`.build.geometry_image_from_mesh` warns and the check fails (:mod:`.judge` says why 1e-4).
FOLDED_WARNING = 1e-4

#: Above this fraction of limit points (level ``levels_finer``) whose normal points into the mesh (more than 120
#: degrees from the nearest input triangle's, :func:`.measure.reversed_normals`), the image is inside out over a
#: patch several pixels wide: ``fairness="auto"`` smooths further, the build warns and the check fails.
REVERSED_WARNING = 1e-3

#: Image sizes ``n="auto"`` tries, smallest first, and the Hausdorff distance (share of the diagonal) that
#: ends the search: the first size whose limit surface is that close to the mesh. Sizes the rate of decrease
#: measured so far predicts to stay above it are skipped (:func:`_next_size`).
AUTO_SIZES = (33, 65, 129, 257)
AUTO_HAUSDORFF = 0.005

#: Fairness weights ``fairness="auto"`` tries in turn while the image folds (more than :data:`FOLDED_WARNING` of
#: its level-:data:`.build.FOLD_LEVEL` triangles) or is inside out (more than :data:`REVERSED_WARNING`), each ``sqrt(10)`` times the last, and the distance (share of the
#: diagonal) a stronger weight may not exceed. Why: the fairness term smooths at the scale ``lambda^(1/4) h / 2``
#: (:mod:`.fit`), so each step widens the smoothing by ``10^(1/8)``, 33 %, and the ripples where the map
#: compresses the mesh (the folds) fade; the surface moves from the mesh as it smooths. Measured on the
#: armadillo at n = 257 with the machine-independent parametrization (folds at level 4 / Hausdorff / inside
#: out): 0.28 % / 0.50 % / 2.7 % at 0.1, 0.31 % / 0.58 % / 2.2 % at 0.3, 0.27 % / 0.67 % / 1.6 % at 1,
#: 0.19 % / 0.89 % / 1.0 % at 3: fairness no longer mends it (one machine's parametrization, before the build
#: was made machine-independent, had given 0.0084 % at 1). What was tried beyond (not kept): fairness raised
#: tenfold per round only on the folded cells and two cells around them (0.62 % -> 0.032 % folds in three
#: rounds, but Hausdorff 0.48 % -> 1.19 % and inside out 2.1 % -> 3.0 %: the claws shrink and turn over);
#: n = 513 (Hausdorff 0.35 %, folds still 0.42 %, 13.9 GB); 800 relaxation steps instead of 200 (stretch
#: 1.67 -> 1.53, folds at fairness 1 0.27 % -> 0.12 %, 4x the time). The folded and inside-out points sit in
#: long strips where the map compresses the limbs across and stretches them along (an image of each control
#: cell's area, 1,583 folded cells, lies along them), and they are inside out against the mesh point they
#: stand for, not only against the closest triangle: a parametrization problem. Also tried on the armadillo
#: (fairness 0.1, before -> after): relaxing the stretch of the map from the image rather than the sphere (each
#: triangle's energy weighted by the octahedral map's sphere area per image area at its centroid, 1 to 5.2; 200
#: more steps) 0.28 % -> 0.24 % folds, 2.7 % -> 2.4 % inside out, Hausdorff 0.50 % -> 0.57 %; reweighting the
#: stretch towards its largest values (weights (stretch / mean)^2, four rounds of 50 steps) 0.25 % folds, no
#: change in the stretch. Neither kept.
AUTO_FAIRNESS = (0.1, 0.3, 1.0, 3.0)
AUTO_FAIRNESS_HAUSDORFF = 0.01

#: What ``n="auto"`` does when the image it chose still folds or is inside out (:func:`_badness` above 1) after the
#: turn guard and fairness were tried: it parametrizes the mesh again with the inverse map's stretch in the coarse
#: levels' relaxations (``level_inverse`` = :data:`ESCALATE_INVERSE`, :data:`.hierarchy.LEVEL_INVERSE`'s comment says
#: why that keeps the coarse levels nearer conformal) and builds an image twice as fine, and again while the last one
#: built still folds (at most :data:`ESCALATE_MAX` samples per side; a map from the Tutte start, which the weight does
#: not change, is reused for it); an image less past the thresholds than the one kept so far replaces it, if it is no
#: farther from the mesh than ``max(AUTO_FAIRNESS_HAUSDORFF, that one's distance)`` (:func:`_prefer`; ``folds[
#: "escalation_tried"]`` has every image tried). The bent blob (5,120 triangles) went 65 -> 129 (0.0103 % folds) ->
#: 257 (0.0071 %, 0.15 % of the diagonal): one doubling had kept the 129 image, just past the threshold. Why both at
#: once: at n = 257 the thin limbs of the four-legged scan cannot be sampled evenly and densely at once. Measured
#: (folds at level 4 / inside out / Hausdorff, what the build kept): beast.obj 0.34 % / 2.5 % / 0.72 % at 257;
#: level_inverse 1 alone 0.038 % / 0.71 % / 0.91 %; n = 513 alone 0.16 % / 0.48 % / 0.89 %; both (this build, measured
#: by ``splinevis check``) 0.0146 % / 0.155 % / 0.46 %. armadillo.obj 0.118 % / 0.34 % / 0.93 % at 257; level_inverse
#: 1 alone 0.118 % / 0.47 % / 0.91 %; both 0.0343 % / 0.063 % / 0.46 %. It costs a second parametrization and an image
#: four times as large: the builds took 406 s (armadillo, alone) and 495 s (beast, beside another) instead of about
#: 100 s. A mesh whose image does not fold never pays it. What was tried beyond it (docs/geometry_images.md has the
#: figures): per-vertex sweeps on the escalation's map (nearer conformal, more folds), fairness raised on the folded
#: cells only (fewer folds, more inside out). What stops the beast's 513 image is its inside-out share: fairness 3
#: takes its folds under the threshold (0.0059 %) but not that (0.17 %), flaps in the concave creases.
ESCALATE_INVERSE = 1.0
ESCALATE_MAX = 513


def auto_oversample(n: int, vertices: int) -> int:
    """Samples per control interval for an ``n x n`` image of a mesh of ``vertices`` vertices: at least 2 (two
    samples per control interval, what the least-squares fit needs to see each cubic span's shape), and enough
    that the ``M x M`` sample grid (``M = k (n - 1) + 1``) holds about 4 samples per mesh vertex (``M >= 2
    sqrt(V)``), at most 4. Measured on the beast scan (32k vertices) at ``n = 257``: 2 instead of 4 samples
    263k directions instead of 1.05M (9 s instead of 43 s) and gives the same Hausdorff distance (0.898 %) and
    folds within 5 % (0.079 % against 0.076 %).

    >>> auto_oversample(257, 32311), auto_oversample(129, 32311), auto_oversample(33, 5000)
    (2, 3, 4)
    """
    need = int(np.ceil(2.0 * np.sqrt(max(int(vertices), 1)) / max(int(n) - 1, 1)))
    return int(min(max(need, 2), 4))


def _next_size(index: int, sizes, tried: dict) -> int:
    """The index in ``sizes`` to try after ``sizes[index]``: the next one, or, once two sizes are measured, the
    first the distances' rate of decrease so far predicts within :data:`AUTO_HAUSDORFF` (the last at most): a size
    predicted to stay above the goal is not built (its sampling, fit and measurement would be spent to no use).

    >>> _next_size(1, (33, 65, 129, 257), {33: 0.034, 65: 0.023})   # 0.68 a doubling: 257 still above, skip 129
    3
    >>> _next_size(1, (33, 65, 129, 257), {33: 0.012, 65: 0.006})   # halved: 129 predicted at 0.3 %
    2
    >>> _next_size(3, (33, 65, 129, 257), {33: 0.034, 65: 0.023, 257: 0.0067})  # the last size measured: done
    4
    """
    if index < 1 or len(tried) < 2 or index + 1 >= len(sizes):
        return index + 1
    before, last = list(tried)[-2:]  # the last two measured: a rate per step of the list
    h0, h1 = tried[before], tried[last]
    rate = (h1 / h0) ** (1.0 / max(sizes.index(last) - sizes.index(before), 1)) if h0 > 0 else 1.0
    if not 0.0 < rate < 1.0:
        return index + 1
    steps = int(np.ceil(np.log(AUTO_HAUSDORFF / h1) / np.log(rate)))
    return min(index + max(steps, 1), len(sizes) - 1)


def _badness(folds: dict) -> float:
    """How far the image is past the fold and inside-out thresholds: the larger of the folded fraction over
    :data:`FOLDED_WARNING` and the reversed fraction over :data:`REVERSED_WARNING` (at most 1: neither exceeded).

    >>> _badness({"fraction": 5e-5, "reversed": 2e-3})
    2.0
    """
    return max(folds["fraction"] / FOLDED_WARNING, folds.get("reversed", 0.0) / REVERSED_WARNING)


def _prefer(folds_new: dict, hausdorff_new: float, folds: dict, hausdorff: float) -> bool:
    """Whether the fit without the smoothing's turn guard replaces the guarded one (``turn_guard="auto"``): it
    is less past the fold and inside-out thresholds (:func:`_badness`) and within the distance budget a stronger
    fairness has, :data:`AUTO_FAIRNESS_HAUSDORFF` (or the guarded fit's distance, if that is larger): the guard
    keeps protrusions sampled, and losing them shows as distance.

    >>> _prefer({"fraction": 2e-5, "reversed": 6e-4}, 0.0042, {"fraction": 4e-5, "reversed": 3e-3}, 0.0026)
    True
    >>> _prefer({"fraction": 2e-5, "reversed": 6e-4}, 0.012, {"fraction": 4e-5, "reversed": 3e-3}, 0.0026)
    False
    """
    return _badness(folds_new) < _badness(folds) and hausdorff_new <= max(AUTO_FAIRNESS_HAUSDORFF, hausdorff)


def _guard_words(tried: dict) -> str:
    """The build warning's account of ``folds["turn_guard_tried"]``: empty unless the unguarded smoothing was
    measured.

    >>> _guard_words({"turn guard": (2.8e-3, 2.7e-2, 5.0e-3), "no turn guard": (1.2e-3, 3.4e-3, 9.3e-3)})
    'smoothed without the turn guard (folds, inside out, distance: 0.28%, 2.7%, 0.5% with it; 0.12%, 0.34%, 0.93% without); '
    """
    if "no turn guard" not in tried:
        return ""
    words = "; ".join(", ".join(f"{100 * x:.2g}%" for x in tried[k]) + f" {w}"
                      for k, w in (("turn guard", "with it"), ("no turn guard", "without")))
    return f"smoothed without the turn guard (folds, inside out, distance: {words}); "


def _escalation_words(tried: dict) -> str:
    """The build warning's account of ``folds["escalation_tried"]`` (:data:`ESCALATE_INVERSE`): empty unless the
    finer image from the second parametrization was built.

    >>> _escalation_words({"n = 257, level_inverse 0": (1.2e-3, 3.4e-3, 9.3e-3),
    ...                    "n = 513, level_inverse 1": (3.9e-4, 1.1e-3, 4.9e-3)})
    'rebuilt from a parametrization nearer conformal (folds, inside out, distance: n = 257, level_inverse 0: 0.12%, 0.34%, 0.93%; n = 513, level_inverse 1: 0.039%, 0.11%, 0.49%); '
    """
    if not tried:
        return ""
    words = "; ".join(f"{k}: " + ", ".join(f"{100 * x:.2g}%" for x in v) for k, v in tried.items())
    return f"rebuilt from a parametrization nearer conformal (folds, inside out, distance: {words}); "

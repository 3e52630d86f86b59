"""What a family gives ``splinevis check``, and the picture measures every family shares.

A family judge (:class:`FamilyJudge`, one per family, in the family's own folder as ``judge.py``) knows how to
read a file, build its spline model, build the mesh users would draw today from the same data (the
*baseline*), and measure the family's accuracy figure. Everything else, cameras, timing, memory, warnings,
pictures and the verdict, is common (:mod:`splinevis.check.run`).

Picture measures (:func:`silhouette_measures`), from two renders of the same camera:

* silhouette IoU: |S ∩ B| / |S ∪ B| of the pixels the spline (S) and the baseline (B) cover;
* background inside the silhouette (leaks): pixels of B's silhouette, eroded by ``margin`` pixels so that the
  chord error of the baseline's outline does not count, where the spline shows background. The baseline is a
  sampled copy of the same data, but not the same surface (a smoothing spline thins a one-voxel vessel that
  marching cubes keeps): a few of these are differences of shape, many are holes;
* pinholes: leaks in background components of at most ``pinhole_pixels`` pixels (8-connected) of the spline's
  render, each wholly inside B's interior: cracks and missed roots, never a difference of shape at this size.

Verdict thresholds (:data:`THRESHOLDS`) are about what a user sees, not tuned to the files: a silhouette that
differs from the baseline's by more than 10 % of their union is a different picture (FAIL), more than 3 % is worth
a look (WARN); one leaking pixel in a thousand of the interior is a visible hole pattern (FAIL), any is a WARN.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

__all__ = ["FamilyJudge", "Finding", "silhouette_measures", "THRESHOLDS", "worst_level"]

LEVELS = ("PASS", "WARN", "FAIL")

THRESHOLDS = {
    "iou_fail": 0.90,  # silhouette IoU below: a different picture
    "iou_warn": 0.97,
    "leak_warn": 1e-3,  # leaking fraction of the baseline's interior above: worth a look
    "leak_fail": 1e-2,  # above: holes a user sees
    "pinhole_fail": 1e-4,  # pinhole fraction of the interior above, and at least pinhole_count: a pattern of cracks
    "pinhole_count": 10,  # (one tiny hole can be a true gap of the smooth surface between two thin features)
    "pinhole_pixels": 4,
    "margin": 2,  # pixels eroded off the baseline silhouette before counting leaks
}


@dataclass
class Finding:
    """One judged fact about a file: ``level`` in PASS/WARN/FAIL and the reason in words.

    >>> Finding("WARN", "3 faces skipped")
    Finding(level='WARN', reason='3 faces skipped')
    """

    level: str
    reason: str

    def __post_init__(self):
        if self.level not in LEVELS:
            raise ValueError(f"finding level {self.level!r}: choose one of {LEVELS}.")

    def as_dict(self) -> dict:
        """As ``report.json`` holds it.

        >>> Finding("PASS", "ok").as_dict()
        {'level': 'PASS', 'reason': 'ok'}
        """
        return {"level": self.level, "reason": self.reason}


def worst_level(findings) -> str:
    """The verdict of a list of findings: its worst level (PASS when empty).

    >>> worst_level([Finding("PASS", "a"), Finding("WARN", "b")])
    'WARN'
    """
    return max((f.level for f in findings), key=LEVELS.index, default="PASS")


@dataclass
class FamilyJudge:
    """What one family provides to ``splinevis check`` (module docstring).

    Attributes
    ----------
    family : str
        ``"terrain"``, ``"volume"``, ``"nurbs"`` or ``"mesh"``.
    baseline_name : str
        What users draw today from the same data, in words (e.g. ``"warp_by_scalar mesh"``).
    read : callable
        ``read(path, options, findings) -> data``: the family's reader; appends a Finding for every choice it
        had to make for the user (a filled nodata hole, a chosen array) and raises on files it cannot read.
    build : callable
        ``build(data, options, findings) -> model``: the spline model ``Plotter.add_spline`` draws.
    baseline : callable
        ``baseline(data, model, options, findings) -> pyvista.DataSet`` in the same world frame as the model.
    accuracy : callable
        ``accuracy(path, data, model, baseline, options, findings) -> dict``: the family's accuracy figures
        (numbers); appends a Finding saying whether they are good enough.
    add : callable
        ``add(plotter, model, options) -> actor``: draw the model with the default effects.

    Examples
    --------
    >>> from splinevis.terrain.judge import JUDGE
    >>> JUDGE.family, JUDGE.baseline_name
    ('terrain', 'warp_by_scalar mesh')
    """

    family: str
    baseline_name: str
    read: Callable
    build: Callable
    baseline: Callable
    accuracy: Callable
    add: Callable
    description: str = ""
    extra: dict = field(default_factory=dict)


def silhouette_measures(spline_mask, baseline_mask, *, margin: int | None = None) -> dict:
    """IoU of two silhouettes and the spline's background pixels inside the baseline's (module docstring).

    Parameters
    ----------
    spline_mask, baseline_mask : (H, W) bool
        Pixels each render covers (window depth < 1).
    margin : int, optional
        Pixels eroded off the baseline silhouette before leaks are counted (default ``THRESHOLDS["margin"]``).

    Returns
    -------
    dict
        ``iou``, ``spline_pixels``, ``baseline_pixels``, ``interior`` (baseline pixels after erosion), ``leaks``
        (of those, background in the spline render) and ``leak_fraction``.

    Examples
    --------
    >>> b = np.zeros((20, 20), bool); b[4:16, 4:16] = True
    >>> s = b.copy(); s[10, 10] = False  # one pinhole
    >>> m = silhouette_measures(s, b)
    >>> m["leaks"], m["pinholes"], m["interior"], round(m["iou"], 4)
    (1, 1, 64, 0.9931)
    """
    from scipy import ndimage

    s = np.asarray(spline_mask, bool)
    b = np.asarray(baseline_mask, bool)
    if s.shape != b.shape:
        raise ValueError(f"silhouettes of different sizes: {s.shape} and {b.shape}.")
    margin = THRESHOLDS["margin"] if margin is None else int(margin)
    union = int((s | b).sum())
    interior = ndimage.binary_erosion(b, structure=np.ones((3, 3)), iterations=margin, border_value=0) if margin else b
    leak = interior & ~s
    leaks = int(leak.sum())
    n_inside = int(interior.sum())
    labels, count = ndimage.label(~s, structure=np.ones((3, 3)))
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    outside = np.bincount(labels.ravel(), weights=(~interior).ravel(), minlength=count + 1)
    small = (sizes <= THRESHOLDS["pinhole_pixels"]) & (outside == 0)
    small[0] = False
    pinholes = int(small[labels].sum())
    return {"iou": float((s & b).sum() / union) if union else 1.0, "spline_pixels": int(s.sum()),
            "baseline_pixels": int(b.sum()), "interior": n_inside, "leaks": leaks,
            "leak_fraction": leaks / n_inside if n_inside else 0.0, "pinholes": pinholes,
            "pinhole_fraction": pinholes / n_inside if n_inside else 0.0}


def picture_findings(view: str, m: dict) -> list:
    """Findings of one view's :func:`silhouette_measures` against :data:`THRESHOLDS`.

    >>> [f.level for f in picture_findings("default", {"iou": 0.95, "leaks": 0, "leak_fraction": 0.0, "pinholes": 0,
    ...                                                 "pinhole_fraction": 0.0, "spline_pixels": 10, "baseline_pixels": 10})]
    ['WARN']
    """
    out = []
    if m["baseline_pixels"] == 0 and m["spline_pixels"] == 0:
        return [Finding("FAIL", f"{view} view: neither the spline nor the baseline covers a pixel (empty picture)")]
    if m["spline_pixels"] == 0:
        return [Finding("FAIL", f"{view} view: the spline draws nothing where the baseline covers "
                                f"{m['baseline_pixels']} pixels")]
    iou = m["iou"]
    if iou < THRESHOLDS["iou_fail"]:
        out.append(Finding("FAIL", f"{view} view: silhouette IoU {iou:.3f} against the baseline "
                                   f"(< {THRESHOLDS['iou_fail']}: a different picture)"))
    elif iou < THRESHOLDS["iou_warn"]:
        out.append(Finding("WARN", f"{view} view: silhouette IoU {iou:.3f} against the baseline "
                                   f"(< {THRESHOLDS['iou_warn']})"))
    if m["leak_fraction"] > THRESHOLDS["leak_fail"]:
        out.append(Finding("FAIL", f"{view} view: {m['leaks']} background pixels inside the silhouette "
                                   f"({100 * m['leak_fraction']:.2f} % of its interior: holes, or a different shape "
                                   f"where IoU is low)"))
    elif m["leak_fraction"] > THRESHOLDS["leak_warn"]:
        out.append(Finding("WARN", f"{view} view: {m['leaks']} background pixels inside the silhouette "
                                   f"({100 * m['leak_fraction']:.2f} % of its interior)"))
    if m["pinhole_fraction"] > THRESHOLDS["pinhole_fail"] and m["pinholes"] >= THRESHOLDS["pinhole_count"]:
        out.append(Finding("FAIL", f"{view} view: {m['pinholes']} pinhole pixels (holes of at most "
                                   f"{THRESHOLDS['pinhole_pixels']} px inside the surface: cracks)"))
    elif m["pinholes"]:
        out.append(Finding("WARN", f"{view} view: {m['pinholes']} pinhole pixel(s) inside the surface"))
    return out

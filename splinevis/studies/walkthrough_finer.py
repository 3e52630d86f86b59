"""Walkthrough study, sections (f) and (g): views closer than the finest static level allows, and a trimmed CAD
assembly through the STEP reader.

* **(f) Finer than level 0.** The same fly-through (its close approach ends a few percent of the model's size
  from a teapot) at one pixel of error with static levels only, with dynamic tessellation
  (:class:`splinevis.nurbs.lod.dynamic.Refiner` in the mesh worker) and with dynamic tessellation plus exact
  close-ups (:class:`splinevis.nurbs.lod.closeup.CloseUp`): frame times, triangles, how many super-surfaces the
  view wanted finer than level 0, how many were drawn refined, how many waited, and how many were drawn exactly.
* **(g) A trimmed CAD assembly.** Filleted plates with holes (:mod:`datasets_synthetic.cad_parts`) written to
  STEP by OpenCASCADE and read back: build time, triangles, the open edges of the assembled mesh at level 0 and
  at random level combinations (a closed solid has none), and the fly-through.
"""

from __future__ import annotations

import time

import numpy as np

__all__ = ["finer_than_level0", "cad_assembly", "FINER_CONFIGS"]

#: (f)'s configurations: (name, Walkthrough options; "closeup" True makes a CloseUp).
FINER_CONFIGS = [("static levels", dict(threaded=True)),
                 ("+ dynamic tessellation", dict(threaded=True, dynamic=True)),
                 ("+ exact close-ups", dict(threaded=True, dynamic=True, closeup=True))]


def _finer_columns(frames) -> dict:
    """What (f) adds to the fly-through's row: refined and waiting super-surfaces, exact close-ups."""
    mean = lambda k: float(np.mean([f.get(k, 0) for f in frames]))  # noqa: E731
    exact = [f.get("closeup", 0) for f in frames]
    return {"refined": mean("refined"), "pending": mean("finer_pending"),
            "closeup_frames": int(sum(1 for x in exact if x)), "closeup_max": int(max(exact) if exact else 0)}


def finer_than_level0(lod, path, fly, progress=False) -> list:
    """(f): one row per configuration of :data:`FINER_CONFIGS` on ``path``: the row of ``fly(lod, path,
    **options) -> (row, frames)`` (the study's fly-through) with the refined, waiting and exact super-surfaces.

    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> from splinevis.nurbs.lod.pipeline import camera_path
    >>> def fly(lod, path, **options):  # a stand-in: the study's row and frames of a still camera
    ...     return {"fps": 100.0}, [{"time_ms": 10.0, "triangles": 8, "needs_finer": 1, "refined": 1, "closeup": 0}]
    >>> rows = finer_than_level0(build_lod(sphere(), 0.05, levels=1, progress=False), [], fly)
    >>> [r["configuration"] for r in rows][-1], rows[0]["fps"]
    ('+ exact close-ups', 100.0)
    """
    from ..nurbs.lod.closeup import CloseUp

    rows = []
    for name, options in FINER_CONFIGS:
        options = dict(options)
        if options.pop("closeup", False):
            options["closeup"] = CloseUp(pixel_error=1.0)
        row, frames = fly(lod, path, pixel_error=1.0, **options)
        rows.append({"configuration": name, **row, **_finer_columns(frames)})
    return rows


def _open_edges(tri) -> int:
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return int((counts != 2).sum())


def cad_assembly(folder, copies: int, delta: float, path_of, fly, levels: int = 3, combos: int = 3) -> dict:
    """(g): ``copies`` filleted plates through STEP (:func:`datasets_synthetic.cad_parts.plates`) at ``delta``;
    ``path_of(lod)`` gives the fly-through, ``fly`` flies it. Without OpenCASCADE the result says so.

    >>> from pathlib import Path
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     r = cad_assembly(Path(d), 1, 0.01, lambda lod: [], lambda lod, path, **o: ({"fps": 0.0}, []))
    >>> r["faces"], r["open_edges_level0"], r["triangles_level0"] > 1000
    (32, 0, True)
    """
    from ..io.nurbs_step import ocp_available
    from ..nurbs.lod.levels import assemble, build_lod

    if not ocp_available():
        return {"available": False, "note": "OpenCASCADE (OCP) not importable: install the cad extra"}
    from datasets_synthetic.cad_parts import plates

    t0 = time.perf_counter()
    model = plates(folder / f"plates{copies}.step", copies=copies)
    read_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    lod = build_lod(model, float(delta), levels=levels, progress=False)
    build_s = time.perf_counter() - t0
    S = len(lod.supers.members)
    _, tri, _ = assemble(lod, np.zeros(S, dtype=int))
    rng = np.random.default_rng(0)
    mixed = [_open_edges(assemble(lod, rng.integers(0, lod.levels, S))[1]) for _ in range(combos)]
    row, _ = fly(lod, path_of(lod), pixel_error=1.0, threaded=True)
    return {"available": True, "source": model.source.split(" (", 1)[-1].rstrip(")"), "copies": copies,
            "faces": len(model),
            "patches": len(lod.bezier), "super_surfaces": S, "delta": float(delta), "read_s": read_s,
            "build_s": build_s, "triangles_level0": int(tri.shape[0]), "open_edges_level0": _open_edges(tri),
            "open_edges_mixed_max": int(max(mixed)), "combos": combos,
            "triangles_per_level": lod.triangles.sum(axis=0).tolist(), **row}

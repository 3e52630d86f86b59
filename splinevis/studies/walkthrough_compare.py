"""The walkthrough study's comparisons of static meshes at equal measured deviation [Kumar1997]: levels of
detail against uniform tessellation and against OpenCASCADE's mesher (section (b) of
:mod:`splinevis.studies.walkthrough`), and simplified levels against plain ones (section (e)).

Every mesh is measured the same way: :func:`measured_deviation` (largest distance to the model's surfaces,
both ways), its triangles, and :func:`frame_ms` (one frame of the whole mesh in view, 800x600, flat shaded for
every mesh alike). A level is matched with the coarsest mesh of another mesher whose measured deviation is at
most the level's (:func:`match`).
"""

from __future__ import annotations

import time

import numpy as np

from .nurbs_occ import occ_available

__all__ = ["WINDOW", "plotter", "measured_deviation", "frame_ms", "static_mesh", "lod_bounds", "match", "lod_vs_meshes",
           "occ_deflections", "simplification_levels"]

WINDOW = (800, 600)


def plotter():
    """An offscreen pyvista plotter of the study's :data:`WINDOW`, white, without multisampling (llvmpipe's 4x
    multisampling costs ~70 ms a frame alone and is the same for every configuration).

    >>> pl = plotter()
    >>> tuple(pl.window_size), pl.render_window.GetMultiSamples()
    ((800, 600), 0)
    >>> pl.close()
    """
    import pyvista as pv

    pl = pv.Plotter(off_screen=True, window_size=WINDOW)
    pl.render_window.SetMultiSamples(0)
    pl.set_background("white")
    return pl


def measured_deviation(mesh, model, samples_per_span: int = 24) -> float:
    """Largest distance between a triangle mesh and the surfaces of ``model``, measured both ways: from dense
    surface points (:func:`splinevis.nurbs.tessellate.tessellate` vertices at ``samples_per_span``, exact
    surface points) to the mesh, and from the mesh's edge midpoints and centroids to the dense surface mesh.
    The same measure for every mesh, so deviations compare. The dense mesh's own chord error enters the second
    part: on the teapots 24 per span changes a deviation of 0.018 by 4e-4 against 40 per span (measured);
    compare meshes several times coarser than the dense one.

    Examples
    --------
    >>> from splinevis.nurbs.exact import cylinder
    >>> from splinevis.nurbs.tessellate import tessellate
    >>> d = measured_deviation(tessellate(cylinder(1.0), 4), cylinder(1.0))
    >>> 0.015 < d < 0.025  # about 1 - cos(pi / 16) = 0.019 (the chord_deviation example)
    True
    """
    import pyvista as pv

    from ..nurbs.tessellate import tessellate

    dense = tessellate(model, int(samples_per_span))
    target = pv.PolyData(np.asarray(mesh.points), faces=mesh.faces)
    a = np.abs(pv.PolyData(dense.points).compute_implicit_distance(target)["implicit_distance"]).max()
    tri = mesh.faces.reshape(-1, 4)[:, 1:]
    P = np.asarray(mesh.points)[tri]
    probes = np.concatenate([P.mean(axis=1), 0.5 * (P[:, 0] + P[:, 1]), 0.5 * (P[:, 1] + P[:, 2]),
                             0.5 * (P[:, 2] + P[:, 0])])
    surface = pv.PolyData(dense.points, faces=dense.faces)
    b = np.abs(pv.PolyData(probes).compute_implicit_distance(surface)["implicit_distance"]).max()
    return float(max(a, b))


def frame_ms(mesh, bounds, repeats: int = 5) -> float:
    """Median time (ms) of one frame of ``mesh`` seen whole from above one corner of ``bounds`` (x0, x1, y0, y1,
    z0, z1), flat shaded: the mesh's points and triangles only, so every compared mesh is drawn alike.

    >>> from splinevis.nurbs.exact import cylinder
    >>> from splinevis.nurbs.tessellate import tessellate
    >>> mesh = tessellate(cylinder(1.0), 4)
    >>> frame_ms(mesh, mesh.bounds, repeats=1) > 0
    True
    """
    import pyvista as pv

    pl = plotter()
    try:
        pl.add_mesh(pv.PolyData(np.asarray(mesh.points), faces=mesh.faces), color="tan")
        b = np.asarray(bounds, dtype=np.float64)
        c = 0.5 * (b[0::2] + b[1::2])
        D = float(np.linalg.norm(b[1::2] - b[0::2]))
        pl.camera_position = [tuple(c + D * np.array([0.6, -0.8, 0.5])), tuple(c), (0.0, 0.0, 1.0)]
        pl.reset_camera_clipping_range()
        pl.show(auto_close=False)
        times = []
        for _ in range(int(repeats) + 1):
            t0 = time.perf_counter()
            pl.render_window.Render()
            times.append(time.perf_counter() - t0)
        return 1e3 * float(np.median(times[1:]))
    finally:
        pl.close()


def static_mesh(lod, level: int):
    """Every super-surface of ``lod`` at one ``level``, as a pyvista PolyData
    (:func:`splinevis.nurbs.lod.levels.assemble`).

    >>> from splinevis.nurbs.exact import torus
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod = build_lod(torus(), 0.01, levels=2, progress=False)
    >>> [static_mesh(lod, level).n_cells == int(lod.triangles[:, level].sum()) for level in (0, 1)]
    [True, True]
    """
    import pyvista as pv

    from ..nurbs.lod.levels import assemble

    points, tri, _ = assemble(lod, np.full(len(lod.supers.members), int(level), dtype=np.int64))
    return pv.PolyData(np.asarray(points), faces=pv.CellArray.from_regular_cells(np.asarray(tri, dtype=np.int64)))


def lod_bounds(lod) -> np.ndarray:
    """``(x0, x1, y0, y1, z0, z1)`` of the boxes of every super-surface of ``lod``.

    >>> from splinevis.nurbs.exact import torus
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod_bounds(build_lod(torus(), 0.05, levels=1, progress=False)).round(6).tolist()
    [-2.5, 2.5, -2.5, 2.5, -0.5, 0.5]
    """
    b = np.asarray(lod.boxes)
    return np.array([b[:, 0].min(), b[:, 1].max(), b[:, 2].min(), b[:, 3].max(), b[:, 4].min(), b[:, 5].max()])


def _row(name, mesh, model, bounds, **extra) -> dict:
    return {"mesh": name, **extra, "triangles": int(mesh.n_cells), "deviation": measured_deviation(mesh, model),
            "frame_ms": frame_ms(mesh, bounds)}


def match(level: dict, candidates: list, prefix: str, none: str) -> dict:
    """The coarsest (fewest triangles) of ``candidates`` whose ``deviation`` is at most the ``level`` row's, as
    columns ``prefix``, ``prefix_deviation``, ``prefix_triangles``, ``prefix_frame_ms`` and ``prefix_ratio``
    (its triangles over the level's); ``none`` names the mesh when no candidate is that accurate.

    >>> level = {"deviation": 0.1, "triangles": 100}
    >>> meshes = [{"mesh": "a", "deviation": 0.2, "triangles": 50, "frame_ms": 1.0},
    ...           {"mesh": "b", "deviation": 0.09, "triangles": 120, "frame_ms": 2.0},
    ...           {"mesh": "c", "deviation": 0.01, "triangles": 900, "frame_ms": 9.0}]
    >>> match(level, meshes, "uniform", "none")
    {'uniform': 'b', 'uniform_deviation': 0.09, 'uniform_triangles': 120, 'uniform_frame_ms': 2.0, 'uniform_ratio': 1.2}
    >>> match(level, meshes[:1], "occ", "none finer than 0.2")["occ"]
    'none finer than 0.2'
    """
    ok = [c for c in candidates if c["deviation"] <= level["deviation"]]
    best = min(ok, key=lambda r: r["triangles"]) if ok else None
    if best is None:
        return {prefix: none, f"{prefix}_deviation": None, f"{prefix}_triangles": None, f"{prefix}_frame_ms": None,
                f"{prefix}_ratio": None}
    return {prefix: best["mesh"], f"{prefix}_deviation": best["deviation"], f"{prefix}_triangles": best["triangles"],
            f"{prefix}_frame_ms": best["frame_ms"], f"{prefix}_ratio": best["triangles"] / level["triangles"]}


def occ_deflections(tolerance, step: float = np.sqrt(2.0)) -> list:
    """OpenCASCADE deflections for the levels of tolerances ``tolerance``: from half the finest to the coarsest,
    a factor ``step`` apart (the mesher's deflection is its own chord estimate, so the range reaches beyond the
    finest level).

    >>> occ_deflections([0.01, 0.04], step=2.0)
    [0.005, 0.01, 0.02, 0.04]
    """
    lo, hi = 0.5 * float(np.min(tolerance)), float(np.max(tolerance))
    n = int(np.floor(np.log(hi / lo) / np.log(step) + 1e-9)) + 1
    return [float(lo * step**k) for k in range(n)]


def lod_vs_meshes(lod, model, per_spans=range(1, 17), deflections=None) -> dict:
    """Section (b): every super-surface of ``lod`` at one level (rows ``levels``) against uniform tessellation
    at ``per_spans`` (rows ``uniform``) and OpenCASCADE's ``BRepMesh`` at ``deflections`` (rows ``occ``; default
    :func:`occ_deflections` of ``lod.tolerance``; one row saying so when OCP is not importable), each measured
    alike; ``matches``: per level, the coarsest uniform and OpenCASCADE mesh at most as far from the surface
    (:func:`match`).

    >>> from splinevis.nurbs.exact import torus
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod = build_lod(torus(), 0.05, levels=2, progress=False)
    >>> out = lod_vs_meshes(lod, torus(), per_spans=(2, 4), deflections=(0.05,))
    >>> [len(out[k]) for k in ("levels", "uniform", "matches")], out["occ_available"] == (len(out["occ"]) == 1)
    ([2, 2, 2], True)
    """
    from ..nurbs.tessellate import tessellate

    bounds = lod_bounds(lod)
    levels = [_row(f"LOD level {level}", static_mesh(lod, level), model, bounds, bound=float(lod.tolerance[level]))
              for level in range(lod.levels)]
    uniform = [_row(f"uniform per_span={p}", tessellate(model, int(p)), model, bounds, per_span=int(p))
               for p in per_spans]
    none_uniform = f"none of per_span <= {max(per_spans)}" if len(uniform) else "none (no per_span)"
    available = occ_available()
    occ = []
    if available:
        from .nurbs_occ import occ_tessellate

        deflections = occ_deflections(lod.tolerance) if deflections is None else deflections
        occ = [_row(f"OpenCASCADE deflection={d:.3g}", occ_tessellate(model, float(d)), model, bounds,
                    deflection=float(d)) for d in deflections]
        none_occ = f"none of deflection >= {min(deflections):.3g}" if len(deflections) else "none (no deflection)"
    else:
        none_occ = "OpenCASCADE (OCP) not importable"
    matches = [{"level": row["mesh"], "lod_deviation": row["deviation"], "lod_triangles": row["triangles"],
                "lod_frame_ms": row["frame_ms"],
                **match(row, uniform, "uniform", none_uniform),
                **match(row, occ, "occ", none_occ)} for row in levels]
    return {"levels": levels, "uniform": uniform, "occ_available": available,
            "occ": occ or [{"mesh": "OpenCASCADE: not available (OCP not importable; pip install splinevis[cad])"}],
            "matches": matches}


def simplification_levels(plain, simplified, model, samples_per_span: int = 24) -> list:
    """Section (e): per level of the same model built without and with a
    :class:`~splinevis.nurbs.lod.simplify.Simplifier` (``plain``, ``simplified``): the proven part ``delta_l``,
    the simplification's ``eps_l``, the bound ``delta_l + eps_l``, triangles without and with simplification,
    the super-surfaces whose level lost triangles, the largest distance the Simplifier measured
    (``lod.simplified``) and the study's :func:`measured_deviation` of both static levels (``samples_per_span``:
    its dense sampling; fewer on models of many small patches).

    >>> from splinevis.nurbs.exact import torus
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> from splinevis.nurbs.lod.simplify import Simplifier
    >>> a = build_lod(torus(), 0.01, levels=3, progress=False)
    >>> b = build_lod(torus(), 0.01, levels=3, simplify=Simplifier(), progress=False)
    >>> rows = simplification_levels(a, b, torus())
    >>> [(r["delta"], round(r["eps"], 12)) for r in rows]
    [(0.01, 0.0), (0.04, 0.02), (0.16, 0.08)]
    >>> rows[2]["triangles_simplified"] < rows[2]["triangles_plain"], rows[2]["simplifier_measured"] <= 0.24
    (True, True)
    """
    if plain.triangles.shape != simplified.triangles.shape or plain.tolerance[0] != simplified.tolerance[0]:
        raise ValueError("simplification_levels compares two builds of one model at one delta and one number of "
                         f"levels; got tolerances {plain.tolerance.tolist()} and {simplified.tolerance.tolist()}.")
    rows = []
    for level in range(plain.levels):
        delta, bound = float(plain.tolerance[level]), float(simplified.tolerance[level])
        a, b = plain.triangles[:, level], simplified.triangles[:, level]
        rows.append({"level": level, "delta": delta, "eps": bound - delta, "bound": bound,
                     "triangles_plain": int(a.sum()), "triangles_simplified": int(b.sum()),
                     "ratio": float(b.sum() / a.sum()), "supers_reduced": int(np.sum(b < a)),
                     "supers": int(a.size), "simplifier_measured": float(simplified.simplified[:, level].max()),
                     "deviation_plain": measured_deviation(static_mesh(plain, level), model, samples_per_span),
                     "deviation_simplified": measured_deviation(static_mesh(simplified, level), model,
                                                                samples_per_span)})
    return rows

"""Memory and preprocessing of the volume renderer per volume size, in the layout of [Kalbe2008, Table 1],
and that table's own numbers, which are shown only in a table labelled "paper" (section 3 of
:mod:`splinevis.studies.volume`)."""

from __future__ import annotations

import time

from .report import md_table, paper_table, progress_bar

__all__ = ["PAPER_TABLE_1", "PAPER_COLUMNS", "MEMORY_COLUMNS", "memory_rows", "memory_markdown"]

#: [Kalbe2008, Table 1] (text extraction; columns read in order): dataset, voxels, isovalue rho, #cubes,
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

#: The measured columns, in the order of the paper's table where it has them.
MEMORY_COLUMNS = [
    ("volume", "volume", "s"), ("scheme", "scheme", "s"), ("cubes", "relevant_cubes", "int"),
    ("tets", "relevant_tets", "int"), ("geometry MB (blocks)", "geometry_MB", "f2"),
    ("geometry MB (cube proxies)", "geometry_cubes_MB", "f2"), ("data texture MB", "data_texture_MB", "f2"),
    ("determining set MB", "determining_set_MB", "f2"), ("all coefficients MB", "all_coefficients_MB", "f2"),
    ("coef. table MB", "coefficient_table_MB", "f2"), ("octree MB", "octree_MB", "f2"),
    ("spline s", "spline_s", "f2"), ("octree s", "octree_s", "f2"), ("relevant s", "relevant_s", "f2"),
    ("program s", "program_s", "f2"), ("preprocessing s", "preprocessing_s", "f2"),
    ("2nd isovalue s", "second_isovalue_s", "f2")]

#: The columns of :data:`PAPER_TABLE_1` (the first is labelled "paper" by :func:`~.report.paper_table`).
PAPER_COLUMNS = [
    ("dataset", "dataset", "s"), ("voxels", "voxels", "s"), ("rho", "rho", "f2"), ("cubes", "cubes", "e"),
    ("patches", "patches", "e"), ("D2 MB", "D2_MB", "f2"), ("D3 MB", "D3_MB", "f2"), ("geometry MB", "geometry_MB", "f2"),
    ("octree s", "octree_s", "f2"), ("QSS s", "QSS_s", "f1"), ("S31 s", "S31_s", "f1"), ("QSS fps", "QSS_fps", "s"),
    ("S31 fps", "S31_fps", "s")]


def memory_rows(sizes=(64, 128, 256), schemes=("quadratic", "cubic"), progress=True):
    """Memory and preprocessing per Marschner-Lobb volume size and scheme (isovalue 0.5, then 0.45).

    Examples
    --------
    >>> from splinevis.studies.volume_memory import memory_rows
    >>> rows = memory_rows(sizes=(8,), schemes=("quadratic",), progress=False)
    >>> [(r["volume"], r["scheme"], r["relevant_cubes"], r["relevant_tets"]) for r in rows]
    [('8^3', 'quadratic', 116, 1344)]
    >>> rows[0]["second_isovalue"], rows[0]["second_isovalue_cubes"]
    (0.45, 112)
    """
    from datasets_synthetic.volumes import marschner_lobb
    from ..volume.isosurface import Isosurface
    from ..volume.model import VolumeSpline
    from ..volume.program import isosurface_program
    from ..volume.tables import memory_report

    field = marschner_lobb()
    rows = []
    for n in progress_bar(sizes, "memory / preprocessing", enabled=progress):
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


def memory_markdown(rows) -> list:
    """The markdown section of ``rows`` (from :func:`memory_rows`) and of the paper's table, as the parts
    the study's report joins with newlines.

    Examples
    --------
    Rows need the keys of :data:`MEMORY_COLUMNS` (a missing one is a ``-`` cell) and ``n``; a 256^3 row
    adds the line on the 5 s goal:

    >>> from splinevis.studies.volume_memory import memory_markdown
    >>> row = {"volume": "256^3", "n": 256, "scheme": "quadratic", "relevant_cubes": 120000, "preprocessing_s": 3.2}
    >>> md = memory_markdown([row])
    >>> print(md[1].splitlines()[2])
    | 256^3 | quadratic | 120,000 | - | - | - | - | - | - | - | - | - | - | - | - | 3.20 | - |
    >>> md[2]
    '\\nGoal: 256^3 preprocessing for one isovalue <= 5 s: quadratic 3.20 s (met).\\n'
    >>> md[3].splitlines()[1]  # the paper's numbers, labelled as such
    '### paper (Kalbe & Zeilfelder 2008, Table 1, NVIDIA 8800 Ultra, 1280x1024; real data sets, not ours)'
    """
    md = ["\n## 3. Memory and preprocessing (Marschner-Lobb, isovalue 0.5; layout of the paper's Table 1)\n",
          md_table(rows, MEMORY_COLUMNS)]
    big = [r for r in rows if r["n"] == 256]
    if big:
        md.append("\nGoal: 256^3 preprocessing for one isovalue <= 5 s: " + ", ".join(
            f"{r['scheme']} {r['preprocessing_s']:.2f} s ({'met' if r['preprocessing_s'] <= 5 else 'NOT met'})" for r in big) + ".\n")
    md.append("\n" + paper_table("Kalbe & Zeilfelder 2008, Table 1, NVIDIA 8800 Ultra, 1280x1024; real data sets, not ours",
                                 PAPER_TABLE_1, PAPER_COLUMNS))
    md.append("\nD2/D3 = the paper's determining sets (20 resp. 56 floats per cube) = our \"determining set MB\"; our "
              "default encoding uploads the data texture (1 float per sample) instead.\n")
    return md

"""Benchmark case ``mesh_guided``: the mesh-guided terrain program against the box ray cast and a plain mesh.

The scene is the profile benchmark's (``bench_profile.py``): a 65x65 fractal terrain, C1, full-screen oblique view at
800x600, one light. Measured side by side in one process, interleaved one frame each per round (so load from
other processes falls on all alike; rates use each configuration's fastest frame):

* ``raycast (box)``: the terrain program as users get it by default (the bounding box proxy and the full
  hierarchy walk per fragment);
* ``mesh-guided k=1`` (and ``k=2``): ``program_options={"proxy": "mesh"}``: the lifted tessellation with k x k
  sub-squares per cell, each fragment tracing its ray to the first root (splinevis.terrain.mesh_proxy);
* ``plain mesh, same triangles``: what users draw today: the spline sampled at the same vertices (k = 1: the
  grid's own samples, 2 triangles per cell, as many as the mesh-guided proxy's top) as a VTK mesh with
  per-vertex normals and Phong shading, one light.

Ratios: mesh-guided against the box (how much faster the exact picture got) and against the plain mesh (what
exactness still costs over a mesh of the same size).

    python benchmarks/run.py --cases mesh_guided       # or: python benchmarks/bench_mesh_guided.py
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

WINDOW = (800, 600)


def _plain_mesh(terrain, k):
    """The spline sampled k x k per cell as a pyvista surface with point normals (the mesh users draw)."""
    import numpy as np
    import pyvista as pv

    ncy, ncx = terrain.shape
    x0, x1, y0, y1 = terrain.extent
    xs = np.linspace(x0, x1, k * ncx + 1)
    ys = np.linspace(y0, y1, k * ncy + 1)
    X, Y = np.meshgrid(xs, ys)
    Z = terrain.evaluate(X, Y)
    grid = pv.StructuredGrid(X, Y, Z).extract_surface().triangulate()
    return grid.compute_normals(cell_normals=False, point_normals=True, split_vertices=False)


def measure(repeats):
    """Frame rows of every configuration (module docstring), all open at once and timed in turn."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_profile import CAMERA, _terrain

    from splinevis.analysis.timing import interleaved_frame_times
    from splinevis.plotting import Plotter

    terrain = _terrain()
    configs = [("raycast (box)", {}, None), ("mesh-guided k=1", {"proxy": "mesh", "mesh_samples": 1}, None),
               ("mesh-guided k=2", {"proxy": "mesh", "mesh_samples": 2}, None),
               ("plain mesh, same triangles (k=1)", None, 1), ("plain mesh, same triangles (k=2)", None, 2)]
    scenes = []
    for name, options, k in configs:
        pl = Plotter(off_screen=True, window_size=WINDOW)
        if options is not None:
            pl.add_spline(terrain, lights=1, program_options=options)
            # the mesh-guided proxy's top: 2 k^2 triangles per cell (walls and bottom add a border's worth)
            tris = terrain.num_patches * options["mesh_samples"] ** 2 if options else None
        else:
            mesh = _plain_mesh(terrain, k)
            pl.add_mesh(mesh, color="tan", smooth_shading=True)
            tris = mesh.n_cells
        pl.camera_position = CAMERA
        pl.camera.clipping_range = (0.01, 10.0)
        scenes.append((name, pl, tris))
    rows = []
    for (name, pl, tris), f in zip(scenes, interleaved_frame_times([s[1] for s in scenes], repeats)):
        covered = float((pl.depth_buffer() < 1.0).mean())
        pl.close()
        rows.append({"config": name, "triangles": tris, "hit_pixels": covered, "min_ms": f["min_ms"],
                     "median_ms": f["median_ms"], "repeats": repeats})
    return rows


def bench_mesh_guided(repeats, quick):
    """The ``mesh_guided`` case: the rows and the ratios (module docstring)."""
    rows = measure(3 if quick else repeats)
    by = {r["config"]: r for r in rows}
    ratios = {}
    for k in (1, 2):
        mg = by[f"mesh-guided k={k}"]["min_ms"]
        ratios[f"box / mesh-guided k={k}"] = by["raycast (box)"]["min_ms"] / mg
        ratios[f"mesh-guided k={k} / plain mesh k={k}"] = mg / by[f"plain mesh, same triangles (k={k})"]["min_ms"]
    return {"scene": "65x65 fractal terrain, C1, 800x600, oblique full-screen view, 1 light", "rows": rows,
            "ratios": ratios}


def mesh_guided_markdown(result) -> str:
    lines = ["## Mesh-guided terrain against the box ray cast and a plain mesh (one run, interleaved)", "",
             f"Scene: {result['scene']}. Fastest of the frames; the median shows the machine's load.", "",
             "| renderer | triangles | pixels hit | fastest ms | median ms |", "|---|---:|---:|---:|---:|"]
    for r in result["rows"]:
        tris = "-" if r["triangles"] is None else f"{r['triangles']:,}"
        lines.append(f"| {r['config']} | {tris} | {r['hit_pixels']:.3f} | {r['min_ms']:.1f} | {r['median_ms']:.1f} |")
    lines += ["", "| ratio | value |", "|---|---:|"]
    lines += [f"| {k} | {v:.2f} |" for k, v in result["ratios"].items()]
    return "\n".join(lines) + "\n"


def main(argv=None):
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=9)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args(argv)
    result = bench_mesh_guided(args.repeats, args.quick)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "mesh_guided.json").write_text(json.dumps(result, indent=2))
    md = mesh_guided_markdown(result)
    (out / "mesh_guided.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    sys.exit(main())

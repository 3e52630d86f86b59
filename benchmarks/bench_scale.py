"""Benchmark cases for scale: a 3601 x 3601 terrain (an SRTM tile's size) and the cold start of a new process.

Each runs in a fresh Python process, so its peak memory (ru_maxrss) and its start-up are its own.
"""

from __future__ import annotations

import json
import subprocess
import sys

_LARGE = r'''
import json, resource, time
from datasets_synthetic.dem_files import fractal_terrain
from splinevis.analysis.timing import frame_times
from splinevis.plotting import Plotter
from splinevis.terrain.model import TerrainSpline
n = {n}
z = fractal_terrain(n, seed=7, amplitude=900.0)
t0 = time.perf_counter()
t = TerrainSpline.from_heights(z, "C1", spacing=(30.0, 30.0), origin=(500000.0, 4100000.0))
build = time.perf_counter() - t0
pl = Plotter(off_screen=True, window_size=(800, 600))
t1 = time.perf_counter()
pl.add_spline(t, lights=2)
x0, x1, y0, y1 = t.extent
w = x1 - x0
pl.camera_position = [(x0 - 0.2 * w, y0 - 0.3 * w, 0.55 * w), (0.5 * (x0 + x1), 0.5 * (y0 + y1), 300.0), (0, 0, 1)]
pl.reset_camera_clipping_range()
pl.render_now()
first = time.perf_counter() - t1
r = frame_times(pl, {repeats})
covered = float((pl.depth_buffer() < 1).mean())
pl.close()
print(json.dumps({{"grid": f"{{n}}x{{n}}", "patches": t.num_patches, "construction_s": build, "program_and_first_frame_s": first,
                  "frame_min_ms": r["min_ms"], "frame_median_ms": r["median_ms"], "screen_covered": covered,
                  "peak_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}}))
'''

_COLD = r'''
import json, time
t0 = time.perf_counter()
import numpy as np
import splinevis
from splinevis.terrain.model import TerrainSpline
from splinevis.volume.model import VolumeSpline
t_import = time.perf_counter() - t0
z = np.add.outer(np.sin(np.linspace(0, 3, 65)), np.cos(np.linspace(0, 3, 65)))
t1 = time.perf_counter()
TerrainSpline.from_heights(z, "C1")
x = np.linspace(-1, 1, 16)
v = np.sqrt(np.add.outer(np.add.outer(x ** 2, x ** 2), x ** 2))
VolumeSpline(v, "quadratic").relevant(0.7)
VolumeSpline(v, "cubic").relevant(0.7)
t_models = time.perf_counter() - t1
pl = splinevis.Plotter(off_screen=True, window_size=(400, 300))
pl.add_terrain(z, "C1")
pl.render_now()
t_picture = time.perf_counter() - t0
pl.close()
print(json.dumps({{"import_s": t_import, "models_s": t_models, "first_picture_s": t_picture}}))
'''


def _run(code: str) -> dict:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def bench_large_terrain(repeats, quick):
    """A 3601 x 3601 C1 terrain (quick: 2049 x 2049): construction, program + first frame, frame time, peak MB."""
    return [_run(_LARGE.format(n=2049 if quick else 3601, repeats=max(2, repeats // 2)))]


def bench_cold_start(repeats, quick):
    """Seconds from a new process to models and to the first terrain picture (median of runs)."""
    runs = [_run(_COLD.format()) for _ in range(2 if quick else 3)]
    return [{k: sorted(r[k] for r in runs)[len(runs) // 2] for k in runs[0]}]

"""Run the terrain study: accuracy table, figures, accuracy vs time (Pareto), throughput, scaling.

    python examples/terrain_study.py [out_dir] [--quick]
"""

import sys

from splinevis.studies.terrain import run_terrain_study

out = next((a for a in sys.argv[1:] if not a.startswith("--")), "out/terrain_study")
result = run_terrain_study(out, quick="--quick" in sys.argv)
for row in result["crossover"]:
    if row["spline_cheaper"]:
        print(f"{row['spline']} at {row['iterations']} iterations: {row['spline_ms']:.1f} ms, "
              f"normal error {row['normal_err_median_deg']:.2e} deg; a mesh needs "
              f"{row['mesh_ms_for_same_error'] or float('nan'):.1f} ms ({row['note'] or 'interpolated'})")
print(f"files in {out}")

"""Run the volume study: approximation, accuracy vs time against marching cubes and VTK's ray caster,
memory and preprocessing (in the layout of [Kalbe2008, Table 1]), side-by-side figures.

    python examples/volume_study.py [out_dir] [--quick]
"""

import sys

from splinevis.studies.volume import run_volume_study

out = next((a for a in sys.argv[1:] if not a.startswith("--")), "out/volume_study")
result = run_volume_study(out, quick="--quick" in sys.argv)
print(result["cubic"]["note"])
for r in result["accuracy_vs_time"]:
    err = r["normal_err_median_deg"]
    print(f"{r['method']:18s} {r['config']:28s} {r['frame_median_ms']:9.1f} ms  normal error "
          f"{'-' if err is None else f'{err:.3f}'} deg  coverage mismatch {r['coverage_mismatch']} px")
for r in result["memory"]:
    print(f"{r['volume']} {r['scheme']}: preprocessing {r['preprocessing_s']:.2f} s, second isovalue "
          f"{r['second_isovalue_s']:.2f} s, {r['relevant_cubes']} cubes")
print(f"files in {out}")

"""Fly through a large NURBS model with levels of detail [Kumar1997]: frames, triangles and frame times.

    python examples/walkthrough.py [MODEL_FILE_OR_TEAPOT_COUNT] [OUT_DIR] [--window] [--static] [--exact]

MODEL_FILE_OR_TEAPOT_COUNT is a NURBS file (.3dm, .igs, .step, .g2, .json, .bpt) or a number of Newell teapots
on a grid (default 64: 2,048 patches). The model is cut into Bezier patches, grouped into super-surfaces and
tessellated at four levels with proven bounds (``splinevis.nurbs.lod.levels.build_lod``); a camera path makes a
low pass over the model and a close approach; each frame draws one crack-free mesh of the levels the
screen-space error picks, culled by view frustum and back-patch tests, built by worker threads while the
renderer draws the previous one; where even the finest level is too coarse for the view, the mesh worker
tessellates finer on demand (dynamic tessellation; ``--static`` turns it off). Writes ``OUT_DIR/frame_0000.png``
..., ``OUT_DIR/frames.csv`` (per-frame log: frame time, triangles, visible and refined super-surfaces, stage
times) and ``OUT_DIR/summary.png`` (four frames). With ``--exact`` the super-surfaces that fill the view are drawn
exactly by the per-fragment NURBS program (about a second a frame on a CPU renderer), the rest as meshes.

With ``--window`` and a display (``DISPLAY`` set) a window opens instead: fly with the mouse (VTK's trackball
camera: left drag rotates, right drag or the wheel zooms, middle drag pans); the workers follow your camera and
the newest mesh is swapped in. Close the window to end. Without a display ``--window`` says so and flies the
path off screen.
"""

import csv
import os
import sys
from pathlib import Path

import numpy as np
import pyvista as pv
from PIL import Image

from splinevis.nurbs.lod.levels import build_lod
from splinevis.nurbs.lod.pipeline import Walkthrough, camera_path


def load(arg):
    if arg and not arg.isdigit():
        from splinevis.io import read_nurbs

        return read_nurbs(arg)
    from datasets_synthetic.large_models import teapot_field

    return teapot_field(int(arg or 64))


def main(arg="", out="walkthrough_out", window=False, frames=48, size=(800, 600), dynamic=True, exact=False):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    model = load(arg)
    lo, hi = np.asarray(model.bounds()[0::2]), np.asarray(model.bounds()[1::2])
    lod = build_lod(model, 1e-3 * float(np.linalg.norm(hi - lo)), levels=4)
    print(f"{len(lod.bezier):,} Bezier patches, {len(lod.supers.members):,} super-surfaces, level bounds "
          f"{', '.join(f'{t:.3g}' for t in lod.tolerance)}")
    on_screen = window and bool(os.environ.get("DISPLAY"))
    if window and not on_screen:
        print("--window: no display (DISPLAY is not set), so no window can open; flying the path off screen "
              f"instead (frames in {out}).", file=sys.stderr)
    pl = pv.Plotter(off_screen=not on_screen, window_size=size)
    pl.set_background("white")
    if exact:
        from splinevis.nurbs.lod.closeup import CloseUp
    walk = Walkthrough(lod, pl, threaded=True, pixel_error=1.0, dynamic=dynamic,
                       closeup=CloseUp(pixel_error=1.0) if exact else None)
    if on_screen:
        pl.camera_position = camera_path(model.bounds(), 2)[0]
        print("Fly with the mouse; close the window to end.")
        walk.interact()
        pl.close()
        return []
    log = walk.fly(camera_path(model.bounds(), frames), frames_dir=out)
    pl.close()
    with open(out / "frames.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(log[0]))
        w.writeheader()
        w.writerows(log)
    ms = np.array([r["time_ms"] for r in log])
    print(f"{len(log)} frames: median {np.median(ms):.1f} ms ({1000 / np.median(ms):.1f} fps), "
          f"triangles {min(r['triangles'] for r in log):,} to {max(r['triangles'] for r in log):,}")
    if dynamic:
        print(f"dynamic tessellation: up to {max(r['refined'] for r in log):,} super-surfaces refined "
              f"({max(r['refined_triangles'] for r in log):,} triangles), "
              f"the mesh worker tessellated {sum(r['tessellate_ms'] for r in log) / 1e3:.1f} s during the flight")
    picks = [out / f"frame_{k:04d}.png" for k in np.linspace(0, len(log) - 1, 4).astype(int)]
    row = np.concatenate([np.asarray(Image.open(p).convert("RGB")) for p in picks], axis=1)
    Image.fromarray(row).save(out / "summary.png")
    print(f"wrote {out / 'summary.png'}")
    return log


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a not in ("--window", "--static", "--exact")]
    main(args[0] if args else "", args[1] if len(args) > 1 else "walkthrough_out", window="--window" in sys.argv,
         dynamic="--static" not in sys.argv, exact="--exact" in sys.argv)

"""Compare two folders of rendered figures pixel for pixel: the check that a restructuring changed no picture.

    python tools/compare_figures.py BEFORE_DIR AFTER_DIR [--max-pixels N] [--diff-dir DIR]

For every PNG present in both folders it prints the image size, the number of pixels that differ and the
largest channel difference; with ``--diff-dir`` it writes an image per pair with the differing pixels in
magenta over a dimmed copy. Exit code 0 when no image has more than ``--max-pixels`` differing pixels
(default 0: identical), 1 otherwise, 2 when the folders share no PNG or sizes differ.

Typical use, before and after a change::

    git worktree add /tmp/before HEAD~1 && (cd /tmp/before && splinevis demo --out /tmp/before/out)
    splinevis demo --out out && python tools/compare_figures.py /tmp/before/out out
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from PIL import Image


def compare(before: Path, after: Path, diff_dir: Path | None = None) -> list[dict]:
    rows = []
    for a in sorted(before.glob("*.png")):
        b = after / a.name
        if not b.is_file():
            continue
        x = np.asarray(Image.open(a).convert("RGB")).astype(int)
        y = np.asarray(Image.open(b).convert("RGB")).astype(int)
        if x.shape != y.shape:
            rows.append({"name": a.name, "size": f"{x.shape[1]}x{x.shape[0]} vs {y.shape[1]}x{y.shape[0]}",
                         "differing": -1, "max_diff": -1})
            continue
        diff = np.abs(x - y).max(axis=-1)
        rows.append({"name": a.name, "size": f"{x.shape[1]}x{x.shape[0]}", "differing": int((diff > 0).sum()),
                     "max_diff": int(diff.max())})
        if diff_dir is not None and diff.any():
            diff_dir.mkdir(parents=True, exist_ok=True)
            vis = (x * 0.35).astype(np.uint8)
            vis[diff > 0] = (255, 0, 255)
            Image.fromarray(vis).save(diff_dir / a.name)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before", type=Path)
    ap.add_argument("after", type=Path)
    ap.add_argument("--max-pixels", type=int, default=0, help="differing pixels allowed per image (default 0)")
    ap.add_argument("--diff-dir", type=Path, default=None, help="write difference images here")
    args = ap.parse_args(argv)
    rows = compare(args.before, args.after, args.diff_dir)
    if not rows:
        print(f"no PNG in both {args.before} and {args.after}", file=sys.stderr)
        return 2
    print(f"{'figure':32s} {'size':>12s} {'differing px':>13s} {'max diff':>9s}")
    for r in rows:
        print(f"{r['name']:32s} {r['size']:>12s} {r['differing']:>13d} {r['max_diff']:>9d}")
    if any(r["differing"] < 0 for r in rows):
        return 2
    return 0 if all(r["differing"] <= args.max_pixels for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())

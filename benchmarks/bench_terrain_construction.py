"""Throughput of terrain coefficient construction (splinevis.terrain.terrain_coefficients).

    python benchmarks/bench_terrain_construction.py [--n 1024] [--repeats 5]

Prints, per scheme, the best wall time of ``repeats`` runs on an n x n grid of random heights and the
throughput in patches (triangles) per second. The first call per scheme (which builds and caches the
weight matrix; for C1 it solves the derivation system) is not timed.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from splinevis.terrain import SCHEMES, terrain_coefficients


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1024, help="grid size (n x n heights)")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    z = np.random.default_rng(1).standard_normal((args.n, args.n))
    print(f"grid {args.n}x{args.n}, best of {args.repeats}")
    print(f"{'scheme':10s} {'patches':>10s} {'time [s]':>10s} {'patches/s':>12s}")
    for scheme in SCHEMES:
        zz = z
        if scheme == "C0":  # needs 4k + 1 heights: use the largest such size <= n
            m = 4 * ((args.n - 1) // 4) + 1
            zz = z[:m, :m]
        terrain_coefficients(zz[:9, :9], scheme)  # warm-up: builds the weights
        best = np.inf
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            coef, _ = terrain_coefficients(zz, scheme)
            best = min(best, time.perf_counter() - t0)
        patches = coef.shape[0] * coef.shape[1] * 2
        print(f"{scheme:10s} {patches:10d} {best:10.4f} {patches / best:12.3e}")


if __name__ == "__main__":
    main()

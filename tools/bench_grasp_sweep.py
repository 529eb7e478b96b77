#!/usr/bin/env python3
"""Grasp sweep benchmark: 10^4 positions of a cylinder under the hand, batched
(hybrid.hand_sweep) against one call per position (hybrid.hand), in one run; prints both times
and their ratio. Run with the build's module:

    PYTHONPATH=build/python /usr/bin/python3 tools/bench_grasp_sweep.py [ROWS] [THREADS]
"""
import sys
import time

import numpy as np

import hybrid


def main():
    rows = int(sys.argv[1]) if len(sys.argv) > 1 else 10000
    threads = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    rng = np.random.default_rng(1)
    offsets = np.column_stack([rng.uniform(-0.04, 0.04, rows), rng.uniform(-0.05, 0.09, rows)])
    base = (0.0, 0.06, 0.02)
    start = time.perf_counter()
    sweep = hybrid.hand_sweep(["circle:%r,%r,%r" % base], offsets, threads=threads)
    batched = time.perf_counter() - start
    start = time.perf_counter()
    for dx, dy in offsets:
        try:
            hybrid.hand(["circle:%r,%r,%r" % (base[0] + dx, base[1] + dy, base[2])])
        except ValueError:
            pass
    single = time.perf_counter() - start
    statuses = dict(zip(*np.unique(sweep["status"], return_counts=True)))
    print(f"{rows} positions: hand_sweep ({threads} threads) {batched:.3f} s, "
          f"hand() per position {single:.3f} s, ratio {single / batched:.1f}")
    print("statuses:", ", ".join(f"{k} {v}" for k, v in sorted(statuses.items())))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""The Python module's finger against the command line and a plain-Python finger, in one run.

For N motor positions (default 10^6, uniform in [0, 255], fixed seed) and each contact case:
  1. hybrid.finger_angles(g, ...) (the C++ closed form, vectorised);
  2. `hybrid finger --queries FILE` (one process for the whole batch, CSV out): the largest
     difference in any angle must be <= 1e-9;
  3. tools/report_finger.py, a plain-Python quasistatic finger written apart from the C++ (the
     report's tables, like Klamp't's emulator), one query at a time on the first --python-queries
     positions: the largest difference (<= 1e-9 expected) and the time per query of both.
Each timing is the best of --repeat runs after one untimed warm-up run (and one untimed call of
every case at the start). Prints a table and the
speed ratio (plain Python time per query / hybrid's); exits 1 if an
agreement check fails (never on timings: they are measured, not asserted).

Usage: PYTHONPATH=build/python /usr/bin/python3 tools/bench_python_finger.py [--n N]
       [--python-queries M] [--hybrid build/bin/hybrid] [--repeat R]
"""

import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import report_finger  # noqa: E402

import hybrid  # noqa: E402

CASES = [
    ("free", {}),
    ("gob1=80", {"gob1": 80.0}),
    ("gob1=80 gob2=150", {"gob1": 80.0, "gob2": 150.0}),
    ("gob2=50", {"gob2": 50.0}),
    ("gob1=100 gob2=140 gob3=220", {"gob1": 100.0, "gob2": 140.0, "gob3": 220.0}),
]


def cli_angles(binary, g, contacts, folder):
    path = os.path.join(folder, "queries.csv")
    np.savetxt(path, g, fmt="%.17g", header="g", comments="")
    command = [binary, "finger", "--queries", path]
    for k, v in contacts.items():
        command += ["--" + k, repr(v)]
    out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    rows = list(csv.DictReader(out.splitlines()))
    return np.array([[float(r["theta1"]), float(r["theta2"]), float(r["theta3"])] for r in rows])


def best_time(f, repeat):
    f()  # warm-up, untimed: first-call costs (allocator growth, page faults, threads)
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        result = f()
        best = min(best, time.perf_counter() - start)
    return best, result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=1000000, help="motor positions (default 10^6)")
    parser.add_argument("--python-queries", type=int, default=100000,
                        help="positions the plain-Python finger answers (default 10^5)")
    parser.add_argument("--hybrid", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "build", "bin", "hybrid"))
    parser.add_argument("--repeat", type=int, default=5, help="timing runs, best kept (default 5)")
    args = parser.parse_args()
    if args.n < 1 or not 1 <= args.python_queries <= args.n or args.repeat < 1:
        parser.error("need n >= python-queries >= 1 and repeat >= 1")
    g = np.random.default_rng(20261124).uniform(0.0, 255.0, args.n)
    failed = False
    total_ours = total_python = 0.0
    print("%-28s %12s %12s %14s %14s" % ("case", "max |d| cli", "max |d| py", "ours ns/query",
                                        "python ns/query"))
    # Process warm-up, untimed: the first calls of a process pay for the allocator growing the
    # heap to the 24 MB results and for the first threads; without this the first case measured
    # would carry them.
    for _, contacts in CASES:
        hybrid.finger_angles(g, **contacts)
    with tempfile.TemporaryDirectory() as folder:
        for name, contacts in CASES:
            t_ours, ours = best_time(lambda: hybrid.finger_angles(g, **contacts), args.repeat)
            cli = cli_angles(args.hybrid, g, contacts, folder)
            m = args.python_queries
            sub = g[:m].tolist()
            t_py, ref = best_time(
                lambda: [report_finger.finger_angles(x, **contacts) for x in sub], args.repeat)
            d_cli = float(np.abs(ours - cli).max())
            d_py = float(np.abs(ours[:m] - np.array(ref)).max())
            failed = failed or not (d_cli <= 1e-9 and d_py <= 1e-9)
            ns_ours, ns_py = t_ours / args.n * 1e9, t_py / m * 1e9
            total_ours += ns_ours
            total_python += ns_py
            print("%-28s %12.3g %12.3g %14.2f %14.1f" % (name, d_cli, d_py, ns_ours, ns_py))
    print("speed: plain Python / hybrid.finger_angles per query = %.0f (mean over the cases)"
          % (total_python / total_ours))
    print("agreement: " + ("FAILED" if failed else "every angle within 1e-9 of both references"))
    single_call_ratio(args.repeat)
    return 1 if failed else 0


def single_call_ratio(repeat):
    """One position per call, as a controller's loop asks: hybrid.finger_angles(g) (its scalar
    path) against the plain-Python finger, best of `repeat` timings of 20000 calls each."""
    import timeit
    calls = 20000
    for name, contacts in (("free", {}), ("gob1=80", {"gob1": 80.0})):
        ours = min(timeit.repeat(lambda: hybrid.finger_angles(100.0, **contacts), number=calls,
                                 repeat=max(repeat, 1))) / calls
        theirs = min(timeit.repeat(lambda: report_finger.finger_angles(100.0, **contacts),
                                   number=calls, repeat=max(repeat, 1))) / calls
        print("single call, %-8s hybrid %.0f ns, plain Python %.0f ns: hybrid / Python = %.2f"
              % (name, ours * 1e9, theirs * 1e9, ours / theirs))


if __name__ == "__main__":
    sys.exit(main())

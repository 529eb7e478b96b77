#!/usr/bin/env python3
"""Runs the expression benchmark once and prints, per expression, the compiled IR's time against
the same expression written in C++ (median CPU time of the repetitions in one run).

usage: tools/bench_expression.py [BUILD_DIR]   (default: build)
Exit status 1 if any ratio exceeds 3 (the target of docs/benchmarks.md), so the script can gate.
"""
import json
import statistics
import subprocess
import sys

build = sys.argv[1] if len(sys.argv) > 1 else "build"
out = subprocess.run(
    [f"{build}/benchmarks/expression_benchmark", "--benchmark_format=json",
     "--benchmark_repetitions=7", "--benchmark_report_aggregates_only=false",
     "--benchmark_filter=Compiled|Native"],
    check=True, capture_output=True, text=True).stdout
runs = {}
for b in json.loads(out)["benchmarks"]:
    if b.get("run_type") != "iteration":
        continue
    kind, case = b["run_name"].split("/")
    runs.setdefault((kind, b.get("label", case)), []).append(b["cpu_time"])

worst = 0.0
print(f"{'expression':<16} {'compiled ns':>12} {'C++ ns':>8} {'ratio':>6}")
for (kind, label), times in sorted(runs.items()):
    if kind != "BM_Compiled":
        continue
    compiled = statistics.median(times)
    native = statistics.median(runs[("BM_Native", label)])
    ratio = compiled / native
    worst = max(worst, ratio)
    print(f"{label:<16} {compiled:12.2f} {native:8.2f} {ratio:6.2f}")
print(f"worst ratio {worst:.2f} (target <= 3)")
sys.exit(0 if worst <= 3.0 else 1)

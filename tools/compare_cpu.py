#!/usr/bin/env python3
"""CPU time of one command line run by two builds of `hybrid`, interleaved, and their ratio.

Runs `OLD ARGS...` and `NEW ARGS...` alternately --runs times each (the two in turn, so that a
change in the machine's speed during the measurement falls on both), and prints each run's
user + system CPU seconds of the child process (getrusage), the medians and the ratio
old / new. Both must exit with the same status each time; their standard outputs are
compared too (--same-output), except lines that contain a wall-clock figure, given by
--ignore (a regular expression, default: lines with "seconds", "time:" or a figure in s).

Usage: tools/compare_cpu.py OLD NEW [--runs N] [--same-output] [--ignore REGEX] -- ARGS...
Example (the diagnosis of the demo, a build of an earlier commit against this one):
  tools/compare_cpu.py /tmp/hybrid_before build/bin/hybrid --runs 5 -- \\
      diagnose data/finger_demo.csv --quiet --threads 1
Exits 1 if a status differs (or, with --same-output, an output), 2 on a usage error.
"""

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys


def run(command):
    """Runs `command`; returns (CPU seconds of the child, exit status, standard output)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, done.returncode, done.stdout.decode(errors="replace")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("old", help="the reference build's hybrid")
    parser.add_argument("new", help="the build measured")
    parser.add_argument("--runs", type=int, default=5, help="runs of each (default 5)")
    parser.add_argument("--same-output", action="store_true",
                        help="the standard outputs must be equal (but for --ignore lines)")
    parser.add_argument("--ignore", default=r"seconds|time:|[0-9] s\b",
                        help="lines of the output left out of the comparison (regex)")
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    options = parser.parse_args(argv[:split])
    args = argv[split + 1:]
    if not args or options.runs < 1:
        parser.error("give the arguments after -- and --runs >= 1")
    for binary in (options.old, options.new):
        if not os.access(binary, os.X_OK):
            parser.error(binary + ": not an executable")
    ignore = re.compile(options.ignore)

    def kept(text):
        return [line for line in text.splitlines() if not ignore.search(line)]

    times = {"old": [], "new": []}
    failed = False
    for i in range(options.runs):
        results = {}
        for name, binary in (("old", options.old), ("new", options.new)):
            cpu, status, out = run([binary] + args)
            times[name].append(cpu)
            results[name] = (status, out)
            print("run %d %s: %.3f s CPU, exit %d" % (i + 1, name, cpu, status))
        if results["old"][0] != results["new"][0]:
            print("exit statuses differ: %d and %d" % (results["old"][0], results["new"][0]))
            failed = True
        if options.same_output and kept(results["old"][1]) != kept(results["new"][1]):
            print("outputs differ in run %d" % (i + 1))
            failed = True
    old = statistics.median(times["old"])
    new = statistics.median(times["new"])
    print("median CPU: old %.3f s (%.3f-%.3f), new %.3f s (%.3f-%.3f)" %
          (old, min(times["old"]), max(times["old"]), new, min(times["new"]),
           max(times["new"])))
    print("ratio old / new: %.2f" % (old / new if new > 0 else float("inf")))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

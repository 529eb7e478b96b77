#!/usr/bin/env python3
"""Runs the linear-hybrid-automata benchmarks of spec/benchmarks/ through `hybrid check --json`
and compares every verdict with spec/benchmarks/expected.tsv (docs/benchmarks_lha.md).

usage: tools/benchmarks.py [options] [BENCHMARK ...]

BENCHMARK is a file of spec/benchmarks/ (`nav2.ha`, or `nav2`) or a path to a model; default:
every file listed in expected.tsv, in its order. The models run one after the other (timings
are wall times on a machine that may be doing other things: compare them on an idle one).

Output: one row per property: file, property, expected, got, method, seconds (the tool's own
time for the property, as `hybrid check --json` reports it: the properties one reachability
run decides share its time), status:
  OK        the verdict is the expected one
  MISMATCH  a decided verdict (proved, violated, reachable, unreachable) other than the
            expected one
  UNKNOWN   no decided verdict: `unknown` (the tool's reason is listed below the table), a proof
            of the runs up to a time only (`proved within T`, `unreachable within T`: not the
            unbounded property's verdict), or the run timed out (`timeout`), failed (`error`)
            or did not report the property (`missing`)
  -         a decided verdict for a property expected.tsv does not list (expected `-`)
Then the unknowns with their reasons and the total time.

Exit status: 0; 1 if some status is MISMATCH (with --require-all: also if some is UNKNOWN);
2 on a usage error (an unknown benchmark, no `hybrid` binary).

--peer-command TEMPLATE runs a peer tool once per model for comparison, e.g.
  --peer-command 'peer_checker --model {model}'   ({model}: the model's path, shell-quoted;
  {name}: the model's file name without .ha)
through the shell, with the same --timeout, and prints its wall and CPU times (user + system, of
the command and what it waited for) and the ratios of ours (the whole `hybrid check` process) to
the peer's. The peer's verdicts are not read. --repeat N runs each model N times, ours and the
peer's in turns, and reports the medians.

--per-property runs `hybrid check --property P` once per expected property, and the peer command
(which may then name {property}) once per property too, for tools that check one property per
run (Flow*: one unsafe set per model file). The peer's verdict is the last word SAFE, UNSAFE or
UNKNOWN in its output (Flow*'s), shown beside ours with both wall times and their ratio; a run
whose output has none of them ("-": the peer cannot state that property) is not compared. E.g.
  tools/benchmarks.py --expected spec/benchmarks/expected_flowpipe.tsv --per-property \
      --peer-command '/path/to/run_one.sh {name}_{property}'
"""
import argparse
import json
import os
import re
import resource
import shlex
import signal
import subprocess
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCHMARKS = os.path.join(REPO, "spec", "benchmarks")
EXPECTED = os.path.join(BENCHMARKS, "expected.tsv")

# The quick subset (--quick): models whose every verdict is decided and as expected today
# (docs/benchmarks_lha.md), about 10 s together on this 2-core machine under load (fischer_5.ha
# and tte_5.ha take most of it). The test BenchmarksTest.QuickSubsetIsDecidedAsExpected runs
# `--quick --require-all`, so only fully decided models belong here. Left out: the model with
# an unknown verdict (fischer_6) and the decided but slow ones (fiscs05, tte_7: 9 to 30 s each).
QUICK = [
    "water_tank.ha",
    "nav2.ha",
    "nav3.ha",
    "nav4.ha",
    "fischer_2.ha",
    "fischer_2_unsafe.ha",
    "fischer_3.ha",
    "fischer_3_unsafe.ha",
    "fischer_4.ha",
    "fischer_4_unsafe.ha",
    "fischer_5.ha",
    "fiscs04.ha",
    "fiscu04.ha",
    "tte_5.ha",
    "disc_2.ha",
    "disc_3.ha",
]

DECIDED = {"proved", "violated", "reachable", "unreachable"}


def read_expected(path):
    """{file: [(property, verdict), ...]} in the file's order (dicts keep insertion order)."""
    expected = {}
    with open(path) as f:
        for number, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if not line.strip() or line.startswith("#"):
                continue
            fields = line.split("\t")
            if fields[0] == "file":
                continue  # the header
            if len(fields) != 3:
                sys.exit("%s:%d: expected 3 tab-separated columns" % (path, number))
            expected.setdefault(fields[0], []).append((fields[1], fields[2]))
    return expected


def resolve(name, expected):
    """(path, key in expected.tsv) of a benchmark named on the command line."""
    for candidate in (name, name + ".ha"):
        if candidate in expected or os.path.isfile(os.path.join(BENCHMARKS, candidate)):
            return os.path.join(BENCHMARKS, candidate), candidate
    if os.path.isfile(name):
        return name, os.path.basename(name)
    raise ValueError("no benchmark %r (neither in %s nor a file)" % (name, BENCHMARKS))


def kill_group(process):
    """Kills the process and everything it started (it leads its own session)."""
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def terminated(signum, frame):
    """SIGTERM (e.g. ctest's timeout) unwinds like Ctrl-C, so run() kills its process group."""
    raise KeyboardInterrupt("signal %d" % signum)


def run(command, timeout, shell=False):
    """(exit code or None on timeout, stdout, stderr, wall seconds, CPU seconds); the whole
    process group is killed after `timeout` seconds. The CPU seconds (user + system) are those of
    the command and of every process it waited for: the change of RUSAGE_CHILDREN across the run
    (the runs are one at a time); a process group killed at the timeout loses its children's."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    process = subprocess.Popen(command, shell=shell, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                               start_new_session=True)
    try:
        out, err = process.communicate(timeout=timeout)
        code = process.returncode
    except subprocess.TimeoutExpired:
        kill_group(process)
        out, err = process.communicate()
        code = None
    except BaseException:  # interrupted (Ctrl-C, SIGTERM): leave no process behind
        kill_group(process)
        process.wait()
        raise
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return code, out.decode(errors="replace"), err.decode(errors="replace"), wall, cpu


def peer_verdict(text):
    """The last SAFE, UNSAFE or UNKNOWN word of a peer's output, or "-"."""
    found = re.findall(r"\b(SAFE|UNSAFE|UNKNOWN)\b", text)
    return found[-1] if found else "-"


def peer_template(template, path, prop=None):
    name = os.path.splitext(os.path.basename(path))[0]
    command = template.replace("{model}", shlex.quote(path)).replace("{name}", name)
    return command.replace("{property}", prop) if prop is not None else command


def check_model(hybrid, path, key, properties, args, only=None):
    """The rows of one model (dicts) and our wall time (of property `only` alone if given)."""
    command = [hybrid, "check", path, "--json"]
    if only is not None:
        command += ["--property", only]
        properties = [(n, v) for n, v in properties if n == only]
    if args.budget is not None:
        command += ["--budget", str(args.budget)]
    if args.method:
        command += ["--method", args.method]
    code, out, err, wall, cpu = run(command, args.timeout)
    reported = {}
    failure = None
    if code is None:
        failure = ("timeout", "killed after the --timeout of %g s" % args.timeout)
    else:
        try:
            reported = {p["name"]: p for p in json.loads(out)["properties"]}
        except (ValueError, KeyError, TypeError):
            message = err.strip().splitlines()[-1] if err.strip() else "no JSON output"
            failure = ("error", "exit code %d: %s" % (code, message[:300]))
    rows = []
    names = [name for name, _ in properties]
    names += [name for name in reported if name not in dict(properties)]
    if not names and failure is not None:
        names = ["-"]  # a model without expected properties that failed: still one row
    for name in names:
        want = dict(properties).get(name, "-")
        p = reported.get(name)
        if p is not None:
            got, method = p.get("verdict", "?"), p.get("method", "-")
            seconds, reason = p.get("seconds"), p.get("reason", "")
            if "verdict_within" in p:
                # A proof of the runs up to a time only ("proved within T"): not the verdict of
                # the unbounded property, so undecided here.
                got = "%s within %g" % (got, p["verdict_within"])
        elif failure is not None:
            (got, reason), method, seconds = failure, "-", None
        else:
            got, method, seconds, reason = "missing", "-", None, "not in the tool's output"
        if got not in DECIDED:
            status = "UNKNOWN"
        elif want == "-":
            status = "-"
        elif got == want:
            status = "OK"
        else:
            status = "MISMATCH"
        rows.append({"file": key, "property": name, "expected": want, "got": got,
                     "method": method, "seconds": seconds, "status": status, "reason": reason})
    return rows, wall, cpu


def median(values):
    ordered = sorted(values)
    middle = len(ordered) // 2
    return ordered[middle] if len(ordered) % 2 else (ordered[middle - 1] + ordered[middle]) / 2


def compare_model(path, key, properties, args, only=None):
    """The rows of one model (its first run; of property `only` alone if given) and its entry of
    "models": our wall and CPU seconds and, with --peer-command, the peer's (and the verdict in
    its last output), each the median of --repeat runs made in turns (ours, the peer's, ours,
    ...), so that a change of the machine's load falls on both."""
    rows, walls, cpus, peer_walls, peer_cpus, peer_codes = None, [], [], [], [], []
    peer_output = ""
    for _ in range(args.repeat):
        model_rows, wall, cpu = check_model(args.hybrid, path, key, properties, args, only=only)
        rows = rows if rows is not None else model_rows
        walls.append(wall)
        cpus.append(cpu)
        if args.peer_command:
            command = peer_template(args.peer_command, path, only)
            code, out, err, peer_wall, peer_cpu = run(command, args.timeout, shell=True)
            peer_output = out + err
            peer_walls.append(peer_wall)
            peer_cpus.append(peer_cpu)
            peer_codes.append(code)
    entry = {"file": key, "seconds": median(walls), "cpu_seconds": median(cpus),
             "runs": args.repeat}
    if only is not None:
        entry["property"] = only
    if args.peer_command:
        peer, peer_cpu = median(peer_walls), median(peer_cpus)
        # A timeout in any run counts (None); else the last run's exit code.
        code = None if None in peer_codes else peer_codes[-1]
        entry.update({"peer_seconds": peer, "peer_cpu_seconds": peer_cpu,
                      "peer_exit_code": code, "peer_verdict": peer_verdict(peer_output),
                      "ratio": entry["seconds"] / peer if peer > 0 else None,
                      # A peer killed at the timeout was not waited for: its CPU time is lost.
                      "cpu_ratio": entry["cpu_seconds"] / peer_cpu
                      if peer_cpu > 0 and code is not None else None})
    return rows, entry


def format_row(row, widths):
    seconds = "-" if row["seconds"] is None else "%.3f" % row["seconds"]
    cells = [row["file"], row["property"], row["expected"], row["got"], row["method"], seconds,
             row["status"]]
    return "  ".join(c.ljust(w) if i != 5 else c.rjust(w)
                     for i, (c, w) in enumerate(zip(cells, widths))).rstrip()


def main():
    parser = argparse.ArgumentParser(
        description="Runs `hybrid check --json` on the benchmarks of spec/benchmarks/ and "
                    "compares the verdicts with spec/benchmarks/expected.tsv.",
        epilog="Exit status: 0; 1 if a decided verdict contradicts the expected one (with "
               "--require-all: also if a verdict is unknown, timed out or failed); 2 on a "
               "usage error. Quick subset: " + " ".join(QUICK) + ".")
    parser.add_argument("benchmarks", nargs="*", metavar="BENCHMARK",
                        help="file of spec/benchmarks/ (nav2.ha or nav2) or path to a model "
                             "(default: every file of expected.tsv)")
    parser.add_argument("--quick", action="store_true",
                        help="the quick subset (fully decided models, under 60 s in all)")
    parser.add_argument("--hybrid", default=os.path.join(REPO, "build", "bin", "hybrid"),
                        help="the hybrid binary (default: build/bin/hybrid of the repository)")
    parser.add_argument("--budget", type=float,
                        help="passed to `hybrid check --budget` (default: the tool's)")
    parser.add_argument("--method", choices=["auto", "reach", "flowpipe", "prove", "sample"],
                        help="passed to `hybrid check --method` (default: the tool's, auto)")
    parser.add_argument("--timeout", type=float, default=600,
                        help="seconds per model before its process is killed (default 600)")
    parser.add_argument("--json", action="store_true", help="machine-readable output")
    parser.add_argument("--require-all", action="store_true",
                        help="an undecided verdict (unknown, timeout, error) is a failure too")
    parser.add_argument("--peer-command", metavar="TEMPLATE",
                        help="shell command of a peer tool, {model} replaced by the model's "
                             "path; its wall and CPU times and the ratios ours/peer are printed")
    parser.add_argument("--repeat", type=int, default=1, metavar="N",
                        help="run each model N times (in turns with the peer's) and report the "
                             "medians of the wall and CPU times (default 1)")
    parser.add_argument("--per-property", action="store_true",
                        help="one run per property, ours (--property) and the peer's "
                             "({property} in its template)")
    parser.add_argument("--expected", default=EXPECTED,
                        help="the table of expected verdicts (default: spec/benchmarks/"
                             "expected.tsv)")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")
    signal.signal(signal.SIGTERM, terminated)

    expected = read_expected(args.expected)
    names = list(args.benchmarks)
    if args.quick:
        names += [q for q in QUICK if q not in names]
    if not names:
        names = list(expected)
    try:
        models = [resolve(name, expected) for name in names]
    except ValueError as error:
        parser.error(str(error))
    if not (os.path.isfile(args.hybrid) and os.access(args.hybrid, os.X_OK)):
        parser.error("no executable %s (build it: cmake --build build --target hybrid)"
                     % args.hybrid)

    widths = [max([len("file")] + [len(k) for _, k in models]),
              max([len("property")] + [len(p) for _, k in models
                                       for p, _ in expected.get(k, [])]),
              len("unreachable"), len("unreachable"), len("method"), 8, len("MISMATCH")]
    header = ["file", "property", "expected", "got", "method", "seconds", "status"]
    if not args.json:
        print("  ".join(h.ljust(w) if i != 5 else h.rjust(w)
                        for i, (h, w) in enumerate(zip(header, widths))).rstrip())
        print("  ".join("-" * w for w in widths))
        sys.stdout.flush()

    start = time.monotonic()
    rows, per_model = [], []
    for path, key in models:
        if args.per_property:
            for prop, _ in expected.get(key, []):
                model_rows, entry = compare_model(path, key, expected.get(key, []), args,
                                                  only=prop)
                ours = entry["seconds"]
                rows += model_rows
                if args.peer_command:
                    # A property the peer has no run for ("-") is not compared.
                    if entry["peer_verdict"] == "-":
                        entry["ratio"] = entry["cpu_ratio"] = None
                    for r in model_rows:
                        r["peer_verdict"] = entry["peer_verdict"]
                per_model.append(entry)
                if not args.json:
                    for row in model_rows:
                        widths[1] = max(widths[1], len(row["property"]))
                        print(format_row(row, widths))
                    if args.peer_command:
                        ratio = "-" if entry["ratio"] is None else "%.3g" % entry["ratio"]
                        cpu_ratio = ("-" if entry["cpu_ratio"] is None
                                     else "%.3g" % entry["cpu_ratio"])
                        print("    peer: %s in %.3f s%s; ours %.3f s; ours/peer %s; CPU ours "
                              "%.3f s, peer %.3f s, ours/peer %s%s"
                              % (entry["peer_verdict"], entry["peer_seconds"],
                                 "" if entry["peer_exit_code"] is not None else " (timeout)",
                                 ours, ratio, entry["cpu_seconds"], entry["peer_cpu_seconds"],
                                 cpu_ratio,
                                 "" if args.repeat == 1 else " (medians of %d)" % args.repeat))
                    sys.stdout.flush()
            continue
        model_rows, entry = compare_model(path, key, expected.get(key, []), args)
        rows += model_rows
        ours = entry["seconds"]
        per_model.append(entry)
        if not args.json:
            for row in model_rows:
                widths[1] = max(widths[1], len(row["property"]))
                print(format_row(row, widths))
            if args.peer_command:
                status = ("timeout" if entry["peer_exit_code"] is None
                          else "exit %d" % entry["peer_exit_code"])
                ratio = "-" if entry["ratio"] is None else "%.3g" % entry["ratio"]
                cpu_ratio = "-" if entry["cpu_ratio"] is None else "%.3g" % entry["cpu_ratio"]
                print("  %s: ours %.3f s, peer %.3f s (%s), ours/peer %s; CPU ours %.3f s, "
                      "peer %.3f s, ours/peer %s%s"
                      % (key, ours, entry["peer_seconds"], status, ratio, entry["cpu_seconds"],
                         entry["peer_cpu_seconds"], cpu_ratio,
                         "" if args.repeat == 1 else " (medians of %d)" % args.repeat))
            sys.stdout.flush()
    total = time.monotonic() - start

    counts = {s: sum(r["status"] == s for r in rows) for s in ("OK", "MISMATCH", "UNKNOWN")}
    failed = counts["MISMATCH"] > 0 or (args.require_all and counts["UNKNOWN"] > 0)
    if args.json:
        json.dump({"hybrid": args.hybrid, "total_seconds": total, "counts": counts,
                   "require_all": args.require_all, "ok": not failed, "models": per_model,
                   "properties": rows}, sys.stdout, indent=2)
        print()
    else:
        undecided = [r for r in rows if r["status"] in ("MISMATCH", "UNKNOWN")]
        if undecided:
            print("\nUnknown and contradicted verdicts, with the tool's reason:")
            for r in undecided:
                print("  %s %s: %s (expected %s): %s"
                      % (r["file"], r["property"], r["got"], r["expected"], r["reason"]))
        print("\nWall time per %s (s): " % ("property" if args.per_property else "model")
              + ", ".join("%s%s %.2f" % (m["file"], ":" + m["property"] if "property" in m
                                         else "", m["seconds"]) for m in per_model))
        print("\n%d properties in %d models: %d OK, %d MISMATCH, %d UNKNOWN; total %.1f s"
              % (len(rows), len(models), counts["OK"], counts["MISMATCH"], counts["UNKNOWN"],
                 total))
        if args.peer_command:
            ours = sum(m["seconds"] for m in per_model)
            peer = sum(m["peer_seconds"] for m in per_model)
            print("wall time: ours %.1f s, peer %.1f s, ours/peer %s"
                  % (ours, peer, "%.3g" % (ours / peer) if peer > 0 else "-"))
            compared = [m for m in per_model if m.get("cpu_ratio") is not None]
            ours_cpu = sum(m["cpu_seconds"] for m in compared)
            peer_cpu = sum(m["peer_cpu_seconds"] for m in compared)
            print("CPU time of the %d runs compared: ours %.1f s, peer %.1f s, ours/peer %s"
                  % (len(compared), ours_cpu, peer_cpu,
                     "%.3g" % (ours_cpu / peer_cpu) if peer_cpu > 0 else "-"))
            cpu_ratios = sorted(m["cpu_ratio"] for m in compared)
            if cpu_ratios:
                print("CPU ratio ours/peer per run: max %.3g, median %.3g; %d of %d at most 1, "
                      "%d at most 1.5" % (cpu_ratios[-1], median(cpu_ratios),
                                         sum(r <= 1 for r in cpu_ratios),
                                         len(cpu_ratios), sum(r <= 1.5 for r in cpu_ratios)))
            ratios = [m["ratio"] for m in per_model if m.get("ratio")]
            if ratios:
                print("ratio ours/peer per run: max %.3g, median %.3g; %d of %d runs faster than "
                      "the peer" % (max(ratios), sorted(ratios)[len(ratios) // 2],
                                    sum(r < 1 for r in ratios), len(ratios)))
    return 1 if failed else 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(130)

#!/usr/bin/env python3
"""Compares one close-then-open cycle of the finger (spec/finger.ha, default scenario) simulated by
our Simulator with the same hybrid automaton simulated in Python by scipy's solve_ivp, at equal
event accuracy, and prints the speed ratio.

usage: tools/compare_scipy.py [BUILD_DIR]   (default: build)

Our side: BUILD_DIR/benchmarks/simulation_benchmark --benchmark_filter=FingerCycle (Google
Benchmark, the Simulator built once, one Simulator::Run per iteration, default options; median of
the repetitions). Its counter max_event_error is the largest distance of its event times from the
analytic 110, 140, 240, 265, 365, 395.

scipy's side: the modes the scenario visits (c000_l000, c000_l00n, c000_l10n, c000_l11n) with
their flows and every outgoing guard of spec/finger.ha, solve_ivp (RK45, rtol 1e-10, atol 1e-12,
our defaults) with one terminal event function per state comparison of a guard, in the guard's
crossing direction (>=: rising, <=: falling, ==: both), restarted after every jump and at every
input breakpoint (255, 265, 505). Guards are checked in their closure within 1e-9 at an event and
strictly on entry and at breakpoints (our semantics). A transition whose input condition (u > 0,
u < 0, m1 u > 0, ...) is false on a segment gets no event function there, and mode invariants are
not monitored: both only make scipy's side cheaper, so the ratio is conservative. Timed with
time.perf_counter over repeated runs in this process (median).

From Python (as a roboticist calls it): hybrid.load("spec/finger.ha") once (the module of
BUILD_DIR/python), then Model.simulate() of the same cycle per call, timed like scipy's side in this
process (median), its event times checked against the analytic ones; the ratio printed beside the
C++ one. Skipped with a note if the module is not built.

Exit status 1 if any side misses the analytic event times by more than 1e-9 or visits other
modes, or if ours (from C++, and from Python when built) is less than 100 times faster (the
target of docs/benchmarks.md).
"""
import json
import os
import statistics
import subprocess
import sys
import time

try:
    import numpy as np
    from scipy.integrate import solve_ivp
    import scipy
except ImportError as error:
    # Debian's python3-scipy installs for /usr/bin/python3; `python3` may be another interpreter
    # (pyenv). Retry once with the system one.
    SYSTEM_PYTHON = "/usr/bin/python3"
    if (os.access(SYSTEM_PYTHON, os.X_OK) and os.path.realpath(sys.executable) !=
            os.path.realpath(SYSTEM_PYTHON) and "COMPARE_SCIPY_REEXEC" not in os.environ):
        os.environ["COMPARE_SCIPY_REEXEC"] = "1"
        os.execv(SYSTEM_PYTHON, [SYSTEM_PYTHON, os.path.abspath(__file__)] + sys.argv[1:])
    sys.exit(f"compare_scipy.py: needs scipy and numpy ({error}); install them with "
             "`apt-get install python3-scipy python3-numpy` (tools/setup.sh lists them)")

TOL = 1e-9  # event-time accuracy required of both sides
ANALYTIC = [110.0, 140.0, 240.0, 265.0, 365.0, 395.0]
TARGET_RATIO = 100.0

# spec/finger.ha parameters.
THETA1_MIN, THETA1_MAX = 0.0, 70.0
THETA2_MIN, THETA2_MAX = 0.0, 90.0
THETA3_MIN, THETA3_MAX = -55.0, 43.0
M1, M2 = THETA1_MAX / 140, THETA2_MAX / 100
GOB1 = GOB2 = GOB3 = 256.0
# The scenario: u = step(0: 1, 255: 0, 265: -1, 505: 0), until 530.
U_POINTS = [(0.0, 1.0), (255.0, 0.0), (265.0, -1.0), (505.0, 0.0)]
UNTIL = 530.0

TH1, TH2, TH3, G = range(4)


def m3(g):
    return THETA3_MIN + (THETA3_MAX - THETA3_MIN) / (255 - g)


# Flows of the visited modes: dx/dt(x, u).
FLOWS = {
    "c000_l000": lambda x, u: np.array([M1 * u, 0.0, -(M1 * u), u]),
    "c000_l00n": lambda x, u: np.array([M1 * u, 0.0, 0.0, u]),
    "c000_l10n": lambda x, u: np.array([0.0, M2 * u, 0.0, u]),
    "c000_l11n": lambda x, u: np.zeros(4),
}

# Outgoing transitions of the visited modes, in declaration order: (name, target, state
# comparisons as (residual(x) = lhs - rhs, relation), input condition on u). The targets outside
# the visited modes are never reached in this scenario (the script checks the mode sequence).
GE, LE, EQ = ">=", "<=", "=="
TRANSITIONS = {
    "c000_l000": [
        ("t1_c000_l000_to_c100_l000", "c100_l000", [(lambda x: x[G] - GOB1, GE)], lambda u: u > 0),
        ("t3_c000_l000_to_c000_l100", "c000_l100", [(lambda x: x[TH1] - THETA1_MAX, GE)],
         lambda u: M1 * u > 0),
        ("t1_c000_l000_to_c010_l000", "c010_l000", [(lambda x: x[G] - GOB2, GE)], lambda u: u > 0),
        ("t1_c000_l000_to_c001_l000", "c001_l000", [(lambda x: x[G] - GOB3, GE)], lambda u: u > 0),
        ("t5_c000_l000_to_c000_l00n", "c000_l00n", [(lambda x: x[TH3] - THETA3_MIN, LE)],
         lambda u: -(M1 * u) < 0),
    ],
    "c000_l00n": [
        ("t1_c000_l00n_to_c100_l00n", "c100_l00n", [(lambda x: x[G] - GOB1, GE)], lambda u: u > 0),
        ("t3_c000_l00n_to_c000_l10n", "c000_l10n", [(lambda x: x[TH1] - THETA1_MAX, GE)],
         lambda u: M1 * u > 0),
        ("t1_c000_l00n_to_c010_l000", "c010_l000", [(lambda x: x[G] - GOB2, GE)], lambda u: u > 0),
        ("t1_c000_l00n_to_c001_l00n", "c001_l00n", [(lambda x: x[G] - GOB3, GE)], lambda u: u > 0),
        ("t6_c000_l00n_to_c000_l000", "c000_l000",
         [(lambda x: x[TH1] + x[TH2] - (-THETA3_MIN), LE)], lambda u: u < 0),
    ],
    "c000_l10n": [
        ("t4_c000_l10n_to_c000_l00n", "c000_l00n", [(lambda x: x[TH2] - THETA2_MIN, EQ)],
         lambda u: u < 0),
        ("t1_c000_l10n_to_c010_l100", "c010_l100", [(lambda x: x[G] - GOB2, GE)], lambda u: u > 0),
        ("t3_c000_l10n_to_c000_l11n", "c000_l11n", [(lambda x: x[TH2] - THETA2_MAX, GE)],
         lambda u: M2 * u > 0),
        ("t1_c000_l10n_to_c001_l10n", "c001_l10n", [(lambda x: x[G] - GOB3, GE)], lambda u: u > 0),
        ("t6_c000_l10n_to_c000_l100", "c000_l100",
         [(lambda x: x[TH1] + x[TH2] - (-THETA3_MIN), LE)], lambda u: u < 0),
    ],
    "c000_l11n": [
        ("t4_c000_l11n_to_c000_l010", "c000_l010", [(lambda x: x[TH2] - THETA2_MIN, EQ)],
         lambda u: u < 0),
        ("t4_c000_l11n_to_c000_l10n", "c000_l10n", [(lambda x: x[TH3] - THETA3_MIN, EQ)],
         lambda u: u < 0),
        ("t6_c000_l11n_to_c000_l110", "c000_l110",
         [(lambda x: x[TH1] + x[TH2] - (-THETA3_MIN), LE)], lambda u: u < 0),
    ],
}
DIRECTION = {GE: 1.0, LE: -1.0, EQ: 0.0}


def holds(relation, r, closure):
    """Our Holds(): `closure` takes each comparison within TOL (all relations here are non-strict
    or ==, so closure only matters through the tolerance, as in the Simulator)."""
    if relation == GE:
        return r >= -TOL
    if relation == LE:
        return r <= TOL
    return abs(r) <= TOL


def enabled(mode, x, u, closure):
    for name, target, comparisons, input_ok in TRANSITIONS[mode]:
        if input_ok(u) and all(holds(rel, res(x), closure) for res, rel in comparisons):
            return name, target
    return None


def simulate_scipy():
    """One run of the scenario; returns the events [(time, transition, source, target)]."""
    t, x, mode = 0.0, np.zeros(4), "c000_l000"
    breaks = [p[0] for p in U_POINTS[1:] if p[0] < UNTIL] + [UNTIL]
    events = []
    seg = 0  # index of the input segment [U_POINTS[seg], U_POINTS[seg + 1])

    def settle(u):  # event iteration on entry / at a breakpoint (strict check)
        nonlocal mode
        for _ in range(100):
            jump = enabled(mode, x, u, closure=False)
            if jump is None:
                return
            events.append((t, jump[0], mode, jump[1]))
            mode = jump[1]
        raise RuntimeError("event iteration does not settle")

    settle(U_POINTS[0][1])
    while t < UNTIL:
        u = U_POINTS[seg][1]
        t_stop = breaks[seg]
        # One terminal event function per state comparison of a transition possible under u.
        funcs, owners = [], []
        for k, (name, target, comparisons, input_ok) in enumerate(TRANSITIONS[mode]):
            if not input_ok(u):
                continue
            for res, rel in comparisons:
                f = (lambda res: lambda _t, y: res(y))(res)
                f.terminal = True
                f.direction = DIRECTION[rel]
                funcs.append(f)
                owners.append(k)
        flow = FLOWS[mode]
        sol = solve_ivp(lambda _t, y: flow(y, u), (t, t_stop), x, method="RK45", rtol=1e-10,
                        atol=1e-12, events=funcs or None)
        if sol.status < 0:
            raise RuntimeError(sol.message)
        t, x = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:  # a terminal event: fire the first transition enabled in closure
            jump = enabled(mode, x, u, closure=True)
            if jump is None:
                raise RuntimeError(f"event at t = {t} in {mode} with no enabled transition")
            events.append((t, jump[0], mode, jump[1]))
            mode = jump[1]
            settle(u)
        else:  # reached the breakpoint: the input jumps
            seg += 1
            if t < UNTIL:
                settle(U_POINTS[seg][1])
    return events


def median_seconds(call, seconds=3.0, least=5, most=50):
    """The median wall time of `call()` over at least `least` calls, up to `most` within about
    `seconds`."""
    samples = []
    deadline = time.perf_counter() + seconds
    while len(samples) < least or (time.perf_counter() < deadline and len(samples) < most):
        start = time.perf_counter()
        call()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples), len(samples)


def from_python(build):
    """(median seconds of Model.simulate() of the finger's cycle, its max event-time error), or
    None if BUILD_DIR/python has no module."""
    module_dir = os.path.join(build, "python")
    if not os.path.isdir(os.path.join(module_dir, "hybrid")):
        return None
    sys.path.insert(0, os.path.abspath(module_dir))
    import hybrid  # noqa: E402 (the build's module)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    model = hybrid.load(os.path.join(root, "spec", "finger.ha"))
    run = model.simulate()
    times = [e["time"] for e in run["events"]]
    error = (max(abs(a - b) for a, b in zip(times, ANALYTIC))
             if run["status"] == "completed" and len(times) == len(ANALYTIC) else float("inf"))
    seconds, _ = median_seconds(model.simulate, least=200, most=5000)
    return seconds, error


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    exe = os.path.join(build, "benchmarks", "simulation_benchmark")
    if not os.access(exe, os.X_OK):
        sys.exit(f"compare_scipy.py: {exe} not found; build the project first "
                 f"(cmake -S . -B {build} -G Ninja && ninja -C {build})")

    # Ours.
    out = subprocess.run(
        [exe, "--benchmark_filter=BM_FingerCycle$", "--benchmark_format=json",
         "--benchmark_repetitions=7", "--benchmark_min_time=0.2"],
        check=True, capture_output=True, text=True).stdout
    runs = [b for b in json.loads(out)["benchmarks"] if b.get("run_type") == "iteration"]
    if not runs or "error_occurred" in runs[0] and runs[0]["error_occurred"]:
        sys.exit("compare_scipy.py: BM_FingerCycle did not run: " +
                 str(runs[0].get("error_message") if runs else "no result"))
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[runs[0]["time_unit"]]
    ours = statistics.median(b["real_time"] * scale for b in runs)
    ours_error = runs[0]["max_event_error"]

    # scipy.
    events = simulate_scipy()
    times = [e[0] for e in events]
    path = [e[2] for e in events] + [events[-1][3]] if events else []
    expected_path = ["c000_l000", "c000_l00n", "c000_l10n", "c000_l11n", "c000_l10n",
                     "c000_l00n", "c000_l000"]
    ok = True
    if path != expected_path or len(times) != len(ANALYTIC):
        print(f"scipy: unexpected mode sequence {path}")
        ok = False
        scipy_error = float("inf")
    else:
        scipy_error = max(abs(a - b) for a, b in zip(times, ANALYTIC))
    theirs, count = median_seconds(simulate_scipy)
    python = from_python(build)

    ratio = theirs / ours
    print(f"finger close-then-open cycle (spec/finger.ha default scenario, 6 events)")
    print(f"  ours : {ours * 1e6:10.2f} us per cycle (median of {len(runs)} repetitions), "
          f"max event-time error {ours_error:.3g}")
    print(f"  scipy: {theirs * 1e6:10.2f} us per cycle (median of {count} runs, "
          f"scipy {scipy.__version__} solve_ivp RK45), max event-time error {scipy_error:.3g}")
    print(f"  ratio: ours is {ratio:.1f}x faster (target >= {TARGET_RATIO:g}x)")
    errors = [("ours", ours_error), ("scipy", scipy_error)]
    if python is None:
        print(f"  from Python: skipped ({build}/python has no module; build the target _hybrid)")
    else:
        python_ratio = theirs / python[0]
        print(f"  from Python: Model.simulate {python[0] * 1e6:10.2f} us per cycle (median), "
              f"max event-time error {python[1]:.3g}")
        print(f"  ratio from Python: ours is {python_ratio:.1f}x faster than scipy "
              f"(target >= {TARGET_RATIO:g}x)")
        errors.append(("ours from Python", python[1]))
        if python_ratio < TARGET_RATIO:
            print(f"FAIL: ratio from Python {python_ratio:.1f} below the target {TARGET_RATIO:g}")
            ok = False
    for name, err in errors:
        if not err <= TOL:
            print(f"FAIL: {name} event times miss the analytic ones by {err:.3g} > {TOL:g}")
            ok = False
    if ratio < TARGET_RATIO:
        print(f"FAIL: ratio {ratio:.1f} below the target {TARGET_RATIO:g}")
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

"""The bundled thermostat data (data/thermostat_*.csv, the example data of `hybrid diagnose`) and
their generator, tools/thermostat_trace.py, run by ctest (thermostat_data):

- every data file is written again, byte for byte, by the command in its first line;
- the generator is independent of the project (standard library only, never runs `hybrid`), and
  its noiseless traces, written from the closed form, agree with `hybrid simulate` (CVODE with
  event location) within 1e-6 degC at every sample, and its switching times with the simulator's
  events within 1e-6 min, on both models (spec/thermostat.ha, lazy; spec/thermostat_urgent.ha,
  urgent) for u = 10 and u = 5 over 60 minutes, with each data file's defect applied to the
  model: the heater by `--set p=2.4`, the switch-on level by a copy of the urgent model whose
  guard reads x <= 18.5, the sensor bias (which no model has) added to the simulated x."""

import ast
import csv
import glob
import json
import os
import shlex
import subprocess
import sys

import pytest

SOURCE = os.environ.get("HYBRID_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("HYBRID_BINARY", os.path.join(SOURCE, "build", "bin", "hybrid"))
PYTHON = "/usr/bin/python3"  # the interpreter the data files' commands name
GENERATOR = os.path.join(SOURCE, "tools", "thermostat_trace.py")
sys.path.insert(0, os.path.join(SOURCE, "tools"))
import thermostat_trace  # noqa: E402

DATA = ["thermostat_clean.csv", "thermostat_weak_heater.csv", "thermostat_sensor_bias.csv",
        "thermostat_threshold.csv"]
UNTIL, STEP, INPUTS = 60.0, 0.25, (10.0, 5.0)
TOLERANCE = 1e-6


def test_every_thermostat_data_file_is_listed():
    found = sorted(os.path.basename(p) for p in glob.glob(os.path.join(SOURCE, "data", "thermostat_*.csv")))
    assert found == sorted(DATA)


@pytest.mark.parametrize("name", DATA)
def test_data_file_is_regenerated_by_its_header_command(name):
    path = os.path.join(SOURCE, "data", name)
    with open(path, "rb") as f:
        committed = f.read()
    first = committed.split(b"\n", 1)[0].decode()
    assert first.startswith("# made by: /usr/bin/python3 tools/thermostat_trace.py "), first
    command = shlex.split(first[len("# made by: "):])
    out = subprocess.run(command, cwd=SOURCE, capture_output=True)
    assert out.returncode == 0, out.stderr.decode()
    assert out.stdout == committed, "%s differs from the output of: %s" % (name, first)
    # The layout `hybrid diagnose` reads: comments, the header, 4 runs of 241 samples.
    lines = committed.decode().splitlines()
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    assert list(rows[0].keys()) == ["run", "time", "u", "x"]
    assert len(rows) == 4 * 241
    assert [r["u"] for r in rows[::241]] == ["10", "10", "5", "5"]
    assert [float(r["time"]) for r in rows[:241]] == [k * STEP for k in range(241)]


def test_generator_is_independent_of_the_project():
    """Standard library only: no `hybrid` module, no subprocess (it never runs the program)."""
    with open(GENERATOR) as f:
        tree = ast.parse(f.read())
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            imported.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            imported.add((node.module or "").split(".")[0])
    assert imported <= {"argparse", "math", "random", "sys"}, imported


def generated(options):
    """run -> [(time, x)] of the noiseless generator over INPUTS."""
    command = [PYTHON, GENERATOR, *options, "--noiseless", "--runs", ",".join("%g" % u for u in INPUTS),
               "--until", "%g" % UNTIL, "--step", "%g" % STEP]
    out = subprocess.run(command, cwd=SOURCE, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    lines = [line for line in out.stdout.splitlines() if not line.startswith("#")]
    runs = {}
    for row in csv.DictReader(lines):
        runs.setdefault(int(row["run"]), []).append((float(row["time"]), float(row["x"])))
    return runs


def simulated(tmp_path, model, u, sets):
    """[(time, x)] at the sample times and the switching times of `hybrid simulate`."""
    trace, log = tmp_path / ("trace_%g.csv" % u), tmp_path / ("events_%g.csv" % u)
    command = [BINARY, "simulate", model, "--input", "u=%r" % u, "--until", "%g" % UNTIL,
               "--sample", "%g" % STEP, "-o", str(trace), "--events", str(log)]
    for s in sets:
        command += ["--set", s]
    out = subprocess.run(command, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    with open(trace) as f:
        samples = [(float(r["time"]), float(r["x"])) for r in csv.DictReader(f)
                   if r["kind"] in ("start", "sample", "end")]
    with open(log) as f:
        switches = [(float(r["time"]), r["mode_after"]) for r in csv.DictReader(f)]
    return samples, switches


# name: (generator options, model, --set of simulate, a guard rewritten in a copy of the model,
#        the bias added to the simulated x, the switching levels of the generator's closed form)
CASES = {
    "lazy": (["--model", "lazy"], "thermostat.ha", [], None, 0.0, (3.0, 18.0, 22.0)),
    "lazy_weak_heater": (["--model", "lazy", "--heater", "2.4"], "thermostat.ha", ["p=2.4"], None,
                         0.0, (2.4, 18.0, 22.0)),
    "lazy_sensor_bias": (["--model", "lazy", "--bias", "0.4"], "thermostat.ha", [], None, 0.4,
                         (3.0, 18.0, 22.0)),
    "urgent": (["--model", "urgent"], "thermostat_urgent.ha", [], None, 0.0, (3.0, 18.0, 22.0)),
    "urgent_weak_heater": (["--model", "urgent", "--heater", "2.4"], "thermostat_urgent.ha",
                           ["p=2.4"], None, 0.0, (2.4, 18.0, 22.0)),
    "urgent_threshold": (["--model", "urgent", "--switch-on", "18.5"], "thermostat_urgent.ha", [],
                         ("guard x <= 18;", "guard x <= 18.5;"), 0.0, (3.0, 18.5, 22.0)),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_noiseless_generator_agrees_with_simulate(tmp_path, case):
    options, model_name, sets, rewrite, bias, (p, s_on, s_off) = CASES[case]
    model = os.path.join(SOURCE, "spec", model_name)
    if rewrite:
        with open(model) as f:
            text = f.read()
        assert text.count(rewrite[0]) == 1
        model = str(tmp_path / model_name)
        with open(model, "w") as f:
            f.write(text.replace(*rewrite))
    runs = generated(options)
    assert sorted(runs) == [1, 2]
    for run, u in enumerate(INPUTS, start=1):
        samples, switches = simulated(tmp_path, model, u, sets)
        ours = runs[run]
        assert len(ours) == len(samples) == 241
        assert [t for t, _ in ours] == [t for t, _ in samples]
        worst = max(abs(x - (xs + bias)) for (_, x), (_, xs) in zip(ours, samples))
        assert worst <= TOLERANCE, "u = %g: max |generator - simulate| = %.3g" % (u, worst)
        # The closed form's switching times (the generator's own function) against the events.
        segments = thermostat_trace.events(u, p, s_on, s_off, UNTIL)
        closed = [(end, "on" if mode == "off" else "off") for _, end, mode, _, _ in segments[:-1]]
        assert len(closed) == len(switches) >= 10, (closed, switches)
        assert [m for _, m in closed] == [m for _, m in switches]
        assert max(abs(t - ts) for (t, _), (ts, _) in zip(closed, switches)) <= TOLERANCE


def diagnose_generated(tmp_path, spec, generator_args):
    """`hybrid diagnose spec/SPEC.ha` on a trace the generator makes with `generator_args`."""
    trace = tmp_path / "trace.csv"
    trace.write_text(subprocess.run([sys.executable, GENERATOR, *generator_args], cwd=SOURCE,
                                    check=True, capture_output=True, text=True).stdout)
    out = subprocess.run([BINARY, "diagnose", os.path.join(SOURCE, "spec", spec + ".ha"),
                          str(trace), "--json"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_diagnose_names_a_moved_invariant_of_the_lazy_thermostat(tmp_path):
    # The lazy thermostat switches where its invariants end: a heater that starts at 18.5 instead
    # of 18 is the invariant threshold `off.invariant`, found from a trace the generator makes.
    report = diagnose_generated(tmp_path, "thermostat", ["--switch-on", "18.5", "--seed", "7"])
    assert report["cause"] == ["off.invariant"]
    assert abs(report["parameters"]["off.invariant"] - 18.5) < 0.025


def test_diagnose_names_a_delayed_switch_of_the_urgent_thermostat(tmp_path):
    # The heater starts 0.5 min after x reaches 18 (the generator's closed form with a delay):
    # the candidate `switch_on.delay` (a pending mode with a clock) is named with its value.
    report = diagnose_generated(tmp_path, "thermostat_urgent",
                                ["--model", "urgent", "--switch-on-delay", "0.5", "--seed", "9"])
    assert report["cause"] == ["switch_on.delay"]
    assert abs(report["parameters"]["switch_on.delay"] - 0.5) < 0.025

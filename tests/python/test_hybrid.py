"""Tests of the Python module `hybrid` (python/, docs/python.md), run by ctest (python_tests) with
PYTHONPATH=build/python. Oracles written apart from the code under test: the plain-Python finger
of tools/report_finger.py (the report's tables), the command line's answers
(`hybrid finger --queries`, `hybrid info --json`, `hybrid check --json`), and analytic solutions
(the thermostat's exponential relaxation, a constant-rate tank)."""

import csv
import json
import math
import os
import re
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import hybrid

SOURCE = os.environ.get("HYBRID_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("HYBRID_BINARY", os.path.join(SOURCE, "build", "bin", "hybrid"))
sys.path.insert(0, os.path.join(SOURCE, "tools"))
sys.path.insert(0, os.path.join(SOURCE, "tests", "test_utilities"))
import report_finger  # noqa: E402
from tank_model import TANK  # noqa: E402

CONTACTS = [{}, {"gob1": 80.0}, {"gob1": 80.0, "gob2": 150.0}, {"gob2": 50.0},
            {"gob1": 60.0, "gob3": 200.0}, {"gob1": 140.0}, {"gob3": 30.0}]


def run(*args):
    return subprocess.run([BINARY, *args], capture_output=True, text=True)


@pytest.mark.parametrize("contacts", CONTACTS)
def test_finger_angles_equal_the_plain_python_finger(contacts):
    g = np.linspace(0.0, 255.0, 5101)
    ours = hybrid.finger_angles(g, **contacts)
    reference = np.array([report_finger.finger_angles(x, **contacts) for x in g])
    assert ours.shape == (g.size, 3) and ours.dtype == np.float64
    assert np.abs(ours - reference).max() <= 1e-9


@pytest.mark.parametrize("contacts", CONTACTS)
def test_finger_angles_equal_the_command_line(tmp_path, contacts):
    g = np.random.default_rng(7).uniform(0.0, 255.0, 200000)  # two threads past 65536
    queries = tmp_path / "q.csv"
    np.savetxt(queries, g, fmt="%.17g", header="g", comments="")
    options = sum((["--" + k, repr(v)] for k, v in contacts.items()), [])
    out = run("finger", "--queries", str(queries), *options)
    assert out.returncode == 0, out.stderr
    rows = list(csv.DictReader(out.stdout.splitlines()))
    cli = np.array([[float(r["theta" + str(i)]) for i in (1, 2, 3)] for r in rows])
    assert np.abs(hybrid.finger_angles(g, **contacts) - cli).max() <= 1e-9


def test_finger_angles_shapes_and_errors():
    assert hybrid.finger_angles(102.0).tolist() == [[51.0, 0.0, -51.0]]
    assert hybrid.finger_angles([[0.0, 255.0]]).shape == (2, 3)
    assert hybrid.finger_angles(np.array([], dtype=float)).shape == (0, 3)
    for bad in (-1.0, 255.5, float("nan")):
        with pytest.raises(ValueError, match=r"g must be a motor position in \[0, 255\]"):
            hybrid.finger_angles([1.0, bad])
    with pytest.raises(ValueError, match="gob2"):
        hybrid.finger_angles(1.0, gob2=300.0)


def test_finger_angles_read_a_models_constants(tmp_path):
    # The bundled finger model gives the report's constants, so the same angles.
    model = os.path.join(SOURCE, "spec", "finger.ha")
    g = np.linspace(0, 255, 256)
    assert np.array_equal(hybrid.finger_angles(g, model=model), hybrid.finger_angles(g))
    two = tmp_path / "two.ha"
    two.write_text("automaton a { mode m {} init m {} }\nautomaton b { mode m {} init m {} }\n"
                   "system s { instance A = a; instance B = b; }\n")
    with pytest.raises(ValueError, match="not a finger model"):
        hybrid.finger_angles(1.0, model=str(two))


def test_model_errors_name_file_line_and_column(tmp_path):
    bad = tmp_path / "bad.ha"
    bad.write_text("automaton a {\n  mode m { x' = 1; }\n}\n")
    with pytest.raises(hybrid.ModelError) as e:
        hybrid.load(bad)
    assert str(e.value).startswith(str(bad) + ":2:")
    assert isinstance(e.value, ValueError)
    with pytest.raises(hybrid.ModelError, match="cannot"):
        hybrid.load(tmp_path / "missing.ha")


def test_info_is_the_command_lines(tmp_path):
    path = os.path.join(SOURCE, "spec", "thermostat.ha")
    model = hybrid.load(path)
    assert model.name == "thermostat" and model.path == path
    out = run("info", path, "--json")
    assert out.returncode == 0, out.stderr
    assert model.info() == json.loads(out.stdout)


def test_dot_draws_every_mode():
    dot = hybrid.load(os.path.join(SOURCE, "spec", "thermostat.ha")).dot()
    assert dot.startswith("digraph") and "switch_on" in dot and "switch_off" in dot


def test_thermostat_relaxes_exponentially():
    # Mode off: x' = a (u - x), a = 0.1, from x = 20 with u = 10: x(t) = 10 + 10 exp(-0.1 t),
    # which reaches the invariant's bound 18 at t = 10 ln(1.25), where the lazy switch_on fires.
    model = hybrid.load(os.path.join(SOURCE, "spec", "thermostat.ha"))
    r = model.simulate(until=2.0, inputs={"u": 10.0}, sample=0.25)
    assert r["status"] == "completed", r["message"]
    t, x = r["time"], r["states"]["x"]
    assert t.shape == x.shape and t[0] == 0.0 and t[-1] == 2.0
    assert np.abs(x - (10.0 + 10.0 * np.exp(-0.1 * t))).max() <= 1e-6
    assert set(r["modes"]) == {"off"} and r["events"] == []
    r = model.simulate(until=3.0, inputs={"u": [(0.0, 10.0)]})
    event = r["events"][0]
    assert abs(event["time"] - 10.0 * math.log(1.25)) <= 1e-6
    assert event["transitions"] == ["switch_on"]
    assert (event["mode_before"], event["mode_after"]) == ("off", "on")
    assert event["before"]["x"] == pytest.approx(18.0) and event["cause"] == "invariant"
    assert r["final"]["time"] == 3.0 and r["final"]["values"]["x"] == r["states"]["x"][-1]


@pytest.mark.parametrize("model, kwargs, args", [
    ("thermostat.ha", {"until": 30.0, "inputs": {"u": 10.0}}, ["--until", "30", "--input", "u=10"]),
    ("finger.ha", {}, []),                                          # six events, phase 1 and 2
    ("hand.ha", {}, []),                                            # composed: A.m|B.n labels
    ("bouncing_ball.ha", {"parameters": {"v_rest": 0.0}}, ["--set", "v_rest=0"]),  # Zeno
    ("controlled_finger.ha", {"sample": 7.0}, ["--sample", "7"]),   # samples between events
])
def test_simulate_has_the_command_lines_members(model, kwargs, args):
    # The members built in this process (the quick path) equal the program's JSON, read by the
    # json module: the same values, key for key, Zeno's member included.
    path = os.path.join(SOURCE, "spec", model)
    r = hybrid.load(path).simulate(**kwargs)
    proc = subprocess.run([BINARY, "simulate", path, *args, "--json"], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode in (0, 5), proc.stderr
    cli = json.loads(proc.stdout)
    assert len(cli["events"]) >= 2
    assert ("zeno" in cli) == (model == "bouncing_ball.ha")
    assert {k: v for k, v in r.items() if k not in ("time", "states", "modes")} == cli
    # The trajectory's last instant is the report's final state.
    assert r["modes"][-1] == cli["final"]["mode"] and r["time"][-1] == cli["final"]["time"]
    assert {name: column[-1] for name, column in r["states"].items()} == cli["final"]["values"]


def test_tank_inputs_and_parameters(tmp_path):
    # h' = 0.5 + d from h = 5: with d = -0.2 then 0 after t = 2, h(4) = 5 + 0.3 * 2 + 0.5 * 2.
    path = tmp_path / "tank.ha"
    path.write_text(TANK)
    model = hybrid.load(path)
    r = model.simulate(until=4.0, inputs={"d": "step(0: -0.2, 2: 0)"})
    assert r["status"] == "completed", r["message"]
    assert abs(r["states"]["h"][-1] - 6.6) <= 1e-9
    with pytest.raises(KeyError):
        model.simulate(until=1.0, inputs={"nope": 0.0})
    with pytest.raises(ValueError):
        model.simulate(until=1.0, inputs={"d": 5.0})  # outside the input's bounds


def test_check_verdicts_and_traces_match_the_command_line(tmp_path):
    # The tank rises at 0.3 to 0.5 per second from 5 and is kept below 8 by its invariant: h > 6
    # and h >= 7 are reached (after 2 s at most), h <= 8 always holds.
    path = tmp_path / "tank.ha"
    path.write_text(TANK)
    report = hybrid.load(path).check(method="auto")
    verdicts = {p["name"]: p["verdict"] for p in report["properties"]}
    assert verdicts == {"stays_below_6": "violated", "reaches_7": "reachable",
                        "below_8": "proved"}
    violated = next(p for p in report["properties"] if p["name"] == "stays_below_6")
    assert violated["trace"]
    out = run("check", str(path), "--json")
    cli = json.loads(out.stdout)
    assert [(p["name"], p["verdict"]) for p in cli["properties"]] == \
        [(p["name"], p["verdict"]) for p in report["properties"]]
    with pytest.raises(ValueError):
        hybrid.load(path).check(properties=["no_such_property"])


def test_hand_is_the_command_lines():
    objects = ["circle:0,0.15,0.03"]
    report = hybrid.hand(objects=objects, g=200.0)
    out = run("hand", "--object", objects[0], "--g", "200", "--json")
    assert out.returncode == 0, out.stderr
    assert report == json.loads(out.stdout)
    assert [f["finger"] for f in report["fingers"]] == ["A", "B", "C"]
    with pytest.raises(ValueError, match="circle"):
        hybrid.hand(objects=["circle:0,0.15"])


def expect_argument_error(call, argument, message):
    """`call()` raises a ValueError about keyword argument `argument` whose message starts with
    `message`: in the module's words, never a command-line flag."""
    with pytest.raises(ValueError) as e:
        call()
    assert str(e.value).startswith(message), str(e.value)
    assert e.value.argument == argument
    assert "--" not in str(e.value), str(e.value)


def test_errors_name_the_keyword_argument_not_a_flag(tmp_path):
    # The same checks as the command line's, whose messages name --method, --depth, --object,
    # --g, --threads, --property: here the keyword arguments.
    path = tmp_path / "tank.ha"
    path.write_text(TANK)
    model = hybrid.load(path)
    expect_argument_error(lambda: model.check(method="x"), "method",
                          "method must be 'auto', 'reach', 'flowpipe', 'prove' or 'sample', not 'x'")
    expect_argument_error(lambda: model.check(depth=5000), "depth",
                          "depth must be in [0, 1000]")
    expect_argument_error(lambda: model.check(budget=0.0), "budget",
                          "budget must be a number of budget seconds in (0, 1e6]")
    expect_argument_error(lambda: model.check(properties=["nope"]), "properties",
                          "properties: 'nope' is not a property of " + str(path))
    expect_argument_error(lambda: hybrid.hand(objects=["circle:0,0.15"]), "objects",
                          "objects 'circle:0,0.15': column ")
    expect_argument_error(lambda: hybrid.hand(g=300.0), "g",
                          "g must be a motor position in [0, 255] (got 300)")
    expect_argument_error(lambda: hybrid.hand(g_b=-1.0), "g_b",
                          "g_b must be a motor position in [0, 255] (got -1)")
    data = os.path.join(SOURCE, "data", "finger_demo.csv")
    expect_argument_error(lambda: hybrid.diagnose(data, threads=0), "threads",
                          "threads must lie in [1, 64]")
    expect_argument_error(lambda: hybrid.finger_angles(1.0, gob3=-2.0), "gob3",
                          "gob3 must be a motor position in [0, 255]")
    # The command line names the flags for the same mistakes.
    out = run("check", str(path), "--method", "x")
    assert out.returncode == 2
    assert out.stderr == ("hybrid check: --method must be 'auto', 'reach', 'flowpipe', 'prove' or "
                          "'sample', "
                          "not 'x'\n")


LOG_LINE = re.compile(r"^hybrid \[(debug|info|warning)\] ([^:]+): ")


def test_log_level_is_the_command_lines(tmp_path):
    # set_log_level logs to standard error as `hybrid --log LEVEL` does: the same lines (their
    # level and topic; numbers such as times may differ) for the same check.
    path = tmp_path / "tank.ha"
    path.write_text(TANK)
    script = ("import sys, hybrid\n"
              "hybrid.set_log_level('debug')\n"
              "hybrid.load(sys.argv[1]).check(method='prove', budget=5.0, depth=4)\n"
              "hybrid.set_log_level(None)\n"
              "hybrid.load(sys.argv[1]).check(method='prove', budget=5.0, depth=4)\n")
    python = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True,
                            text=True)
    assert python.returncode == 0, python.stderr
    cli = run("--log", "debug", "check", str(path), "--method", "prove", "--budget", "5",
              "--depth", "4")
    assert cli.returncode in (0, 6, 7), cli.stderr

    def kinds(text):
        lines = text.splitlines()
        for line in lines:
            assert LOG_LINE.match(line), line
        return sorted({LOG_LINE.match(line).groups() for line in lines})

    assert kinds(python.stderr) == kinds(cli.stderr)
    # After the command's name too; nothing without --log; a bad level is a usage error.
    after = run("check", str(path), "--method", "prove", "--budget", "5", "--depth", "4",
                "--log", "debug")
    assert kinds(after.stderr) == kinds(cli.stderr)
    assert run("check", str(path), "--method", "prove", "--budget", "5", "--depth", "4").stderr == ""
    bad = run("--log", "loud", "info", str(path))
    assert bad.returncode == 2 and "--log" in bad.stderr, bad.stderr
    expect_argument_error(lambda: hybrid.set_log_level("loud"), "level",
                          "level must be 'debug', 'info', 'warning' or None, not 'loud'")


def test_diagnose_is_the_command_lines():
    data = os.path.join(SOURCE, "data", "finger_demo.csv")
    report = hybrid.diagnose(data)
    out = run("diagnose", data, "--json")
    assert out.returncode == 0, out.stderr
    cli = json.loads(out.stdout)
    del report["seconds"], cli["seconds"]  # wall times
    assert report == cli


def test_diagnose_any_model_is_the_command_lines_with_arrays():
    import numpy
    model = os.path.join(SOURCE, "spec", "thermostat_urgent.ha")
    data = os.path.join(SOURCE, "data", "thermostat_threshold.csv")
    report = hybrid.diagnose(model, data)
    out = run("diagnose", model, data, "--json")
    assert out.returncode == 0, out.stderr
    cli = json.loads(out.stdout)
    curves = report.pop("curves")
    del report["seconds"], cli["seconds"]  # wall times
    assert report == cli
    # One array per run and variable, as long as the run's rows in the CSV.
    with open(data) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))][1:]
    per_run = {}
    for r in rows:
        per_run[r[0]] = per_run.get(r[0], 0) + 1
    assert [c["run"] for c in curves] == list(per_run)
    for c in curves:
        assert isinstance(c["time"], numpy.ndarray) and len(c["time"]) == per_run[c["run"]]
        for key in ("measured", "baseline", "extended"):
            assert c[key]["x"].shape == c["time"].shape
    # A trace without its model is refused, naming what to do.
    with pytest.raises(ValueError, match="give its model"):
        hybrid.diagnose(data)


def test_diagnose_bad_data_names_the_row(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("nothing,useful\n1,2\n")
    with pytest.raises(hybrid.DataError) as e:
        hybrid.diagnose(bad)
    assert str(e.value).startswith(str(bad) + ":")


# A model whose simulation is long: a fast oscillator (period 2 pi / 1000), recorded every time
# unit, so that CVODE takes about 10^4 steps per unit (about 25 s to t = 1000).
OSCILLATOR = """automaton osc {
  var x;
  var v;
  mode m {
    x' = v;
    v' = -1000000 * x;
  }
  init m { x = 1; v = 0; }
}
"""

# Long calls: each runs for tens of seconds when not interrupted (fischer_6's reachability stops at
# its budget after about a minute, docs/benchmarks_lha.md; disc_3's, used before, now ends within
# a second on its hulls).
LONG_CALLS = {
    "check": ("fischer_6", "model.check(method='reach')"),
    "simulate": ("oscillator", "model.simulate(until=1000.0, sample=1.0)"),
}


@pytest.mark.parametrize("call", sorted(LONG_CALLS))
def test_ctrl_c_stops_a_long_call_at_once(tmp_path, call):
    # SIGINT a second into the call: KeyboardInterrupt within seconds (not when the call would
    # have returned), and no process left computing (the process group is empty).
    which, expression = LONG_CALLS[call]
    if which == "oscillator":
        path = tmp_path / "osc.ha"
        path.write_text(OSCILLATOR)
    else:
        path = os.path.join(SOURCE, "spec", "benchmarks", which + ".ha")
    script = (
        "import sys, time, hybrid\n"
        "model = hybrid.load(sys.argv[1])\n"
        "print('started', flush=True)\n"
        "try:\n"
        "    " + expression + "\n"
        "    print('returned', flush=True)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n")
    process = subprocess.Popen([sys.executable, "-c", script, str(path)], stdout=subprocess.PIPE,
                               text=True, start_new_session=True)
    try:
        assert process.stdout.readline() == "started\n"
        time.sleep(1.0)
        process.send_signal(signal.SIGINT)
        sent = time.monotonic()
        out, _ = process.communicate(timeout=120)
        elapsed = time.monotonic() - sent
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    assert out == "interrupted\n"
    assert elapsed < 5.0, f"KeyboardInterrupt {elapsed:.1f} s after SIGINT"
    time.sleep(0.2)
    with pytest.raises(ProcessLookupError):  # nothing of the call still runs
        os.killpg(process.pid, 0)


def test_long_calls_raise_the_same_errors_and_work_off_the_main_thread(tmp_path):
    # Errors of a call made in another process are the same Python exceptions, and a call from
    # another thread (which signals never interrupt) gives the same answer.
    bad = tmp_path / "bad.ha"
    bad.write_text("automaton a {\n  mode m { x' = 1; }\n}\n")
    data = os.path.join(SOURCE, "data", "finger_demo.csv")
    with pytest.raises(hybrid.ModelError) as e:
        hybrid.diagnose(data, model=bad)
    assert str(e.value).startswith(str(bad) + ":2:")
    path = tmp_path / "tank.ha"
    path.write_text(TANK)
    model = hybrid.load(path)
    with pytest.raises(ValueError, match="no_such_property"):
        model.check(properties=["no_such_property"])
    results = {}
    worker = threading.Thread(target=lambda: results.update(
        check=model.check(), run=model.simulate(until=4.0, sample=0.5)))
    worker.start()
    worker.join()
    verdicts = [(p["name"], p["verdict"]) for p in model.check()["properties"]]
    assert [(p["name"], p["verdict"]) for p in results["check"]["properties"]] == verdicts
    here = model.simulate(until=4.0, sample=0.5)
    assert np.array_equal(results["run"]["time"], here["time"])
    assert np.array_equal(results["run"]["states"]["h"], here["states"]["h"])
    assert results["run"]["modes"] == here["modes"] and results["run"]["events"] == here["events"]


def test_reach_set_encloses_the_falling_ball():
    """The flowpipe of the bouncing ball as arrays: every box of the first fall holds the closed
    form h(t) = 10 - g t^2 / 2 at its ends, and no box rises above the drop height."""
    model = hybrid.load(os.path.join(SOURCE, "spec", "bouncing_ball.ha"))
    reach = model.reach_set(properties=["never_rises_above_drop"])
    h = reach["variables"].index("h")
    assert reach["lo"].shape == reach["hi"].shape and reach["lo"].shape[1] == 2
    assert (reach["hi"][:, h] <= 10.0).all()
    first_impact = (2 * 10 / 9.81) ** 0.5
    checked = 0
    for (t0, t1), lo, hi in zip(reach["time"], reach["lo"], reach["hi"]):
        if t1 > first_impact:
            break
        for t in (t0, t1):
            assert lo[h] <= 10 - 9.81 * t * t / 2 <= hi[h]
        checked += 1
    assert checked > 5
    corners = model.reach_vertices("h", "v", properties=["never_rises_above_drop"])
    assert corners.shape == (len(reach["mode"]), 4, 2)
    with pytest.raises(ValueError):
        model.reach_vertices("h", "nope")


def test_simulate_long_runs_leave_the_quick_path_with_the_same_result():
    # 240,000 samples: more than the 20000 passes run in the process first, so the run starts
    # again where Ctrl-C can stop it (a child process on the main thread, the process elsewhere).
    model = hybrid.load(os.path.join(SOURCE, "spec", "thermostat.ha"))
    main = model.simulate(sample=0.0005)
    assert main["status"] == "completed" and len(main["time"]) > 240000
    other = {}
    worker = threading.Thread(target=lambda: other.update(model.simulate(sample=0.0005)))
    worker.start()
    worker.join()
    np.testing.assert_array_equal(main["time"], other["time"])
    for name, values in main["states"].items():
        np.testing.assert_array_equal(values, other["states"][name])
    assert main["events"] == other["events"]
    # A short run takes the quick path and is the same run as a long one's beginning.
    short = model.simulate(until=5.0, sample=0.0005)
    k = len(short["time"])
    np.testing.assert_array_equal(short["time"][:k - 1], main["time"][:k - 1])


def test_finger_angles_out_and_single_positions():
    g = np.linspace(0.0, 255.0, 1001)
    expected = hybrid.finger_angles(g, gob1=80.0)
    out = np.full((1001, 3), np.nan)
    assert hybrid.finger_angles(g, gob1=80.0, out=out) is out
    np.testing.assert_array_equal(out, expected)
    for bad in (np.zeros((1001, 3), dtype=np.float32), np.zeros((1000, 3)), np.zeros((3, 1001)).T,
                np.zeros((1001, 3))[::1, :].copy().view()[:, :]):
        if bad.flags.c_contiguous and bad.dtype == np.float64 and bad.shape == (1001, 3):
            continue
        with pytest.raises(ValueError, match="out must be a writable C-contiguous float64"):
            hybrid.finger_angles(g, out=bad)
    frozen = np.zeros((1001, 3))
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="out must be"):
        hybrid.finger_angles(g, out=frozen)
    # One position (a Python number) takes the scalar path: the batch's numbers, the same errors.
    for contacts in ({}, {"gob1": 80.0}, {"gob2": 50.0}, {"gob1": 100.0, "gob2": 140.0}):
        batch = hybrid.finger_angles(g, **contacts)
        for k in (0, 137, 500, 999, 1000):
            single = hybrid.finger_angles(float(g[k]), **contacts)
            assert single.shape == (1, 3)
            np.testing.assert_array_equal(single[0], batch[k])
    assert hybrid.finger_angles(200).shape == (1, 3)
    with pytest.raises(ValueError, match="g must be a motor position"):
        hybrid.finger_angles(300.0)
    with pytest.raises(ValueError, match="gob1 must be a motor position"):
        hybrid.finger_angles(100.0, gob1=-1.0)

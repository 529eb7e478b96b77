"""Grasp sweeps (hybrid.hand_sweep, hybrid.finger_sweep): every row equals the report of one call
(hybrid.hand / hybrid.finger, and on a sample the program's `hybrid hand --json`), statuses
instead of exceptions, and the errors in the API's words."""

import json
import os
import subprocess

import numpy as np
import pytest

import hybrid

SOURCE = os.environ.get("HYBRID_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("HYBRID_BINARY", os.path.join(SOURCE, "build", "bin", "hybrid"))

CYLINDER = (0.0, 0.06, 0.02)


def _offsets(n, seed):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-0.04, 0.04, n), rng.uniform(-0.05, 0.09, n)])


def _moved(offset):
    # The object moved in Python's own double arithmetic: the same sums the sweep does.
    return "circle:%r,%r,%r" % (CYLINDER[0] + offset[0], CYLINDER[1] + offset[1], CYLINDER[2])


def _expect_row(sweep, i, report, fingers):
    assert sweep["status"][i] == report["status"]
    first = report["first_contact"]
    assert (np.isnan(sweep["first_contact"][i]) if first is None
            else sweep["first_contact"][i] == first)
    for f, finger in enumerate(fingers):
        assert sweep["motor"][i, f] == finger["motor"]
        assert list(sweep["theta"][i, f]) == [finger["theta1"], finger["theta2"], finger["theta3"]]
        assert sweep["phase"][i, f] == finger["phase"]
        assert sweep["mode"][i, f] == finger["mode"]
        stop = finger["stop"]
        assert sweep["stop"][i, f] == (np.inf if stop is None else stop)
        contacts = {c["link"]: c for c in finger["contacts"]}
        for link in range(3):
            c = contacts.get(link + 1)
            if c is None:
                assert np.isnan(sweep["contact_g"][i, f, link])
                assert sweep["contact_by"][i, f, link] == ""
            else:
                assert sweep["contact_g"][i, f, link] == c["g"]
                assert sweep["contact_by"][i, f, link] == c["by"]


def test_hand_sweep_rows_equal_single_calls():
    offsets = _offsets(10000, 1)
    sweep = hybrid.hand_sweep(["circle:%r,%r,%r" % CYLINDER], offsets)
    assert sweep["theta"].shape == (10000, 3, 3)
    statuses = set(sweep["status"])
    assert {"contact", "invalid"} <= statuses
    for i, offset in enumerate(offsets):
        try:
            report = hybrid.hand([_moved(offset)])
        except ValueError as e:
            assert sweep["status"][i] == "invalid"
            assert sweep["message"][i] in str(e)
            continue
        _expect_row(sweep, i, report, report["fingers"])
    # The number of threads does not change the result.
    one = hybrid.hand_sweep(["circle:%r,%r,%r" % CYLINDER], offsets[:500], threads=1)
    for key in ("motor", "theta", "contact_g", "stop", "first_contact"):
        np.testing.assert_array_equal(one[key], sweep[key][:500])


def test_hand_sweep_rows_equal_the_program():
    offsets = _offsets(200, 2)
    for mode, g in (("basic", 255.0), ("pinch", 255.0), ("wide", 60.0)):
        sweep = hybrid.hand_sweep(["circle:%r,%r,%r" % CYLINDER], offsets, mode=mode, g=g)
        valid = [i for i in range(len(offsets)) if sweep["status"][i] != "invalid"][:8]
        assert valid
        for i in valid:
            out = subprocess.run([BINARY, "hand", "--object", _moved(offsets[i]), "--mode", mode,
                                  "--g", repr(g), "--json"], capture_output=True, text=True,
                                 check=True).stdout
            report = json.loads(out)
            _expect_row(sweep, i, report, report["fingers"])


def test_hand_sweep_statuses():
    # Before the first contact, beyond reach, overlapping the palm: statuses, not exceptions.
    offsets = np.array([[0.0, 0.0], [0.5, 0.5], [0.0, -0.07]])
    early = hybrid.hand_sweep(["circle:%r,%r,%r" % CYLINDER], offsets, g=20.0)
    assert list(early["status"]) == ["free", "out_of_reach", "invalid"]
    assert "palm" in early["message"][2]
    full = hybrid.hand(["circle:%r,%r,%r" % CYLINDER])
    assert early["first_contact"][0] == full["first_contact"] > 20.0
    assert np.isnan(early["first_contact"][1])
    assert (early["motor"][0] == 20.0).all()


def test_finger_sweep_rows_equal_single_calls_and_the_program():
    rng = np.random.default_rng(3)
    offsets = np.column_stack([rng.uniform(-0.05, 0.05, 600), rng.uniform(-0.04, 0.06, 600)])
    base = "circle:0.06,0.08,0.01"
    sweep = hybrid.finger_sweep([base], offsets, g=200.0)
    assert sweep["theta"].shape == (600, 1, 3)
    checked = 0
    for i, (dx, dy) in enumerate(offsets):
        moved = "circle:%r,%r,0.01" % (0.06 + dx, 0.08 + dy)
        try:
            report = hybrid.finger(200.0, objects=[moved])
        except ValueError:
            assert sweep["status"][i] == "invalid"
            continue
        _expect_row(sweep, i, report, [report])
        if checked < 10:
            out = subprocess.run([BINARY, "finger", "--g", "200", "--object", moved, "--json"],
                                 capture_output=True, text=True, check=True).stdout
            assert json.loads(out) == report
            checked += 1
    assert checked == 10


def test_sweep_errors_in_the_api_words():
    with pytest.raises(ValueError, match="offsets must be an array of shape"):
        hybrid.hand_sweep(["circle:0,0.06,0.02"], np.zeros((3, 3)))
    with pytest.raises(ValueError, match="offsets: row 1 is not finite"):
        hybrid.hand_sweep(["circle:0,0.06,0.02"], np.array([[0.0, 0.0], [np.nan, 0.0]]))
    with pytest.raises(ValueError, match="threads must be in 1..64"):
        hybrid.hand_sweep(["circle:0,0.06,0.02"], np.zeros((1, 2)), threads=0)
    with pytest.raises(ValueError) as e:
        hybrid.finger_sweep(["circle:0,0.06"], np.zeros((1, 2)))
    assert "objects" in str(e.value) and "--object" not in str(e.value)


def test_joint_state_equals_the_program_and_stays_within_the_limits():
    js = hybrid.joint_state(["circle:0,0.06,0.02"])
    out = subprocess.run([BINARY, "hand", "--object", "circle:0,0.06,0.02", "--joint-state",
                          "--json"], capture_output=True, text=True, check=True).stdout
    assert json.loads(out)["joint_state"] == js
    # The xacro's limits, typed from ros-industrial/robotiq's visualization package.
    limits = {"palm_finger_1_joint": (-0.1784, 0.192), "palm_finger_2_joint": (-0.192, 0.1784)}
    for finger in ("finger_1", "finger_2", "finger_middle"):
        limits.update({finger + "_joint_1": (0.0495, 1.2218), finger + "_joint_2": (0.0, 1.5708),
                       finger + "_joint_3": (-1.2217, -0.0523)})
    assert sorted(js["name"]) == sorted(limits)
    for name, value in zip(js["name"], js["position"]):
        assert limits[name][0] <= value <= limits[name][1], name
    report = hybrid.hand(["circle:0,0.06,0.02"])
    model = dict(zip(js["name"], js["model_position"]))
    import math
    assert model["finger_middle_joint_3"] == pytest.approx(math.radians(report["fingers"][0]["theta3"]), abs=1e-15)
    assert model["finger_1_joint_1"] == pytest.approx(math.radians(report["fingers"][1]["theta1"]), abs=1e-15)

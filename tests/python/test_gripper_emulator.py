"""hybrid.Gripper, the stateful emulator: stepped at 1 kHz it equals one whole run of the same
system (spec/gripper.ha) with the same requests; its registers and statuses follow the manual's
meanings as docs/gripper_emulator.md states them; its errors name the register."""

import numpy as np
import pytest

import hybrid

import os

SOURCE = os.environ.get("HYBRID_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CYLINDER = ["circle:0,0.06,0.02"]  # link 2 meets it; link 3 then wraps (phase 3) to 43 degrees
FINGERTIPS = ["circle:0,0.11,0.01"]  # the fingertips (link 3) meet it: no phase 3


def _grasp(objects, dt=0.001, seconds=3.0):
    grip = hybrid.Gripper(objects=objects)
    grip.command(rACT=1, rGTO=1, rPRA=255)
    return [grip.step(dt) for _ in range(int(round(seconds / dt)))]


# The largest |difference| (degrees) allowed between the emulator and the whole run: 1e-9; with
# phase 3, whose law the integrator follows (every other flow is an exact segment), the emulator
# restarts the integrator at every step, and each restart adds its error: 2e-9 (the whole run at a
# relative tolerance of 1e-12, the emulator's 1e-13; both stay within 1.4e-9 of the closed form).
@pytest.mark.parametrize("objects, tolerance", [(FINGERTIPS, 1e-9), (CYLINDER, 2e-9)])
def test_steps_at_1khz_equal_the_whole_run(objects, tolerance):
    states = _grasp(objects)
    # Activation moves the scissor axis to the basic position (137) at full speed first; the
    # fingers' requests apply at the first step after it arrives.
    release = next(s["time"] for s in states if s["status"]["gIMC"] == 3)
    assert release == pytest.approx(137 / 255, abs=0.0011)
    # The whole run: the same system, requests and contact positions (those hybrid.hand reports
    # for the cylinder), sampled every millisecond.
    params = {f"{f}.gob{i}": 256.0 for f in "ABC" for i in (1, 2, 3)}
    for name, finger in zip("ABC", hybrid.hand(objects)["fingers"]):
        for c in finger["contacts"]:
            params[f"{name}.gob{c['link']}"] = c["g"]
    closing = [(0.0, 0.0), (release, 255.0)]
    run = hybrid.load(os.path.join(SOURCE, "spec", "gripper.ha")).simulate(
        until=3.0, sample=0.001, parameters=params, tolerance=1e-12,
        inputs={"ctlS.request": 137.0, "ctlA.request": closing, "ctlB.request": closing,
                "ctlC.request": closing})
    assert run["status"] == "completed"
    worst = 0.0
    for s in states:
        # The state at the step's end: the last one recorded at that time (after any jump).
        k = np.searchsorted(run["time"], s["time"] + 1e-12) - 1
        assert abs(run["time"][k] - s["time"]) < 1e-9
        for f, name in enumerate("ABC"):
            whole = [run["states"][f"{name}.theta{i}"][k] for i in (1, 2, 3)]
            worst = max(worst, float(np.max(np.abs(np.array(whole) - s["theta"][f]))))
    assert worst <= tolerance, worst
    print(f"{objects}: max |emulator - whole run| = {worst:.3g} deg")
    # The grasp itself: the fingers end where hybrid.hand puts them, stopped by the object.
    hand = hybrid.hand(objects)
    for f, finger in enumerate(hand["fingers"]):
        assert states[-1]["theta"][f] == pytest.approx(
            [finger["theta1"], finger["theta2"], finger["theta3"]], abs=1e-6)
    status = states[-1]["status"]
    assert (status["gDTA"], status["gDTB"], status["gDTC"]) == (2, 2, 2)
    assert status["gSTA"] == 2 and status["gIMC"] == 3 and status["gPOS"] == 137
    # Phase 3 against its closed form (hybrid.finger_angles at the motor's position).
    for s in states:
        for f in range(3):
            contacts = {f"gob{c['link']}": c["g"] for c in hand["fingers"][f]["contacts"]}
            expected = hybrid.finger_angles([s["motor"][f]], **contacts)[0]
            assert np.max(np.abs(expected - s["theta"][f])) <= 2e-9


def test_registers_and_statuses():
    grip = hybrid.Gripper()
    assert grip.state["status"]["gIMC"] == 0
    # Before activation nothing moves.
    grip.command(rGTO=1, rPRA=200)
    assert grip.step(0.5)["motor"] == [0.0, 0.0, 0.0]
    # Activation, then a go-to at half speed: the free fingers reach the request (gDT 3).
    grip.command(rACT=1, rGTO=1, rPRA=100, rSPA=0)
    s = grip.step(0.6)
    assert s["status"]["gIMC"] == 3 and s["scissor"] == pytest.approx(137.0)
    s = grip.step(1.0)
    assert s["status"]["gSTA"] == 0  # the lowest speed: 51 counts/s, still moving
    s = grip.step(1.5)
    assert s["motor"] == pytest.approx([100.0] * 3) and s["status"]["gSTA"] == 3
    # Individual control: finger B alone closes further.
    grip.command(rICF=1, rPRA=100, rPRB=150, rPRC=100, rSPB=255)
    s = grip.step(1.0)
    assert s["motor"] == pytest.approx([100.0, 150.0, 100.0])
    # Stop (rGTO = 0) halts the motors where they are.
    grip.command(rGTO=0, rICF=0, rPRA=0)
    assert grip.step(0.5)["motor"] == pytest.approx([100.0, 150.0, 100.0])
    # Scissor mode: the request drives the scissor axis, fingers B and C turn sideways.
    grip.command(rGTO=1, rMOD=3, rPRA=200, rSPA=255)
    s = grip.step(1.5)
    assert s["status"]["gIMC"] == 3 and s["status"]["gMOD"] == 3
    s = grip.step(1.5)
    assert s["scissor"] == pytest.approx(200.0)
    assert s["spread_angle"] == pytest.approx(-17 + 34 * 200 / 255)
    # Automatic release opens every finger.
    grip.command(rATR=1)
    s = grip.step(6.0)
    assert s["motor"] == pytest.approx([0.0, 0.0, 0.0])
    # Reset.
    grip.command(rACT=0)
    assert grip.step(0.01)["status"]["gIMC"] == 0


def test_bad_registers_are_named():
    grip = hybrid.Gripper()
    with pytest.raises(ValueError, match="rPRB must be in 0..255"):
        grip.command(rPRB=300)
    with pytest.raises(ValueError, match="no register named 'rXYZ'"):
        grip.command(rXYZ=1)
    with pytest.raises(ValueError, match="dt must be in"):
        grip.step(0.0)

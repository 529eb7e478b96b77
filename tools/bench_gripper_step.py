#!/usr/bin/env python3
"""Emulator benchmark: hybrid.Gripper.step at 1 kHz for 3 s of a basic-mode grasp (a cylinder
the fingers wrap: phase 3 included, and a fingertip grasp without it), against one whole run of
the same system (hybrid.Model.simulate of spec/gripper.ha, sampled every millisecond), in one run;
prints the cost per step, the real-time factor and the ratio. Run with the build's module:

    PYTHONPATH=build/python /usr/bin/python3 tools/bench_gripper_step.py
"""
import os
import time

import hybrid

SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
DT, SECONDS = 0.001, 3.0


def emulate(objects):
    grip = hybrid.Gripper(objects=objects)
    grip.command(rACT=1, rGTO=1, rPRA=255)
    start = time.perf_counter()
    states = [grip.step(DT) for _ in range(int(round(SECONDS / DT)))]
    elapsed = time.perf_counter() - start
    release = next(s["time"] for s in states if s["status"]["gIMC"] == 3)
    return elapsed, release


def whole_run(objects, release):
    params = {f"{f}.gob{i}": 256.0 for f in "ABC" for i in (1, 2, 3)}
    for name, finger in zip("ABC", hybrid.hand(objects)["fingers"]):
        for c in finger["contacts"]:
            params[f"{name}.gob{c['link']}"] = c["g"]
    closing = [(0.0, 0.0), (release, 255.0)]
    model = hybrid.load(os.path.join(SOURCE, "spec", "gripper.ha"))
    start = time.perf_counter()
    model.simulate(until=SECONDS, sample=DT, parameters=params, tolerance=1e-12,
                   inputs={"ctlS.request": 137.0, "ctlA.request": closing,
                           "ctlB.request": closing, "ctlC.request": closing})
    return time.perf_counter() - start


def main():
    for label, objects in (("cylinder (phase 3)", ["circle:0,0.06,0.02"]),
                           ("fingertips", ["circle:0,0.11,0.01"])):
        steps = int(round(SECONDS / DT))
        emulated, release = emulate(objects)
        whole = whole_run(objects, release)
        print(f"{label}: Gripper.step {emulated / steps * 1e6:.1f} us per 1 ms step "
              f"({SECONDS / emulated:.1f}x real time); whole run {whole:.3f} s; "
              f"stepping / whole run {emulated / whole:.1f}")


if __name__ == "__main__":
    main()

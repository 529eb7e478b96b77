#!/usr/bin/env bash
# The main job on the bundled models: install, build, then for every model in spec/ print its
# summary (`hybrid info`), write it as JSON, render its mode graph to SVG and simulate its default
# scenario (trajectory and event log as CSV). Results in out/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/build.sh" --program   # the program only: the tests are built by tools/test.sh
hybrid="$root/build/bin/hybrid"
out="$root/out"
mkdir -p "$out"
for model in "$root"/spec/*.ha; do
  name=$(basename "$model" .ha)
  echo "=== $name ==="
  "$hybrid" info "$model"
  "$hybrid" info "$model" --json > "$out/$name.json"
  "$hybrid" dot "$model" -o "$out/$name.dot"
  dot -Tsvg "$out/$name.dot" -o "$out/$name.svg"
  if [ "$name" = driven_finger ] || [ "$name" = controller ]; then  # controlled_finger's parts
    echo "wrote out/$name.json, out/$name.dot, out/$name.svg"; echo; continue
  fi
  # Simulate the model's default scenario (exit 5 = stopped early, reported, not a failure here).
  status=0
  "$hybrid" simulate "$model" --out "$out/$name.trace.csv" --events "$out/$name.events.csv" || status=$?
  [ "$status" -eq 0 ] || [ "$status" -eq 5 ] || exit "$status"
  echo "wrote out/$name.json, out/$name.dot, out/$name.svg, out/$name.trace.csv, out/$name.events.csv"
  echo
done

# The gripper (docs/finger_model.md): the closed form against the report's figures, objects by
# geometry checked against the simulated automaton, and the hand closing on a cylinder.
echo "=== gripper ==="
"$hybrid" finger --g 120
"$hybrid" finger --draw "$out/finger_free.svg" --plot "$out/finger_angles_free.svg"     # figures 6.2, 5.2
for gob in 30 70 110; do                                                                # figure 5.4
  "$hybrid" finger --gob1 "$gob" --plot "$out/finger_angles_gob$gob.svg" --draw "$out/finger_gob$gob.svg"
done
"$hybrid" finger --gob2 200 --plot "$out/finger_angles_gob200.svg" --draw "$out/finger_gob200.svg"
# A cylinder of radius 1 cm in the finger plane: contacts found by geometry, then the automaton with
# distance guards simulated and compared with the closed form (exit 5 if they differ by > 1e-6 deg).
"$hybrid" finger --g 255 --object circle:0.06,0.08,0.01 --simulate \
  --draw "$out/finger_object.svg" --plot "$out/finger_angles_object.svg"
"$hybrid" finger --g 255 --object circle:0.06,0.08,0.01 --simulate --json > "$out/finger_object.json"
# The hand (basic mode, one motor command) closing on a cylinder across the palm, simulated as three
# composed finger automata with geometric contact; and pinch mode, where fingers touch each other.
"$hybrid" hand --object circle:0,0.06,0.02 --simulate --draw "$out/hand_basic.svg"
"$hybrid" hand --object circle:0,0.06,0.02 --simulate --json > "$out/hand_basic.json"
"$hybrid" hand --object circle:0,0.06,0.02 --mode pinch --draw "$out/hand_pinch.svg"
echo "wrote out/finger_*.svg, out/finger_object.json, out/hand_basic.svg, out/hand_basic.json, out/hand_pinch.svg"
echo

# Verification (docs/verification.md): every invariant of the finger and of the hand proved for all
# inputs and object positions (exit 0 only if every verdict is proved or reachable); the finger's
# reachable discrete states.
echo "=== check ==="
"$hybrid" check spec/finger.ha
"$hybrid" check spec/finger.ha --json > "$out/check_finger.json"
"$hybrid" check spec/hand.ha --json > "$out/check_hand.json"
grep -c '"verdict": "proved"' "$out/check_hand.json" | sed 's/^/hand: proved properties: /'
"$hybrid" check spec/finger.ha --modes --json > "$out/check_finger_modes.json"
# The finger behind its controller: the controller's invariants (docs/finger_model.md, "The
# controller").
"$hybrid" check spec/controlled_finger.ha
# The hand behind its three controllers: each finger's invariants, proved on finger and controller.
"$hybrid" check spec/controlled_hand.ha --json > "$out/check_controlled_hand.json"
grep -c '"verdict": "proved"' "$out/check_controlled_hand.json" |
  sed 's/^/controlled hand: proved properties: /'
echo "wrote out/check_finger.json, out/check_hand.json, out/check_finger_modes.json," \
  "out/check_controlled_hand.json"
echo

# Affine and nonlinear dynamics (docs/verification.md, "flowpipe"): the thermostat and the ball
# decided by flowpipes and the falsifier (exit 6: a property is violated, as expected), and the
# reach set of Van der Pol drawn.
echo "=== flowpipes ==="
"$hybrid" check spec/thermostat.ha || [ $? -eq 6 ]
"$hybrid" check spec/bouncing_ball.ha
"$hybrid" check spec/benchmarks/gearbox.ha || [ $? -eq 6 ]     # impacts: the sets keep correlations
"$hybrid" check spec/benchmarks/vanderpol.ha --property y_below_2_75 \
  --plot-reach "$out/vanderpol_reach.svg" --axes x,y
echo "wrote out/vanderpol_reach.svg"
echo

# Diagnosis from measured data (docs/diagnosis.md): the bundled demo data (SYNTHETIC: made by
# `hybrid synthesize --effect backlash=6 --effect theta3_bias=2.5 --seed 7`, see its header) are
# diagnosed; the extended model is written and `hybrid check` proves the finger's invariants on it.
echo "=== diagnose ==="
"$hybrid" diagnose data/finger_demo.csv --out-model "$out/finger_extended.ha" --report "$out/diagnosis"
"$hybrid" diagnose data/finger_demo.csv --json > "$out/diagnosis.json"
"$hybrid" check "$out/finger_extended.ha" --json > "$out/check_finger_extended.json"
grep -c '"verdict": "proved"' "$out/check_finger_extended.json" | sed 's/^/extended finger: proved properties: /'
echo "wrote out/diagnosis.json, out/diagnosis/ (SVG plots), out/finger_extended.ha, out/check_finger_extended.json"

# Diagnosis of any model (docs/diagnosis.md, "Any model"): the thermostat's measured traces (SYNTHETIC:
# made by tools/thermostat_trace.py from the closed form, see each file's header) against the model;
# each hidden defect named with its value, the extended models written and checked (exit 6: the
# thermostat's `comfortable` is violated for an outside temperature of 30 degC, as for the model given).
echo "=== diagnose any model ==="
for trace in clean weak_heater sensor_bias; do
  echo "data/thermostat_$trace.csv:"
  "$hybrid" diagnose spec/thermostat.ha "data/thermostat_$trace.csv" > "$out/thermostat_$trace.txt"
  grep -E '^(cause:|  [A-Za-z_.]+ = |explained:)' "$out/thermostat_$trace.txt"
done
"$hybrid" diagnose spec/thermostat_urgent.ha data/thermostat_threshold.csv \
  --out-model "$out/thermostat_extended.ha" --report "$out/thermostat_diagnosis"
"$hybrid" check "$out/thermostat_extended.ha" || [ $? -eq 6 ]
echo "wrote out/thermostat_*.txt, out/thermostat_extended.ha, out/thermostat_diagnosis/ (x.svg)"

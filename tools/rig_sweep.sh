#!/usr/bin/env bash
# Diagnoses data from the independent rig (tests/test_utilities/robotiq_rig.h) with one hidden
# effect at each given size, for noise seeds 1..SEEDS: the measurement behind the rig thresholds
# of docs/diagnosis_detectability.md. Each case is DiagnoseRigTest.Explore
# (tests/gripper/finger_diagnosis_test.cc): 10 runs of the report's protocol past the stop and
# back, stepped by 1 count (seed % 3 == 0), 2 counts (1) or irregularly (2), with a reversal on
# the way up when the seed is odd; it prints "rig KIND SIZE seed S: DIAGNOSIS".
#
# Usage: tools/rig_sweep.sh [--seeds N] [--build-dir DIR] KIND SIZE...
#   KIND   backlash, motor_offset, theta1_max, theta2_max, theta3_max (the deviation from the
#          model's value), theta1_bias, theta2_bias, theta3_bias, compliance_link1,
#          compliance_link2, theta3_fraction (deviation from 0.5), none
#   SIZE   signed sizes, e.g. 0.5 -0.5 2
# Example: tools/rig_sweep.sh --seeds 3 backlash 0.3 0.6 6 15   (about 2 s per case)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
seeds=3
build="$root/build"
usage() { sed -n '2,/^set -euo/p' "$0" | sed -n 's/^# \{0,1\}//p'; exit "$1"; }
while [ $# -gt 0 ]; do
  case "$1" in
    --seeds) seeds=${2:?}; shift 2 ;;
    --build-dir) build=${2:?}; shift 2 ;;
    -h|--help) usage 0 ;;
    -*) echo "rig_sweep.sh: unknown option $1" >&2; usage 2 >&2 ;;
    *) break ;;
  esac
done
[ $# -ge 2 ] || usage 2 >&2
case "$seeds" in ''|*[!0-9]*) echo "rig_sweep.sh: --seeds must be a positive integer" >&2; exit 2 ;; esac
test_binary="$build/tests/finger_diagnosis_test"
[ -x "$test_binary" ] || { echo "rig_sweep.sh: build the tests first ($test_binary)" >&2; exit 2; }
kind=$1; shift
for size in "$@"; do
  for seed in $(seq 1 "$seeds"); do
    HYBRID_DIAGNOSE_RIG="$kind,$size,$seed,$((seed % 3)),$((seed % 2))" \
      "$test_binary" --gtest_filter='DiagnoseRigTest.Explore' | grep '^rig ' || true
  done
done

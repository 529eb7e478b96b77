#!/usr/bin/env bash
# The main job on the bundled models: install, build, then for every model in spec/ print its
# summary (`hybrid info`), write it as JSON, render its mode graph to SVG and simulate its default
# scenario (trajectory and event log as CSV). Results in out/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/build.sh"
hybrid="$root/build/tools/hybrid"
out="$root/out"
mkdir -p "$out"
for model in "$root"/spec/*.ha; do
  name=$(basename "$model" .ha)
  echo "=== $name ==="
  "$hybrid" info "$model"
  "$hybrid" info "$model" --json > "$out/$name.json"
  "$hybrid" dot "$model" -o "$out/$name.dot"
  dot -Tsvg "$out/$name.dot" -o "$out/$name.svg"
  # Simulate the model's default scenario (exit 5 = stopped early, reported, not a failure here).
  status=0
  "$hybrid" simulate "$model" --out "$out/$name.trace.csv" --events "$out/$name.events.csv" || status=$?
  [ "$status" -eq 0 ] || [ "$status" -eq 5 ] || exit "$status"
  echo "wrote out/$name.json, out/$name.dot, out/$name.svg, out/$name.trace.csv, out/$name.events.csv"
  echo
done

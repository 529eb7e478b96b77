#!/usr/bin/env bash
# The main job on the bundled models: install, build, then for every model in spec/ print its
# summary (`hybrid info`), write it as JSON, and render its mode graph to SVG. Results in out/.
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
  echo "wrote out/$name.json, out/$name.dot, out/$name.svg"
  echo
done

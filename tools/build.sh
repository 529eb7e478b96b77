#!/usr/bin/env bash
# Installs the Debian dependencies (tools/setup.sh) and builds into build/ (Release).
# Usage: tools/build.sh [--program] [extra cmake arguments]
#   --program   build only the `hybrid` program (build/bin/hybrid) and what it links, as the
#               main job needs (tools/main_job.sh); without it, everything: the program, the
#               Python module, the tests and the benchmarks (tools/test.sh).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
targets=()
if [ "${1:-}" = --program ]; then
  targets=(--target hybrid)
  shift
fi
"$root/tools/setup.sh"
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$root/build" -j "$(nproc)" "${targets[@]}"

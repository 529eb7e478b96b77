#!/usr/bin/env bash
# Installs, builds and runs every test (rapidcheck seeds pinned in tests/CMakeLists.txt).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/tools/build.sh"
cd "$root/build"
ctest --output-on-failure -j "$(nproc)"

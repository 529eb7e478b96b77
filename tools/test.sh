#!/usr/bin/env bash
# Installs, builds and runs every test (rapidcheck seeds pinned in tests/CMakeLists.txt). Three
# stages, all run by default (`.ci/run`); name some to run only those (docs/fuzzing.md for fuzz):
#   release    the Release build in build/ and its whole suite (ctest), and the function-size
#              limits (tools/function_sizes.py: none over 150 lines, at most 5 over 100);
#   sanitized  the whole suite again under AddressSanitizer + UndefinedBehaviorSanitizer with leak
#              detection on (build-asan/, -O1, fewer rapidcheck cases); any finding fails its test;
#   fuzz       every libFuzzer harness (tests/fuzz/) for a short bounded time (tools/fuzz.sh).
# Usage: tools/test.sh [release] [sanitized] [fuzz]      (no argument: all three)
# Environment: HYBRID_FUZZ_SECONDS (default 20) seconds per harness in the fuzz stage.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
stages=("$@")
[ ${#stages[@]} -gt 0 ] || stages=(release sanitized fuzz)
jobs=$(nproc)

run_release() {
  "$root/tools/build.sh"
  (cd "$root/build" && ctest --output-on-failure -j "$jobs")
  python3 "$root/tools/function_sizes.py"
}

run_sanitized() {
  "$root/tools/setup.sh"
  # -g1: line tables only. The sanitizers' reports keep file:line:column in every frame, and the
  # build takes a third less time than with full debug information (-g: the parser alone, 113 s
  # of one core against 61 s).
  cmake -S "$root" -B "$root/build-asan" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DHYBRID_SANITIZE=ON \
    -DCMAKE_CXX_FLAGS_DEBUG=-g1 \
    -DHYBRID_BUILD_BENCHMARKS=OFF \
    -DHYBRID_RC_PARAMS="seed=20261121 max_success=60" \
    -DHYBRID_RC_PARAMS_SLOW="seed=20261121 max_success=20" -DHYBRID_TEST_TIMEOUT=1200
  cmake --build "$root/build-asan" -j "$jobs"
  # Leak detection on; any report aborts the test (non-zero exit); suppressions only for the
  # uninstrumented system libraries' own allocations (tests/sanitizer/lsan.supp says which and why).
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1:detect_stack_use_after_return=0:strict_string_checks=1"
  export LSAN_OPTIONS="suppressions=$root/tests/sanitizer/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  # The engine agreement test's random systems (tests/solvers/verification/engine_agreement_test.cc):
  # fewer under the sanitizers, as rapidcheck's cases above (200 in the Release stage).
  export HYBRID_AGREEMENT_SYSTEMS="${HYBRID_AGREEMENT_SYSTEMS:-60}"
  # The flowpipe engine's soundness test (tests/solvers/flowpipe/flowpipe_soundness_test.cc): its
  # Taylor steps are many times slower unoptimised (30 models and 5 systems in the Release stage).
  export HYBRID_FLOWPIPE_SOUNDNESS_MODELS="${HYBRID_FLOWPIPE_SOUNDNESS_MODELS:-6}"
  export HYBRID_FLOWPIPE_SYSTEMS_MODELS="${HYBRID_FLOWPIPE_SYSTEMS_MODELS:-2}"
  # The diagnosis property test over random models (automaton_diagnosis_property_test.cc): 56
  # draws in the Release stage.
  export HYBRID_MODEL_DIAGNOSE_DRAWS="${HYBRID_MODEL_DIAGNOSE_DRAWS:-12}"
  # Left to the Release stage (CI time): the CMake package's install-and-consume test and the
  # benchmark script's test, 50 s and 124 s under the sanitizers in CI: packaging, and the
  # script's verdicts on the LHA benchmarks, whose reachability engine runs under the sanitizers
  # in its own tests and in the engine agreement test.
  (cd "$root/build-asan" &&
     ctest --output-on-failure -j "$jobs" --timeout 900 -E '^(cmake_package|BenchmarksTest)$')
}

run_fuzz() {
  "$root/tools/fuzz.sh" --seconds "${HYBRID_FUZZ_SECONDS:-20}"
}

for stage in "${stages[@]}"; do
  echo "=== test stage: $stage ==="
  case "$stage" in
    release) run_release ;;
    sanitized) run_sanitized ;;
    fuzz) run_fuzz ;;
    *) echo "tools/test.sh: unknown stage '$stage' (expected release, sanitized or fuzz)" >&2; exit 2 ;;
  esac
done
echo "=== all test stages passed: ${stages[*]} ==="

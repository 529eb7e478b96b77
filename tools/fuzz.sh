#!/usr/bin/env bash
# Builds the libFuzzer harnesses (tests/fuzz/) and runs each for a bounded time; see docs/fuzzing.md.
#
# Usage: tools/fuzz.sh [--seconds N] [--runs R] [--jobs J] [--fast] [--build-dir DIR] [--fresh]
#                      [--no-build] [harness...] [-- libFuzzer flags...]
#   --seconds N    run each harness for at most N seconds (default 20)
#   --runs R       ... or until it has executed R inputs, whichever comes first (default: no limit)
#   --jobs J       run up to J harnesses at the same time, one process (one core) each (default 1)
#   --fast         LeakSanitizer alone instead of ASan + UBSan (3 to 4 times faster; for long
#                  runs beside the ASan ones: no heap-overflow, use-after-free or UB checks)
#   --build-dir D  the fuzz build directory (default build-fuzz, with --fast build-fuzz-fast;
#                  configured here with clang++)
#   --fresh        start from the seeds alone (delete the corpus the previous runs grew)
#   --no-build     use the harnesses already built
#   harness...     some of: fuzz_model_parser fuzz_round_trip fuzz_signal fuzz_object
#                  fuzz_measured_data fuzz_numbers fuzz_options fuzz_spaceex fuzz_trace_data
#                  (default: all)
# Each harness runs with -max_total_time=N -rss_limit_mb=2048 -timeout=10 (seconds per input),
# (HYBRID_FUZZ_RSS_MB overrides the 2048 MB of -rss_limit_mb and -malloc_limit_mb: long runs),
# leak detection on and -print_final_stats=1; its corpus is DIR/fuzz/corpus/HARNESS (seeds copied
# in by tests/fuzz/collect_seeds.py), its log DIR/fuzz/logs/HARNESS.log, and any crashing, timing
# out, leaking or memory-exhausting input is written to DIR/fuzz/findings/HARNESS/ (those of
# earlier runs stay there but are not reported again).
# Prints the executions of each harness; exits 1 if any harness found anything (or did not run).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

all_harnesses=(fuzz_model_parser fuzz_round_trip fuzz_signal fuzz_object fuzz_measured_data
               fuzz_numbers fuzz_options fuzz_spaceex fuzz_trace_data)
seconds=20
runs=""
jobs=1
build_dir=""
profile=asan
fresh=0
build=1
harnesses=()
extra=()
# usage STATUS: prints this file's header and exits with STATUS.
usage() { sed -n '2,/^set -euo/p' "$0" | sed -n 's/^# \{0,1\}//p'; exit "$1"; }
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=${2:?}; shift 2 ;;
    --runs) runs=${2:?}; shift 2 ;;
    --jobs) jobs=${2:?}; shift 2 ;;
    --fast) profile=fast; shift ;;
    --build-dir) build_dir=$(realpath -m "${2:?}"); shift 2 ;;
    --fresh) fresh=1; shift ;;
    --no-build) build=0; shift ;;
    -h|--help) usage 0 ;;
    --) shift; extra=("$@"); break ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; usage 2 >&2 ;;
    *) harnesses+=("$1"); shift ;;
  esac
done
rss_mb=${HYBRID_FUZZ_RSS_MB:-2048}
if [ -z "$build_dir" ]; then
  build_dir="$root/build-fuzz"
  [ "$profile" = asan ] || build_dir="$root/build-fuzz-$profile"
fi
for n in "$seconds" "$jobs" "$rss_mb" ${runs:+"$runs"}; do
  [[ "$n" =~ ^[1-9][0-9]*$ ]] || { echo "fuzz.sh: '$n' is not a positive integer (--seconds, --runs, --jobs, HYBRID_FUZZ_RSS_MB)" >&2; exit 2; }
done
[ ${#harnesses[@]} -gt 0 ] || harnesses=("${all_harnesses[@]}")
for h in "${harnesses[@]}"; do
  [[ " ${all_harnesses[*]} " == *" $h "* ]] || { echo "fuzz.sh: no harness '$h'" >&2; exit 2; }
done

# The dictionary of each harness (tests/fuzz/dictionaries/).
dictionary() {
  case "$1" in
    fuzz_model_parser|fuzz_round_trip) echo model ;;
    *) echo "${1#fuzz_}" ;;
  esac
}

if [ "$build" -eq 1 ]; then
  launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  generator=()
  if command -v ninja >/dev/null; then generator=(-G Ninja); fi
  if [ ! -f "$build_dir/CMakeCache.txt" ]; then
    cmake -S "$root" -B "$build_dir" "${generator[@]}" -DCMAKE_CXX_COMPILER=clang++ \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHYBRID_BUILD_FUZZERS=ON -DHYBRID_BUILD_TESTS=OFF \
      -DHYBRID_BUILD_BENCHMARKS=OFF -DHYBRID_FUZZ_PROFILE="$profile" "${launcher[@]}"
  else
    cmake -S "$root" -B "$build_dir" -DHYBRID_BUILD_FUZZERS=ON -DHYBRID_FUZZ_PROFILE="$profile" \
      >/dev/null
  fi
  cmake --build "$build_dir" --target "${harnesses[@]}" -j "${HYBRID_BUILD_JOBS:-$(nproc)}"
fi

work="$build_dir/fuzz"
mkdir -p "$work/logs"
# Findings older than this run's start are not this run's (one stamp per run: runs of other
# harnesses in the same directory may overlap).
stamp=$(mktemp "$work/logs/.started.XXXXXX")
trap 'rm -f "$stamp"' EXIT
# Leak detection on (LSan); suppressions only for uninstrumented system libraries
# (tests/sanitizer/lsan.supp). No recovery from UBSan findings (also compiled in).
# malloc_context_size=10 (default 30) makes allocation-heavy harnesses ~25% faster; reproduce a
# finding by running the harness on it directly for full stacks (docs/fuzzing.md). The fast
# profile's standalone LSan reads LSAN_OPTIONS only: there malloc_context_size=4 keeps its stack
# depot small (with 30, every distinct parser recursion stack was kept: fuzz_model_parser grew
# about 1.5 KB per input) and halves the time per input.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:detect_stack_use_after_return=0:malloc_context_size=10:${ASAN_OPTIONS:-}"
lsan_supp="$root/tests/sanitizer/lsan.supp"
lsan_context=""
[ "$profile" = asan ] || lsan_context="malloc_context_size=4:"
export LSAN_OPTIONS="${lsan_context}${LSAN_OPTIONS:-}${LSAN_OPTIONS:+:}print_suppressions=0$([ -f "$lsan_supp" ] && echo ":suppressions=$lsan_supp")"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"

# run_one HARNESS: fuzzes it; the exit status of libFuzzer goes to its log's last line.
run_one() {
  local h=$1 corpus="$work/corpus/$1" findings="$work/findings/$1" log="$work/logs/$1.log"
  [ "$fresh" -eq 0 ] || rm -rf "$corpus"
  mkdir -p "$corpus" "$findings"
  python3 "$root/tests/fuzz/collect_seeds.py" "$root" "$h" "$corpus" >/dev/null
  local flags=(-max_total_time="$seconds" -rss_limit_mb="$rss_mb" -malloc_limit_mb="$rss_mb" -timeout=10
               -detect_leaks=1 -print_final_stats=1 -close_fd_mask=1
               -artifact_prefix="$findings/"
               -dict="$root/tests/fuzz/dictionaries/$(dictionary "$h").dict")
  [ -z "$runs" ] || flags+=(-runs="$runs")
  local status=0
  "$build_dir/tests/fuzz/$h" "${flags[@]}" "${extra[@]}" "$corpus" >"$log" 2>&1 || status=$?
  echo "fuzz.sh: exit status $status" >>"$log"
}

# Runs the harnesses, at most $jobs at a time.
for h in "${harnesses[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  echo "fuzz.sh: running $h for at most ${seconds}s${runs:+ or $runs executions}"
  run_one "$h" &
done
wait || true

# The final statistic NAME of a log (empty if libFuzzer did not print it).
stat() { sed -n "s/^stat::$2: *//p" "$1" | tail -n 1; }

# A timeout is re-run alone: one that does not reproduce (the input then runs in time) came from
# the machine stalling the process, not from the input; it cuts the harness's run short but is
# not a finding. Everything else new in the findings folder is.
failed=0
printf '\n%-20s %12s %10s %8s %s\n' harness executions "exec/s" "new" result
for h in "${harnesses[@]}"; do
  log="$work/logs/$h.log"
  status=$(sed -n 's/^fuzz.sh: exit status //p' "$log" | tail -n 1)
  executions=$(stat "$log" number_of_executed_units)
  findings=() stalls=()
  for f in $(find "$work/findings/$h" -type f -newer "$stamp" | sort); do
    if [[ "$(basename "$f")" == timeout-* ]] &&
       "$build_dir/tests/fuzz/$h" -timeout=10 -rss_limit_mb="$rss_mb" "$f" >"$log.rerun" 2>&1; then
      stalls+=("$f")
    else
      findings+=("$f")
    fi
  done
  result=ok
  if [ ${#findings[@]} -eq 0 ] && [ ${#stalls[@]} -gt 0 ] && [ "$status" = 70 ]; then
    result="ok, cut short: a timeout that does not reproduce (machine stalled): ${stalls[*]}"
  elif [ "${status:-1}" != 0 ] || [ -z "$executions" ] || [ ${#findings[@]} -gt 0 ] ||
       grep -qE '^==[0-9]+==ERROR|^SUMMARY: (Address|Leak|UndefinedBehavior)Sanitizer|==fuzz== contract broken|ERROR: libFuzzer' "$log"; then
    result="FAILED (status ${status:-?}; see $log)"
    failed=1
  fi
  printf '%-20s %12s %10s %8s %s\n' "$h" "${executions:--}" "$(stat "$log" average_exec_per_sec)" \
    "$(stat "$log" new_units_added)" "$result"
  for f in "${findings[@]}"; do
    echo "    finding: $f  (reproduce: $build_dir/tests/fuzz/$h $f)"
  done
done
exit "$failed"

#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, MECCANO_FUZZ: ASan + UBSan + libFuzzer) and runs each for a
# number of seconds on its seed corpus; fails on the first crash, hang, leak or oversized allocation.
#
# Usage: tests/fuzz/run_fuzz.sh [--parallel] [seconds per target, default 60] [build-dir, default build-fuzz/ in the checkout]
#
# --parallel runs all targets at once (for long unattended runs) instead of one after the other.
# FUZZ_UNIT_TIMEOUT (seconds, default 10) is libFuzzer's -timeout, which counts wall time: a fuzzer
# starved of CPU (niced beside other work) can pass 10 s on an input that takes milliseconds, so raise
# it for long runs on a busy machine, and replay a reported timeout before believing it.
#
# New inputs that libFuzzer finds go to <build-dir>/corpus/<target>/ (the seeds under
# tests/fuzz/corpus/ stay as they are); a crashing input is saved as <build-dir>/artifacts/<target>-*
# and can be replayed with: <build-dir>/tests/fuzz/<target> <file>.
set -euo pipefail
: "${CMAKE_GENERATOR:=Ninja}"   # for new build trees only (CMake reads it when it creates one)
export CMAKE_GENERATOR
cd "$(dirname "$0")/../.."
parallel=0
if [ "${1:-}" = --parallel ]; then parallel=1; shift; fi
seconds=${1:-60}
build=${2:-build-fuzz}
jobs=$(( $(nproc) < 2 ? $(nproc) : 2 ))
targets=(fuzz_read_obj fuzz_read_stl fuzz_read_off fuzz_read_msh fuzz_read_tsurf fuzz_validate_surface)

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DMECCANO_FUZZ=ON \
      -DMECCANO_BUILD_TESTS=OFF -DMECCANO_BUILD_SOLVER_DEMO=OFF > "$build.log" 2>&1 || { cat "$build.log"; exit 1; }
cmake --build "$build" -j"$jobs" --target "${targets[@]}" >> "$build.log" 2>&1 || { tail -60 "$build.log"; exit 1; }

export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
mkdir -p "$build/artifacts"
# Runs one target; prints its result and returns non-zero on a finding.
fuzz_target() {
  local target=$1
  # Readers see whole files (a few KiB suffice for every section and count); validation inputs
  # decode at most three 64-triangle surfaces.
  local max_len=16384
  [ "$target" = fuzz_validate_surface ] && max_len=4096
  mkdir -p "$build/corpus/$target"
  local log="$build/$target.log"
  if ! "$build/tests/fuzz/$target" -max_total_time="$seconds" -max_len="$max_len" -rss_limit_mb=2048 \
       -timeout="${FUZZ_UNIT_TIMEOUT:-10}" -print_final_stats=1 -artifact_prefix="$build/artifacts/$target-" \
       "$build/corpus/$target" "tests/fuzz/corpus/$target" > "$log" 2>&1; then
    tail -40 "$log"
    echo "fuzz: $target FAILED (log $log, input in $build/artifacts/)"
    return 1
  fi
  local runs
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  echo "fuzz: $target ok: $runs executions in ${seconds} s"
}

if [ "$parallel" = 1 ]; then
  pids=()
  for target in "${targets[@]}"; do fuzz_target "$target" & pids+=($!); done
  failed=0
  for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
  exit "$failed"
fi
for target in "${targets[@]}"; do
  fuzz_target "$target"
done

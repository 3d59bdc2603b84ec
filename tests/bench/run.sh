#!/usr/bin/env bash
# Builds the project and runs every benchmark, printing their Markdown tables: the bench_* programs (given
# the extra arguments) and a quick run of bench_faults.sh (real faults and hard surfaces, a few minutes).
# The long runs are separate: tests/bench/bench_faults.sh without --quick (3-4 hours; --write updates
# doc/benchmarks.md) and tests/bench/compare_references.sh (doc/comparison.md).
# Usage: tests/bench/run.sh [extra arguments passed to each bench_* program]
set -euo pipefail
cd "$(dirname "$0")/../.."
scripts/build.sh
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(date -u +%F)"
for bench in build/tests/bench/bench_*; do
  [ -x "$bench" ] || continue
  echo
  echo "## $(basename "$bench")"
  echo
  "$bench" "$@"
done
echo
echo "## bench_faults.sh --quick"
echo
if [ -x build/reference/reference-gmsh ]; then
  tests/bench/bench_faults.sh --quick
else
  echo "Skipped: build/reference/reference-gmsh was not built (no Gmsh library found)."
fi

#!/usr/bin/env bash
# Builds the project and runs every benchmark, printing their Markdown tables.
# Usage: tests/bench/run.sh [extra arguments passed to each benchmark]
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

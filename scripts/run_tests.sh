#!/usr/bin/env bash
# Set up the machine, build, and run the whole test suite with CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
ctest --test-dir build -j"$(nproc)" --output-on-failure

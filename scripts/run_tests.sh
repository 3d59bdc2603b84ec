#!/usr/bin/env bash
# Set up the machine, check the C++ formatting (scripts/check_format.sh), build with warnings as errors
# (MECCANO_WERROR), run clang-tidy over the library (scripts/run_tidy.sh), and run the whole test suite with CTest (every label: unit, pipeline, long; the
# layering check is a unit test); then the quick sanitized subset (ASan + UBSan,
# scripts/run_sanitized_tests.sh --quick) and a short fuzzing run of the surface readers and the
# validation (20 s per target) when clang and libFuzzer are available.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/check_format.sh
MECCANO_WERROR=ON scripts/build.sh
scripts/run_tidy.sh
ctest --test-dir build -j"$(nproc)" --output-on-failure
scripts/run_sanitized_tests.sh --quick build-asan
if command -v clang++ > /dev/null && echo 'extern "C" int LLVMFuzzerTestOneInput(const char*, unsigned long) { return 0; }' \
     | clang++ -x c++ -fsanitize=fuzzer -o /dev/null - 2> /dev/null; then
  tests/fuzz/run_fuzz.sh 20
else
  echo "fuzz: skipped (clang++ with libFuzzer not available)"
fi

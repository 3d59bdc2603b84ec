#!/usr/bin/env bash
# Configures and builds meccano-immerse (Release) in ./build. Used by the two README commands.
# MECCANO_WERROR=ON|OFF in the environment sets the CMake option MECCANO_WERROR (warnings are errors);
# scripts/run_tests.sh, the CI path, sets ON. Unset, the build keeps what build/ was configured with.
set -euo pipefail
: "${CMAKE_GENERATOR:=Ninja}"   # for new build trees only (CMake reads it when it creates one)
export CMAKE_GENERATOR
cd "$(dirname "$0")/.."
werror=()
if [ -n "${MECCANO_WERROR:-}" ]; then werror=(-DMECCANO_WERROR="$MECCANO_WERROR"); fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON "${werror[@]}" > build.log 2>&1 || { cat build.log; exit 1; }
cmake --build build -j"$(nproc)" >> build.log 2>&1 || { tail -60 build.log; exit 1; }
echo "build: ok (log in build.log)"

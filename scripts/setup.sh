#!/usr/bin/env bash
# Installs every Debian package meccano-immerse needs to build, test and run its demos.
# Idempotent; needs root (or sudo) on a Debian 12 machine.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  ninja-build                         # the scripts' CMake generator: tests compile while the library links
  libeigen3-dev                       # the module's only library dependency (with OpenMP)
  libgtest-dev libbenchmark-dev       # tests and benchmarks
  libgmsh-dev gmsh                    # independent MSH reader in the tests, reference meshes
  libtet1.5-dev tetgen                # the TetGen reference mesher (reference/reference-tetgen)
  libdeal.ii-dev                      # the adapter meccano::dealii and the demo solver: deal.II with Trilinos and MPI
  python3-dolfinx python3-gmsh        # the user guide's dolfinx example, run by CTest (tests/dolfinx/)
  python3 python3-matplotlib python3-numpy   # plots in doc/
  clang libclang-rt-14-dev libomp-dev  # libFuzzer targets (tests/fuzz/): clang's sanitizers, libFuzzer, OpenMP
  clang-format clang-tidy             # .clang-format and .clang-tidy: style and static checks in CI
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "setup: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"

#!/usr/bin/env bash
# Builds tests/consumer/main.cpp against an installed meccano-immerse, as an FE code would, and runs
# it. CTest runs each step as a test (tests/consumer.cmake), the install once, as a fixture.
#
#   run_consumer.sh install WORK BUILD_DIR   cmake --install BUILD_DIR --prefix WORK/prefix
#   run_consumer.sh cmake WORK               find_package(MeccanoImmerse) project in WORK/cmake, then run
#   run_consumer.sh pkg-config WORK LIBDIR   c++ $(pkg-config --cflags --libs meccano-immerse) in
#                                            WORK/pkg-config (.pc under WORK/prefix/LIBDIR), then run
#   run_consumer.sh dealii WORK              find_package(MeccanoImmerse COMPONENTS dealii) project
#                                            tests/consumer_dealii in WORK/dealii; runs its program on
#                                            a mesh of the library, then on a file of the installed tool
#
# Every step starts from an emptied directory, so nothing left by an earlier run can hide a packaging
# defect. CMAKE and CXX name the cmake and the compiler to use (default: those on PATH).
set -euo pipefail

consumer_dir=$(cd "$(dirname "$0")" && pwd)
cmake=${CMAKE:-cmake}
cxx=${CXX:-c++}
usage="usage: run_consumer.sh install WORK BUILD_DIR | cmake WORK | pkg-config WORK LIBDIR | dealii WORK"
[ $# -ge 2 ] || { echo "$usage" >&2; exit 2; }
step=$1
prefix=$2/prefix
out=$2/$step

fresh_dir() { rm -rf "$1"; mkdir -p "$1"; }
# A copy installed elsewhere (say in /usr/local) must not stand in for the one under test.
found_under_prefix() {
  case $2 in "$prefix"/*) ;; *) echo "run_consumer.sh: $1 found at $2, not under $prefix" >&2; exit 1 ;; esac
}

# Configures and builds the CMake project in $1 against the installed package, in $out.
build_with_cmake() {
  fresh_dir "$out"
  "$cmake" -S "$1" -B "$out" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release
  found_under_prefix MeccanoImmerse "$(sed -n 's/^MeccanoImmerse_DIR:PATH=//p' "$out/CMakeCache.txt")"
  "$cmake" --build "$out"
}

case $step in
  install)
    [ $# -eq 3 ] || { echo "$usage" >&2; exit 2; }
    fresh_dir "$prefix"
    "$cmake" --install "$3" --prefix "$prefix"
    ;;
  cmake)
    build_with_cmake "$consumer_dir"
    "$out/consumer"
    ;;
  pkg-config)
    [ $# -eq 3 ] || { echo "$usage" >&2; exit 2; }
    fresh_dir "$out"
    export PKG_CONFIG_PATH=$prefix/$3/pkgconfig
    found_under_prefix meccano-immerse.pc "$(pkg-config --path meccano-immerse)"
    # Word splitting of the flags is intended: they are separate compiler arguments.
    # shellcheck disable=SC2046
    "$cxx" -std=c++20 -O2 "$consumer_dir/main.cpp" -o "$out/consumer" $(pkg-config --cflags --libs meccano-immerse)
    # Only needed for a shared library (BUILD_SHARED_LIBS=ON); pkg-config adds no run path.
    LD_LIBRARY_PATH=$(pkg-config --variable=libdir meccano-immerse) "$out/consumer"
    ;;
  dealii)
    build_with_cmake "$consumer_dir/../consumer_dealii"
    "$out/flux_jump"
    "$prefix/bin/meccano-immerse" --box 0,0,0,1,1,1 --level 1 --surface "$consumer_dir/../../meshes/spherical_cap.obj:cap" \
      --resolution 0.08 --quiet --output "$out/cap.msh"
    "$out/flux_jump" "$out/cap.msh" cap
    ;;
  *)
    echo "$usage" >&2
    exit 2
    ;;
esac

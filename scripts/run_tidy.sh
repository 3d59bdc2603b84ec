#!/usr/bin/env bash
# clang-tidy (.clang-tidy) over the library's sources, or the files given, with the compile commands of
# the build tree build/ (scripts/build.sh exports them; configured here if it does not exist yet). Exits 1
# if clang-tidy reports a warning. CI (scripts/run_tests.sh) runs it after the build.
#   scripts/run_tidy.sh                      every source of module/src and module/cli
#   scripts/run_tidy.sh FILE.cpp ...         those files
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f build/compile_commands.json ] || cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON > /dev/null
if [ $# -gt 0 ]; then files=("$@"); else mapfile -t files < <(git ls-files 'module/src/*.cpp' 'module/cli/*.cpp'); fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
printf '%s\n' "${files[@]}" | xargs -P "$(nproc)" -n 1 clang-tidy -p build --quiet > "$log" 2> /dev/null || true
if grep -qE "(warning|error):" "$log"; then
  cat "$log"
  echo "tidy: $(grep -cE "(warning|error):" "$log") finding(s)"
  exit 1
fi
echo "tidy: ok (${#files[@]} files)"

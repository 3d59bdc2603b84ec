#!/usr/bin/env bash
# Fails, listing the files, when a tracked C++ file differs from what clang-format (.clang-format) makes of
# it. CI runs it (scripts/run_tests.sh); `scripts/check_format.sh --fix` reformats those files in place.
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h')
if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${files[@]}"
  exit 0
fi
unformatted=()
for f in "${files[@]}"; do
  clang-format --dry-run --Werror "$f" > /dev/null 2>&1 || unformatted+=("$f")
done
if [ ${#unformatted[@]} -gt 0 ]; then
  echo "format: ${#unformatted[@]} file(s) differ from .clang-format (scripts/check_format.sh --fix):"
  printf '  %s\n' "${unformatted[@]}"
  exit 1
fi
echo "format: ok (${#files[@]} files)"

#!/usr/bin/env bash
# Fails when any C++ source of the project is not formatted as .clang-format says (the CI
# main leg runs it before building). Pinned to clang-format 14, Debian 12's: another version
# may lay out the same code differently. Usage:
#   tools/check-format.sh           # list the files that differ, exit 1 if any
#   tools/check-format.sh --fix     # format them in place
set -euo pipefail
cd "$(dirname "$0")/.."
fmt=${CLANG_FORMAT:-clang-format-14}
command -v "$fmt" >/dev/null || { echo "check-format: $fmt not found (apt install clang-format-14)" >&2; exit 2; }
mapfile -t files < <(git ls-files '*.cpp' '*.h' '*.hpp')
if [ "${1:-}" = "--fix" ]; then
  printf '%s\0' "${files[@]}" | xargs -0 "$fmt" -i
  exit 0
fi
bad=()
for f in "${files[@]}"; do
  "$fmt" "$f" | cmp -s - "$f" || bad+=("$f")
done
if [ ${#bad[@]} -gt 0 ]; then
  echo "check-format: ${#bad[@]} of ${#files[@]} files are not clang-format clean (fix: tools/check-format.sh --fix):" >&2
  printf '  %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "check-format: ${#files[@]} files clean"

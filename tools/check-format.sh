#!/usr/bin/env bash
# Fails when a source of the project is not formatted as .clang-format says: the C++ (*.cpp, *.h,
# *.hpp) and the shaders (*.glsl, which clang-format lays out as C; engine/shaders/.clang-format and
# gi/shaders/.clang-format keep their #include lines in order). The CI main leg runs it before
# building. Pinned to clang-format 14, Debian 12's: another version may lay out the same code
# differently. Usage:
#   tools/check-format.sh                   # every tracked source: list the files that differ, exit 1 if any
#   tools/check-format.sh --fix             # format them in place
#   tools/check-format.sh [--fix] FILE...   # only these files (say, the ones a commit touches)
set -euo pipefail
fix=0
if [ "${1:-}" = "--fix" ]; then
  fix=1
  shift
fi
# Named files are taken relative to the caller's directory, before moving to the repository root.
named=()
for f in "$@"; do
  case $f in
    *.cpp | *.h | *.hpp | *.glsl) ;;
    *) echo "check-format: $f is neither C++ (.cpp, .h, .hpp) nor GLSL (.glsl)" >&2; exit 2 ;;
  esac
  [ -f "$f" ] || { echo "check-format: no file $f" >&2; exit 2; }
  named+=("$(realpath "$f")")
done
cd "$(dirname "$0")/.."
fmt=${CLANG_FORMAT:-clang-format-14}
command -v "$fmt" >/dev/null || { echo "check-format: $fmt not found (apt install clang-format-14)" >&2; exit 2; }

if [ ${#named[@]} -gt 0 ]; then
  files=("${named[@]}")
else
  files=()
  while IFS= read -r f; do files+=("$f"); done < <(git ls-files '*.cpp' '*.h' '*.hpp' '*.glsl')
fi

if [ $fix = 1 ]; then
  printf '%s\0' "${files[@]}" | xargs -0 "$fmt" -i
  exit 0
fi
bad=()
for f in "${files[@]}"; do
  "$fmt" "$f" | cmp -s - "$f" || bad+=("$f")
done
if [ ${#bad[@]} -gt 0 ]; then
  echo "check-format: ${#bad[@]} of ${#files[@]} files are not clang-format clean (fix: tools/check-format.sh --fix [FILE...]):" >&2
  printf '  %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "check-format: ${#files[@]} files clean"

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

# Shaders that other branches were changing when the shaders joined the check (30 Nov 2026): the
# whole-tree check and fix leave them alone until they are formatted (tools/check-format.sh --fix
# FILE, after those branches are merged); then their lines here go. Named files are always checked.
pending=(
  engine/shaders/directional_radiance.glsl
  engine/shaders/forward.frag.glsl
  engine/shaders/forward.vert.glsl
  engine/shaders/reflection_probes.glsl
)

if [ ${#named[@]} -gt 0 ]; then
  files=("${named[@]}")
else
  files=()
  while IFS= read -r f; do
    for p in "${pending[@]}"; do [ "$f" = "$p" ] && continue 2; done
    files+=("$f")
  done < <(git ls-files '*.cpp' '*.h' '*.hpp' '*.glsl')
  for p in "${pending[@]}"; do
    if [ -f "$p" ] && "$fmt" "$p" | cmp -s - "$p"; then
      echo "check-format: $p is pending but already clean: remove it from tools/check-format.sh's pending list" >&2
    else
      echo "check-format: $p left out (pending, see tools/check-format.sh)" >&2
    fi
  done
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

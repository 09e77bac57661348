#!/usr/bin/env bash
# Bakes one scene with the gi-bake of two build directories and compares the bundles byte
# for byte (every file but bake_stats.json, docs/bake-bundle.md). CI's sanitizer leg runs it on
# the main leg's GCC build and the instrumented clang build: a bake must not depend on the
# compiler (gi/src/core/random.h: draws sequenced) any more than on the thread count.
#   tools/compare-bakes.sh build build-san [SCENE] [PRESET]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 2 ]; then
  echo "usage: tools/compare-bakes.sh BUILD_A BUILD_B [SCENE (assets/demo_level.gltf)] [PRESET (preview)]" >&2
  exit 2
fi
scene=${3:-assets/demo_level.gltf}
preset=${4:-preview}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The instrumented build's programs need the sanitizer leg's environment (tools/sanitize.sh).
driver=$(ls /usr/lib/*/dri/swrast_dri.so 2>/dev/null | head -1 || true)
for side in a b; do
  dir=$1
  [ "$side" = b ] && dir=$2
  bake="$dir/tools/gi-bake/gi-bake"
  [ -x "$bake" ] || { echo "compare-bakes.sh: no gi-bake in $dir (build it first)" >&2; exit 1; }
  start=$(date +%s)
  LD_PRELOAD="${driver}" ASAN_OPTIONS="verify_asan_link_order=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}" \
    "$bake" --scene "$scene" --preset "$preset" --out "$work/$side.gibake" >"$work/$side.log" 2>&1 ||
    { cat "$work/$side.log"; echo "compare-bakes.sh: the bake with $bake failed" >&2; exit 1; }
  echo "compare-bakes.sh: $bake baked $scene ($preset) in $(( $(date +%s) - start )) s"
done
different=0
files=0
for f in "$work/a.gibake"/*; do
  name=$(basename "$f")
  [ "$name" = bake_stats.json ] && continue
  files=$((files + 1))
  if ! cmp -s "$f" "$work/b.gibake/$name"; then
    echo "compare-bakes.sh: $name differs between $1 and $2" >&2
    different=1
  fi
done
for f in "$work/b.gibake"/*; do
  [ -e "$work/a.gibake/$(basename "$f")" ] || { echo "compare-bakes.sh: only $2 wrote $(basename "$f")" >&2; different=1; }
done
[ $different = 0 ] && echo "compare-bakes.sh: $files files byte-identical between $1 and $2"
exit $different

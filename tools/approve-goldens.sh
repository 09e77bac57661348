#!/usr/bin/env bash
# Regenerates the golden images of tests/golden/ by replaying the committed sessions
# headlessly, exactly as tests/demo/golden_test.cpp does (session, frame and size from
# tests/golden/goldens.txt). Review the new images before committing them.
#   tools/approve-goldens.sh [BUILD_DIR]        # default BUILD_DIR: build
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
demo="$build_dir/game_demo/gi_demo"
[ -x "$demo" ] || { echo "approve-goldens: $demo not built (BUILD_DIR=$build_dir bash tools/build.sh)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
while read -r session frame width height; do
  case "$session" in ''|'#'*) continue ;; esac
  "$demo" --headless --replay "tests/sessions/$session.girec" --frames $((frame + 1)) --width "$width" \
          --height "$height" --out "$tmp/$session" --every "$frame" --only-written-frames >/dev/null
  out=$(printf "tests/golden/%s_f%04d.png" "$session" "$frame")
  cp "$(printf "%s/%s/frame_%04d.png" "$tmp" "$session" "$frame")" "$out"
  echo "approved $out"
done < tests/golden/goldens.txt

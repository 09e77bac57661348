#!/usr/bin/env bash
# Regenerates the golden images of tests/golden/ by replaying the committed sessions
# headlessly, exactly as tests/demo/golden_test.cpp does (session, frame and size from
# tests/golden/goldens.txt; the fixed exposure game_demo::kDemoExposure, 0.3, not gi_demo's
# automatic default). Review the new images before committing them.
#   tools/approve-goldens.sh [BUILD_DIR]        # default BUILD_DIR: build
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
demo="$build_dir/game_demo/gi_demo"
[ -x "$demo" ] || { echo "approve-goldens: $demo not built (BUILD_DIR=$build_dir bash tools/build.sh)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
bundle="$build_dir/test-bundles/demo_level.gibake"
while read -r session frame width height lighting; do
  case "$session" in ''|'#'*) continue ;; esac
  gi=() suffix=""
  if [ "${lighting:-}" = "gi" ]; then
    # The bake the golden test uses (ctest's DemoBundle.BakePreview writes the same).
    [ -f "$bundle/manifest.json" ] || "$build_dir/tools/gi-bake/gi-bake" --scene assets/demo_level.gltf --preset preview \
                                           --out "$bundle" >/dev/null
    gi=(--gi-bundle "$bundle") suffix="_gi"
  fi
  "$demo" --headless --replay "tests/sessions/$session.girec" --exposure 0.3 --frames $((frame + 1)) --width "$width" \
          --height "$height" --out "$tmp/$session$suffix" --every "$frame" --only-written-frames "${gi[@]}" >/dev/null
  out=$(printf "tests/golden/%s_f%04d%s.png" "$session" "$frame" "$suffix")
  cp "$(printf "%s/%s%s/frame_%04d.png" "$tmp" "$session" "$suffix" "$frame")" "$out"
  echo "approved $out"
done < tests/golden/goldens.txt

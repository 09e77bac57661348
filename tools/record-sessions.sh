#!/usr/bin/env bash
# Re-records the committed play sessions (tests/sessions/*.girec) from their scripted
# inputs on the current assets/demo_level.gltf. Run it after regenerating the demo level
# (the replay tests then say "scene ... differs from the one this session was recorded on"),
# then regenerate the goldens with tools/approve-goldens.sh.
#   tools/record-sessions.sh [BUILD_DIR]        # default BUILD_DIR: build
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
demo="$build_dir/game_demo/gi_demo"
[ -x "$demo" ] || { echo "record-sessions: $demo not built (BUILD_DIR=$build_dir bash tools/build.sh)" >&2; exit 1; }
mkdir -p tests/sessions
# name:script:frames. The scene path is stored as given, relative to the source tree.
for spec in walk_flashlight:walk_flashlight:900 push_crates:push_crates:900 split_screen:split_screen:600 \
            open_door:open_door:160 push_crates_wall:crate_to_wall:720; do
  IFS=: read -r name script frames <<<"$spec"
  "$demo" --headless --no-render --scene assets/demo_level.gltf --script "$script" --frames "$frames" \
          --width 320 --height 180 --record "tests/sessions/$name.girec" >/dev/null
  echo "recorded tests/sessions/$name.girec ($frames frames, script $script)"
done

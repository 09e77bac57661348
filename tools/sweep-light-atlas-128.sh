#!/usr/bin/env bash
# The light atlas's before/after on the Cornell box at 128 texels/m (issue 17, docs/light_atlas.md):
# VPL shooting (the old presets) and the final gather against the same 4096-spp path-traced
# reference (each at its own texel samples), then the table of speed-ups at equal error.
# Run on an otherwise idle machine: the table's seconds are wall-clock bake times.
#   bash tools/sweep-light-atlas-128.sh            (about 6 min on 2 cores, references cached)
set -euo pipefail
cd "$(dirname "$0")/.."
sweep=${GI_SWEEP:-build/tools/gi-sweep/gi-sweep}
out=docs/sweeps/light_atlas_128
cache=${CACHE:-build/reference-cache}
"$sweep" --method light_atlas --scene assets/cornell_box.gltf --knob density=128 --knob final=shoot \
  --knob vpls=300,1000,3000 --knob bounces=8,16 --out "$out/shoot" --cache "$cache" --threads 2
"$sweep" --method light_atlas --scene assets/cornell_box.gltf --knob density=128 --knob final=gather \
  --knob vpls=300 --knob bounces=64 --knob solve_rays=4,8,16,32,128 --knob rays=0,128,512,1024,2048 \
  --knob filter=0,1,2.5 --knob direct_samples=4 --out "$out/gather" --cache "$cache" --threads 2
/usr/bin/python3 tools/light-atlas-speedup.py "$out/shoot/light_atlas_cornell_box.csv" \
  "$out/gather/light_atlas_cornell_box.csv" > "$out/speedup.md"
cat "$out/speedup.md"

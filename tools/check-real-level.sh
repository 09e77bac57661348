#!/usr/bin/env bash
# Issue 32's measurement on a real third-party level, in one command: the Dabrovic Sponza
# atrium (untextured) under a gradient sky and a high or a low sun, under the sky alone and
# under the high sun alone (what the renderer gets wrong besides the sky), and the Cornell box
# without its lamp under the sky through its open side; each baked at every preset, each
# view's frame against the path tracer's truth per region and over the frame
# (tools/gi-frame-truth), plus Sponza's bake time and peak memory per preset (gi-bake under
# /usr/bin/time -v). Writes the generated part of docs/real_level.md (between its "generated"
# markers; the text around them is kept) and everything else into OUT.
#   tools/check-real-level.sh                  # build/ ; presets preview and medium
#   PRESETS="preview medium high" tools/check-real-level.sh build
#   SPP=128 WIDTH=160 HEIGHT=90 DOC=/tmp/real_level.md tools/check-real-level.sh   # a quick look
# 1024 paths per pixel keep the truth's own noise (reference noise) at 0.02 over the lit views
# and 0.1-0.15 in the darkest (the gallery under the sky alone); the bias's share of it stays
# under 0.5% wherever the frame is within a factor 2 of the truth.
# The level is read from GI_EXTERNAL_ASSETS_DIR (default ../shared/external-assets), never
# copied. gi-bake bakes it --untextured (the bakers read textures since issue 33 and a
# bundle's geometry hash covers them), so the bundle is the untextured scene's that
# gi-frame-truth --untextured judges (it checks the geometry and lights hashes when it loads it). About 30 minutes on 2 busy cores
# with the default presets (8 bakes of the level, 9 truths); "high" adds 4 bakes of about
# half an hour each there.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
assets="${GI_EXTERNAL_ASSETS_DIR:-$root/../shared/external-assets}"
sponza="$assets/dabrovic-sponza/sponza.gltf"
cornell="$root/assets/cornell_box.gltf"
out="${OUT:-$build/real-level}"
doc="${DOC:-$root/docs/real_level.md}"
read -r -a presets <<< "${PRESETS:-preview medium}"
width="${WIDTH:-240}" height="${HEIGHT:-135}" spp="${SPP:-1024}"

if [[ ! -f "$sponza" ]]; then
  echo "check-real-level: $sponza not found (set GI_EXTERNAL_ASSETS_DIR)" >&2
  exit 1
fi
cmake --build "$build" --target gi-bake gi-frame-truth > /dev/null
bake_tool="$build/tools/gi-bake/gi-bake"
frame_truth="$build/tools/gi-frame-truth/gi-frame-truth"
rm -rf "$out"
mkdir -p "$out/bundles" "$out/images"
started=$(date +%s)
load_before=$(cut -d' ' -f1-3 /proc/loadavg)

# The lights, views and regions (docs/real_level.md says why these).
sky='zenith:10,16,30;horizon:28,30,34;ground:6,6,6'
high_sun='direction:0.25,-1,0.15;irradiance:700,650,600'
low_sun='direction:0.906,-0.423,0;irradiance:700,650,600'
views=(--camera 'courtyard=-10,1.7,-2,8,4,4.5,60' --camera 'gallery=-13.5,6.5,5.5,14,6,3,60')
regions=(--region 'courtyard:-11.6,-1,-3.18,11.6,4.75,3.18' --region 'arcades:-16.3,-1,-7.3,16.3,4.75,7.3'
         --region 'gallery:-16.3,4.75,-7.3,16.3,10.2,7.3')
common=(--width "$width" --height "$height" --spp "$spp" --out "$out/images" --md "$out/table.md" --csv "$out/table.csv")

# bake NAME PRESET LIGHTS...: Sponza under LIGHTS (--sky, --sun) with gi-bake; one line of
# bakes.md: wall time and peak resident memory (from /usr/bin/time -v when installed).
bake() {
  local name=$1 preset=$2
  shift 2
  local dir="$out/bundles/${name}_${preset}.gibake" log="$out/bake_${name}_${preset}.log"
  local t0 t1 wall rss="n/a (install the Debian package time)"
  echo "check-real-level: baking $name at $preset" >&2
  t0=$(date +%s.%N)
  if [[ -x /usr/bin/time ]]; then
    /usr/bin/time -v -o "$log.time" "$bake_tool" --scene "$sponza" --untextured "$@" --preset "$preset" --out "$dir" > "$log"
    rss=$(awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2 / 1024}' "$log.time")
  else
    "$bake_tool" --scene "$sponza" --untextured "$@" --preset "$preset" --out "$dir" > "$log"
  fi
  t1=$(date +%s.%N)
  wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.1f", b - a}')
  local atlas
  atlas=$(sed -n 's/^gi-bake:   atlas \([0-9x]*\) at \([0-9.]*\) texels\/m, \([0-9]*\) texels lit.*/\1 at \2 texels\/m, \3 texels/p' "$log")
  echo "| $name | $preset | $wall | $rss | $atlas |" >> "$out/bakes.md"
}

# measure LABEL LIGHTS...: gi-frame-truth under LIGHTS with the bundles of LABEL at every preset.
measure() {
  local label=$1
  shift
  local bundles=()
  for p in "${presets[@]}"; do bundles+=(--bundle "$p=$out/bundles/${label}_$p.gibake"); done
  echo "check-real-level: measuring $label" >&2
  "$frame_truth" --scene "$sponza" --untextured --label "$label" "$@" "${bundles[@]}" "${views[@]}" \
    "${regions[@]}" "${common[@]}" > "$out/measure_$label.txt"
}

# The issue's three lightings, and the high sun without the sky: what the renderer gets wrong
# besides the sky (the sun's shadows, the atlas's bounce light).
for p in "${presets[@]}"; do
  bake sponza_high_sun "$p" --sky "$sky" --sun "$high_sun"
  bake sponza_low_sun "$p" --sky "$sky" --sun "$low_sun"
  bake sponza_sky_only "$p" --sky "$sky"
  bake sponza_high_sun_no_sky "$p" --sun "$high_sun"
done
measure sponza_high_sun --sky "$sky" --sun "$high_sun"
measure sponza_low_sun --sky "$sky" --sun "$low_sun"
measure sponza_sky_only --sky "$sky"
measure sponza_high_sun_no_sky --sun "$high_sun"
echo "check-real-level: measuring the Cornell box" >&2
cornell_presets=()
for p in "${presets[@]}"; do cornell_presets+=(--preset "$p"); done
"$frame_truth" --scene "$cornell" --no-lights --sky "$sky" --label cornell_box_sky "${cornell_presets[@]}" \
  "${common[@]}" > "$out/measure_cornell_box_sky.txt"

# The frame's cost at the demo's size (its accuracy numbers, from 2 paths per pixel, are not used).
echo "check-real-level: timing the frame at 960x540" >&2
cost_bundles=()
for p in "${presets[@]}"; do cost_bundles+=(--bundle "$p=$out/bundles/sponza_high_sun_$p.gibake"); done
"$frame_truth" --scene "$sponza" --untextured --sky "$sky" --sun "$high_sun" --label sponza_high_sun \
  "${cost_bundles[@]}" "${views[@]}" --width 960 --height 540 --spp 2 --out "$out/cost" > "$out/cost_960x540.txt"

elapsed=$(( $(date +%s) - started ))
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

# The generated block: the frame summary (from the CSV), every region, the bakes, the costs.
generated="$out/generated.md"
{
  echo "<!-- generated by tools/check-real-level.sh: begin -->"
  echo "Measured $(date -u +%F) on revision \`$(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)\`,"
  echo "$(nproc) cores, load average $load_before before and $load_after after; ${width}x${height} pixels,"
  echo "truth $spp paths per pixel (two halves); the whole run took $((elapsed / 60)) min $((elapsed % 60)) s."
  echo
  echo "**Over the frame** (every pixel that shows the level; the sky is left out):"
  echo
  echo "| lighting | view | bake | frame bias | truth rel RMSE | worst region (bias) | truth noise (bias ± / rel) |"
  echo "|---|---|---|---:|---:|---|---:|"
  awk -F, 'NR > 1 {
      key = $1 SUBSEP $3 SUBSEP $2
      if (!(key in seen)) { seen[key] = 1; order[++n] = key }
      if ($4 == "frame") { bias[key] = $11; rmse[key] = $14; bnoise[key] = $12; rnoise[key] = $15 }
      else if ($4 != "other" && $8 > 0 && (!(key in worst) || ($11 < 0 ? -$11 : $11) > worstabs[key])) {
        worst[key] = $4; worstabs[key] = ($11 < 0 ? -$11 : $11); worstbias[key] = $11 }
    }
    END {
      for (i = 1; i <= n; ++i) {
        split(order[i], k, SUBSEP)
        w = (order[i] in worst) ? sprintf("%s (%+.1f%%)", worst[order[i]], 100 * worstbias[order[i]]) : "-"
        printf "| %s | %s | %s | %+.1f%% | %.3f | %s | %.1f%% / %.3f |\n", k[1], k[2], k[3], 100 * bias[order[i]],
               rmse[order[i]], w, 100 * bnoise[order[i]], rnoise[order[i]]
      }
    }' "$out/table.csv"
  echo
  echo "**Per region:**"
  echo
  cat "$out/table.md"
  echo
  echo "**Bakes of Dabrovic Sponza** (gi-bake --untextured; the file's JPEGs are still decoded, part of the memory):"
  echo
  echo "| lighting | preset | wall s | peak RSS MB | atlas |"
  echo "|---|---|---:|---:|---|"
  cat "$out/bakes.md"
  echo
  echo "**The frame's cost**, Sponza under the high sun at 960x540 (the renderer's pass timings of the"
  echo "median of 5 frames after 2 warm-up frames, and the range; \"first\" is the first frame of a view,"
  echo "which on the first view also compiles the shaders, uploads the GI data and draws the shadow"
  echo "maps; llvmpipe: CPU time, on the busy machine above; each run's costs at ${width}x${height} are in"
  echo "OUT/measure_*.txt):"
  echo
  echo '```'
  grep -hE ': frame [0-9.]+ ms|^    ' "$out/cost_960x540.txt" || true
  echo '```'
  echo "<!-- generated by tools/check-real-level.sh: end -->"
} > "$generated"

# Into the page: replace the generated block, keep the rest (a new page gets a stub).
if [[ ! -f "$doc" ]]; then
  printf '# A real level against the path tracer\n\n%s\n%s\n' "<!-- generated by tools/check-real-level.sh: begin -->" \
    "<!-- generated by tools/check-real-level.sh: end -->" > "$doc"
fi
awk -v gen="$generated" '
  /<!-- generated by tools\/check-real-level.sh: begin -->/ { while ((getline line < gen) > 0) print line; skip = 1; next }
  /<!-- generated by tools\/check-real-level.sh: end -->/ { skip = 0; next }
  !skip { print }' "$doc" > "$doc.partial"
mv "$doc.partial" "$doc"
echo "check-real-level: wrote $doc (images and logs in $out) in $((elapsed / 60)) min $((elapsed % 60)) s" >&2

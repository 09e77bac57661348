#!/usr/bin/env bash
# The light atlas on a real level, measured as a new user lights it (issue 35): Dabrovic
# Sponza untextured, under a 700 W/m^2 sun and a gradient sky, at 8 texels/m, against a
# split truth (two path-traced atlases of TRUTH_SPP samples per texel with different seeds,
# their noise removed), with the path tracer baking the same texels at a few spp in the
# same sweep; then the table of speed-ups at equal error on the indirect-dominated texels
# and on the whole lightmap (docs/sweeps/light_atlas_sponza/speedup.md).
# Run on an otherwise idle machine: the tables' seconds are wall-clock bake times.
#   bash tools/sweep-light-atlas-sponza.sh           (the truth alone takes ~2 x the 256-spp
#                                                     path tracer's time; cached in $CACHE)
#   HIGH=0 bash tools/sweep-light-atlas-sponza.sh    (without the high preset's run)
#   TABLE_ONLY=1 bash tools/sweep-light-atlas-sponza.sh   (speedup.md from the CSVs already there)
#   DENOISE=0 / EMITTERS=0                           (without the guided denoiser's runs / the
#                                                     emitter-sampled gather's runs)
#   FILTERS=0                                        (without the 2.5-texel / unfiltered runs)
#   TEXTURED=1 bash tools/sweep-light-atlas-sponza.sh   (the level with its textures, in the
#       bakers, the path tracer and the truth alike: docs/sweeps/light_atlas_sponza_textured/;
#       its own truth, cached apart from the untextured one). The preset row and the path
#       tracer's alone: TEXTURED=1 FILTERS=0 DENOISE=0 EMITTERS=0 HIGH=0 TRUTH_SPP=256
set -euo pipefail
cd "$(dirname "$0")/.."
sweep=${GI_SWEEP:-build/tools/gi-sweep/gi-sweep}
textured=${TEXTURED:-0}
out=docs/sweeps/light_atlas_sponza
texture_flag=(--untextured)
if [[ $textured != 0 ]]; then
  out=docs/sweeps/light_atlas_sponza_textured
  texture_flag=()
fi
cache=${CACHE:-build/reference-cache}
scene=${GI_EXTERNAL_ASSETS_DIR:-../shared/external-assets}/dabrovic-sponza/sponza.gltf
truth_spp=${TRUTH_SPP:-256}
pt_spp=${PT_SPP:-16,64}
lighting=("${texture_flag[@]}" --sky 'zenith:10,16,30;horizon:28,30,34;ground:6,6,6'
  --sun 'direction:0.25,-1,0.15;irradiance:700,650,600' --split-truth "$truth_spp")
common=(--scene "$scene" "${lighting[@]}" --cache "$cache" --threads 2)
gather=(--method light_atlas --knob density=8 --knob final=gather --knob vpls=1000 --knob bounces=64)
run() { if [[ ${TABLE_ONLY:-0} == 0 ]]; then "$@"; fi; }
csvs=()
if [[ ${FILTERS:-1} != 0 ]]; then  # 32 kept + 128 fresh rays, with the 2.5-texel filter (the presets before) and without
  run "$sweep" "${gather[@]}" --knob solve_rays=32 --knob rays=128 --knob filter=2.5,0 --knob direct_samples=8 \
    "${common[@]}" --out "$out/gather"
  csvs+=("$out/gather/light_atlas_sponza.csv")
fi
# the medium preset's settings now (preview's but 8 direct samples): 32 kept + 128 cosine + 32 emitter
# rays, the punctual lights' and the sun's direct light at every landing, the read light filtered 1.5
# texels, the guided denoiser's 3 passes at sigma 1.5, both fitting a local plane (ridge 0), no output
# filter, near landings regathered with 4 rays and theirs with 1 (near_depth 2; 1: without), and the
# 15% of the texels whose kept rays read the most variable light gathered twice (adaptive 0: without)
run "$sweep" "${gather[@]}" --knob solve_rays=32 --knob rays=128 --knob emitter_rays=32 --knob filter=0 \
  --knob denoise=3 --knob denoise_sigma=1.5 --knob denoise_ridge=0 --knob source_ridge=0 \
  --knob landing_direct=punctual --knob source_filter=1.5 --knob near_rays=4 --knob near_depth=1,2 \
  --knob near_deep_rays=1 --knob adaptive=0,0.15 --knob direct_samples=8 "${common[@]}" --out "$out/preset"
csvs+=("$out/preset/light_atlas_sponza.csv")
run "$sweep" --method pathtracer_atlas --knob density=8 --knob "spp=$pt_spp" "${common[@]}" --out "$out/pathtracer"
if [[ ${DENOISE:-1} != 0 ]]; then  # the guided denoiser alone (docs/light_atlas.md), 2 passes, at two ray budgets
  run "$sweep" "${gather[@]}" --knob solve_rays=32 --knob rays=128 --knob filter=0 --knob direct_samples=8 \
    --knob denoise=2 "${common[@]}" --out "$out/denoise"
  run "$sweep" "${gather[@]}" --knob solve_rays=64 --knob rays=256 --knob filter=0 --knob direct_samples=8 \
    --knob denoise=0,2 "${common[@]}" --out "$out/denoise_64_256"
  csvs+=("$out/denoise/light_atlas_sponza.csv" "$out/denoise_64_256/light_atlas_sponza.csv")
fi
if [[ ${EMITTERS:-1} != 0 ]]; then  # the emitter-sampled gather at about the cosine rays' time
  run "$sweep" "${gather[@]}" --knob solve_rays=32 --knob rays=64 --knob emitter_rays=32 --knob filter=0 \
    --knob direct_samples=8 --knob denoise=0 "${common[@]}" --out "$out/emitters"
  csvs+=("$out/emitters/light_atlas_sponza.csv")
fi
if [[ ${HIGH:-1} != 0 ]]; then  # high: 128 kept + 1024 fresh rays, no filter
  run "$sweep" "${gather[@]}" --knob solve_rays=128 --knob rays=1024 --knob filter=0 --knob direct_samples=16 \
    "${common[@]}" --out "$out/high"
  csvs+=("$out/high/light_atlas_sponza.csv")
fi
{
  echo "# The light atlas against the path tracer on Dabrovic Sponza (issue 35)"
  echo
  echo "Regenerate: \`TEXTURED=$textured FILTERS=${FILTERS:-1} DENOISE=${DENOISE:-1} EMITTERS=${EMITTERS:-1}" \
    "TRUTH_SPP=$truth_spp PT_SPP=$pt_spp HIGH=${HIGH:-1} bash tools/sweep-light-atlas-sponza.sh\`"
  if [[ $textured != 0 ]]; then textures="With its textures"; else textures="Untextured"; fi
  echo "(the sweeps' own commands are at the top of their .md files). $textures, the sun"
  echo "\`direction:0.25,-1,0.15;irradiance:700,650,600\` and the sky \`zenith:10,16,30;horizon:28,30,34;ground:6,6,6\`,"
  echo "8 texels/m; truth: two $truth_spp-spp path-traced atlases, their noise removed. Load average when the"
  echo "sweeps ended: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores (seconds under load are inflated alike for both)."
  echo
  /usr/bin/python3 tools/light-atlas-speedup.py --vs-pathtracer "$out/pathtracer/pathtracer_atlas_sponza.csv" \
    "${csvs[@]}"
} > "$out/speedup.md"
cat "$out/speedup.md"

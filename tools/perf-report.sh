#!/usr/bin/env bash
# Regenerates docs/performance.md's measured block and docs/images/performance.png (issue 23):
# runs the per-frame GI benchmarks with interleaved repetitions (medians reported), writes
# their JSON to out/perf/, then tools/perf-report.py turns the JSON into the table and plot.
#   tools/perf-report.sh build              # build dir holding gi/benchmarks/*_bench
#   BEFORE=/work/main/build tools/perf-report.sh build   # + the old pane sum from another build
#   FRAME=0 tools/perf-report.sh build     # skip the demo frame runs (they bake out/demo_level.gibake if missing)
# REPS (default 3) repetitions per benchmark. The machine's load average is recorded before
# and after: on a shared machine the absolute times move with it, the ratios against the
# yardsticks measured in the same loops much less.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=out/perf
reps=${REPS:-3}
mkdir -p "$out"
rm -f "$out"/frame_*.txt "$out"/frame.json
bench="$build/gi/benchmarks"
common=(--benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true
        --benchmark_report_aggregates_only=false --benchmark_out_format=json)
{ echo "start $(date -u +%FT%TZ) $(cut -d' ' -f1-3 /proc/loadavg) nproc $(nproc)"; } > "$out/load.txt"
"$bench/prm_gpu_bench" "${common[@]}" --benchmark_out="$out/prm_gpu_bench.json" > /dev/null
"$bench/prm_relight_bench" "${common[@]}" --benchmark_out="$out/prm_relight_bench.json" > /dev/null
"$bench/brf_bench" "${common[@]}" --benchmark_filter='BM_BrfGpuInfluence|BM_BrfGatherCpu|BM_BrfGpu/30/[01]/0$' \
  --benchmark_out="$out/brf_bench.json" > /dev/null
if [[ -n "${BEFORE:-}" && -x "$BEFORE/gi/benchmarks/prm_gpu_bench" ]]; then
  "$BEFORE/gi/benchmarks/prm_gpu_bench" "${common[@]}" --benchmark_out="$out/prm_gpu_bench_before.json" > /dev/null
fi
if [[ "${FRAME:-1}" != 0 ]]; then
  # The demo level's frame (README command 1's bundle and tour), 60 frames at each size: the
  # demo's own summary (frames/s, pass medians) plus the process's CPU seconds.
  bundle=out/demo_level.gibake
  [[ -f "$bundle/manifest.json" ]] || "$build/tools/gi-bake/gi-bake" --scene assets/demo_level.gltf \
      --preset preview --out "$bundle" > /dev/null
  # "_flat": the same frame with --shading flat, the yardstick (every surface its base colour,
  # everything else as usual). 96x54: shading costs next to nothing, so its frame is the part
  # that does not scale with pixels.
  for run in 960x540 960x540_flat 640x360 640x360_flat 96x54; do
    size=${run%_flat}
    shading=full; [[ $run == *_flat ]] && shading=flat
    log="$out/frame_$run.txt"
    { TIMEFORMAT="process CPU s: %U user %S sys"; time "$build/game_demo/gi_demo" --headless --frames 60 \
        --width "${size%x*}" --height "${size#*x}" --shading "$shading" --gi-bundle "$bundle" ; } > "$log" 2>&1
  done
fi
{ echo "end $(date -u +%FT%TZ) $(cut -d' ' -f1-3 /proc/loadavg)"; } >> "$out/load.txt"
/usr/bin/python3 tools/perf-report.py "$out" docs/performance.md docs/images/performance.png

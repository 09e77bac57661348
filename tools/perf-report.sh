#!/usr/bin/env bash
# Regenerates docs/performance.md's measured block and docs/images/performance.png (issue 23):
# runs the per-frame GI benchmarks with interleaved repetitions (medians reported), writes
# their JSON to out/perf/, then tools/perf-report.py turns the JSON into the table and plot.
#   tools/perf-report.sh build              # build dir holding gi/benchmarks/*_bench
#   BEFORE=/work/main/build tools/perf-report.sh build   # + the old pane sum from another build
# REPS (default 3) repetitions per benchmark. The machine's load average is recorded before
# and after: on a shared machine the absolute times move with it, the ratios against the
# yardsticks measured in the same loops much less.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=out/perf
reps=${REPS:-3}
mkdir -p "$out"
bench="$build/gi/benchmarks"
common=(--benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true
        --benchmark_report_aggregates_only=false --benchmark_out_format=json)
{ echo "start $(date -u +%FT%TZ) $(cut -d' ' -f1-3 /proc/loadavg) nproc $(nproc)"; } > "$out/load.txt"
"$bench/prm_gpu_bench" "${common[@]}" --benchmark_out="$out/prm_gpu_bench.json" > /dev/null
"$bench/prm_relight_bench" "${common[@]}" --benchmark_out="$out/prm_relight_bench.json" > /dev/null
"$bench/brf_bench" "${common[@]}" --benchmark_filter='BM_BrfGpuInfluence|BM_BrfGatherCpu' \
  --benchmark_out="$out/brf_bench.json" > /dev/null
if [[ -n "${BEFORE:-}" && -x "$BEFORE/gi/benchmarks/prm_gpu_bench" ]]; then
  "$BEFORE/gi/benchmarks/prm_gpu_bench" "${common[@]}" --benchmark_out="$out/prm_gpu_bench_before.json" > /dev/null
fi
{ echo "end $(date -u +%FT%TZ) $(cut -d' ' -f1-3 /proc/loadavg)"; } >> "$out/load.txt"
/usr/bin/python3 tools/perf-report.py "$out" docs/performance.md docs/images/performance.png

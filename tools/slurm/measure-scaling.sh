#!/usr/bin/env bash
# The table of docs/distributed-bake.md: bake seconds against shard count on this machine.
# Shards run one after another as separate gi-bake processes with one thread each (what one
# core of a cluster node does), the merge after them; the baseline is the one-process bake
# with one thread. Times are CPU seconds (user + system) of each process, which a loaded,
# shared machine disturbs far less than wall time (the wall time of the whole run is
# printed too). Prints a Markdown table; a node per shard would take max(shard) + merge.
#   bash tools/slurm/measure-scaling.sh [BUILD_DIR] [SCENE] [PRESET] [SHARD COUNTS...]
#   GI_BAKE_OPTS="--methods light_atlas,prm" bash tools/slurm/measure-scaling.sh   # more gi-bake options
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
scene=${2:-$repo/assets/demo_level.gltf}
preset=${3:-preview}
shift $(($# < 3 ? $# : 3))
counts=("$@")
[ ${#counts[@]} -gt 0 ] || counts=(1 2 4 8)
gi_bake=$build/tools/gi-bake/gi-bake
work=$(mktemp -d /tmp/gi-scaling.XXXXXX)
trap 'rm -rf "$work"' EXIT
# cpu_seconds LOG COMMAND...: runs COMMAND (stdout to LOG), prints its CPU seconds.
cpu_seconds() {
  python3 - "$@" << 'PY'
import resource, subprocess, sys
with open(sys.argv[1], "w") as log:
    subprocess.run(sys.argv[2:], check=True, stdout=log, stderr=subprocess.STDOUT)
r = resource.getrusage(resource.RUSAGE_CHILDREN)
print(f"{r.ru_utime + r.ru_stime:.2f}")
PY
}
calc() { python3 -c "print($1)"; }
# shellcheck disable=SC2206  # GI_BAKE_OPTS is a list of options
opts=(--preset "$preset" --threads 1 ${GI_BAKE_OPTS:-})
started=$(date +%s)

whole=$(cpu_seconds "$work/whole.log" "$gi_bake" --scene "$scene" --out "$work/whole.gibake" "${opts[@]}")
grep -E "^gi-bake: (atlas|prm|dlm|brf|antiradiance): " "$work/whole.log" | sed 's/^/one process: /' >&2
echo "| shards N | shard CPU s (min / max) | sum of shards | merge | max shard + merge | speed-up | byte-identical |"
echo "|---:|---:|---:|---:|---:|---:|:---:|"
echo "| one process | | | | $whole | 1.00 | |"
for n in "${counts[@]}"; do
  out=$work/n$n.gibake
  min="" max=0 sum=0
  for ((i = 0; i < n; i++)); do
    s=$(cpu_seconds "$work/shard.log" "$gi_bake" --scene "$scene" --out "$out" "${opts[@]}" --shard "$i/$n")
    sum=$(calc "round($sum + $s, 2)")
    max=$(calc "max($max, $s)")
    if [ -z "$min" ]; then min=$s; else min=$(calc "min($min, $s)"); fi
  done
  grep -E "shard [0-9]+/[0-9]+:" "$work/shard.log" | sed "s/^/N = $n, last shard: /" >&2
  merge=$(cpu_seconds "$work/merge.log" "$gi_bake" --scene "$scene" --out "$out" "${opts[@]}" --merge)
  grep -E "^gi-bake: (atlas|prm|dlm|brf|antiradiance): " "$work/merge.log" | sed "s/^/N = $n, merge: /" >&2
  same=yes
  for f in "$work/whole.gibake"/*; do
    [ "$(basename "$f")" = bake_stats.json ] && continue
    cmp -s "$f" "$out/$(basename "$f")" || same=no
  done
  wall=$(calc "round($max + $merge, 2)")
  speed=$(calc "round($whole / ($max + $merge), 2)")
  echo "| $n | $min / $max | $sum | $merge | $wall | $speed | $same |"
  rm -rf "$out" "$out.shards"
done
echo "(measured in $(($(date +%s) - started)) s wall on $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg))" >&2

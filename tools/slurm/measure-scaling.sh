#!/usr/bin/env bash
# The table of docs/distributed-bake.md: bake seconds against shard count on this machine,
# shards run one after another as separate gi-bake processes with one thread each (what one
# cluster node's core does), the merge after them; the one-process bake with one thread is
# the baseline. Prints a Markdown table and the serial fraction s fitted from it (Amdahl:
# speed-up on N nodes = 1 / (s + (1 - s) / N)).
#   bash tools/slurm/measure-scaling.sh [BUILD_DIR] [SCENE] [PRESET] [SHARD COUNTS...]
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
now() { date +%s.%N; }
secs() { python3 -c "print(f'{$2 - $1:.2f}')"; }
opts=(--preset "$preset" --threads 1)

t0=$(now)
"$gi_bake" --scene "$scene" --out "$work/whole.gibake" "${opts[@]}" > "$work/whole.log"
whole=$(secs "$t0" "$(now)")
echo "| shards N | shard seconds (min / max) | sum of shards | merge | cluster wall (max shard + merge) | speed-up | byte-identical |"
echo "|---:|---:|---:|---:|---:|---:|:---:|"
echo "| one process | | | | $whole | 1.00 | |"
for n in "${counts[@]}"; do
  out=$work/n$n.gibake
  min="" max=0 sum=0
  for ((i = 0; i < n; i++)); do
    t0=$(now)
    "$gi_bake" --scene "$scene" --out "$out" "${opts[@]}" --shard "$i/$n" > "$work/shard.log"
    s=$(secs "$t0" "$(now)")
    sum=$(python3 -c "print(f'{$sum + $s:.2f}')")
    max=$(python3 -c "print(max($max, $s))")
    min=$(python3 -c "print($s if '$min' == '' else min($min, $s))")
  done
  t0=$(now)
  "$gi_bake" --scene "$scene" --out "$out" "${opts[@]}" --merge > "$work/merge.log"
  merge=$(secs "$t0" "$(now)")
  same=yes
  for f in "$work/whole.gibake"/*; do
    [ "$(basename "$f")" = bake_stats.json ] && continue
    cmp -s "$f" "$out/$(basename "$f")" || same=no
  done
  wall=$(python3 -c "print(f'{$max + $merge:.2f}')")
  speed=$(python3 -c "print(f'{$whole / ($max + $merge):.2f}')")
  echo "| $n | $min / $max | $sum | $merge | $wall | $speed | $same |"
  rm -rf "$out" "$out.shards"
done

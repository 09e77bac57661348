#!/usr/bin/env bash
# Submits a distributed bake to Slurm (docs/distributed-bake.md): an array job of N shard
# tasks and a merge job that runs once all of them succeeded.
#   tools/slurm/submit.sh --shards 16 --gi-bake /shared/gi/bin/gi-bake \
#       --scene /shared/level.gltf --out /shared/out/level.gibake -- --preset high
# Paths must be on a file system every node sees. Options after `--` go to every gi-bake
# call (the same in shards and merge: the merge refuses shards baked with other options).
# Extra sbatch options (partition, account, CPUs per task) go in SBATCH_EXTRA, e.g.
#   SBATCH_EXTRA="--partition=bake --cpus-per-task=8"
# Prints "<array job id> <merge job id>".
#
# Path-traced references the same way: --gi-reference instead of --gi-bake, and --out names
# the shard directory (gi-reference --shard-dir); the outputs are in the options:
#   tools/slurm/submit.sh --shards 16 --gi-reference /shared/gi/bin/gi-reference \
#       --scene /shared/level.gltf --out /shared/out/truth.shards -- \
#       --atlas-density 32 --spp 4096 --atlas-out /shared/out/truth
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
shards="" gi_bake="" gi_reference="" scene="" out="" logs=""
usage() {
  echo "usage: submit.sh --shards N --gi-bake PATH --scene SCENE --out BUNDLE [--logs DIR] [-- gi-bake options]" >&2
  echo "       submit.sh --shards N --gi-reference PATH --scene SCENE --out SHARD_DIR [--logs DIR] [-- gi-reference options]" >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case $1 in
    --shards) shards=$2; shift 2 ;;
    --gi-bake) gi_bake=$2; shift 2 ;;
    --gi-reference) gi_reference=$2; shift 2 ;;
    --scene) scene=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --logs) logs=$2; shift 2 ;;
    --) shift; break ;;
    *) usage ;;
  esac
done
[ -n "$shards" ] && [ -n "$scene" ] && [ -n "$out" ] || usage
if [ -n "$gi_bake" ] && [ -n "$gi_reference" ] || [ -z "$gi_bake$gi_reference" ]; then usage; fi
[[ $shards =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: --shards must be a positive integer" >&2; exit 2; }
logs=${logs:-$(dirname "$out")}
mkdir -p "$logs"
if [ -n "$gi_reference" ]; then
  # Shard files of an earlier run in this directory would be merged too (and refused as
  # foreign); only they are removed (the directory may hold other files).
  rm -f "$out"/*.girefshard
  # shellcheck disable=SC2086  # SBATCH_EXTRA is a list of options
  array=$(sbatch --parsable ${SBATCH_EXTRA:-} --array=0-$((shards - 1)) \
    --output="$logs/gi-reference-shard-%A_%a.log" \
    "$here/reference-shard.sbatch" "$gi_reference" "$shards" "$scene" "$out" "$@")
  array=${array%%;*}
  # shellcheck disable=SC2086
  merge=$(sbatch --parsable ${SBATCH_EXTRA:-} --dependency=afterok:"$array" --kill-on-invalid-dep=yes \
    --output="$logs/gi-reference-merge-%j.log" "$here/reference-merge.sbatch" "$gi_reference" "$scene" "$out" "$@")
  merge=${merge%%;*}
  echo "$array $merge"
  exit 0
fi
# Shard files of an earlier bake of this bundle would be merged too (and refused as foreign).
rm -rf "$out.shards"
# shellcheck disable=SC2086  # SBATCH_EXTRA is a list of options
array=$(sbatch --parsable ${SBATCH_EXTRA:-} --array=0-$((shards - 1)) --output="$logs/gi-bake-shard-%A_%a.log" \
  "$here/bake-shard.sbatch" "$gi_bake" "$shards" "$scene" "$out" "$@")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_EXTRA:-} --dependency=afterok:"$array" --kill-on-invalid-dep=yes \
  --output="$logs/gi-bake-merge-%j.log" "$here/merge.sbatch" "$gi_bake" "$scene" "$out" "$@")
merge=${merge%%;*}
echo "$array $merge"

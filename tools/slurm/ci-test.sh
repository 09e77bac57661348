#!/usr/bin/env bash
# CI leg "slurm" (docs/distributed-bake.md): a single-node Slurm on localhost — munged with a
# generated key, slurmctld and slurmd (Debian's slurm-wlm 22.05, tools/install-deps.sh) with
# a generated slurm.conf, everything in a temporary directory — runs tools/slurm/submit.sh's
# array job (3 shards + the dependent merge) for the Cornell box's light atlas and PRM and
# compares the merged bundle byte for byte with a local one-process bake, then the same for a
# path-traced reference (a small image and the atlas's ground truth, gi-reference --shard). It stops the
# daemons it started (trap), prints their logs on failure, and gives every wait a timeout.
#   bash tools/slurm/ci-test.sh [BUILD_DIR]      # needs BUILD_DIR/tools/gi-bake/gi-bake
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
gi_bake=$build/tools/gi-bake/gi-bake
gi_reference=$build/tools/gi-reference/gi-reference
shards=${GI_SLURM_SHARDS:-3}
start_time=$(date +%s)
say() { echo "slurm-ci: $*"; }
die() { echo "slurm-ci: FAIL: $*" >&2; exit 1; }

[ -x "$gi_bake" ] || die "$gi_bake not built (cmake --build $build --target gi-bake)"
[ -x "$gi_reference" ] || die "$gi_reference not built (cmake --build $build --target gi-reference)"
for tool in munged munge slurmctld slurmd sbatch squeue scontrol sinfo; do
  command -v "$tool" > /dev/null || die "$tool not found: install slurmctld slurmd slurm-client munge (tools/install-deps.sh)"
done

work=$(mktemp -d /tmp/gi-slurm-ci.XXXXXX)
chmod 755 "$work"
pids=()
declare -A daemon=()  # PID -> name, for the messages
status=1
cleanup() {
  local rc=$?
  for pid in "${pids[@]}"; do kill "$pid" 2> /dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2> /dev/null || true
  done
  if [ "$status" -ne 0 ] || [ "$rc" -ne 0 ]; then
    for log in "$work"/*.log "$work"/logs/*.log; do
      [ -f "$log" ] || continue
      echo "----- $log (last 40 lines)" >&2
      tail -n 40 "$log" >&2
    done
    echo "slurm-ci: files kept in $work" >&2
  else
    rm -rf "$work"
  fi
}
trap cleanup EXIT

# wait_for SECONDS WHAT PID COMMAND...: polls COMMAND every 0.2 s; fails at once when the
# daemon PID (- for none) has exited.
wait_for() {
  local seconds=$1 what=$2 pid=$3
  shift 3
  local deadline=$(($(date +%s) + seconds))
  until "$@" > /dev/null 2>&1; do
    [ "$pid" = - ] || kill -0 "$pid" 2> /dev/null || die "${daemon[$pid]:-the daemon} (PID $pid) exited while waiting for $what (logs below)"
    [ "$(date +%s)" -lt "$deadline" ] || die "timed out after ${seconds} s waiting for $what"
    sleep 0.2
  done
}

# munge: a fresh key, its own socket.
dd if=/dev/urandom of="$work/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge.key"
munged -F --force --key-file="$work/munge.key" --socket="$work/munge.sock" --pid-file="$work/munged.pid" \
  --log-file="$work/munged.log" --seed-file="$work/munged.seed" > "$work/munged.log" 2>&1 &
pids+=($!) && daemon[$!]=munged
wait_for 10 "munged's socket" "${pids[-1]}" test -S "$work/munge.sock"

# slurm.conf: one node (this host, all its CPUs), one partition, ports from the PID.
node=$(hostname -s)
cpus=$(nproc)
port=$((20000 + ($$ % 2000) * 2))
mkdir -p "$work/state" "$work/spool" "$work/logs"
cat > "$work/slurm.conf" << CONF
ClusterName=gi-ci
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge.sock
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
MinJobAge=600
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=ci Nodes=$node Default=YES MaxTime=30 State=UP
CONF
export SLURM_CONF=$work/slurm.conf

slurmctld -D -i -f "$SLURM_CONF" > "$work/slurmctld.out.log" 2>&1 &
pids+=($!) && daemon[$!]=slurmctld
wait_for 20 "slurmctld to answer" "${pids[-1]}" scontrol ping
slurmd -D -f "$SLURM_CONF" -N "$node" > "$work/slurmd.out.log" 2>&1 &
pids+=($!) && daemon[$!]=slurmd
node_idle() { sinfo -h -n "$node" -o %T | grep -qx idle; }
wait_for 30 "node $node to be idle" "${pids[-1]}" node_idle
say "Slurm up on $node ($cpus CPUs) in $(($(date +%s) - start_time)) s"

# The bake both ways.
scene=$repo/assets/cornell_box.gltf
opts=(--preset preview --methods light_atlas,prm --density 10 --seed 3)
"$gi_bake" --scene "$scene" --out "$work/local.gibake" "${opts[@]}" > "$work/local-bake.log" 2>&1 ||
  die "the local bake failed"
jobs=$(bash "$repo/tools/slurm/submit.sh" --shards "$shards" --gi-bake "$gi_bake" --scene "$scene" \
  --out "$work/slurm.gibake" --logs "$work/logs" -- "${opts[@]}" 2> "$work/submit.log") ||
  die "submit.sh failed: $(cat "$work/submit.log")"
read -r array merge <<< "$jobs"
[[ $array =~ ^[0-9]+$ && $merge =~ ^[0-9]+$ ]] || die "submit.sh printed '$jobs', not two job ids"
say "submitted array job $array ($shards shards) and merge job $merge"

job_state() { scontrol -o show job "$1" 2> /dev/null | grep -o 'JobState=[A-Z_]*' | head -n 1 | cut -d= -f2; }
merge_done() {
  case $(job_state "$merge") in
    COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY | BOOT_FAIL | DEADLINE) return 0 ;;
    *) return 1 ;;
  esac
}
# wait_merge ARRAY MERGE: until the merge job ended; lists the array's tasks; fails unless COMPLETED.
wait_merge() {
  merge=$2
  wait_for 90 "the merge job $merge" "${pids[-1]}" merge_done
  local state
  state=$(job_state "$merge")
  scontrol -o show job "$1" | sed -E 's/.*JobId=([0-9]+).*ArrayTaskId=([0-9]+).*JobState=([A-Z_]+).*/slurm-ci: shard task \2 of array job \1: \3/' || true
  [ "$state" = COMPLETED ] || die "merge job $merge ended $state"
}
wait_merge "$array" "$merge"

# Byte for byte (bake_stats.json holds the timings and hosts and differs by design).
[ -f "$work/slurm.gibake/manifest.json" ] || die "no merged bundle"
files=0
for f in "$work/local.gibake"/*; do
  name=$(basename "$f")
  [ "$name" = bake_stats.json ] && continue
  cmp "$f" "$work/slurm.gibake/$name" || die "$name differs between the Slurm bake and the local bake"
  files=$((files + 1))
done
[ "$(ls "$work/slurm.gibake" | wc -l)" -eq "$(ls "$work/local.gibake" | wc -l)" ] || die "the bundles hold other files"
[ "$files" -ge 4 ] || die "only $files files compared"
say "bake: $shards shards through Slurm, $files files byte-identical to the local bake"

# A path-traced reference both ways: a small camera image and the atlas's ground truth.
ref_opts=(--spp 2 --bounces 2 --seed 3 --width 32 --height 24 --atlas-density 10)
"$gi_reference" --scene "$scene" "${ref_opts[@]}" --out "$work/local-ref.exr" --atlas-out "$work/local-ref_atlas" \
  > "$work/local-reference.log" 2>&1 ||
  die "the local reference failed"
jobs=$(bash "$repo/tools/slurm/submit.sh" --shards "$shards" --gi-reference "$gi_reference" --scene "$scene" \
  --out "$work/slurm-ref.shards" --logs "$work/logs" -- "${ref_opts[@]}" --out "$work/slurm-ref.exr" \
  --atlas-out "$work/slurm-ref_atlas" 2> "$work/submit.log") ||
  die "submit.sh --gi-reference failed: $(cat "$work/submit.log")"
read -r array merge <<< "$jobs"
[[ $array =~ ^[0-9]+$ && $merge =~ ^[0-9]+$ ]] || die "submit.sh --gi-reference printed '$jobs', not two job ids"
say "submitted reference array job $array ($shards shards) and merge job $merge"
wait_merge "$array" "$merge"
ref_files=0
for f in local-ref.exr local-ref_atlas/atlas_direct.exr local-ref_atlas/atlas_indirect.exr local-ref_atlas/atlas_total.exr; do
  [ -s "$work/$f" ] || die "the local reference wrote no $f"
  cmp "$work/$f" "$work/${f//local-ref/slurm-ref}" || die "$f differs between the Slurm reference and the local one"
  ref_files=$((ref_files + 1))
done
status=0
say "PASS: $shards shards through Slurm: $files bundle files and $ref_files reference files byte-identical to local runs, $(($(date +%s) - start_time)) s"

#!/usr/bin/env bash
# Fuzzes every reader of the project for SECONDS each (libFuzzer, ASan + UBSan with
# float-cast-overflow; tests/fuzz/README.md). Builds only the fuzz targets in the instrumented
# build the sanitizer leg shares (tools/configure-sanitized.sh: clang, build-san/, FUZZ_BUILD_DIR),
# then runs each over its seed corpus and the inputs of fixed findings (tests/fuzz/corpus/<name>/
# and tests/fuzz/regressions/<name>/, read only; inputs it finds go to build-san/corpus/<name>/)
# and prints a table.
#   tools/fuzz.sh 120                 # every target, 120 s each
#   tools/fuzz.sh 30 gltf session     # only these targets
# Exit status 1 when any target reports a finding (crash, sanitizer report, leak, timeout,
# out of memory, a failed check): the input is in build-san/findings/<name>/ and its log
# in build-san/logs/<name>.log. Reproduce with: build-san/.../fuzz_<name> <input>.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ] || ! [[ $1 =~ ^[0-9]+$ ]] || [ "$1" -lt 1 ]; then
  echo "usage: tools/fuzz.sh SECONDS [TARGET...]" >&2
  exit 2
fi
seconds=$1
shift
build_dir=${FUZZ_BUILD_DIR:-build-san}
root=$(pwd)
bash tools/configure-sanitized.sh "$build_dir"
build_start=$(date +%s)
cmake --build "$build_dir" --target fuzz_targets -j "$(nproc)"
echo "fuzz.sh: fuzz targets built in $(( $(date +%s) - build_start )) s"

declare -A program
names=()
while read -r name prog; do
  program[$name]=$prog
  names+=("$name")
done <"$build_dir/fuzz_targets.txt"
if [ $# -gt 0 ]; then
  for n in "$@"; do
    [ -n "${program[$n]:-}" ] || { echo "fuzz.sh: no fuzz target '$n' (have: ${names[*]})" >&2; exit 2; }
  done
  names=("$@")
fi

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:symbolize=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/tests/sanitizer/lsan.supp}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
mkdir -p "$build_dir/logs"
rows=()
failed=0
for n in "${names[@]}"; do
  work="$build_dir/corpus/$n"
  findings="$build_dir/findings/$n"
  mkdir -p "$work" "$findings"
  log="$build_dir/logs/$n.log"
  start=$(date +%s)
  set +e
  # -rss_limit_mb: a reader that allocates 2 GB for an input of a few KB is a finding.
  # -timeout: one input taking 25 s is a hang. Seeds are read from the source tree, new
  # inputs written to the build directory's corpus only.
  regressions=()
  [ -d "$root/tests/fuzz/regressions/$n" ] && regressions=("$root/tests/fuzz/regressions/$n")
  "${program[$n]}" "$work" "$root/tests/fuzz/corpus/$n" "${regressions[@]}" -max_total_time="$seconds" -rss_limit_mb=2048 \
    -timeout=25 -print_final_stats=1 -artifact_prefix="$findings/" >"$log" 2>&1
  rc=$?
  set -e
  took=$(( $(date +%s) - start ))
  execs=$(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  rate=$(grep -m1 -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || true)
  units=$(find "$work" -type f | wc -l)
  if [ $rc -eq 0 ]; then
    result=ok
  else
    failed=1
    artifact=$(ls -t "$findings" 2>/dev/null | head -1)
    result="FINDING (exit $rc) $findings/$artifact; $(grep -m1 -E 'ERROR: |runtime error|gi_fuzz: check failed' "$log" | cut -c1-120)"
  fi
  rows+=("$(printf '%-18s %12s %8s %6s s %6s %7s  %s' "$n" "${execs:--}" "${rate:--}" "$took" "${cov:--}" "$units" "$result")")
  echo "fuzz.sh: $n: $result"
done

echo
printf '%-18s %12s %8s %8s %6s %7s  %s\n' target execs exec/s time cov corpus result
for r in "${rows[@]}"; do echo "$r"; done
exit $failed

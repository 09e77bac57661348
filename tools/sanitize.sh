#!/usr/bin/env bash
# The sanitizer leg: the ctest suite (but the long tests of tests/sanitizer/main_leg_only.txt,
# which the main leg runs) built instrumented (tools/configure-sanitized.sh:
# clang, AddressSanitizer + UndefinedBehaviorSanitizer with float-cast-overflow, every report
# fatal) in build-san/ (SANITIZE_BUILD_DIR), the build the fuzz leg shares, GL tests included
# on llvmpipe, leak detection on. Extra arguments go to ctest (tools/sanitize.sh -R Gltf).
#
# The test environment (docs/reliability.md "CI legs"):
#  - LD_PRELOAD of Mesa's DRI driver (swrast_dri.so, llvmpipe). Every test that makes a GL
#    context ends in eglTerminate, which dlcloses the driver; LeakSanitizer, running at exit,
#    then no longer scans the driver's globals (which still point to what it allocated for
#    the process's life) and cannot name its frames: each such test failed with reports like
#    "Direct leak of 128 byte(s) ... #1 (<unknown module>)" (32 of the 115 engine tests, the
#    issue counts 59 in the whole suite). Preloaded, the driver stays mapped: those blocks
#    are reachable, nothing is reported, leak detection stays on for everything else.
#  - LSAN_OPTIONS=suppressions=tests/sanitizer/lsan.supp: third-party modules only; a leak
#    in a driver module, now that its frames have names, would be suppressed there by module.
#  - ASAN_OPTIONS=verify_asan_link_order=0 lets the preloaded driver come before the ASan
#    runtime (which the executables link; the driver is not instrumented).
# A GCC build with -DGI_SANITIZE=ON (ASan + UBSan without float-cast-overflow) is the same
# check for a team without clang: SANITIZE_BUILD_DIR=build-asan with that configure.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
build_dir=${SANITIZE_BUILD_DIR:-build-san}
bash tools/configure-sanitized.sh "$build_dir"
build_start=$(date +%s)
# As tools/build.sh: ccache caches the users of the tests' precompiled headers only with this.
export CCACHE_SLOPPINESS=${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}
# SANITIZE_TARGETS: build only these targets (e.g. "engine_tests"; default: everything, the
# fuzz targets included).
# shellcheck disable=SC2086
cmake --build "$build_dir" -j "$(nproc)" ${SANITIZE_TARGETS:+--target $SANITIZE_TARGETS}
echo "sanitize.sh: built in $(( $(date +%s) - build_start )) s"

driver=""
for d in /usr/lib/x86_64-linux-gnu/dri/swrast_dri.so /usr/lib/*/dri/swrast_dri.so /usr/lib/dri/swrast_dri.so; do
  if [ -f "$d" ]; then driver=$d; break; fi
done
[ -n "$driver" ] || { echo "sanitize.sh: Mesa's swrast_dri.so not found (libgl1-mesa-dri)" >&2; exit 1; }

export LD_PRELOAD="$driver${LD_PRELOAD:+ $LD_PRELOAD}"
export ASAN_OPTIONS="detect_leaks=1:verify_asan_link_order=0:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$root/tests/sanitizer/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
# The long tests of tests/sanitizer/main_leg_only.txt run in the main leg only: each name
# must still be a test (a renamed one would silently come back here).
# One listing of the suite (a `ctest -N -R name | grep -q` per name failed at random under
# pipefail: grep quit at its match, ctest then died of SIGPIPE).
tests=$(ctest --test-dir "$build_dir" -N | sed -n 's/^ *Test *#[0-9]*: //p')
skip=()
while read -r name _; do
  [ -z "$name" ] || [[ $name == \#* ]] && continue
  grep -qxF -- "$name" <<<"$tests" ||
    { echo "sanitize.sh: tests/sanitizer/main_leg_only.txt names '$name', which is not a test" >&2; exit 1; }
  skip+=("${name//./\\.}")
done <"$root/tests/sanitizer/main_leg_only.txt"
skip_regex="^($(IFS='|'; echo "${skip[*]}"))\$"
test_start=$(date +%s)
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" --timeout 1800 -E "$skip_regex" "$@"
echo "sanitize.sh: tests ran in $(( $(date +%s) - test_start )) s"

#!/usr/bin/env bash
# Configures the one instrumented build the fuzz and sanitizer legs share (docs/reliability.md
# "CI legs"): clang, -DGI_FUZZ=ON (the whole project compiled with ASan + UBSan including
# float-cast-overflow, every report fatal, plus libFuzzer's coverage instrumentation), tests,
# tools and the demo on, benchmarks off, -O2 -g1. tools/fuzz.sh builds the fuzz targets in it,
# tools/sanitize.sh everything else and runs the whole ctest suite; neither compiles the
# libraries again. Usage: tools/configure-sanitized.sh [BUILD_DIR] (default build-san).
#
# GI_WERROR is off here: clang warns where GCC (the main leg, -Werror) does not
# (-Wdouble-promotion on glibc's INFINITY); the warnings are the main leg's to enforce.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build-san}
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
mkdir -p "$build_dir"
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DGI_FUZZ=ON -DGI_SANITIZE=OFF -DGI_WERROR=OFF \
  -DGI_BUILD_TESTS=ON -DGI_BUILD_TOOLS=ON -DGI_BUILD_DEMO=ON -DGI_BUILD_BENCHMARKS=OFF -DGI_TEST_TIMEOUT=1500 \
  "${launcher[@]}" >"$build_dir/configure.log" 2>&1 || { cat "$build_dir/configure.log"; exit 1; }

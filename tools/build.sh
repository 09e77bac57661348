#!/usr/bin/env bash
# Configures and builds the project into build/ (RelWithDebInfo, asserts off, unless BUILD_TYPE says
# otherwise). Debug info is line tables only (-g1): backtraces, perf and sanitizer reports name
# files and lines; full -g made the build ~1.5x slower (docs/reliability.md "Times").
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${BUILD_DIR:-build}
# ccache when the machine has it (as tools/configure-sanitized.sh): a rebuild after a small
# change, or of a fresh clone beside a built one, compiles only what changed.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-RelWithDebInfo}" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DGI_WERROR=ON "${launcher[@]}" "$@"
# ccache caches the sources that use the test executables' precompiled headers
# (cmake/GiTestPch.cmake) only with this sloppiness; without it they compile uncached.
export CCACHE_SLOPPINESS=${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}
cmake --build "$build_dir" -j "$(nproc)"

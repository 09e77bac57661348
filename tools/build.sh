#!/usr/bin/env bash
# Configures and builds the project into build/ (Release with asserts off unless BUILD_TYPE says otherwise).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${BUILD_DIR:-build}
# ccache when the machine has it (as tools/configure-sanitized.sh): a rebuild after a small
# change, or of a fresh clone beside a built one, compiles only what changed.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-RelWithDebInfo}" -DGI_WERROR=ON "${launcher[@]}" "$@"
cmake --build "$build_dir" -j "$(nproc)"

#!/usr/bin/env bash
# Configures and builds the project into build/ (Release with asserts off unless BUILD_TYPE says otherwise).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${BUILD_DIR:-build}
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-RelWithDebInfo}" -DGI_WERROR=ON "$@"
cmake --build "$build_dir" -j "$(nproc)"

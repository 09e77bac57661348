#!/usr/bin/env bash
# Installs every build and test dependency of the project from Debian's packages.
# Idempotent: packages already present are left alone; `apt-get update` runs once.
# clang-format-14 checks the sources' layout (tools/check-format.sh, CI main leg).
# clang, libclang-rt-14-dev (libFuzzer and clang's sanitizer runtimes, only recommended by
# clang) and llvm (llvm-symbolizer for sanitizer stack traces) build the fuzz targets
# (tools/fuzz.sh); the regular build stays GCC.
# python3-matplotlib draws the sweep plots (tools/plot-sweep.py); nothing in the build needs it.
# slurmctld, slurmd, slurm-client and munge run the CI leg "slurm": a single-node Slurm on
# localhost for the distributed bake's test (tools/slurm/ci-test.sh); nothing in the build needs them.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git
  libembree-dev libglm-dev libtinygltf-dev libdraco-dev libstb-dev nlohmann-json3-dev
  libglfw3-dev libegl-dev libgl-dev libgl1-mesa-dri libegl-mesa0 libgles-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libeigen3-dev libzstd-dev libtinyexr-dev libcli11-dev libimgui-dev libtbb-dev libxxhash-dev
  xvfb xauth
  clang libclang-rt-14-dev llvm clang-format-14
  python3-matplotlib
  slurmctld slurmd slurm-client munge
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"

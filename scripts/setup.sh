#!/usr/bin/env bash
# Installs the Debian packages FluoroCT needs (only those missing), then configures and builds into build/.
# Sourced by demo.sh and test.sh; safe to run again (fast when nothing is missing or changed).
set -euo pipefail

FCT_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
FCT_BUILD="${FCT_BUILD_DIR:-$FCT_ROOT/build}"
# FCT_CMAKE_ARGS, FCT_BUILD_TARGETS (arrays, optional): extra CMake arguments of the first configure and the targets
# to build (default: all); the sanitizer build of scripts/test.sh sets them.

FCT_PACKAGES=(
  cmake ninja-build ccache g++ pkg-config
  qt6-base-dev libqt6opengl6-dev libxkbcommon-dev libgl-dev libvtk9-dev libeigen3-dev libopencv-dev libpng-dev libtiff-dev libdcmtk-dev
  libgtest-dev libgmock-dev nlohmann-json3-dev libfmt-dev libtbb-dev libcli11-dev zlib1g-dev libopenigtlink-dev
  libxml2-dev libnlopt-dev
  xvfb xauth plastimatch parallel dicom3tools
)
# Opt-in: a one-node Slurm cluster for trying study-slurm.sbatch, installed only by scripts/slurm-local.sh.
FCT_SLURM_PACKAGES=(slurm-wlm munge)
# Opt-in: libFuzzer (clang) and DCMTK's tools (seeds in every transfer syntax), installed only by scripts/fuzz.sh.
FCT_FUZZ_PACKAGES=(clang-14 libfuzzer-14-dev dcmtk)

# Installs those of the given packages (default: FCT_PACKAGES) that are missing.
fct_install_packages() {
  local wanted=("$@") missing=()
  ((${#wanted[@]})) || wanted=("${FCT_PACKAGES[@]}")
  for pkg in "${wanted[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  if ((${#missing[@]} == 0)); then
    return 0
  fi
  echo "setup: installing missing Debian packages: ${missing[*]}"
  local sudo=()
  if [[ $(id -u) -ne 0 ]]; then
    sudo=(sudo)
  fi
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
}

fct_build() {
  local jobs="${FCT_JOBS:-$(nproc)}"
  # Relative paths in ccache's keys, so that clones in other folders (CI) reuse the cache.
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$FCT_ROOT}"
  if [[ ! -f "$FCT_BUILD/build.ninja" ]]; then
    cmake -S "$FCT_ROOT" -B "$FCT_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release "${FCT_CMAKE_ARGS[@]}"
  fi
  cmake --build "$FCT_BUILD" -j "$jobs" ${FCT_BUILD_TARGETS[@]+--target "${FCT_BUILD_TARGETS[@]}"}
}

fct_install_packages
fct_build

#!/usr/bin/env bash
# Installs what Impetus needs to build and test, from Debian's packages. Run as root (or with sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libfcl-dev libccd-dev libassimp-dev libyaml-cpp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev
  # frictional contact problems in fclib's HDF5 form (core/fclib; brings HDF5 and SuiteSparse)
  libfclib-dev
  # KLU, the sparse LU of the frictional Newton's Jacobians (resolution/ledas/sparse_lu.hpp)
  libsuitesparse-dev
  binutils python3
  # peers side by side (benchmarks/peers) and charts (scripts/charts.py)
  libbullet-dev libode-dev libmujoco-dev python3-matplotlib
  # fuzzing (libFuzzer) and the sanitizer run
  clang libclang-rt-dev
  # glTF 2.0 export of runs (core/cli/gltf_export.cpp)
  libtinygltf-dev
  # the viewer page's test in a headless browser, screenshots read back (tests/cli/test_viewer.cpp)
  chromium libpng-dev
  # the Python package (python/): bindings, numpy state, its tests, sweeps on Dask
  python3-dev pybind11-dev python3-numpy python3-pytest python3-distributed python3-yaml
  # islands and the narrowphase on every core (oneTBB: the world's thread arena, parallel_for)
  libtbb-dev
)

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup.sh: run as root (or install sudo)" >&2; exit 1; }
  as_root=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update
"${as_root[@]}" apt-get install -y --no-install-recommends "${packages[@]}"

# Node.js and npm from Debian unless the machine has them already (a newer Node.js from elsewhere stays).
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  "${as_root[@]}" apt-get install -y --no-install-recommends nodejs npm
fi

# npm packages, pinned by their package-lock.json: three.js and esbuild for the viewer page
# (core/cli/viewer, bundled into the tool by the build), the Khronos glTF-Validator for the glTF tests.
root=$(cd "$(dirname "$0")/.." && pwd)
npm ci --prefix "$root/core/cli/viewer" --no-audit --no-fund --loglevel=error
npm ci --prefix "$root/tests/gltf" --no-audit --no-fund --loglevel=error

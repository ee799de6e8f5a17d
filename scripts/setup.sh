#!/usr/bin/env bash
# Installs what Impetus needs to build and test, from Debian's packages. Run as root (or with sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libfcl-dev libccd-dev libassimp-dev libyaml-cpp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev
  # frictional contact problems in fclib's HDF5 form (core/fclib; brings HDF5)
  libfclib-dev
  binutils python3
  # peers side by side (benchmarks/peers) and charts (scripts/charts.py)
  libbullet-dev libode-dev libmujoco-dev python3-matplotlib
  # fuzzing (libFuzzer) and the sanitizer run
  clang libclang-rt-dev
  # glTF 2.0 export of runs (core/cli/gltf_export.cpp)
  libtinygltf-dev
)

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup.sh: run as root (or install sudo)" >&2; exit 1; }
  as_root=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update
"${as_root[@]}" apt-get install -y --no-install-recommends "${packages[@]}"

# The Khronos glTF-Validator (npm, pinned in tests/gltf/package-lock.json) for the glTF export tests, with
# the machine's Node.js and npm.
root=$(cd "$(dirname "$0")/.." && pwd)
if command -v npm >/dev/null && command -v node >/dev/null; then
  npm ci --prefix "$root/tests/gltf" --no-audit --no-fund --loglevel=error
else
  echo "setup.sh: Node.js and npm not found: the glTF validation test (tests/cli/test_gltf.cpp) will fail" >&2
fi

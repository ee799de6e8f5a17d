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
)

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup.sh: run as root (or install sudo)" >&2; exit 1; }
  as_root=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update
"${as_root[@]}" apt-get install -y --no-install-recommends "${packages[@]}"

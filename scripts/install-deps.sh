#!/usr/bin/env bash
# Installs what bvhkit's build, tests and same-run benchmarks need on Debian/Ubuntu, skipping what is
# already there. Needs root (or sudo) only when something is missing.
#   scripts/install-deps.sh            everything: the tests, the fuzzers and every benchmark peer
#   scripts/install-deps.sh --demo     only what the demo needs (a compiler, CMake, Ninja, libpng)
set -euo pipefail
if [ "${1:-}" = "--demo" ]; then
  packages=(cmake ninja-build g++ libpng-dev)
else
  packages=(cmake ninja-build g++ make pkg-config libgtest-dev libbenchmark-dev
            libembree-dev libbox2d-dev libbullet-dev libpng-dev libfcl-dev clang libclang-rt-14-dev
            libcgal-dev libtbb-dev libgmp-dev)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root to install ${missing[*]}" >&2; exit 1; }
  sudo_cmd="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo_cmd apt-get update -qq
$sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"

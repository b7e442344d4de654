#!/usr/bin/env bash
# The test suite, as CI runs it: installs dependencies if missing, builds Release and the
# AddressSanitizer + UndefinedBehaviorSanitizer build, runs every test in both, checks that a separate
# CMake project can find_package(bvhkit) from an install, and fuzzes each mesh reader briefly.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)

echo "== Release build and tests"
cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release

echo "== Sanitizer build (ASan + UBSan) and tests"
cmake --preset debug-asan >/dev/null
cmake --build --preset debug-asan -j "$jobs"
ctest --preset debug-asan

echo "== Install and consume with find_package(bvhkit)"
rm -rf build/install build/consumer
cmake --install build/release --prefix build/install >/dev/null
cmake -S tests/consumer -B build/consumer -G Ninja -DCMAKE_PREFIX_PATH="$PWD/build/install" >/dev/null
cmake --build build/consumer
build/consumer/consumer

echo "== Fuzzing the mesh readers"
scripts/fuzz.sh "${BVHKIT_FUZZ_SECONDS:-15}"

echo "== All tests passed"

#!/usr/bin/env bash
# The test suite, as CI runs it: installs dependencies if missing, builds Release and the
# AddressSanitizer + UndefinedBehaviorSanitizer build and runs every test in both, runs the
# concurrency tests under ThreadSanitizer, builds the plain configuration a user without any optional
# package gets, checks that a separate CMake project can find_package(bvhkit) from an install, builds
# the Python package and runs its tests, and fuzzes each mesh reader and the tree file loader briefly. Tests that cannot run here (a mesh or a peer library not found)
# are reported as skipped, with the reason.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
logs=build/test-logs
mkdir -p "$logs"
# Each stage's wall time, printed at the end (CI's budget is kept by looking at these).
timings=()
stage_start=$SECONDS
stage_name=""
stage() {
    if [ -n "$stage_name" ]; then timings+=("$(printf '%5ds  %s' $((SECONDS - stage_start)) "$stage_name")"); fi
    stage_name="$1"
    stage_start=$SECONDS
    if [ -n "$1" ]; then echo "== $1"; fi
}

stage "Release build and tests"
cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release 2>&1 | tee "$logs/release.log"

stage "Sanitizer build (ASan + UBSan) and tests"
cmake --preset debug-asan >/dev/null
cmake --build --preset debug-asan -j "$jobs"
ctest --preset debug-asan 2>&1 | tee "$logs/asan.log"

stage "ThreadSanitizer: const queries from many threads"
# oneTBB is left out here (its own worker pool is not instrumented); the threads are the test's own.
cmake -S . -B build/tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBVHKIT_WERROR=ON \
    -DBVHKIT_BUILD_TESTS=ON -DBVHKIT_BUILD_TOOLS=OFF -DBVHKIT_BUILD_EXAMPLES=OFF -DBVHKIT_WITH_TBB=OFF \
    -DCMAKE_CXX_FLAGS="-fsanitize=thread -O1 -g" -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread >/dev/null
cmake --build build/tsan --target bvhkit_tests_concurrency -j "$jobs"
TSAN_OPTIONS="halt_on_error=1" build/tsan/tests/bvhkit_tests_concurrency

stage "Plain build without any optional package (cmake -B build && cmake --build build)"
disabled=()
for package in embree box2d PkgConfig CGAL TBB PNG GTest benchmark; do
    disabled+=("-DCMAKE_DISABLE_FIND_PACKAGE_${package}=ON")
done
# Debug: this run checks what compiles and runs without the optional packages, and -O0 compiles faster.
cmake -S . -B build/bare -G Ninja -DCMAKE_BUILD_TYPE=Debug "${disabled[@]}" > "$logs/bare-configure.log"
grep -E "not found|skipped|not used" "$logs/bare-configure.log" || true
cmake --build build/bare -j "$jobs"
build/bare/tools/bvhkit info sphere:subdiv=5
build/bare/tools/bvhkit-bench rays sphere:subdiv=5 --rays 20000 --size 128 --reps 1
build/bare/examples/bvhkit_example_quickstart

stage "Install and consume with find_package(bvhkit)"
rm -rf build/install build/consumer
cmake --install build/release --prefix build/install >/dev/null
cmake -S tests/consumer -B build/consumer -G Ninja -DCMAKE_PREFIX_PATH="$PWD/build/install" >/dev/null
cmake --build build/consumer
build/consumer/consumer

stage "Python package (pip install into build/python-venv) and its tests"
scripts/test-python.sh

stage "Fuzzing the mesh readers"
# Ten seconds a reader from the seed corpus: a smoke test of the readers on every run; longer
# runs: BVHKIT_FUZZ_SECONDS=600 scripts/test.sh, or scripts/fuzz.sh 600.
scripts/fuzz.sh "${BVHKIT_FUZZ_SECONDS:-10}"

stage "Skipped tests (not run here, and why)"
for run in release asan; do
    skipped=$(grep -c "(Skipped)" "$logs/$run.log" || true)
    echo "$run: $skipped skipped"
done
# The reasons, once each: GoogleTest's skip messages from both runs.
grep -h -A1 ": Skipped$" build/release/Testing/Temporary/LastTest.log build/asan/Testing/Temporary/LastTest.log 2>/dev/null |
    grep -v -e ": Skipped$" -e "^--" |
    sort | uniq -c | sort -rn | head -20 || true

stage ""
printf '%s\n' "${timings[@]}"
echo "== All tests passed in $((SECONDS / 60)) min $((SECONDS % 60)) s"

#!/usr/bin/env bash
# Builds the libFuzzer targets for the mesh readers and the tree file loader (clang, ASan + UBSan)
# in build/fuzz and runs each for a bounded time from a small seed corpus written here (for the
# loader: small trees saved by tree_file_seeds).
#   scripts/fuzz.sh [seconds per target, default 20]
# Exits non-zero if a fuzzer reports a crash, leak, timeout or sanitizer error; the reproducer is
# left in build/fuzz/artifacts/.
set -euo pipefail

seconds="${1:-20}"
if ! [[ "$seconds" =~ ^[0-9]+$ ]]; then
    echo "usage: $0 [seconds per target]" >&2
    exit 2
fi
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$repo/build/fuzz"

# libFuzzer needs clang and its runtime (Debian: libclang-rt-14-dev); install them only if missing
# and only when we may.
fuzzer_runtime_works() {
    command -v clang++ > /dev/null 2>&1 || return 1
    local probe
    probe="$(mktemp -d)"
    printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' \
        > "$probe/probe.cpp"
    clang++ -fsanitize=fuzzer "$probe/probe.cpp" -o "$probe/probe" > /dev/null 2>&1
    local status=$?
    rm -rf "$probe"
    return $status
}
if ! fuzzer_runtime_works; then
    if [[ "$(id -u)" == "0" ]] && command -v apt-get > /dev/null; then
        echo "fuzz.sh: installing clang and libclang-rt-14-dev" >&2
        apt-get install -y libclang-rt-14-dev clang
    fi
    if ! fuzzer_runtime_works; then
        echo "fuzz.sh: clang++ with libFuzzer is not available (install clang and libclang-rt-14-dev)" >&2
        exit 2
    fi
fi

CXX=clang++ cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DBVHKIT_BUILD_FUZZ=ON -DBVHKIT_BUILD_TESTS=OFF -DBVHKIT_BUILD_TOOLS=OFF -DBVHKIT_BUILD_BENCH=OFF \
    > "$build.configure.log" 2>&1 || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" --target fuzz_obj fuzz_ply fuzz_stl fuzz_tree_file tree_file_seeds

# Seed corpus: one tiny valid file per format (and variant), written fresh each run.
work="$(mktemp -d)"
pids=()  # the fuzzers running: the trap stops them too if the script is killed
trap 'kill "${pids[@]}" 2>/dev/null || true; rm -rf "$work"' EXIT
mkdir -p "$work/obj" "$work/ply" "$work/stl"
"$build/tests/fuzz/tree_file_seeds" "$work/tree_file"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n' > "$work/obj/quad.obj"
printf '# c\r\nv 0 0 0\r\nvt 0 0\r\nvn 0 0 1\r\nv 1 0 0\r\nv 0 1 0\r\nf -3/1/1 -2/1/1 -1/1/1\r\nf 1//1 2//1 3//1\r\n' \
    > "$work/obj/forms.obj"
ply_header='element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n'
printf "ply\nformat ascii 1.0\n${ply_header}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n" > "$work/ply/ascii.ply"
{
    printf "ply\nformat binary_little_endian 1.0\n${ply_header}"
    printf '\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    printf '\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00\x00\x00'
    printf '\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00'
    printf '\x03\x00\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00'
} > "$work/ply/le.ply"
{
    printf 'ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty float y\nproperty float z\n'
    printf 'element tristrips 1\nproperty list int int vertex_indices\nend_header\n'
    printf '\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    printf '\x3f\xf0\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00'
    printf '\x00\x00\x00\x00\x00\x00\x00\x00\x3f\x80\x00\x00\x00\x00\x00\x00'
    printf '\x00\x00\x00\x04\x00\x00\x00\x00\x00\x00\x00\x01\xff\xff\xff\xff\x00\x00\x00\x02'
} > "$work/ply/strips.ply"
printf 'solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n' \
    > "$work/stl/ascii.stl"
{
    printf 'solid but binary'
    head -c 64 /dev/zero
    printf '\x01\x00\x00\x00'
    head -c 24 /dev/zero
    printf '\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00\x00\x00'
    printf '\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00'
} > "$work/stl/binary.stl"

mkdir -p "$build/artifacts"
# The fuzzers run side by side, as many at once as there are cores (each is one process of one
# thread), and their reports are printed in turn once each is done.
jobs=$(nproc 2>/dev/null || echo 1)
formats=(obj ply stl tree_file)
failed=()
run_fuzzer() {
    "$build/tests/fuzz/fuzz_$1" "$work/$1" -max_total_time="$seconds" -max_len=4096 \
        -rss_limit_mb=1024 -timeout=5 -print_final_stats=1 \
        -artifact_prefix="$build/artifacts/${1}-" > "$work/$1.log" 2>&1
}
for ((first = 0; first < ${#formats[@]}; first += jobs)); do
    batch=("${formats[@]:first:jobs}")
    pids=()
    for format in "${batch[@]}"; do
        run_fuzzer "$format" &
        pids+=($!)
    done
    for i in "${!batch[@]}"; do
        format="${batch[$i]}"
        status=0
        wait "${pids[$i]}" || status=$?
        echo "== fuzz_$format for ${seconds}s"
        tail -n 25 "$work/$format.log"
        if [ "$status" -ne 0 ]; then failed+=("$format"); fi
    done
done
if ((${#failed[@]})); then
    echo "fuzz.sh: findings in: ${failed[*]} (reproducers in $build/artifacts)" >&2
    exit 1
fi
echo "fuzz.sh: no findings"

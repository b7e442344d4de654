#!/usr/bin/env bash
# Downloads the scanned test meshes that bvhkit does not ship (see data/README.md) from the public
# collection alecjacobson/common-3d-test-models, checks each against the checksum of the copy the
# project's figures were measured on, and tells how to point the tests and benchmarks at them.
#   scripts/fetch-meshes.sh [DIR]   (default: ../shared/data beside the checkout)
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dir="${1:-$repo/../shared/data}"
base="https://raw.githubusercontent.com/alecjacobson/common-3d-test-models/master/data"
mkdir -p "$dir"
# name and sha256 of the copy used for the figures in docs/benchmarks.md
meshes=(
  "stanford-bunny.obj 1eb35d1e21ce99e5ce911353b6be278990713448dd9e8f5c9387f9de39b32205"
  "igea.ply 75f065f8fefbb468363718a5df39cc73c89e97c2ce3fa8a3b0086a08bb466222"
  "fandisk.obj ea5bab2fbf545b1915f0d9faf6cc61ff8c18e0d8174ad61f8e35de15d8f6e3f8"
)
fetch() {
  if command -v curl > /dev/null; then curl -fsSL "$1" -o "$2"; else wget -q "$1" -O "$2"; fi
}
for entry in "${meshes[@]}"; do
  read -r name sum <<< "$entry"
  if [ -f "$dir/$name" ]; then
    echo "$name: already in $dir"
    continue
  fi
  echo "$name: downloading"
  fetch "$base/$name" "$dir/$name.part"
  if [ "$(sha256sum "$dir/$name.part" | cut -d' ' -f1)" != "$sum" ]; then
    echo "$name: warning: checksum differs from the measured copy (kept; figures may differ)" >&2
  fi
  mv "$dir/$name.part" "$dir/$name"
done
cp -n "$repo"/data/*.obj "$dir"/ 2> /dev/null || true
echo "done: export BVHKIT_DATA_DIR=$dir (tests and benchmarks then find these meshes)"
echo "not fetched: dragon-lowres.ply and suzanne.obj (not in that collection as plain files);"
echo "the tests that need them are reported as skipped"

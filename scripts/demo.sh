#!/usr/bin/env bash
# The demo: builds the bvhkit command if needed, prints what each builder makes of a mesh, and renders
# it shaded and as a traversal-cost heat map.
#   scripts/demo.sh [MESH] [OUTDIR]
# MESH: a mesh file (relative to where you run this) or a generator spec such as room:objects=200;
# default: the shipped data/spot.obj. The PNGs go to OUTDIR (default: the current folder).
set -euo pipefail
caller="$(pwd)"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mesh="${1:-$repo/data/spot.obj}"
view=()
[ $# -eq 0 ] && view=(--turn 150)  # the shipped cow, seen from the front
if [ -e "$mesh" ]; then  # a file: make its path absolute before leaving the caller's folder
  mesh="$(cd "$(dirname "$mesh")" && pwd)/$(basename "$mesh")"
fi
out="$(cd "${2:-$caller}" && pwd)"
cd "$repo"
scripts/install-deps.sh
bin=build/release/tools/bvhkit
echo "== building the bvhkit command (the first build takes a few minutes)"
cmake --preset release > /dev/null
cmake --build --preset release --target bvhkit_cli -j "$(nproc 2> /dev/null || echo 2)"
echo
echo "== bvhkit info $mesh --all-builders"
"$bin" info "$mesh" --all-builders
echo
echo "== bvhkit render"
"$bin" render "$mesh" "${view[@]}" -o "$out/bvhkit-demo.png"
"$bin" render "$mesh" "${view[@]}" --heatmap -o "$out/bvhkit-demo-heatmap.png"
echo
echo "Open $out/bvhkit-demo.png (shaded) and $out/bvhkit-demo-heatmap.png (box tests per pixel)."

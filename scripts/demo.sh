#!/usr/bin/env bash
# The demo: builds the bvhkit command if needed, then builds a BVH over a procedural mesh (no data file
# needed), prints what each builder makes of it, and renders it shaded and as a traversal-cost heat map.
#   scripts/demo.sh [MESH]   (MESH: a mesh file or a generator spec; default a displaced sphere)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
mesh="${1:-sphere:subdiv=7,displacement=0.25}"
cmake --preset release >/dev/null
cmake --build --preset release --target bvhkit_cli -j "$(nproc 2>/dev/null || echo 2)" >/dev/null
bin=build/release/tools/bvhkit
echo "== bvhkit info $mesh --all-builders"
"$bin" info "$mesh" --all-builders
echo
echo "== bvhkit render"
"$bin" render "$mesh" -o bvhkit-demo.png
"$bin" render "$mesh" --heatmap -o bvhkit-demo-heatmap.png
echo
echo "Open bvhkit-demo.png (shaded) and bvhkit-demo-heatmap.png (box tests per pixel)."

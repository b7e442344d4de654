#!/usr/bin/env bash
# The demo: builds the bvhkit command if needed (the library and the command only: no test framework
# and no benchmark peer, so a fresh machine needs a compiler, CMake, Ninja and libpng), prints what each
# builder makes of a mesh, and renders it shaded and as a traversal-cost heat map.
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
scripts/install-deps.sh --demo
bin=build/demo/tools/bvhkit
echo "== building the bvhkit command into build/demo (the first build takes a few minutes)"
# The peers are benchmark columns only: leaving them out keeps the demo's build to the library and
# the command.
peers=()
for package in embree box2d PkgConfig CGAL GTest benchmark; do
  peers+=("-DCMAKE_DISABLE_FIND_PACKAGE_${package}=ON")
done
cmake -S . -B build/demo -G Ninja -DCMAKE_BUILD_TYPE=Release -DBVHKIT_BUILD_EXAMPLES=OFF "${peers[@]}" > /dev/null
cmake --build build/demo --target bvhkit_cli -j "$(nproc 2> /dev/null || echo 2)"
echo
echo "== bvhkit info $mesh --all-builders"
"$bin" info "$mesh" --all-builders
echo
echo "== bvhkit render"
"$bin" render "$mesh" "${view[@]}" --out "$out/bvhkit-demo.png"
"$bin" render "$mesh" "${view[@]}" --heatmap --out "$out/bvhkit-demo-heatmap.png"
echo
echo "Open $out/bvhkit-demo.png (shaded) and $out/bvhkit-demo-heatmap.png (BVH nodes visited per ray)."

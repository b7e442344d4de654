// `bvhkit bsp`: the BSP tree of a mesh and its statistics.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "args.hpp"
#include "bvhkit/bsp/bsp_tree.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "commands.hpp"
#include "output.hpp"
#include "report.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kHelp =
    R"(usage: bvhkit bsp MESH [--split-weight W] [--max-depth D] [--leaf-size N]
                       [--candidates polygon|axis|both] [--json]

Builds a BSP tree over the mesh's triangles (docs/bsp.md) and prints the mesh's triangle count, then
the build milliseconds (median of 3), nodes, leaves, depth, splits made, polygons after splitting
(at nodes and in leaves), degenerate triangles dropped, memory and whether the tree is solid (every
leaf an empty cell known to be inside or outside).
  --split-weight W  score = W * splits + (1 - W) * |front - back|, W in [0, 1] (default 0.8)
  --max-depth D     a node at depth D becomes a leaf (default 65536)
  --leaf-size N     a node of at most N polygons becomes a leaf (default 0: split to empty leaves)
  --candidates C    splitter candidates: polygon planes (default), axis-aligned planes, or both
MESH is a file (OBJ, PLY, STL) or a generator spec such as torus:u=48,v=24.
)";

double parse_weight(const std::string& s) {
    char* end = nullptr;
    const double w = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !(w >= 0.0 && w <= 1.0))
        throw Error("option --split-weight: '" + s + "' is not a number in [0, 1]");
    return w;
}

BspCandidates parse_candidates(const std::string& s) {
    if (s == "polygon") return BspCandidates::PolygonPlanes;
    if (s == "axis") return BspCandidates::AxisAligned;
    if (s == "both") return BspCandidates::Both;
    throw Error("option --candidates: '" + s + "' is not one of polygon, axis, both");
}

}  // namespace

int bsp_command(int argc, char** argv) {
    const Args args(argc, argv, {"--split-weight", "--max-depth", "--leaf-size", "--candidates"},
                    {"--json"});
    if (args.help()) {
        std::fputs(kHelp, stdout);
        return 0;
    }
    if (args.positional().size() != 1) throw Error("bsp takes one mesh (see --help)");
    BspOptions options;
    if (args.has("--split-weight"))
        options.split_weight = parse_weight(args.value("--split-weight"));
    options.max_depth = std::uint32_t(args.integer("--max-depth", options.max_depth, 0, 1 << 24));
    options.leaf_size = std::uint32_t(args.integer("--leaf-size", 0, 0, 1 << 30));
    if (args.has("--candidates")) options.candidates = parse_candidates(args.value("--candidates"));
    options.validate();
    const TriangleMesh mesh = load_mesh(args.positional()[0]);
    const bool json = args.flag("--json");
    if (!json)
        std::printf("%s: %zu triangles, %zu vertices\n\n", args.positional()[0].c_str(),
                    mesh.triangle_count(), mesh.vertices.size());
    BspTree<double> tree;
    const double ms = bench::median_ms(
        3, [&] { tree = BspTree<double>(mesh, options); }, false);
    const BspStatistics& s = tree.statistics();
    bench::Row row;
    row.set("build_ms", ms).set("nodes", (long long)s.nodes).set("leaves", (long long)s.leaves);
    row.set("depth", (long long)s.depth).set("splits", (long long)s.splits);
    row.set("polygons", (long long)s.polygons).set("at_nodes", (long long)s.polygons_at_nodes);
    row.set("in_leaves", (long long)s.polygons_in_leaves);
    row.set("dropped", (long long)s.dropped_degenerate);
    row.set("memory_kib", double(s.memory_bytes) / 1024.0);
    row.set("solid", std::string(s.solid ? "yes" : "no"));
    print_rows({row}, json);
    return 0;
}

}  // namespace bvhkit::tools

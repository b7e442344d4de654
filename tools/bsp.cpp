// `bvhkit bsp`: the BSP tree of a mesh and its statistics.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "args.hpp"
#include "bvhkit/bsp/bsp_tree.hpp"
#include "bvhkit/bsp/ray.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "commands.hpp"
#include "output.hpp"
#include "ray_sets.hpp"
#include "report.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kBspHelp =
    R"(usage: bvhkit bsp MESH [--split-weight W] [--max-depth D] [--leaf-size N]
                       [--candidates polygon|axis|both] [--compare] [--json]

Builds a BSP tree over the mesh's triangles (docs/bsp.md) and prints the mesh's triangle count, then
the build milliseconds (median of 3), nodes, leaves, depth, splits made, polygons after splitting
(at nodes and in leaves), degenerate triangles dropped, memory and whether the tree is solid (every
leaf an empty cell known to be inside or outside).
  --split-weight W  score = W * splits + (1 - W) * |front - back|, W in [0, 1] (default 0.8)
  --max-depth D     a node at depth D becomes a leaf (default 65536)
  --leaf-size N     a node of at most N polygons becomes a leaf (default 0: split to empty leaves)
  --candidates C    splitter candidates: polygon planes (default), axis-aligned planes, or both
  --compare         also build the TriangleBvh (binned SAH, double) and trace workloads R1 (a
                    256 x 256 camera) and R2 (100,000 random rays from the mesh's box) through
                    both: build time, nodes, memory, rays per second (one thread) for the
                    closest hit, and hits that differ
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

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<Ray<double, 3>> to_double(const std::vector<Ray3f>& rays) {
    std::vector<Ray<double, 3>> out;
    for (const auto& r : rays)
        out.emplace_back(Vec<double, 3>(r.origin), Vec<double, 3>(r.direction), r.tmin, r.tmax);
    return out;
}

// Traces `rays` through both structures (closest hit, one thread) and sets `name`'s columns: rays
// per second on both rows, the BSP's nodes and polygons per ray, and the rays whose hits differ.
void trace_both(const char* name, const std::vector<Ray<double, 3>>& rays,
                const BspTree<double>& bsp, const TriangleBvh<double>& bvh, bench::Row& bsp_row,
                bench::Row& bvh_row) {
    std::vector<double> bsp_t(rays.size()), bvh_t(rays.size());
    BspRayStats stats;
    auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < rays.size(); ++i) bsp_t[i] = closest_hit(bsp, rays[i], &stats).t;
    const double bsp_s = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < rays.size(); ++i) bvh_t[i] = bvh.closest_hit(rays[i]).t;
    const double bvh_s = seconds_since(t0);
    long long differ = 0;
    for (std::size_t i = 0; i < rays.size(); ++i)
        if (std::isinf(bsp_t[i]) != std::isinf(bvh_t[i]) ||
            std::abs(bsp_t[i] - bvh_t[i]) > 1e-9 * std::max(1.0, std::abs(bvh_t[i])))
            ++differ;
    const std::string n = name;
    const double count = double(rays.size());
    bsp_row.set(n + "_rays_per_s", count / bsp_s);
    bsp_row.set(n + "_nodes_per_ray", double(stats.nodes_visited) / count);
    bsp_row.set(n + "_polys_per_ray", double(stats.polygons_tested) / count);
    bsp_row.set(n + "_hits_differ", differ);
    bvh_row.set(n + "_rays_per_s", count / bvh_s);
}

// Adds the BVH's row and both structures' ray throughput on workloads R1 (primary rays of a
// 256 x 256 camera) and R2 (100,000 random rays in the mesh's box).
void compare_with_bvh(const TriangleMesh& mesh, const BspTree<double>& bsp,
                      std::vector<bench::Row>& rows) {
    TriangleBvh<double> bvh;
    const double bvh_ms = bench::median_ms(
        3, [&] { bvh = TriangleBvh<double>(mesh); }, false);
    const auto& b = bvh.bvh();
    const std::size_t bytes = b.nodes.size() * sizeof(b.nodes[0]) +
                              b.primitive_indices.size() * sizeof(std::uint32_t) +
                              bvh.triangle_count() * sizeof(Triangle<double>);
    bench::Row row;
    row.set("structure", std::string("bvh")).set("build_ms", bvh_ms);
    row.set("nodes", (long long)b.nodes.size());
    row.set("polygons", (long long)bvh.triangle_count());
    row.set("memory_kib", double(bytes) / 1024.0);
    trace_both("r1", to_double(camera_rays(mesh.bounds(), 256, 256)), bsp, bvh, rows[0], row);
    trace_both("r2", to_double(random_rays(mesh.bounds(), 100000, 1)), bsp, bvh, rows[0], row);
    rows.push_back(row);
}

}  // namespace

int bsp_command(int argc, char** argv) {
    const Args args(argc, argv, {"--split-weight", "--max-depth", "--leaf-size", "--candidates"},
                    {"--json", "--compare"});
    if (args.help()) {
        std::fputs(kBspHelp, stdout);
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
    row.set("structure", std::string("bsp"));
    row.set("build_ms", ms).set("nodes", (long long)s.nodes).set("leaves", (long long)s.leaves);
    row.set("depth", (long long)s.depth).set("splits", (long long)s.splits);
    row.set("polygons", (long long)s.polygons).set("at_nodes", (long long)s.polygons_at_nodes);
    row.set("in_leaves", (long long)s.polygons_in_leaves);
    row.set("dropped", (long long)s.dropped_degenerate);
    row.set("memory_kib", double(s.memory_bytes) / 1024.0);
    row.set("solid", std::string(s.solid ? "yes" : "no"));
    std::vector<bench::Row> rows{row};
    if (args.flag("--compare")) compare_with_bvh(mesh, tree, rows);
    print_rows(rows, json);
    return 0;
}

}  // namespace bvhkit::tools

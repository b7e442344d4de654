// `bvhkit info`: what a mesh is and what each builder makes of it.
#include <cstdio>

#include "args.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "commands.hpp"
#include "output.hpp"
#include "ray_sets.hpp"
#include "report.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kInfoHelp =
    R"(usage: bvhkit info MESH [--builder NAME | --all-builders] [--spatial-splits]
                   [--threads N] [--json]

Prints the mesh's triangle count and bounds, then for the builder (default binned-sah) or for every
builder: build milliseconds (median of 3), node count, depth, leaf sizes, SAH cost, and the ray cost
of workload R2 (100,000 random rays): box tests and triangle tests per ray. --spatial-splits adds a
row for the high-quality build (binned SAH with spatial splits), with its triangle references.
--threads N is the threads each build may use (default 0: every core when bvhkit has oneTBB; 1
for one-thread build times); the trees and the ray costs are the same for any number.
MESH is a file (OBJ, PLY, STL) or a generator spec such as sphere:subdiv=7.
)";

}  // namespace

int info_command(int argc, char** argv) {
    const Args args(argc, argv, {"--builder", "--threads"},
                    {"--all-builders", "--json", "--spatial-splits"});
    if (args.help()) {
        std::fputs(kInfoHelp, stdout);
        return 0;
    }
    if (args.positional().size() != 1) throw Error("info takes one mesh (see --help)");
    // Every option is checked before anything is printed, so an error stands alone.
    if (args.flag("--all-builders") && args.has("--builder"))
        throw Error("--builder and --all-builders exclude each other");
    std::vector<std::pair<std::string, TriangleBvhOptions>> builders;
    if (args.flag("--all-builders")) {
        for (const auto& [name, options] : all_builder_configurations())
            builders.emplace_back(name, options);
    } else {
        const std::string name = args.value("--builder", "binned-sah");
        builders.emplace_back(name, parse_builder(name));
    }
    if (args.flag("--spatial-splits")) {
        TriangleBvhOptions o;
        o.spatial_splits = true;
        builders.emplace_back("spatial-splits", o);
    }
    for (auto& builder : builders) builder.second.threads = args.threads();
    const TriangleMesh mesh = load_mesh(args.positional()[0]);
    const Aabb3f b = mesh.bounds();
    if (!args.flag("--json"))
        std::printf("%s: %zu triangles, %zu vertices, bounds (%g %g %g) - (%g %g %g)\n\n",
                    args.positional()[0].c_str(), mesh.triangle_count(), mesh.vertices.size(),
                    b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]);

    const std::vector<Ray3f> rays = random_rays(b, 100000, 1);
    std::vector<bench::Row> rows;
    for (const auto& [name, options] : builders) {
        TriangleBvh<float> bvh;
        const double ms = bench::median_ms(
            3, [&] { bvh = TriangleBvh<float>(mesh, options); }, false);
        const BvhStatistics s = statistics(bvh.bvh());
        TraversalStats t;
        for (const auto& r : rays) bvh.closest_hit(r, t);
        std::size_t smallest = 0, largest = 0;
        for (std::size_t k = 0; k < s.leaf_size_histogram.size(); ++k)
            if (s.leaf_size_histogram[k]) {
                if (!smallest) smallest = k;
                largest = k;
            }
        bench::Row row;
        row.set("builder", name).set("build_ms", ms).set("nodes", (long long)s.node_count);
        row.set("depth", (long long)s.depth).set("leaves", (long long)s.leaf_count);
        row.set("leaf_min", (long long)smallest).set("leaf_mean", s.average_leaf_size());
        row.set("leaf_max", (long long)largest).set("sah_cost", s.sah_cost);
        row.set("r2_nodes_per_ray", double(t.nodes_visited) / rays.size());
        row.set("r2_tris_per_ray", double(t.primitives_tested) / rays.size());
        if (!bvh.skipped().empty()) row.set("skipped", (long long)bvh.skipped().size());
        if (bvh.has_split_references())
            row.set("references", (long long)bvh.bvh().primitive_indices.size());
        rows.push_back(row);
    }
    print_rows(rows, args.flag("--json"));
    return 0;
}

}  // namespace bvhkit::tools

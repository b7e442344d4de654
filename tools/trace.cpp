// `bvhkit trace`: the user's rays through the user's mesh, hits written in the docs/workloads.md
// format.
#include <chrono>
#include <cstdio>
#include <limits>
#include <string>

#include "args.hpp"
#include "bvhkit/bsp/bsp_tree.hpp"
#include "bvhkit/bsp/ray.hpp"
#include "bvhkit/io/ray_files.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "commands.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kTraceHelp =
    R"(usage: bvhkit trace MESH --rays FILE --out FILE [--any-hit] [--builder NAME]
                    [--structure bvh|bsp] [--threads N]

Traces every ray of FILE (8 float32 per ray: origin xyz, direction xyz, tmin, tmax) through MESH and
writes, per ray, float32 t (+inf on a miss) and uint32 triangle index (0xFFFFFFFF on a miss); the
index is the triangle's position in the mesh file, polygons split into fans in file order.
With --any-hit each ray stops at the first triangle found (an occlusion query): the hit written is
a hit within [tmin, tmax], not necessarily the closest.
--structure bsp traces through a BSP tree (docs/bsp.md; in double, default options) instead of the
BVH; its --any-hit answer is the closest hit, and --builder does not apply.
--threads 0 (the default) traces on every core when bvhkit has oneTBB, 1 on one thread; the hits
are the same for every thread count (the BSP traces on one thread).
)";

// The same through a BSP tree: rays and t in double, written as float32.
int trace_bsp(const TriangleMesh& mesh, const std::vector<Ray3f>& rays, const std::string& out) {
    const BspTree<double> bsp(mesh);
    std::vector<FileHit> hits(rays.size());
    std::size_t hit_count = 0;
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Ray<double, 3> ray(Vec<double, 3>(rays[i].origin), Vec<double, 3>(rays[i].direction),
                                 rays[i].tmin, rays[i].tmax);
        const BspHit<double> h = closest_hit(bsp, ray);
        hits[i] = h ? FileHit{float(h.t), h.source}
                    : FileHit{std::numeric_limits<float>::infinity(), invalid_index};
        hit_count += bool(h);
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    write_hits(out, hits);
    std::fprintf(stderr, "%zu rays, %zu hits, %.1f ms (closest hit, BSP of %zu nodes); wrote %s\n",
                 rays.size(), hit_count, ms, bsp.statistics().nodes, out.c_str());
    if (bsp.statistics().dropped_degenerate)
        std::fprintf(stderr, "note: %zu degenerate triangles were left out\n",
                     bsp.statistics().dropped_degenerate);
    return 0;
}

}  // namespace

int trace_command(int argc, char** argv) {
    const Args args(argc, argv, {"--rays", "--out", "--builder", "--structure", "--threads"},
                    {"--any-hit"});
    if (args.help()) {
        std::fputs(kTraceHelp, stdout);
        return 0;
    }
    if (args.positional().size() != 1) throw Error("trace takes one mesh (see --help)");
    if (!args.has("--rays") || !args.has("--out"))
        throw Error("trace needs --rays FILE and --out FILE");
    const std::string structure = args.value("--structure", "bvh");
    if (structure != "bvh" && structure != "bsp")
        throw Error("option --structure: '" + structure + "' is not one of bvh, bsp");
    if (structure == "bsp" && args.has("--builder"))
        throw Error("--builder applies to --structure bvh only");
    const auto threads = unsigned(args.threads());
    const TriangleMesh mesh = load_mesh(args.positional()[0]);
    const std::vector<Ray3f> rays = read_rays(args.value("--rays"));
    if (structure == "bsp") return trace_bsp(mesh, rays, args.value("--out"));
    const TriangleBvh<float> bvh(mesh, parse_builder(args.value("--builder", "binned-sah")));
    const bool any = args.flag("--any-hit");
    std::vector<Hit<float>> found(rays.size());
    const auto start = std::chrono::steady_clock::now();
    if (any) {
        // The first triangle found will do, and its index is written: all_hits, stopped at once.
        Executor(threads).parallel_for(rays.size(), TriangleBvh<float>::batch_grain,
                                       [&](std::size_t b, std::size_t e) {
                                           for (std::size_t i = b; i < e; ++i)
                                               bvh.all_hits(rays[i], [&](const Hit<float>& h) {
                                                   found[i] = h;
                                                   return false;
                                               });
                                       });
    } else {
        bvh.trace(rays, found, threads);
    }
    std::vector<FileHit> hits(rays.size());
    std::size_t hit_count = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hit<float>& h = found[i];
        hits[i] = h ? FileHit{h.t, h.primitive}
                    : FileHit{std::numeric_limits<float>::infinity(), invalid_index};
        hit_count += bool(h);
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    write_hits(args.value("--out"), hits);
    std::fprintf(stderr, "%zu rays, %zu hits, %.1f ms (%s); wrote %s\n", rays.size(), hit_count, ms,
                 any ? "any hit" : "closest hit", args.value("--out").c_str());
    if (!bvh.skipped().empty())
        std::fprintf(stderr, "note: %zu triangles with non-finite coordinates were left out\n",
                     bvh.skipped().size());
    return 0;
}

}  // namespace bvhkit::tools

// `bvhkit render`: a picture of a mesh through its BVH, shaded, or as a heat map of the traversal
// cost (box tests per pixel) with its colour scale: the picture BVH users look at to judge a tree.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "args.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/ray_sets.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "commands.hpp"
#include "image.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kHelp =
    R"(usage: bvhkit render [MESH] -o IMAGE.png [--heatmap] [--size WxH] [--builder NAME]

Renders MESH (a file or a generator spec; default: sphere:subdiv=7,displacement=0.25) through its BVH
with the camera of workload R1. The default picture is shaded by the surface normal; --heatmap colours
each pixel by the number of BVH nodes its ray tested, with the scale drawn at the bottom.

  -o FILE         the PNG to write (required)
  --heatmap       traversal-cost heat map instead of shading
  --size WxH      image size (default 800x800)
  --builder NAME  builder (default binned-sah; see bvhkit info --all-builders)
)";

void parse_size(const std::string& s, std::uint32_t& w, std::uint32_t& h) {
    unsigned a = 0, b = 0;
    char x = 0, extra = 0;
    if (std::sscanf(s.c_str(), "%u%c%u%c", &a, &x, &b, &extra) != 3 || (x != 'x' && x != 'X') ||
        a < 16 || b < 16 || a > 16384 || b > 16384)
        throw Error("--size '" + s + "': expected WxH with each side in [16, 16384]");
    w = a;
    h = b;
}

}  // namespace

int render_command(int argc, char** argv) {
    const Args args(argc, argv, {"-o", "--size", "--builder"}, {"--heatmap"});
    if (args.help()) {
        std::fputs(kHelp, stdout);
        return 0;
    }
    if (!args.has("-o")) throw Error("missing -o IMAGE.png (see --help)");
    if (args.positional().size() > 1) throw Error("render takes one mesh (see --help)");
    const std::string spec =
        args.positional().empty() ? "sphere:subdiv=7,displacement=0.25" : args.positional()[0];
    std::uint32_t width = 800, height = 800;
    if (args.has("--size")) parse_size(args.value("--size"), width, height);

    const TriangleMesh mesh = load_mesh(spec);
    const auto t0 = std::chrono::steady_clock::now();
    const TriangleBvh<float> bvh(mesh, parse_builder(args.value("--builder", "binned-sah")));
    const double build_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const std::vector<Ray3f> rays = camera_rays(mesh.bounds(), width, height);

    Image image(width, height);
    const bool heatmap = args.flag("--heatmap");
    std::vector<std::uint32_t> cost(rays.size());
    std::uint32_t max_cost = 1;
    const auto t1 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        TraversalStats stats;
        const Hit<float> hit = bvh.closest_hit(rays[i], stats);
        cost[i] = std::uint32_t(stats.nodes_visited);
        max_cost = std::max(max_cost, cost[i]);
        Rgb& px = image.pixels[i];
        if (!hit) {  // background: a soft vertical gradient
            const double y = double(i / width) / height;
            px = {std::uint8_t(40 + 30 * y), std::uint8_t(44 + 34 * y), std::uint8_t(52 + 40 * y)};
            continue;
        }
        const auto& t = mesh.triangles[hit.primitive];
        const Vec3f n = normalize(cross(mesh.vertices[t[1]] - mesh.vertices[t[0]],
                                        mesh.vertices[t[2]] - mesh.vertices[t[0]]));
        // Two-sided Lambert from a light over the camera's shoulder plus a little ambient.
        const Vec3f light = normalize(Vec3f(-0.4f, 0.8f, 0.45f) - rays[i].direction);
        const float lambert = std::fabs(dot(n, light));
        const float facing = std::fabs(dot(n, rays[i].direction));
        const float v = 0.12f + 0.68f * lambert + 0.2f * facing;
        px = {std::uint8_t(std::min(255.0f, 235 * v)), std::uint8_t(std::min(255.0f, 210 * v)),
              std::uint8_t(std::min(255.0f, 175 * v))};
    }
    const double trace_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();

    if (heatmap) {
        // Scale to the 99.5th percentile: a few grazing rays along silhouettes cost far more than
        // the rest and would otherwise leave the whole picture dark.
        std::vector<std::uint32_t> sorted = cost;
        const std::size_t k = sorted.size() * 995 / 1000;
        std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
        const std::uint32_t scale_top = std::max<std::uint32_t>(1, sorted[k]);
        for (std::size_t i = 0; i < rays.size(); ++i)
            image.pixels[i] = heat_colour(double(cost[i]) / scale_top);
        // The scale: a bar along the bottom, labelled 0 and the maximum.
        const std::uint32_t bar_top = height - 28, bar_bottom = height - 16;
        image.fill(0, bar_top - 4, width, height, {20, 20, 24});
        for (std::uint32_t x = 8; x + 8 < width; ++x)
            image.fill(x, bar_top, x + 1, bar_bottom, heat_colour(double(x - 8) / (width - 16)));
        const Rgb white{240, 240, 240};
        image.text(8, height - 12, "0", white, 2);
        const std::string top = std::to_string(scale_top) + "+ nodes/ray";
        image.text(width - 8 - std::uint32_t(top.size()) * 8, height - 12, top, white, 2);
    }
    write_png(args.value("-o"), image);

    const BvhStatistics s = statistics(bvh.bvh());
    double mean_cost = 0;
    for (auto c : cost) mean_cost += c;
    mean_cost /= double(cost.size());
    std::printf("%s: %zu triangles, %zu nodes, depth %u, SAH cost %.2f, built in %.1f ms\n",
                spec.c_str(), mesh.triangle_count(), s.node_count, s.depth, s.sah_cost, build_ms);
    std::printf(
        "traced %zu rays in %.1f ms (%.1f Mrays/s); nodes tested per ray: mean %.1f, max %u\n",
        rays.size(), trace_ms, rays.size() / trace_ms / 1e3, mean_cost, max_cost);
    std::printf("wrote %s (%ux%u, %s)\n", args.value("-o").c_str(), width, height,
                heatmap ? "traversal-cost heat map" : "shaded");
    return 0;
}

}  // namespace bvhkit::tools

// `bvhkit render`: a picture of a mesh through its BVH, shaded, or as a heat map of the traversal
// cost (BVH nodes visited per ray) with its colour scale: the picture BVH users look at to judge a
// tree.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "args.hpp"
#include "bvhkit/bsp/bsp_tree.hpp"
#include "bvhkit/bsp/ray.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "commands.hpp"
#include "image.hpp"
#include "ray_sets.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kRenderHelp =
    R"(usage: bvhkit render [MESH] --out IMAGE.png [--heatmap [--scale N]] [--size WxH]
                     [--builder NAME] [--structure bvh|bsp] [--turn DEG] [--threads N]

Renders MESH (a file or a generator spec; default: sphere:subdiv=7,displacement=0.25) through its BVH
with the camera of workload R1. The default picture is shaded by the surface normal; --heatmap colours
each pixel by the number of BVH nodes its ray tested, with the scale drawn at the bottom.

  --out FILE      the PNG to write (required; -o is its earlier name)
  --heatmap       traversal-cost heat map instead of shading
  --scale N       heat map: a fixed scale whose top is N nodes per ray, so that pictures of
                  different trees compare (default: the 99.5th percentile of this picture)
  --turn DEG      turn the mesh by DEG degrees about the vertical axis through its centre
                  first (the camera stays where workload R1 puts it)
  --size WxH      image size (default 800x800; at most 4096x4096 pixels in all)
  --builder NAME  builder (default binned-sah; see bvhkit info --all-builders)
  --structure S   bvh (default) or bsp: trace through a BSP tree (docs/bsp.md, double, default
                  options) instead; the heat map then counts BSP nodes visited per ray
  --threads N     threads tracing the picture (default 0: every core when bvhkit has oneTBB);
                  the picture is the same for any number
)";

// A picture takes about 48 bytes a pixel while it is traced (the ray, its cost, the colour), so the
// pixel count is bounded to keep a render under ~1 GB; each side is bounded as the ray sets are.
constexpr std::uint64_t kMaxPixels = std::uint64_t(1) << 24;  // 4096 x 4096

void parse_size(const std::string& s, std::uint32_t& w, std::uint32_t& h) {
    const std::string what = "--size '" + s + "': expected WxH with each side in [16, 16384] and " +
                             "at most " + std::to_string(kMaxPixels) + " pixels in all";
    const std::size_t x = s.find_first_of("xX");
    if (x == std::string::npos) throw Error(what);
    const auto side = [&](const std::string& part) {
        if (part.empty() || part.size() > 5 ||
            part.find_first_not_of("0123456789") != std::string::npos)
            throw Error(what);
        const unsigned long v = std::stoul(part);
        if (v < 16 || v > 16384) throw Error(what);
        return std::uint32_t(v);
    };
    w = side(s.substr(0, x));
    h = side(s.substr(x + 1));
    if (std::uint64_t(w) * h > kMaxPixels) throw Error(what);
}

double parse_degrees(const std::string& s) {
    char* end = nullptr;
    const double deg = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(deg) || std::fabs(deg) > 3600)
        throw Error("--turn '" + s + "': expected degrees in [-3600, 3600]");
    return deg;
}

// Turns the mesh about the vertical (y) axis through its box centre, in double.
void turn_about_vertical(TriangleMesh& mesh, double degrees) {
    const double a = degrees * 3.14159265358979323846 / 180.0, c = std::cos(a), s = std::sin(a);
    const Vec3f centre = mesh.bounds().centroid();
    for (Vec3f& v : mesh.vertices) {
        const double x = double(v[0]) - centre[0], z = double(v[2]) - centre[2];
        v[0] = float(centre[0] + c * x + s * z);
        v[2] = float(centre[2] - s * x + c * z);
    }
}

// The heat map's scale bar: ticks at round numbers of nodes per ray, labelled.
void draw_scale(Image& image, std::uint32_t scale_top, bool fixed) {
    const std::uint32_t width = image.width, height = image.height;
    const std::uint32_t bar_top = height - 34, bar_bottom = height - 22;
    image.fill(0, bar_top - 4, width, height, {20, 20, 24});
    const std::uint32_t bar_left = 8, bar_width = width - 16;
    for (std::uint32_t x = bar_left; x < bar_left + bar_width; ++x)
        image.fill(x, bar_top, x + 1, bar_bottom, heat_colour(double(x - bar_left) / bar_width));
    const Rgb white{240, 240, 240};
    // A step of 1, 2 or 5 times a power of ten giving at most five intervals.
    std::uint32_t step = 1;
    for (std::uint32_t p = 1; p <= scale_top; p *= 10) {
        if (scale_top / p <= 5) {
            step = p;
            break;
        }
        if (scale_top / (2 * p) <= 5) {
            step = 2 * p;
            break;
        }
        if (scale_top / (5 * p) <= 5) {
            step = 5 * p;
            break;
        }
    }
    for (std::uint32_t v = 0; v <= scale_top; v += step) {
        const std::uint32_t x =
            bar_left + std::uint32_t(std::uint64_t(bar_width - 1) * v / scale_top);
        image.fill(x, bar_bottom, x + 1, bar_bottom + 3, white);
        const std::string label = std::to_string(v);
        const std::uint32_t w = std::uint32_t(label.size()) * 8;
        image.text(std::min(x - std::min(x, w / 2), width - w - 4), height - 16, label, white, 2);
    }
    const std::string unit =
        fixed ? "nodes per ray" : "nodes per ray, top at the 99.5th percentile";
    image.text(bar_left, bar_top - 16, unit, white, 2);
}

}  // namespace

int render_command(int argc, char** argv) {
    const Args args(
        argc, argv,
        {"--out", "--size", "--builder", "--scale", "--turn", "--structure", "--threads"},
        {"--heatmap"});
    if (args.help()) {
        std::fputs(kRenderHelp, stdout);
        return 0;
    }
    if (!args.has("--out")) throw Error("missing --out IMAGE.png (see --help)");
    if (args.positional().size() > 1) throw Error("render takes one mesh (see --help)");
    const std::string spec =
        args.positional().empty() ? "sphere:subdiv=7,displacement=0.25" : args.positional()[0];
    std::uint32_t width = 800, height = 800;
    if (args.has("--size")) parse_size(args.value("--size"), width, height);
    if (args.has("--scale") && !args.flag("--heatmap")) throw Error("--scale goes with --heatmap");
    const auto fixed_scale = std::uint32_t(args.integer("--scale", 0, 1, 1000000));
    const BuildOptions build_options = parse_builder(args.value("--builder", "binned-sah"));
    const std::string structure = args.value("--structure", "bvh");
    if (structure != "bvh" && structure != "bsp")
        throw Error("option --structure: '" + structure + "' is not one of bvh, bsp");
    if (structure == "bsp" && args.has("--builder"))
        throw Error("--builder applies to --structure bvh only");
    const bool use_bsp = structure == "bsp";
    const Executor executor(args.threads());

    TriangleMesh mesh = load_mesh(spec);
    if (args.has("--turn")) turn_about_vertical(mesh, parse_degrees(args.value("--turn")));
    const auto t0 = std::chrono::steady_clock::now();
    TriangleBvh<float> bvh;
    BspTree<double> bsp;
    if (use_bsp)
        bsp = BspTree<double>(mesh);
    else
        bvh = TriangleBvh<float>(mesh, build_options);
    const double build_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const std::vector<Ray3f> rays = camera_rays(mesh.bounds(), width, height);

    Image image(width, height);
    const bool heatmap = args.flag("--heatmap");
    std::vector<std::uint32_t> cost(rays.size());
    const auto t1 = std::chrono::steady_clock::now();
    // Every pixel is its own: chunks of rays on any number of threads make the same picture.
    executor.parallel_for(rays.size(), 1024, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            Hit<float> hit;
            if (use_bsp) {
                BspRayStats stats;
                const Ray<double, 3> ray(Vec<double, 3>(rays[i].origin),
                                         Vec<double, 3>(rays[i].direction), rays[i].tmin,
                                         rays[i].tmax);
                const BspHit<double> h = closest_hit(bsp, ray, &stats);
                if (h) hit.t = float(h.t), hit.primitive = h.source;
                cost[i] = std::uint32_t(stats.nodes_visited);
            } else {
                TraversalStats stats;
                hit = bvh.closest_hit(rays[i], stats);
                cost[i] = std::uint32_t(stats.nodes_visited);
            }
            Rgb& px = image.pixels[i];
            if (!hit) {  // background: a soft vertical gradient
                const double y = double(i / width) / height;
                px = {std::uint8_t(40 + 30 * y), std::uint8_t(44 + 34 * y),
                      std::uint8_t(52 + 40 * y)};
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
    });
    const std::uint32_t max_cost =
        std::max<std::uint32_t>(1, *std::max_element(cost.begin(), cost.end()));
    const double trace_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();

    if (heatmap) {
        // Scale to the 99.5th percentile: a few grazing rays along silhouettes cost far more than
        // the rest and would otherwise leave the whole picture dark.
        std::vector<std::uint32_t> sorted = cost;
        const std::size_t k = sorted.size() * 995 / 1000;
        std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
        const std::uint32_t scale_top =
            fixed_scale ? fixed_scale : std::max<std::uint32_t>(1, sorted[k]);
        for (std::size_t i = 0; i < rays.size(); ++i)
            image.pixels[i] = heat_colour(double(cost[i]) / scale_top);
        draw_scale(image, scale_top, fixed_scale != 0);
    }
    write_png(args.value("--out"), image);

    double mean_cost = 0;
    for (auto c : cost) mean_cost += c;
    mean_cost /= double(cost.size());
    if (use_bsp) {
        const BspStatistics& s = bsp.statistics();
        std::printf(
            "%s: %zu triangles, BSP of %zu nodes, depth %zu, %zu splits, built in %.1f ms\n",
            spec.c_str(), mesh.triangle_count(), s.nodes, s.depth, s.splits, build_ms);
    } else {
        const BvhStatistics s = statistics(bvh.bvh());
        std::printf("%s: %zu triangles, %zu nodes, depth %u, SAH cost %.2f, built in %.1f ms\n",
                    spec.c_str(), mesh.triangle_count(), s.node_count, s.depth, s.sah_cost,
                    build_ms);
    }
    std::printf(
        "traced %zu rays in %.1f ms (%.1f Mrays/s); nodes tested per ray: mean %.1f, max %u\n",
        rays.size(), trace_ms, rays.size() / trace_ms / 1e3, mean_cost, max_cost);
    std::printf("wrote %s (%ux%u, %s)\n", args.value("--out").c_str(), width, height,
                heatmap ? "traversal-cost heat map" : "shaded");
    return 0;
}

}  // namespace bvhkit::tools

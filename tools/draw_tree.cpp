// `bvhkit draw-tree`: builds a 2D DynamicTree from a seeded random scene (or a Battle City-like
// map: brick walls, a few tanks and shells) and writes it as SVG: internal nodes as outlines
// coloured by depth, fat boxes dashed, the proxies' own boxes filled.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "args.hpp"
#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/io/file_access.hpp"
#include "commands.hpp"

namespace bvhkit::tools {

namespace {

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void append(std::string& out, const char* format, ...) {
    std::va_list args;
    va_start(args, format);
    std::va_list again;
    va_copy(again, args);
    const int n = std::vsnprintf(nullptr, 0, format, args);
    va_end(args);
    if (n > 0) {
        const std::size_t at = out.size();
        out.resize(at + std::size_t(n) + 1);
        std::vsnprintf(out.data() + at, std::size_t(n) + 1, format, again);
        out.resize(at + std::size_t(n));
    }
    va_end(again);
}

void draw_tree_usage(std::FILE* out) {
    std::fprintf(
        out,
        "usage: bvhkit draw-tree [--out FILE.svg] [--boxes N] [--seed S] [--scene random|battle]\n"
        "              [--strategy guided|bnb|greedy] [--moves M]\n"
        "  Builds a 2D dynamic tree and writes it as SVG (default tree.svg): internal nodes\n"
        "  coloured by depth, fat boxes dashed, proxy boxes filled. --moves moves every box\n"
        "  M times by a small random step first, so the fat boxes show.\n");
}

/// Battle City-like map on a 26 x 26 grid: brick walls in blocks, the player's base, tanks, shells.
std::vector<Aabb2f> battle_scene(std::mt19937& rng) {
    std::vector<Aabb2f> boxes;
    const auto add = [&](float x, float y, float w, float h) {
        boxes.push_back({{x, y}, {x + w, y + h}});
    };
    for (int bx = 1; bx < 13; bx += 2)  // columns of bricks
        for (int y = 2; y < 20; ++y)
            if ((y + bx) % 7 != 0)
                add(float(bx * 2), float(y), 1, 1), add(float(bx * 2 + 1), float(y), 1, 1);
    for (int x = 11; x < 15; ++x) add(float(x), 22, 1, 1);  // wall around the base
    add(11, 23, 1, 1), add(14, 23, 1, 1);
    add(12, 24, 2, 2);  // the base (eagle)
    std::uniform_real_distribution<float> u(0.0f, 24.0f);
    for (int t = 0; t < 6; ++t) add(u(rng), u(rng), 1.8f, 1.8f);    // tanks
    for (int s = 0; s < 8; ++s) add(u(rng), u(rng), 0.25f, 0.25f);  // shells
    return boxes;
}

}  // namespace

int draw_tree_command(int argc, char** argv) {
    const Args args(argc, argv, {"--out", "--boxes", "--seed", "--moves", "--scene", "--strategy"},
                    {});
    if (args.help()) {
        draw_tree_usage(stdout);
        return 0;
    }
    if (!args.positional().empty())
        throw Error("unexpected argument '" + args.positional()[0] + "'");
    const std::string out = args.value("--out", "tree.svg"),
                      scene = args.value("--scene", "random");
    const long n = long(args.integer("--boxes", 200, 0, 10000000));
    const long moves = long(args.integer("--moves", 0, 0, 10000000));
    const auto seed = unsigned(args.integer("--seed", 1, 0, 4294967295LL));
    if (scene != "random" && scene != "battle")
        throw Error("--scene: '" + scene + "' is not random or battle");
    DynamicTreeOptions<float> options;
    const std::string strategy = args.value("--strategy", "guided");
    if (strategy == "guided")
        options.insertion = InsertionStrategy::Guided;
    else if (strategy == "bnb")
        options.insertion = InsertionStrategy::BranchAndBound;
    else if (strategy == "greedy")
        options.insertion = InsertionStrategy::Greedy;
    else
        throw Error("--strategy: '" + strategy + "' is not guided, bnb or greedy");

    std::mt19937 rng(seed);
    std::vector<Aabb2f> boxes;
    if (scene == "battle") {
        options.margin_absolute = 0.05f;
        boxes = battle_scene(rng);
    } else {
        const float side = 3.0f * std::sqrt(float(std::max(1L, n)));
        std::uniform_real_distribution<float> u(0.0f, side), size(0.3f, 2.0f);
        for (long k = 0; k < n; ++k) {
            const Vec2f p(u(rng), u(rng));
            boxes.push_back({p, p + Vec2f(size(rng), size(rng))});
        }
    }
    DynamicTree<float, 2> tree(options);
    std::vector<ProxyId> ids;
    for (const auto& b : boxes) ids.push_back(tree.create(b));
    std::uniform_real_distribution<float> step(-0.3f, 0.3f);
    for (long m = 0; m < moves; ++m)
        for (std::size_t k = 0; k < ids.size(); ++k) {
            const Vec2f d(step(rng), step(rng));
            boxes[k] = {boxes[k].min + d, boxes[k].max + d};
            tree.move(ids[k], boxes[k], d);
        }
    tree.validate();

    // World to picture: 800 px on the longer side, y up.
    Aabb2f world;
    int max_depth = 0;
    tree.for_each_node([&](const Aabb2f& b, int depth, bool, ProxyId) {
        world.grow(b);
        max_depth = std::max(max_depth, depth);
    });
    const Vec2f e = world.extent();
    const float margin = 10, scale = 800.0f / std::max({e[0], e[1], 1e-6f});
    const float width = e[0] * scale + 2 * margin, height = e[1] * scale + 2 * margin;
    std::string svg;  // written whole at the end, so a failed write leaves no partial picture
    const auto rect = [&](const Aabb2f& b, const char* style) {
        append(svg, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" %s/>\n",
               margin + (b.min[0] - world.min[0]) * scale,
               margin + (world.max[1] - b.max[1]) * scale,
               std::max(0.5f, (b.max[0] - b.min[0]) * scale),
               std::max(0.5f, (b.max[1] - b.min[1]) * scale), style);
    };
    append(svg, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\">\n",
           width, height);
    append(svg, "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n");
    // Internal nodes first (shallow ones under deep ones), then the leaves on top.
    for (int want = 0; want <= max_depth; ++want)
        tree.for_each_node([&](const Aabb2f& b, int depth, bool leaf, ProxyId) {
            if (leaf || depth != want) return;
            char style[160];
            const int hue = int(300.0 * depth / std::max(1, max_depth));
            std::snprintf(style, sizeof style,
                          "fill=\"none\" stroke=\"hsl(%d,80%%,45%%)\" stroke-width=\"%.1f\"", hue,
                          std::max(0.6, 2.5 - 0.15 * depth));
            rect(b, style);
        });
    tree.for_each_node([&](const Aabb2f& b, int, bool leaf, ProxyId id) {
        if (!leaf) return;
        rect(b, "fill=\"none\" stroke=\"#555\" stroke-width=\"0.8\" stroke-dasharray=\"3,2\"");
        rect(tree.box(id),
             "fill=\"#888\" fill-opacity=\"0.45\" stroke=\"#222\" stroke-width=\"0.6\"");
    });
    const auto st = tree.stats();
    append(svg,
           "<text x=\"%.0f\" y=\"%.0f\" font-family=\"sans-serif\" font-size=\"12\">%zu proxies, "
           "height %d, area ratio %.2f</text>\n</svg>\n",
           margin, height - 2, st.proxies, st.height, st.area_ratio);
    file_detail::write_file_bytes_of(out, svg, "output file");
    std::printf("wrote %s: %zu proxies, height %d, SAH cost %.1f, area ratio %.3f\n", out.c_str(),
                st.proxies, st.height, st.sah_cost, st.area_ratio);
    return 0;
}

}  // namespace bvhkit::tools

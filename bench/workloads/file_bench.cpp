#include "file_bench.hpp"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>

#include "bvhkit/io/mapped_triangle_bvh.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "ray_sets.hpp"

namespace bvhkit::bench {
namespace {

// A field of /proc/self/status ("RssAnon", "RssFile") in bytes; nothing off Linux.
std::optional<double> status_bytes(const char* field) {
    std::ifstream in("/proc/self/status");
    const std::string prefix = std::string(field) + ":";
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(prefix, 0) == 0) return std::stod(line.substr(prefix.size())) * 1024;
    return std::nullopt;
}

// What making a tree with `make` (and keeping it while `use` runs) adds to resident memory, in MB:
// {anonymous, file-backed}.
template <class Make, class Use>
std::pair<std::optional<double>, std::optional<double>> growth_mb(Make&& make, Use&& use) {
    const auto anon = status_bytes("RssAnon"), file = status_bytes("RssFile");
    const auto tree = make();
    use(tree);
    const auto anon_after = status_bytes("RssAnon"), file_after = status_bytes("RssFile");
    std::pair<std::optional<double>, std::optional<double>> out;
    if (anon && anon_after) out.first = (*anon_after - *anon) / 1e6;
    if (file && file_after) out.second = (*file_after - *file) / 1e6;
    return out;
}

std::size_t trace_all(const auto& tree, const std::vector<Ray3f>& rays) {
    std::size_t hits = 0;
    for (const Ray3f& r : rays) hits += bool(tree.closest_hit(r));
    return hits;
}

}  // namespace

std::vector<Row> run_file_bench(const FileBenchOptions& options, std::FILE* progress) {
    std::vector<Row> rows;
    const auto dir = std::filesystem::temp_directory_path();
    for (const std::string& arg : options.meshes) {
        if (progress) std::fprintf(progress, "files: %s\n", arg.c_str());
        const TriangleMesh mesh = load_mesh(arg);
        const auto path =
            dir /
            ("bvhkit_file_bench_" +
             std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".bvh");
        const std::string name = arg.substr(arg.find_last_of('/') + 1);
        const int reps = options.repetitions;
        const auto row = [&](const char* op, double ms) -> Row& {
            rows.emplace_back();
            return rows.back()
                .set("mesh", name)
                .set("triangles", (long long)mesh.triangle_count())
                .set("operation", op)
                .set("ms", ms);
        };
        const auto memory = [](Row& r, std::pair<std::optional<double>, std::optional<double>> g) {
            if (g.first) r.set("anon_mb", *g.first);
            if (g.second) r.set("file_mb", *g.second);
        };

        std::optional<TriangleBvh<float>> tree;
        row("build", median_ms(
                         reps, [&] { tree.emplace(mesh); }, false));
        row("save", median_ms(reps, [&] { save(*tree, path); }));
        const double file_mb = double(std::filesystem::file_size(path)) / 1e6;
        rows.back().set("size_mb", file_mb);
        const auto rays = random_rays(mesh.bounds(), options.random_rays, 2);
        const auto use = [&](const auto& t) { (void)trace_all(t, rays); };

        // Memory first, each in turn with nothing else of its kind alive.
        const auto map_growth = growth_mb([&] { return map_triangle_bvh<float>(path); }, use);
        const auto load_growth = growth_mb([&] { return load_triangle_bvh<float>(path); }, use);
        const auto [load_ms, map_ms] = median_ms_interleaved(
            reps, [&] { (void)load_triangle_bvh<float>(path); },
            [&] { (void)map_triangle_bvh<float>(path); });
        memory(row("load", load_ms), load_growth);
        memory(row("map", map_ms), map_growth);
        const LoadOptions trusted{.validate = false};
        const auto [load_fast, map_fast] = median_ms_interleaved(
            reps, [&] { (void)load_triangle_bvh<float>(path, trusted); },
            [&] { (void)map_triangle_bvh<float>(path, trusted); });
        row("load-novalidate", load_fast);
        row("map-novalidate", map_fast);

        // R2 through the mapped tree, the same tree in memory walked binary, and the default.
        const auto mapped = map_triangle_bvh<float>(path);
        TriangleBvhOptions binary_options;
        binary_options.ray_layout = RayLayout::Binary;
        const TriangleBvh<float> binary(mesh, binary_options);
        std::size_t hits[3] = {};
        const auto r2 = median_ms_interleaved(reps, {[&] { hits[0] = trace_all(mapped, rays); },
                                                     [&] { hits[1] = trace_all(binary, rays); },
                                                     [&] { hits[2] = trace_all(*tree, rays); }});
        const char* names[] = {"R2-mapped", "R2-memory-binary", "R2-memory-default"};
        for (int i = 0; i < 3; ++i)
            row(names[i], r2[i]).set("hits", (long long)hits[i]).set("ms_vs_mapped", r2[i] / r2[0]);
        std::filesystem::remove(path);
    }
    return rows;
}

}  // namespace bvhkit::bench

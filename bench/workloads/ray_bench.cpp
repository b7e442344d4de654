#include "ray_bench.hpp"

#include "bvhkit/build/options.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/ray_sets.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "embree_scene.hpp"

namespace bvhkit::bench {

bool have_embree() {
#if BVHKIT_HAVE_EMBREE
    return true;
#else
    return false;
#endif
}

namespace {

std::string mesh_name(const std::string& arg) {
    const auto slash = arg.find_last_of('/');
    return slash == std::string::npos ? arg : arg.substr(slash + 1);
}

struct Workload {
    const char* name;
    const std::vector<Ray3f>* rays;
    bool occlusion;
};

}  // namespace

std::vector<Row> run_ray_bench(const RayBenchOptions& options, std::FILE* progress) {
    std::vector<Row> rows;
    BuildOptions build_options = parse_builder(options.builder);
    build_options.threads =
        1;  // single thread, as Embree is run here (the workload compares one thread each)
    for (const std::string& arg : options.meshes) {
        const TriangleMesh mesh = load_mesh(arg);
        const std::string name = mesh_name(arg);
        if (progress)
            std::fprintf(progress, "%s: %zu triangles\n", name.c_str(), mesh.triangle_count());
        const auto row_for = [&](const char* workload, const char* library) {
            Row r;
            r.set("workload", workload).set("mesh", name);
            r.set("triangles", (long long)mesh.triangle_count()).set("library", library);
            return r;
        };
        const Aabb3f bounds = mesh.bounds();
        const std::vector<Ray3f> r1 = camera_rays(bounds, options.camera_size, options.camera_size);
        const std::vector<Ray3f> r2 = random_rays(bounds, options.random_rays, 1);

        // Build: from a mesh in memory to a tree ready to trace, for both libraries. bvhkit's
        // default traces the four-wide layout; the binary layout is measured beside it.
        TriangleBvh<float> ours, binary;
        TriangleBvhOptions binary_options(build_options);
        binary_options.ray_layout = RayLayout::Binary;
        const auto build_ours = [&] { ours = TriangleBvh<float>(mesh, build_options); };
        const auto build_binary = [&] { binary = TriangleBvh<float>(mesh, binary_options); };
#if BVHKIT_HAVE_EMBREE
        EmbreeScene embree(mesh, 1);
        const std::vector<double> build_ms = median_ms_interleaved(
            options.repetitions, {build_ours, build_binary, [&] { embree.build(mesh); }});
#else
        const std::vector<double> build_ms =
            median_ms_interleaved(options.repetitions, {build_ours, build_binary});
#endif
        for (int layout = 0; layout < 2; ++layout) {
            Row row = row_for("build", layout == 0 ? "bvhkit" : "bvhkit-binary");
            row.set("ms", build_ms[layout]).set("sah_cost", statistics(ours.bvh()).sah_cost);
            if (build_ms.size() == 3) row.set("speedup", build_ms[2] / build_ms[layout]);
            rows.push_back(row);
        }
        if (build_ms.size() == 3)
            rows.push_back(row_for("build", "embree3").set("ms", build_ms[2]));

        for (const Workload& w :
             {Workload{"R1", &r1, false}, Workload{"R2", &r2, false}, Workload{"R3", &r2, true}}) {
            if (progress) std::fprintf(progress, "  %s ...\n", w.name);
            std::size_t hits[3] = {};
            // In its own file: see ray_timed_calls.cpp.
            std::vector<std::function<void()>> runs{
                [&] { hits[0] = trace_rays(ours, *w.rays, w.occlusion); },
                [&] { hits[1] = trace_rays(binary, *w.rays, w.occlusion); }};
#if BVHKIT_HAVE_EMBREE
            runs.push_back([&] {
                hits[2] = 0;
                for (const auto& r : *w.rays)
                    hits[2] += w.occlusion ? embree.any_hit(r) : bool(embree.closest_hit(r));
            });
#endif
            const std::vector<double> ms = median_ms_interleaved(options.repetitions, runs);
            const double n = double(w.rays->size());
            for (int layout = 0; layout < 2; ++layout) {
                // Tree quality per ray, counted in a separate untimed pass.
                const TriangleBvh<float>& tree = layout == 0 ? ours : binary;
                TraversalStats traversal;
                for (const auto& r : *w.rays) {
                    if (w.occlusion)
                        tree.any_hit(r, traversal);
                    else
                        tree.closest_hit(r, traversal);
                }
                Row row = row_for(w.name, layout == 0 ? "bvhkit" : "bvhkit-binary");
                row.set("rays", (long long)w.rays->size()).set("hits", (long long)hits[layout]);
                row.set("ms", ms[layout]).set("mrays_per_s", n / ms[layout] / 1e3);
                row.set("nodes_per_ray", double(traversal.nodes_visited) / n);
                row.set("tris_per_ray", double(traversal.primitives_tested) / n);
                if (ms.size() == 3) row.set("speedup", ms[2] / ms[layout]);
                rows.push_back(row);
            }
            if (ms.size() == 3) {
                Row peer = row_for(w.name, "embree3");
                peer.set("rays", (long long)w.rays->size()).set("hits", (long long)hits[2]);
                peer.set("ms", ms[2]).set("mrays_per_s", n / ms[2] / 1e3);
                rows.push_back(peer);
            }
        }
    }
    return rows;
}

}  // namespace bvhkit::bench

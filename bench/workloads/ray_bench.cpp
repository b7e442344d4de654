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

        // Build: from a mesh in memory to a tree ready to trace, for both libraries.
        TriangleBvh<float> ours;
        const auto build_ours = [&] { ours = TriangleBvh<float>(mesh, build_options); };
#if BVHKIT_HAVE_EMBREE
        EmbreeScene embree(mesh, 1);
        const auto [our_build, peer_build] =
            median_ms_interleaved(options.repetitions, build_ours, [&] { embree.build(mesh); });
#else
        const double our_build = median_ms(options.repetitions, build_ours);
#endif
        Row build_row = row_for("build", "bvhkit");
        build_row.set("ms", our_build).set("sah_cost", statistics(ours.bvh()).sah_cost);
#if BVHKIT_HAVE_EMBREE
        build_row.set("speedup", peer_build / our_build);
        rows.push_back(build_row);
        rows.push_back(row_for("build", "embree3").set("ms", peer_build));
#else
        rows.push_back(build_row);
#endif

        for (const Workload& w :
             {Workload{"R1", &r1, false}, Workload{"R2", &r2, false}, Workload{"R3", &r2, true}}) {
            if (progress) std::fprintf(progress, "  %s ...\n", w.name);
            std::size_t our_hits = 0;
            // In its own file: see ray_timed_calls.cpp.
            const auto trace_ours = [&] { our_hits = trace_rays(ours, *w.rays, w.occlusion); };
#if BVHKIT_HAVE_EMBREE
            std::size_t peer_hits = 0;
            const auto trace_peer = [&] {
                peer_hits = 0;
                for (const auto& r : *w.rays)
                    peer_hits += w.occlusion ? embree.any_hit(r) : bool(embree.closest_hit(r));
            };
            const auto [our_ms, peer_ms] =
                median_ms_interleaved(options.repetitions, trace_ours, trace_peer);
#else
            const double our_ms = median_ms(options.repetitions, trace_ours);
#endif
            // Tree quality per ray, counted in a separate untimed pass.
            TraversalStats traversal;
            for (const auto& r : *w.rays) {
                if (w.occlusion)
                    ours.any_hit(r, traversal);
                else
                    ours.closest_hit(r, traversal);
            }
            const double n = double(w.rays->size());
            Row row = row_for(w.name, "bvhkit");
            row.set("rays", (long long)w.rays->size()).set("hits", (long long)our_hits);
            row.set("ms", our_ms).set("mrays_per_s", n / our_ms / 1e3);
            row.set("nodes_per_ray", double(traversal.nodes_visited) / n);
            row.set("tris_per_ray", double(traversal.primitives_tested) / n);
#if BVHKIT_HAVE_EMBREE
            row.set("speedup", peer_ms / our_ms);
            rows.push_back(row);
            Row peer = row_for(w.name, "embree3");
            peer.set("rays", (long long)w.rays->size()).set("hits", (long long)peer_hits);
            peer.set("ms", peer_ms).set("mrays_per_s", n / peer_ms / 1e3);
            rows.push_back(peer);
#else
            rows.push_back(row);
#endif
        }
    }
    return rows;
}

}  // namespace bvhkit::bench

#include "ray_bench.hpp"

#include <cmath>

#include "bvhkit/build/options.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/ray_sets.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "embree_scene.hpp"

namespace bvhkit::bench {

bool have_embree() {
    return BVHKIT_HAVE_EMBREE + 0 != 0;
}

namespace {

std::string mesh_name(const std::string& arg) {
    const auto slash = arg.find_last_of('/');
    return slash == std::string::npos ? arg : arg.substr(slash + 1);
}

struct Timed {
    double ms;
    std::size_t hits;
};

template <class Trace>
Timed time_rays(int reps, const std::vector<Ray3f>& rays, Trace&& trace) {
    std::size_t hits = 0;
    const double ms = median_ms(reps, [&] {
        hits = 0;
        for (const auto& r : rays) hits += trace(r);
    });
    return {ms, hits};
}

}  // namespace

std::vector<Row> run_ray_bench(const RayBenchOptions& options, std::FILE* progress) {
    std::vector<Row> rows;
    const BuildOptions build_options = parse_builder(options.builder);
    for (const std::string& arg : options.meshes) {
        const TriangleMesh mesh = load_mesh(arg);
        const std::string name = mesh_name(arg);
        if (progress)
            std::fprintf(progress, "%s: %zu triangles\n", name.c_str(), mesh.triangle_count());
        const auto base = [&](const char* workload, const char* library) {
            Row r;
            r.set("workload", workload)
                .set("mesh", name)
                .set("triangles", (long long)mesh.triangle_count());
            r.set("library", library);
            return r;
        };
        const Aabb3f bounds = mesh.bounds();
        const std::vector<Ray3f> r1 = camera_rays(bounds, options.camera_size, options.camera_size);
        const std::vector<Ray3f> r2 = random_rays(bounds, options.random_rays, 1);

        // Build.
        TriangleBvh<float> ours;
        const double our_build =
            median_ms(options.repetitions, [&] { ours = TriangleBvh<float>(mesh, build_options); });
        const BvhStatistics stats = statistics(ours.bvh());
        Row build_row = base("build", "bvhkit");
        build_row.set("ms", our_build).set("sah_cost", stats.sah_cost);
#if BVHKIT_HAVE_EMBREE
        EmbreeScene embree(mesh, 1);
        const double embree_build = median_ms(
            options.repetitions, [&] { embree.build(mesh); }, false);
        build_row.set("speedup", embree_build / our_build);
        rows.push_back(build_row);
        rows.push_back(base("build", "embree3").set("ms", embree_build));
#else
        rows.push_back(build_row);
#endif

        struct Workload {
            const char* name;
            const std::vector<Ray3f>* rays;
            bool occlusion;
        };
        for (const Workload& w :
             {Workload{"R1", &r1, false}, Workload{"R2", &r2, false}, Workload{"R3", &r2, true}}) {
            if (progress) std::fprintf(progress, "  %s ...\n", w.name);
            const Timed our =
                w.occlusion ? time_rays(options.repetitions, *w.rays,
                                        [&](const Ray3f& r) { return ours.any_hit(r); })
                            : time_rays(options.repetitions, *w.rays,
                                        [&](const Ray3f& r) { return bool(ours.closest_hit(r)); });
            TraversalStats traversal;
            for (const auto& r : *w.rays) {
                if (w.occlusion)
                    ours.any_hit(r, traversal);
                else
                    ours.closest_hit(r, traversal);
            }
            const double n = double(w.rays->size());
            Row row = base(w.name, "bvhkit");
            row.set("rays", (long long)w.rays->size()).set("hits", (long long)our.hits);
            row.set("ms", our.ms).set("mrays_per_s", n / our.ms / 1e3);
            row.set("nodes_per_ray", traversal.nodes_visited / n);
            row.set("tris_per_ray", traversal.primitives_tested / n);
#if BVHKIT_HAVE_EMBREE
            const Timed peer = w.occlusion
                                   ? time_rays(options.repetitions, *w.rays,
                                               [&](const Ray3f& r) { return embree.any_hit(r); })
                                   : time_rays(options.repetitions, *w.rays, [&](const Ray3f& r) {
                                         return bool(embree.closest_hit(r));
                                     });
            row.set("speedup", peer.ms / our.ms);
            rows.push_back(row);
            Row prow = base(w.name, "embree3");
            prow.set("rays", (long long)w.rays->size()).set("hits", (long long)peer.hits);
            prow.set("ms", peer.ms).set("mrays_per_s", n / peer.ms / 1e3);
            rows.push_back(prow);
#else
            rows.push_back(row);
#endif
        }
    }
    return rows;
}

}  // namespace bvhkit::bench

#include "ray_bench.hpp"

#include <functional>
#include <memory>

#include "bvhkit/build/options.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "embree_scene.hpp"
#include "ray_sets.hpp"

namespace bvhkit::bench {

bool have_embree() {
#if BVHKIT_HAVE_EMBREE
    return true;
#else
    return false;
#endif
}

namespace {

struct Workload {
    const char* name;
    const std::vector<Ray3f>* rays;
    bool occlusion;
};

/// A peer's answer for one ray (hit or occluded); empty without a peer.
using PeerRay = std::function<bool(const Ray3f&, bool occlusion)>;
/// The peer's own batch call on a chunk: found[i] = whether rays[i] hits.
using PeerStream = std::function<void(std::span<const Ray3f>, bool occlusion, std::uint8_t*)>;

/// The time of the row made before for `workload` on the mesh and library of `like`; 0 if none.
double earlier_ms(const std::vector<Row>& rows, const Row& like, const std::string& workload) {
    for (auto r = rows.rbegin(); r != rows.rend(); ++r) {
        const Value* w = r->get("workload");
        const Value* ms = r->get("ms");
        if (w && ms && *w == Value(workload) && *r->get("mesh") == *like.get("mesh") &&
            *r->get("library") == *like.get("library"))
            return std::get<double>(*ms);
    }
    return 0;
}

/// R2-mt and R3-mt: the batch API (trace, occluded) on every core against the peer's one-ray calls
/// (Embree's rtcIntersect1 and rtcOccluded1) made from the same chunks on every core, and against
/// its stream calls (rtcIntersect1M and rtcOccluded1M, flagged incoherent) on those chunks. The
/// speedup is over the faster of the two. The rows name the tree `library`; the peers' own rows
/// only with `peer_rows`.
template <class RowFor>
void add_batch_rows(std::vector<Row>& rows, const TriangleBvh<float>& tree, const char* library,
                    bool peer_rows, const std::vector<Ray3f>& rays, RowFor&& row_for,
                    int repetitions, const PeerRay& peer, const PeerStream& peer_stream) {
    const Executor every_core(0);
    for (const Workload& w : {Workload{"R2-mt", &rays, false}, Workload{"R3-mt", &rays, true}}) {
        std::vector<Hit<float>> hits(rays.size());
        std::vector<std::uint8_t> flags(rays.size()), peer_flags(rays.size()),
            stream_flags(rays.size());
        std::vector<std::function<void()>> runs{[&] {
            if (w.occlusion)
                tree.occluded(rays, flags, every_core);
            else
                tree.trace(rays, hits, every_core);
        }};
        if (peer)
            runs.push_back([&] {
                every_core.parallel_for(rays.size(), TriangleBvh<float>::batch_grain,
                                        [&](std::size_t b, std::size_t e) {
                                            for (std::size_t i = b; i < e; ++i)
                                                peer_flags[i] = peer(rays[i], w.occlusion);
                                        });
            });
        if (peer_stream)
            runs.push_back([&] {
                every_core.parallel_for(rays.size(), TriangleBvh<float>::batch_grain,
                                        [&](std::size_t b, std::size_t e) {
                                            peer_stream(std::span(rays).subspan(b, e - b),
                                                        w.occlusion, stream_flags.data() + b);
                                        });
            });
        const std::vector<double> ms = median_ms_interleaved(repetitions, runs);
        long long found = 0, peer_found = 0, stream_found = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            found += w.occlusion ? flags[i] : bool(hits[i]);
            peer_found += peer_flags[i];
            stream_found += stream_flags[i];
        }
        const double n = double(rays.size());
        const long long threads = have_parallel() ? (long long)hardware_threads() : 1;
        // scaling: the library's one-thread time for the same rays (row R2 or R3) over this one.
        const std::string one_thread = std::string(w.name).substr(0, 2);
        Row row = row_for(w.name, library);
        row.set("rays", (long long)rays.size()).set("hits", found).set("threads", threads);
        row.set("ms", ms[0]).set("mrays_per_s", n / ms[0] / 1e3);
        if (peer) row.set("speedup", (peer_stream ? std::min(ms[1], ms[2]) : ms[1]) / ms[0]);
        if (const double t = earlier_ms(rows, row, one_thread); t > 0)
            row.set("scaling", t / ms[0]);
        rows.push_back(row);
        if (peer && peer_rows) {
            Row p = row_for(w.name, "embree3");
            p.set("rays", (long long)rays.size()).set("hits", peer_found).set("threads", threads);
            p.set("ms", ms[1]).set("mrays_per_s", n / ms[1] / 1e3);
            if (const double t = earlier_ms(rows, p, one_thread); t > 0)
                p.set("scaling", t / ms[1]);
            rows.push_back(p);
        }
        if (peer_stream && peer_rows) {
            Row p = row_for(w.name, "embree3-1M");
            p.set("rays", (long long)rays.size()).set("hits", stream_found).set("threads", threads);
            p.set("ms", ms[2]).set("mrays_per_s", n / ms[2] / 1e3);
            if (const double t = earlier_ms(rows, row_for(w.name, "embree3"), one_thread); t > 0)
                p.set("scaling", t / ms[2]);
            rows.push_back(p);
        }
    }
}

}  // namespace

std::vector<Row> run_ray_bench(const RayBenchOptions& options, std::FILE* progress) {
    std::vector<Row> rows;
    BuildOptions build_options = parse_builder(options.builder);
    build_options.threads =
        1;  // single thread, as Embree is run here (the workload compares one thread each)
    for (const std::string& arg : options.meshes) {
        const TriangleMesh mesh = load_mesh(arg);
        const std::string name = mesh_label(arg);
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
        // default traces the widest layout the CPU runs; the others are measured beside it.
        struct Layout {
            const char* name;
            RayLayout layout;
            bool spatial_splits = false;
            bool auto_spatial_splits = false;
        };
        // bvhkit-auto: spatial splits where the tree's overlap says they pay (the same tree as
        // bvhkit's elsewhere), against Embree's default build.
        std::vector<Layout> layouts{{"bvhkit", RayLayout::Auto},
                                    {"bvhkit-auto", RayLayout::Auto, false, true}};
        if (cpu_has_avx2()) layouts.push_back({"bvhkit-wide4", RayLayout::Wide4});
        layouts.push_back({"bvhkit-binary", RayLayout::Binary});
        if (options.high_quality) layouts.push_back({"bvhkit-sbvh", RayLayout::Auto, true});
        std::vector<TriangleBvh<float>> trees(layouts.size());
        std::vector<std::function<void()>> builds;
        for (std::size_t i = 0; i < layouts.size(); ++i)
            builds.push_back([&, i] {
                TriangleBvhOptions o(build_options);
                o.ray_layout = layouts[i].layout;
                o.spatial_splits = layouts[i].spatial_splits;
                o.auto_spatial_splits = layouts[i].auto_spatial_splits;
                trees[i] = TriangleBvh<float>(mesh, o);
            });
        // The peers: Embree's medium build, and its high-quality build (spatial splits) beside
        // bvhkit's. A bvhkit row's speedup is over its counterpart: embree3-high for bvhkit-sbvh,
        // embree3 for the others.
        std::vector<const char*> peer_names;
#if BVHKIT_HAVE_EMBREE
        // On one thread. Embree 3 limits a device's threads with a process-wide oneTBB
        // global_control, which holds bvhkit's batch calls to one thread too while the device
        // lives: these are released before the batch rows, which make their own.
        std::vector<std::unique_ptr<EmbreeScene>> embree;
        embree.push_back(std::make_unique<EmbreeScene>(mesh, 1));
        peer_names.push_back("embree3");
        if (options.high_quality) {
            embree.push_back(std::make_unique<EmbreeScene>(mesh, 1, true));
            peer_names.push_back("embree3-high");
        }
        for (auto& scene : embree) builds.push_back([&] { scene->build(mesh); });
#endif
        // Index in the timings of layout i's peer, if any.
        const auto peer_of = [&](std::size_t i) {
            return layouts.size() + (layouts[i].spatial_splits && peer_names.size() > 1 ? 1 : 0);
        };
        const bool peer = !peer_names.empty();
        const std::vector<double> build_ms = median_ms_interleaved(options.repetitions, builds);
        for (std::size_t i = 0; i < layouts.size(); ++i) {
            Row row = row_for("build", layouts[i].name);
            row.set("ms", build_ms[i]).set("sah_cost", statistics(trees[i].bvh()).sah_cost);
            if (peer) row.set("speedup", build_ms[peer_of(i)] / build_ms[i]);
            rows.push_back(row);
        }
        for (std::size_t p = 0; p < peer_names.size(); ++p)
            rows.push_back(row_for("build", peer_names[p]).set("ms", build_ms[layouts.size() + p]));

        for (const Workload& w :
             {Workload{"R1", &r1, false}, Workload{"R2", &r2, false}, Workload{"R3", &r2, true}}) {
            if (progress) std::fprintf(progress, "  %s ...\n", w.name);
            std::vector<std::size_t> hits(layouts.size() + peer_names.size(), 0);
            // In its own file: see ray_timed_calls.cpp.
            std::vector<std::function<void()>> runs;
            for (std::size_t i = 0; i < layouts.size(); ++i)
                runs.push_back([&, i] { hits[i] = trace_rays(trees[i], *w.rays, w.occlusion); });
#if BVHKIT_HAVE_EMBREE
            for (std::size_t p = 0; p < embree.size(); ++p)
                runs.push_back([&, p] {
                    std::size_t& n = hits[layouts.size() + p];
                    n = 0;
                    const EmbreeScene& scene = *embree[p];
                    for (const auto& r : *w.rays)
                        n += w.occlusion ? scene.any_hit(r) : bool(scene.closest_hit(r));
                });
#endif
            const std::vector<double> ms = median_ms_interleaved(options.repetitions, runs);
            const double n = double(w.rays->size());
            for (std::size_t i = 0; i < layouts.size(); ++i) {
                // Tree quality per ray, counted in a separate untimed pass.
                TraversalStats traversal;
                for (const auto& r : *w.rays) {
                    if (w.occlusion)
                        trees[i].any_hit(r, traversal);
                    else
                        trees[i].closest_hit(r, traversal);
                }
                Row row = row_for(w.name, layouts[i].name);
                row.set("rays", (long long)w.rays->size()).set("hits", (long long)hits[i]);
                row.set("ms", ms[i]).set("mrays_per_s", n / ms[i] / 1e3);
                row.set("nodes_per_ray", double(traversal.nodes_visited) / n);
                row.set("tris_per_ray", double(traversal.primitives_tested) / n);
                if (peer) row.set("speedup", ms[peer_of(i)] / ms[i]);
                rows.push_back(row);
            }
            for (std::size_t p = 0; p < peer_names.size(); ++p) {
                const std::size_t k = layouts.size() + p;
                Row row = row_for(w.name, peer_names[p]);
                row.set("rays", (long long)w.rays->size()).set("hits", (long long)hits[k]);
                row.set("ms", ms[k]).set("mrays_per_s", n / ms[k] / 1e3);
                rows.push_back(row);
            }
        }
        PeerRay peer_ray;
        PeerStream peer_stream;
#if BVHKIT_HAVE_EMBREE
        embree.clear();
        const EmbreeScene embree_all(mesh, 0);
        peer_ray = [&embree_all](const Ray3f& r, bool occlusion) {
            return occlusion ? embree_all.any_hit(r) : bool(embree_all.closest_hit(r));
        };
        peer_stream = [&embree_all](std::span<const Ray3f> chunk, bool occlusion,
                                    std::uint8_t* found) {
            embree_all.stream_hits(chunk, occlusion, found);
        };
#endif
        add_batch_rows(rows, trees[0], "bvhkit", true, r2, row_for, options.repetitions, peer_ray,
                       peer_stream);
        // The automatic choice's batch rows, where it chose spatial splits (else its tree is
        // bvhkit's).
        if (trees[1].has_split_references())
            add_batch_rows(rows, trees[1], "bvhkit-auto", false, r2, row_for, options.repetitions,
                           peer_ray, peer_stream);
    }
    return rows;
}

}  // namespace bvhkit::bench

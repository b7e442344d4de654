#include "instance_bench.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>

#include "bvhkit/error.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/scene/rays.hpp"
#include "embree_instances.hpp"
#include "ray_sets.hpp"

namespace bvhkit::bench {

std::vector<Transform<float>> crowd_poses(const Aabb3f& bounds, std::size_t count, double density,
                                          std::uint64_t seed) {
    SplitMix64 rng(seed);
    const Vec3d lo(bounds.min), hi(bounds.max);
    const Vec3d c = (lo + hi) * 0.5;
    const double radius = 0.5 * length(hi - lo);
    const double sphere = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
    const double side = std::cbrt(double(count) * sphere / density);
    std::vector<Transform<float>> poses;
    poses.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        // Shoemake, "Uniform random rotations" (1992): a unit quaternion from three uniforms.
        const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
        const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
        const double t1 = 2 * std::numbers::pi * u2, t2 = 2 * std::numbers::pi * u3;
        const Mat3<double> r = rotation_from_quaternion(b * std::cos(t2), a * std::sin(t1),
                                                        a * std::cos(t1), b * std::sin(t2));
        const Vec3d p{rng.uniform(-0.5, 0.5) * side, rng.uniform(-0.5, 0.5) * side,
                      rng.uniform(-0.5, 0.5) * side};
        poses.push_back(Transform<float>(Transform<double>{r, p - r * c}));
    }
    return poses;
}

namespace {

struct Workload {
    const char* name;
    const std::vector<Ray3f>* rays;
    bool occlusion;
};

/// The scene as a user builds it for rays: the mesh added (its hull computed), the instances
/// placed, the rays' bottom-level tree built.
std::unique_ptr<Scene<float>> build_scene(const TriangleMesh& mesh,
                                          std::span<const Transform<float>> poses) {
    auto scene = std::make_unique<Scene<float>>();
    const GeometryId g = scene->add_mesh(mesh);
    for (const Transform<float>& p : poses) scene->add_instance(g, p);
    (void)scene->geometry(g).ray_tree();
    return scene;
}

#if BVHKIT_HAVE_EMBREE
/// The nearest hit of the ray on the mesh placed by `pose`, by brute force in double over every
/// triangle (Moller and Trumbore, "Fast, minimum storage ray/triangle intersection", 1997): the
/// referee for the rays on which the two libraries disagree. Shares no arithmetic with either (the
/// corners are placed in double, where R v + t of float inputs is exact to a few units of 1e-16).
double reference_t(const TriangleMesh& mesh, const Transform<float>& pose, const Ray3f& ray) {
    const Transform<double> p(pose);
    const Vec3d o(ray.origin), d(ray.direction);
    double best = std::numeric_limits<double>::infinity();
    for (const auto& tri : mesh.triangles) {
        const Vec3d a = p.apply(Vec3d(mesh.vertices[tri[0]]));
        const Vec3d e1 = p.apply(Vec3d(mesh.vertices[tri[1]])) - a;
        const Vec3d e2 = p.apply(Vec3d(mesh.vertices[tri[2]])) - a;
        const Vec3d q = cross(d, e2);
        const double det = dot(e1, q);
        if (det == 0) continue;
        const Vec3d s = o - a;
        const double u = dot(s, q) / det;
        if (u < 0 || u > 1) continue;
        const Vec3d r = cross(s, e1);
        const double v = dot(d, r) / det;
        if (v < 0 || u + v > 1) continue;
        const double t = dot(e2, r) / det;
        if (t >= double(ray.tmin) && t <= double(ray.tmax) && t < best) best = t;
    }
    return best;
}

/// Rays whose answers differ, and who was right by the double-precision referee over the
/// instances either library reported (or, for any hit, either library's closest hit reported).
/// A tie: two instances hit at the same t (within the tolerance), where overlapping instances'
/// surfaces cross; either answer is right.
struct Agreement {
    long long disagree = 0, ties = 0, bvhkit_right = 0, embree_right = 0;
};

Agreement compare(const Scene<float>& scene, const TriangleMesh& mesh,
                  std::span<const Transform<float>> poses, const EmbreeInstances& embree,
                  std::span<const Ray3f> rays, bool occlusion) {
    // t agrees within a relative 1e-4, or within 1e-6 of the crowd's size: a ray starting next to
    // a surface has a tiny t, and both libraries round the origin moved into the instance's frame,
    // a difference of float's spacing at the crowd's coordinates.
    const Aabb3f bounds = scene.bounds();
    const double slack = 1e-6 * double(length(bounds.max - bounds.min));
    const auto close = [&](double x, double y) {
        return std::abs(x - y) <= 1e-4 * std::max(x, y) + slack;
    };
    Agreement out;
    for (const Ray3f& r : rays) {
        const SceneHit<float> a = closest_hit(scene, r);
        const EmbreeInstances::Result b = embree.closest_hit(r);
        const long long ia = a ? a.instance.index() : -1, ib = b ? (long long)b.instance : -1;
        if (occlusion) {
            if (any_hit(scene, r) == embree.any_hit(r)) continue;
        } else if (ia == ib && (!a || close(a.t, b.t))) {
            continue;
        }
        ++out.disagree;
        if (ia >= 0 && ib >= 0 && ia != ib && close(a.t, b.t)) {
            ++out.ties;
            continue;
        }
        // The referee's nearest hit over the reported instances.
        long long ir = -1;
        double tr = std::numeric_limits<double>::infinity();
        for (const long long i : {ia, ib})
            if (i >= 0)
                if (const double t = reference_t(mesh, poses[std::size_t(i)], r); t < tr)
                    tr = t, ir = i;
        if (occlusion) {
            const bool hit = ir >= 0;
            out.bvhkit_right += any_hit(scene, r) == hit;
            out.embree_right += embree.any_hit(r) == hit;
            continue;
        }
        const auto right = [&](long long i, double t) {
            return i == ir && (i < 0 || close(t, tr));
        };
        out.bvhkit_right += right(ia, a.t);
        out.embree_right += right(ib, b.t);
    }
    return out;
}
#endif

}  // namespace

std::vector<Row> run_instance_bench(const InstanceBenchOptions& options, std::FILE* progress) {
    std::vector<Row> rows;
    const TriangleMesh mesh = load_mesh(options.mesh);
    const std::string name = mesh_label(options.mesh);
    for (const std::size_t count : options.counts) {
        if (progress)
            std::fprintf(progress, "%zu instances of %s (%zu triangles)\n", count, name.c_str(),
                         mesh.triangle_count());
        const std::vector<Transform<float>> asked =
            crowd_poses(mesh.bounds(), count, options.density, options.seed);
        std::unique_ptr<Scene<float>> scene = build_scene(mesh, asked);
        // Embree gets the poses the scene stored (the rotation replaced by the nearest one), so
        // both libraries place the instances alike. Slot i is pose i in a fresh scene.
        std::vector<Transform<float>> poses;
        scene->for_each_instance([&](InstanceId id) {
            if (std::size_t(id.index()) != poses.size())
                throw Error("bench instances: instance slots are not the poses' order");
            poses.push_back(scene->pose(id));
        });
        const auto row_for = [&](const char* workload, const char* library) {
            Row r;
            r.set("workload", workload).set("mesh", name).set("instances", (long long)count);
            r.set("library", library);
            return r;
        };
        const Aabb3f bounds = scene->bounds();
        const std::vector<Ray3f> r1 = camera_rays(bounds, options.camera_size, options.camera_size);
        const std::vector<Ray3f> r2 = random_rays(bounds, options.random_rays, options.seed);

        std::vector<std::function<void()>> builds{[&] { scene = build_scene(mesh, asked); }};
#if BVHKIT_HAVE_EMBREE
        EmbreeInstances embree(mesh, poses, 1);
        builds.push_back([&] { embree.build(mesh, poses); });
#endif
        const bool peer = builds.size() > 1;
        const std::vector<double> build_ms = median_ms_interleaved(options.repetitions, builds);
        {
            Row row = row_for("build", "bvhkit");
            row.set("ms", build_ms[0]);
            if (peer) row.set("speedup", build_ms[1] / build_ms[0]);
            rows.push_back(row);
            if (peer) rows.push_back(row_for("build", "embree3").set("ms", build_ms[1]));
        }

        for (const Workload& w :
             {Workload{"S3-R1", &r1, false}, Workload{"S3-R1-any", &r1, true},
              Workload{"S3-R2", &r2, false}, Workload{"S3-R2-any", &r2, true}}) {
            if (progress) std::fprintf(progress, "  %s ...\n", w.name);
            std::size_t hits[3] = {0, 0, 0};
            std::vector<SceneHit<float>> batch_hits(w.occlusion ? 0 : w.rays->size());
            std::vector<std::uint8_t> flags(w.occlusion ? w.rays->size() : 0);
            std::vector<std::function<void()>> runs{
                [&] { hits[0] = trace_scene_rays(*scene, *w.rays, w.occlusion); },
                [&] {
                    hits[1] = trace_scene_batch(*scene, *w.rays, w.occlusion, batch_hits, flags);
                }};
#if BVHKIT_HAVE_EMBREE
            runs.push_back([&] {
                std::size_t n = 0;
                for (const Ray3f& r : *w.rays)
                    n += w.occlusion ? embree.any_hit(r) : bool(embree.closest_hit(r));
                hits[2] = n;
            });
#endif
            const std::vector<double> ms = median_ms_interleaved(options.repetitions, runs);
            const double n = double(w.rays->size());
            Row row = row_for(w.name, "bvhkit");
            row.set("rays", (long long)w.rays->size()).set("hits", (long long)hits[0]);
            row.set("ms", ms[0]).set("mrays_per_s", n / ms[0] / 1e3);
            Row batch = row_for(w.name, "bvhkit-batch");
            batch.set("rays", (long long)w.rays->size()).set("hits", (long long)hits[1]);
            batch.set("ms", ms[1]).set("mrays_per_s", n / ms[1] / 1e3);
#if BVHKIT_HAVE_EMBREE
            const Agreement agree = compare(*scene, mesh, poses, embree, *w.rays, w.occlusion);
            row.set("speedup", ms[2] / ms[0]).set("disagree", agree.disagree);
            row.set("ties", agree.ties).set("bvhkit_right", agree.bvhkit_right);
            row.set("embree_right", agree.embree_right);
            batch.set("speedup", ms[2] / ms[1]);
#endif
            rows.push_back(row);
            rows.push_back(batch);
            if (peer) {
                Row p = row_for(w.name, "embree3");
                p.set("rays", (long long)w.rays->size()).set("hits", (long long)hits[2]);
                p.set("ms", ms[2]).set("mrays_per_s", n / ms[2] / 1e3);
                rows.push_back(p);
            }
        }
    }
    return rows;
}

}  // namespace bvhkit::bench

#include "collide_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>

#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/contact_manifold.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/convex_hull.hpp"
#include "bvhkit/volumes/kdop.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/obb_rss.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "bvhkit/volumes/sphere.hpp"
#include "random_rigid_poses.hpp"

#if BVHKIT_HAVE_FCL
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>
#endif

namespace bvhkit::bench {

bool have_fcl() {
#if BVHKIT_HAVE_FCL
    return true;
#else
    return false;
#endif
}

namespace {

/// What one library with one volume type does for the three workloads. Each function runs the
/// whole pose list and records its answers (per pose) so the libraries can be compared.
struct Runner {
    std::string library, bv;
    std::function<bool(const Transform<float>&)> collides;
    std::function<std::size_t(const Transform<float>&)> all_pairs;
    std::function<double(const Transform<float>&)> distance;  // empty: not supported
    // bvhkit only: the model's build time and tree size, and the volume tests of all_pairs calls.
    double build_ms = 0;
    std::size_t tree_bytes = 0;
    std::shared_ptr<std::uint64_t> volume_tests;
};

template <class V>
Runner bvhkit_runner(const TriangleMesh& mesh, const char* bv) {
    const auto t0 = std::chrono::steady_clock::now();
    auto model = std::make_shared<CollisionModel<V>>(mesh);
    auto result = std::make_shared<CollideResult<float>>();
    Runner r;
    r.library = "bvhkit";
    r.bv = bv;
    r.build_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    r.tree_bytes = model->bvh().nodes.size() * sizeof(model->bvh().nodes[0]);
    r.volume_tests = std::make_shared<std::uint64_t>(0);
    r.collides = [model](const Transform<float>& p) { return collides(*model, *model, p); };
    r.all_pairs = [model, result, tests = r.volume_tests](const Transform<float>& p) {
        CollideOptions o;
        o.segments = false;
        collide(*model, *model, p, o, *result);
        *tests += result->stats.volume_tests;
        return result->contacts.size();
    };
    r.distance = [model](const Transform<float>& p) {
        return double(distance(*model, *model, p).distance);
    };
    return r;
}

#if BVHKIT_HAVE_FCL
fcl::Transform3d to_fcl(const Transform<float>& p) {
    fcl::Transform3d t = fcl::Transform3d::Identity();
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) t.linear()(i, j) = p.rotation[i][j];
        t.translation()(i) = p.translation[i];
    }
    return t;
}

template <class BV>
Runner fcl_runner(const TriangleMesh& mesh, const char* bv, bool with_distance) {
    auto model = std::make_shared<fcl::BVHModel<BV>>();
    std::vector<fcl::Vector3d> points;
    std::vector<fcl::Triangle> triangles;
    for (const auto& v : mesh.vertices) points.emplace_back(v[0], v[1], v[2]);
    for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
    model->beginModel();
    model->addSubModel(points, triangles);
    model->endModel();
    // The objects hold the model; b's pose is set per query (FCL keeps the pose in the object).
    auto a = std::make_shared<fcl::CollisionObjectd>(model, fcl::Transform3d::Identity());
    auto b = std::make_shared<fcl::CollisionObjectd>(model, fcl::Transform3d::Identity());
    Runner r;
    r.library = "fcl";
    r.bv = bv;
    r.collides = [a, b](const Transform<float>& p) {
        b->setTransform(to_fcl(p));
        fcl::CollisionRequestd request(1, false);
        fcl::CollisionResultd result;
        fcl::collide(a.get(), b.get(), request, result);
        return result.isCollision();
    };
    r.all_pairs = [a, b](const Transform<float>& p) {
        b->setTransform(to_fcl(p));
        fcl::CollisionRequestd request(100000000, false);
        fcl::CollisionResultd result;
        fcl::collide(a.get(), b.get(), request, result);
        return result.numContacts();
    };
    if (with_distance)
        r.distance = [a, b](const Transform<float>& p) {
            b->setTransform(to_fcl(p));
            fcl::DistanceRequestd request(false);
            fcl::DistanceResultd result;
            fcl::distance(a.get(), b.get(), request, result);
            return result.min_distance;
        };
    return r;
}
#endif

double now_ms() {
    return std::chrono::duration<double, std::milli>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

/// Round-robin timing: every repetition runs each job once in turn; returns median ms per job.
std::vector<double> interleaved(int repetitions, const std::vector<std::function<void()>>& jobs) {
    std::vector<std::vector<double>> times(jobs.size());
    for (int r = 0; r < std::max(1, repetitions); ++r)
        for (std::size_t k = 0; k < jobs.size(); ++k) {
            const double t0 = now_ms();
            jobs[k]();
            times[k].push_back(now_ms() - t0);
        }
    std::vector<double> out;
    for (auto& t : times) out.push_back(median(t));
    return out;
}

/// K2: the contact manifold (query/contact_manifold.hpp) at the colliding poses, OBB models as the
/// Python package's default, against the pair query on the same model (without and with the
/// intersection segments, which the manifold computes), all interleaved.
void time_contacts(const TriangleMesh& mesh, const std::string& name,
                   const std::vector<Transform<float>>& poses, const std::vector<char>& colliding,
                   int repetitions, std::vector<Row>& rows) {
    const CollisionModel<Obb<float>> model(mesh);
    const ContactMesh<float> contact(mesh);
    std::vector<Transform<float>> hit;
    for (std::size_t i = 0; i < poses.size(); ++i)
        if (colliding[i]) hit.push_back(poses[i]);
    if (hit.empty()) return;
    CollideResult<float> pairs;
    ContactManifold<float> manifold;
    ContactOptions every, local;
    every.max_points_per_region = 0;
    local.walk_inside = false;
    long long pair_count = 0, points = 0, all_points = 0, regions = 0;
    for (const auto& p : hit) {
        contact_manifold(model, contact, model, contact, p, ContactOptions{}, manifold);
        pair_count += (long long)manifold.pairs.contacts.size();
        points += (long long)manifold.points.size();
        regions += (long long)manifold.region_count();
        all_points += (long long)manifold.candidate_count;
    }
    volatile std::size_t sink = 0;
    const auto pair_job = [&](bool segments) {
        return [&, segments] {
            CollideOptions o;
            o.segments = segments;
            for (const auto& p : hit) {
                collide(model, model, p, o, pairs);
                sink = sink + pairs.contacts.size();
            }
        };
    };
    const auto manifold_job = [&](const ContactOptions& o) {
        return [&, o] {
            for (const auto& p : hit) {
                contact_manifold(model, contact, model, contact, p, o, manifold);
                sink = sink + manifold.points.size();
            }
        };
    };
    const std::vector<std::function<void()>> jobs = {pair_job(false), pair_job(true),
                                                     manifold_job(ContactOptions{}),
                                                     manifold_job(every), manifold_job(local)};
    const char* modes[] = {"pairs", "pairs_segments", "manifold4", "manifold_all",
                           "manifold4_no_walk"};
    const auto ms = interleaved(repetitions, jobs);
    for (std::size_t j = 0; j < jobs.size(); ++j) {
        Row row;
        row.set("workload", "K2").set("library", "bvhkit").set("bv", "obb").set("mesh", name);
        row.set("mode", modes[j]).set("queries", (long long)hit.size()).set("ms", ms[j]);
        row.set("queries_per_s", double(hit.size()) / (ms[j] / 1000.0));
        row.set("pairs", pair_count);
        if (j >= 2) {
            if (j != 4) row.set("points", j == 2 ? points : all_points).set("regions", regions);
            row.set("vs_pairs", ms[j] / ms[0]);
        }
        rows.push_back(row);
    }
}

}  // namespace

std::vector<Row> run_collide_bench(const CollideBenchOptions& options, std::FILE* progress) {
    std::vector<Row> rows;
    for (const auto& arg : options.meshes) {
        const TriangleMesh mesh = load_mesh(arg);
        const std::string name = mesh_label(arg);
        const auto poses = random_rigid_poses(mesh.bounds(), options.poses, options.seed);
        std::vector<Runner> runners;
        runners.push_back(bvhkit_runner<Aabb3f>(mesh, "aabb"));
        runners.push_back(bvhkit_runner<Obb<float>>(mesh, "obb"));
        runners.push_back(bvhkit_runner<Rss<float>>(mesh, "rss"));
        runners.push_back(bvhkit_runner<ObbRss<float>>(mesh, "obbrss"));
        runners.push_back(bvhkit_runner<Sphere<float>>(mesh, "sphere"));
        runners.push_back(bvhkit_runner<Kdop<float, 18>>(mesh, "kdop18"));
        runners.push_back(bvhkit_runner<ConvexHull<float>>(mesh, "hull"));  // 16 vertices
        runners.push_back(bvhkit_runner<ConvexHull<float, 8>>(mesh, "hull8"));
        runners.push_back(bvhkit_runner<ConvexHull<float, 32>>(mesh, "hull32"));
#if BVHKIT_HAVE_FCL
        runners.push_back(fcl_runner<fcl::OBBRSSd>(mesh, "OBBRSS", true));
        runners.push_back(fcl_runner<fcl::OBBd>(mesh, "OBB", false));  // FCL: no OBB distance
#endif
        if (progress)
            std::fprintf(progress, "%s: %zu triangles, %zu poses\n", name.c_str(),
                         mesh.triangles.size(), poses.size());

        // Answers first (untimed): they pick C2's poses and are compared across libraries.
        const std::size_t n = runners.size();
        std::vector<std::vector<char>> flags(n, std::vector<char>(poses.size()));
        std::vector<std::vector<std::size_t>> pairs(n, std::vector<std::size_t>(poses.size()));
        for (std::size_t k = 0; k < n; ++k)
            for (std::size_t i = 0; i < poses.size(); ++i) {
                flags[k][i] = runners[k].collides(poses[i]);
                pairs[k][i] = runners[k].all_pairs(poses[i]);
            }
        std::vector<double> tests_per_query(n, 0);
        for (std::size_t k = 0; k < n; ++k)
            if (runners[k].volume_tests)
                tests_per_query[k] = double(*runners[k].volume_tests) / double(poses.size());
        std::vector<Transform<float>> apart;
        for (std::size_t i = 0; i < poses.size(); ++i)
            if (!flags[0][i] &&
                (options.distance_poses == 0 || apart.size() < options.distance_poses))
                apart.push_back(poses[i]);
        std::vector<std::vector<double>> dist(n);
        for (std::size_t k = 0; k < n; ++k)
            if (runners[k].distance)
                for (const auto& p : apart) dist[k].push_back(runners[k].distance(p));

        if (progress) {
            for (std::size_t k = 1; k < n; ++k) {
                std::size_t flag_diff = 0, pair_diff = 0;
                for (std::size_t i = 0; i < poses.size(); ++i) {
                    flag_diff += flags[k][i] != flags[0][i];
                    pair_diff += pairs[k][i] != pairs[0][i];
                }
                double worst = 0;
                for (std::size_t i = 0; i < dist[k].size(); ++i)
                    worst = std::max(worst, std::fabs(dist[k][i] - dist[0][i]) /
                                                std::max(1e-30, std::fabs(dist[0][i])));
                std::fprintf(progress,
                             "  agreement %s %s vs bvhkit aabb: colliding flags differ at %zu/%zu "
                             "poses, pair counts at %zu/%zu, distance max rel diff %.2e over %zu\n",
                             runners[k].library.c_str(), runners[k].bv.c_str(), flag_diff,
                             poses.size(), pair_diff, poses.size(), worst, dist[k].size());
            }
        }

        // Timing: each workload, all runners interleaved.
        volatile std::size_t sink = 0;
        const auto time_mode = [&](const char* workload, const char* mode, auto&& job_of,
                                   const std::vector<Transform<float>>& set, bool distance_only) {
            std::vector<std::function<void()>> jobs;
            std::vector<std::size_t> which;
            for (std::size_t k = 0; k < n; ++k) {
                if (distance_only && !runners[k].distance) continue;
                which.push_back(k);
                jobs.push_back([&, k] {
                    for (const auto& p : set) sink = sink + job_of(runners[k], p);
                });
            }
            const auto ms = interleaved(options.repetitions, jobs);
            double fcl_best = 0;
            for (std::size_t j = 0; j < which.size(); ++j)
                if (runners[which[j]].library == "fcl")
                    fcl_best = std::max(fcl_best, double(set.size()) / (ms[j] / 1000.0));
            for (std::size_t j = 0; j < which.size(); ++j) {
                const std::size_t k = which[j];
                const double qps = double(set.size()) / (ms[j] / 1000.0);
                Row row;
                row.set("workload", workload).set("library", runners[k].library);
                row.set("bv", runners[k].bv).set("mesh", name).set("mode", mode);
                row.set("queries", (long long)set.size())
                    .set("ms", ms[j])
                    .set("queries_per_s", qps);
                long long colliding = 0, total_pairs = 0;
                for (std::size_t i = 0; i < poses.size(); ++i) {
                    colliding += flags[k][i];
                    total_pairs += (long long)pairs[k][i];
                }
                row.set("colliding", colliding).set("pairs", total_pairs);
                if (runners[k].volume_tests)
                    row.set("build_ms", runners[k].build_ms)
                        .set("tree_kib", double(runners[k].tree_bytes) / 1024.0)
                        .set("volume_tests_per_query", tests_per_query[k]);
                if (runners[k].library == "bvhkit" && fcl_best > 0)
                    row.set("vs_fcl_best", qps / fcl_best);
                rows.push_back(row);
            }
            if (progress) std::fprintf(progress, "  %s %s timed\n", workload, mode);
        };
        time_mode(
            "C1", "bool",
            [](Runner& r, const Transform<float>& p) { return std::size_t(r.collides(p)); }, poses,
            false);
        time_mode(
            "C1", "all", [](Runner& r, const Transform<float>& p) { return r.all_pairs(p); }, poses,
            false);
        time_mode(
            "C2", "distance",
            [](Runner& r, const Transform<float>& p) { return std::size_t(r.distance(p) > 0); },
            apart, true);
        time_contacts(mesh, name, poses, flags[0], options.repetitions, rows);
        if (progress) std::fprintf(progress, "  K2 contacts timed\n");
    }
    return rows;
}

}  // namespace bvhkit::bench

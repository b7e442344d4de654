// The thread-safety promise of the README ("Threads"): every const query of a built structure may
// run from many threads at once, and gives the answers a single thread gives. Each test runs the
// same queries serially and then from four threads at once on one shared object, and compares.
// CI also runs this program under ThreadSanitizer, which reports any data race among the readers.
#include <gtest/gtest.h>

#include <array>
#include <thread>
#include <vector>

#include "bvhkit/bvhkit.hpp"
#include "bvhkit/math/random.hpp"

namespace bvhkit {
namespace {

constexpr int kThreads = 4;

// Runs body(i) for i in [0, n), first serially into `serial`, then split over kThreads threads into
// `parallel`; the two result vectors must be equal.
template <class R, class F>
void expect_same_from_threads(std::size_t n, F body) {
    std::vector<R> serial(n), parallel(n);
    for (std::size_t i = 0; i < n; ++i) serial[i] = body(i);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            // Interleaved indices, so every thread runs through the whole structure.
            for (std::size_t i = std::size_t(t); i < n; i += kThreads) parallel[i] = body(i);
        });
    for (auto& th : threads) th.join();
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(serial[i], parallel[i]) << "query " << i;
}

std::vector<Vec3f> random_points(const Aabb3f& box, std::size_t n, std::uint64_t seed) {
    SplitMix64 rng(seed);
    std::vector<Vec3f> points(n);
    const Vec3f e = box.extent();
    for (auto& p : points)
        for (int k = 0; k < 3; ++k)
            p[k] = box.min[k] - 0.1f * e[k] + 1.2f * e[k] * float(rng.uniform());
    return points;
}

const TriangleMesh& mesh() {
    static const TriangleMesh m = load_mesh("sphere:subdiv=5,displacement=0.3");
    return m;
}

TEST(ConstQueriesFromThreads, RaysClosestAndAnyHit) {
    const TriangleBvh<float> bvh(mesh());
    const auto origins = random_points(mesh().bounds(), 4000, 1);
    const auto targets = random_points(mesh().bounds(), 4000, 2);
    expect_same_from_threads<std::array<float, 3>>(origins.size(), [&](std::size_t i) {
        const Ray3f ray(origins[i], targets[i] - origins[i]);
        const Hit<float> hit = bvh.closest_hit(ray);
        TraversalStats stats;
        const bool any = bvh.any_hit(ray, stats);
        return std::array<float, 3>{hit.t, float(hit.primitive), any ? 1.0f : 0.0f};
    });
}

TEST(ConstQueriesFromThreads, ClosestPointKNearestRadius) {
    const ClosestPointMesh<float> surface(mesh());
    const auto points = random_points(mesh().bounds(), 3000, 3);
    expect_same_from_threads<std::array<float, 4>>(points.size(), [&](std::size_t i) {
        const MeshPoint<float> q = surface.closest_point(points[i]);
        std::vector<MeshPoint<float>> near, within;
        NearestScratch<float> scratch;  // each thread its own
        surface.k_nearest(points[i], 5, near, scratch);
        surface.within_radius(points[i], 0.2f, within);
        return std::array<float, 4>{q.distance_squared, float(q.triangle),
                                    near.empty() ? -1.0f : near.back().distance_squared,
                                    float(within.size())};
    });
}

TEST(ConstQueriesFromThreads, SignedDistanceAndWindingNumber) {
    const SignedDistanceMesh<float> sdf(mesh());
    const WindingNumberMesh<float> winding(mesh());
    const auto points = random_points(mesh().bounds(), 3000, 4);
    expect_same_from_threads<std::array<float, 3>>(points.size(), [&](std::size_t i) {
        return std::array<float, 3>{sdf.signed_distance(points[i]).distance,
                                    winding.fast(points[i]), sdf.inside(points[i]) ? 1.0f : 0.0f};
    });
}

TEST(ConstQueriesFromThreads, CollisionAndDistanceUnderPoses) {
    const TriangleMesh small = load_mesh("sphere:subdiv=3");
    const CollisionModel<Obb<float>> obb(small);
    const CollisionModel<Rss<float>> rss(small);
    const auto offsets = random_points(Aabb3f(Vec3f(-2.5f), Vec3f(2.5f)), 400, 5);
    expect_same_from_threads<std::array<float, 3>>(offsets.size(), [&](std::size_t i) {
        Transform<float> pose = Transform<float>::identity();
        pose.translation = offsets[i];
        CollideResult<float> contacts;
        collide(obb, obb, pose, CollideOptions{}, contacts);
        return std::array<float, 3>{collides(obb, obb, pose) ? 1.0f : 0.0f,
                                    float(contacts.contacts.size()),
                                    distance(rss, rss, pose).distance};
    });
}

TEST(ConstQueriesFromThreads, DynamicTreeQueries) {
    DynamicTree<float, 2> tree;
    SplitMix64 rng(6);
    for (int i = 0; i < 5000; ++i) {
        const Vec<float, 2> lo(float(rng.uniform() * 100), float(rng.uniform() * 100));
        tree.create(Aabb<float, 2>(lo, lo + Vec<float, 2>(1.5f)));
    }
    std::vector<ProxyPair> pairs;
    tree.find_pairs(pairs);  // the only mutation: before the readers start
    const DynamicTree<float, 2>& reader = tree;
    expect_same_from_threads<std::array<std::size_t, 2>>(2000, [&](std::size_t i) {
        const Vec<float, 2> c(float(i % 100), float(i / 20));
        std::size_t in_box = 0, at_point = 0;
        reader.query(Aabb<float, 2>(c, c + Vec<float, 2>(4.0f)), [&](ProxyId) {
            ++in_box;
            return true;
        });
        reader.query_point(c, [&](ProxyId) {
            ++at_point;
            return true;
        });
        return std::array<std::size_t, 2>{in_box, at_point};
    });
}

/// Twelve instances of mesh() in a row, turned, some overlapping their neighbours.
Scene<float> row_of_instances() {
    Scene<float> scene;
    const GeometryId g = scene.add_mesh(mesh());
    for (int i = 0; i < 12; ++i) {
        Transform<float> pose;
        pose.rotation = rotation_about(normalize(Vec3f(0.3f, 1, 0.2f)), 0.4f * float(i));
        pose.translation = Vec3f(1.9f * float(i), 0.1f * float(i % 3), 0);
        scene.add_instance(g, pose, {.margin = i % 4 == 0 ? 0.05f : 0.0f});
    }
    return scene;
}

TEST(ConstQueriesFromThreads, SceneQueriesOnAFreshScene) {
    // The readers start on a scene whose per-mesh trees are not built yet: the lazy builds (under
    // std::call_once) race with the queries, which TSan watches.
    const Scene<float> reference = row_of_instances();
    const Aabb3f box = reference.bounds();
    const auto origins = random_points(box, 400, 7);
    const auto targets = random_points(box, 400, 8);
    const auto answers = [&](const Scene<float>& scene, std::size_t i) {
        const Ray3f ray(origins[i], targets[i] - origins[i]);
        const SceneHit<float> hit = closest_hit(scene, ray);
        const ScenePoint<float> near = closest_point(scene, origins[i]);
        std::array<double, 6> a{
            hit.t, double(hit.face), double(any_hit(scene, ray)), near.distance, 0, 0};
        if (i % 100 == 0) {  // the pair queries walk every instance: a few of them
            std::vector<InstancePair> pairs;
            colliding_pairs(scene, pairs);
            a[4] = double(pairs.size()) + closest_pair(scene).distance;
            std::vector<SceneDistance<float>> within;
            pairs_within(scene, 0.5f, within);
            a[5] = double(within.size());
            pairs_within(scene, scene, 0.5f, within);
            std::vector<SceneFaceContact<float>> faces;
            colliding_faces(scene, faces);
            a[5] += 1000 * double(within.size()) + 1e6 * double(faces.size());
        }
        return a;
    };
    std::vector<std::array<double, 6>> serial(origins.size()), parallel(origins.size());
    for (std::size_t i = 0; i < origins.size(); ++i) serial[i] = answers(reference, i);
    const Scene<float> fresh = row_of_instances();
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            for (std::size_t i = std::size_t(t); i < origins.size(); i += kThreads)
                parallel[i] = answers(fresh, i);
        });
    for (auto& th : threads) th.join();
    for (std::size_t i = 0; i < origins.size(); ++i) ASSERT_EQ(serial[i], parallel[i]) << i;
}

// The ray batch on the library's own threads, on a scene whose ray trees the batch builds.
TEST(ConstQueriesFromThreads, SceneRayBatchOnAFreshScene) {
    const Scene<float> reference = row_of_instances();
    const Aabb3f box = reference.bounds();
    const auto origins = random_points(box, 2000, 9);
    const auto targets = random_points(box, 2000, 10);
    std::vector<Ray3f> rays;
    for (std::size_t i = 0; i < origins.size(); ++i)
        rays.push_back(Ray3f(origins[i], targets[i] - origins[i]));
    const Scene<float> fresh = row_of_instances();
    std::vector<SceneHit<float>> hits(rays.size());
    std::vector<std::uint8_t> occluded(rays.size());
    closest_hits(fresh, std::span<const Ray3f>(rays), std::span(hits), 0u);
    any_hits(fresh, std::span<const Ray3f>(rays), std::span(occluded), 0u);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const SceneHit<float> one = closest_hit(reference, rays[i]);
        ASSERT_EQ(hits[i].t, one.t) << i;
        ASSERT_EQ(hits[i].face, one.face) << i;
        ASSERT_EQ(bool(occluded[i]), any_hit(reference, rays[i])) << i;
    }
}

}  // namespace
}  // namespace bvhkit

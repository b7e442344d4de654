// Closest point, k nearest and radius queries against brute force (every triangle), on every
// shared mesh and on random soups, float and double; points near the surface and far from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

template <class T>
T distance2(const Triangle<T>& t, const Vec<T, 3>& p) {
    return length_squared(closest_point(t, p).point - p);
}

/// Points near the surface (a random surface point pushed off by up to 1% of the diagonal) and
/// far (uniform in the box grown by half its size on every side).
template <class T>
std::vector<Vec<T, 3>> query_points(const std::vector<Triangle<T>>& tris, std::size_t count,
                                    std::uint64_t seed) {
    test::Random rng(seed);
    Aabb<T, 3> box;
    for (const auto& t : tris) box.grow(t.bounds());
    const Vec<T, 3> e = box.extent();
    const T diag = length(e);
    const Aabb<T, 3> far(box.min - e * T(0.5), box.max + e * T(0.5));
    std::vector<Vec<T, 3>> out;
    for (std::size_t i = 0; i < count; ++i) {
        if (i % 2) {
            out.push_back(rng.point_in(far));
        } else {
            const auto& t = tris[rng.below(std::uint32_t(tris.size()))];
            T a = T(rng.uniform()), b = T(rng.uniform());
            if (a + b > 1) a = 1 - a, b = 1 - b;
            const Vec<T, 3> s = t.p0 + (t.p1 - t.p0) * a + (t.p2 - t.p0) * b;
            out.push_back(s + rng.unit_vector<T>() * (diag * T(0.01 * rng.uniform())));
        }
    }
    return out;
}

template <class T>
void check_against_brute_force(const std::vector<Triangle<T>>& tris, std::size_t point_count,
                               std::uint64_t seed, const BuildOptions& options = {}) {
    const ClosestPointMesh<T> mesh(tris, options);
    const auto points = query_points(tris, point_count, seed);
    NearestScratch<T> scratch;
    std::vector<MeshPoint<T>> knn, inside;
    std::vector<std::pair<T, std::uint32_t>> all(tris.size());
    std::size_t ties = 0;
    for (std::size_t q = 0; q < points.size(); ++q) {
        const Vec<T, 3>& p = points[q];
        for (std::uint32_t i = 0; i < tris.size(); ++i) all[i] = {distance2(tris[i], p), i};
        std::sort(all.begin(), all.end());
        const auto got = mesh.closest_point(p, scratch);
        ASSERT_TRUE(got) << "point " << q;
        const T want = all[0].first;
        ASSERT_NEAR(got.distance_squared, want, T(1e-6) * want + std::numeric_limits<T>::min())
            << "point " << q;
        if (got.triangle != all[0].second) {
            // Allowed for a tie only: the triangle we got is as close as the best.
            ASSERT_EQ(distance2(tris[got.triangle], p), want) << "point " << q;
            ++ties;
        }
        // The point and barycentrics describe the same place on that triangle.
        const Triangle<T>& t = tris[got.triangle];
        const Vec<T, 3> from_uv = t.p0 * (1 - got.u - got.v) + t.p1 * got.u + t.p2 * got.v;
        ASSERT_LE(length(from_uv - got.point), T(1e-4) * (T(1) + length(got.point)));

        // k nearest: the same distances as the k smallest of all.
        const std::size_t k = std::min<std::size_t>(8, tris.size());
        mesh.k_nearest(p, k, knn, scratch);
        ASSERT_EQ(knn.size(), k);
        for (std::size_t j = 0; j < k; ++j)
            ASSERT_EQ(knn[j].distance_squared, all[j].first) << "point " << q << " rank " << j;

        // Within a radius: the same set (the radius between two distances to avoid ties).
        const std::size_t m = std::min<std::size_t>(20, tris.size() - 1);
        const T r2 = (all[m - 1].first + all[m].first) / 2;
        if (!(all[m - 1].first < r2 && r2 < all[m].first)) continue;
        mesh.within_radius(p, std::sqrt(r2), inside);
        std::set<std::uint32_t> got_set, want_set;
        for (const auto& h : inside) got_set.insert(h.triangle);
        for (std::size_t j = 0; j < tris.size() && all[j].first <= r2; ++j)
            if (all[j].first <= std::sqrt(r2) * std::sqrt(r2)) want_set.insert(all[j].second);
        // sqrt(r2)^2 may differ from r2 by an ulp: only a triangle at that very distance may
        // differ, and the radius lies strictly between two distances.
        ASSERT_EQ(got_set, want_set) << "point " << q;
    }
    // Ties are common on meshes (a closest point at a vertex or on an edge belongs to every
    // triangle around it); each one was checked to be exact above.
    ::testing::Test::RecordProperty("ties", int(ties));
}

class SharedMeshNearest : public ::testing::TestWithParam<std::string> {};

TEST_P(SharedMeshNearest, EqualsBruteForceFloatAndDouble) {
    BVHKIT_REQUIRE_MESH(path, GetParam());
    const TriangleMesh mesh = read_mesh(path);
    const std::size_t large = mesh.triangles.size() > 100000;
    const std::size_t points = test::scaled(large ? 60 : 200, 10);
    check_against_brute_force(mesh_triangles<float>(mesh), points, 1);
    check_against_brute_force(mesh_triangles<double>(mesh), points, 2);
}

INSTANTIATE_TEST_SUITE_P(Meshes, SharedMeshNearest,
                         ::testing::Values("teapot.obj", "stanford-bunny.obj", "igea.ply",
                                           "dragon-lowres.ply", "fandisk.obj", "spot.obj",
                                           "suzanne.obj"),
                         test::MeshFileName());

TEST(Nearest, SoupsWithEveryBuilder) {
    const auto tris = test::random_soup<float>(test::scaled(3000, 5), 4);
    for (const auto& [name, options] : all_builder_configurations()) {
        if (options.optimize && options.builder != Builder::BinnedSah) continue;
        SCOPED_TRACE(name);
        check_against_brute_force(tris, test::scaled(100, 5), 5, options);
    }
    check_against_brute_force(test::random_soup<double>(test::scaled(3000, 5), 6),
                              test::scaled(200, 5), 7);
}

TEST(Nearest, EmptyOneAndRadiusLimit) {
    const ClosestPointMesh<float> empty(std::vector<Trianglef>{});
    EXPECT_FALSE(empty.closest_point(Vec3f(0.0f)));
    const ClosestPointMesh<float> one(std::vector<Trianglef>{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
    const auto c = one.closest_point(Vec3f(0.25f, 0.25f, 2.0f));
    ASSERT_TRUE(c);
    EXPECT_EQ(c.triangle, 0u);
    EXPECT_FLOAT_EQ(c.distance_squared, 4.0f);
    EXPECT_FLOAT_EQ(c.u, 0.25f);
    EXPECT_FLOAT_EQ(c.v, 0.25f);
    NearestScratch<float> scratch;
    EXPECT_FALSE(one.closest_point(Vec3f(0.25f, 0.25f, 2.0f), scratch, 3.9f));
    EXPECT_TRUE(one.closest_point(Vec3f(0.25f, 0.25f, 2.0f), scratch, 4.0f));
}

TEST(Nearest, BatchEqualsSingleForAnyThreads) {
    const auto tris = test::random_soup<float>(test::scaled(20000, 10), 8);
    const ClosestPointMesh<float> mesh(tris);
    const auto points = query_points(tris, test::scaled(20000, 10), 9);
    std::vector<MeshPoint<float>> serial(points.size()), parallel(points.size());
    mesh.closest_points(points, serial, 1);
    mesh.closest_points(points, parallel, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
        const auto single = mesh.closest_point(points[i]);
        ASSERT_EQ(serial[i].triangle, single.triangle) << i;
        ASSERT_EQ(serial[i].distance_squared, single.distance_squared) << i;
        ASSERT_EQ(parallel[i].triangle, serial[i].triangle) << i;
        ASSERT_EQ(parallel[i].point, serial[i].point) << i;
    }
}

}  // namespace
}  // namespace bvhkit

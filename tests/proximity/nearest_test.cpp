// Closest point, k nearest and radius queries against brute force (every triangle), on every
// shared mesh and on random soups, float and double; points near the surface and far from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "closest_point_reference.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

class SharedMeshNearest : public ::testing::TestWithParam<std::string> {};

TEST_P(SharedMeshNearest, EqualsBruteForceFloatAndDouble) {
    BVHKIT_REQUIRE_MESH(path, GetParam());
    const TriangleMesh mesh = read_mesh(path);
    const std::size_t large = mesh.triangles.size() > 100000;
    const std::size_t points = test::scaled(large ? 60 : 200, 10);
    test::check_against_brute_force(mesh_triangles<float>(mesh), points, 1);
    test::check_against_brute_force(mesh_triangles<double>(mesh), points, 2);
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
        test::check_against_brute_force(tris, test::scaled(100, 5), 5, options);
    }
    test::check_against_brute_force(test::random_soup<double>(test::scaled(3000, 5), 6),
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
    // Past spatial_order_from, so the batch is answered in spatial order; with non-finite points.
    auto points = test::query_points(tris, test::scaled(20000, 4), 9);
    ASSERT_GE(points.size(), spatial_order_from);
    points[17] = {std::numeric_limits<float>::quiet_NaN(), 0, 0};
    points[18] = {0, 0, std::numeric_limits<float>::infinity()};
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

// The bottom-up, insertion and LBVH builders and the reinsertion optimizer: every tree
// passes validate() and gives the brute-force answer to every ray; the optimizer never raises the
// SAH cost; the parallel path builds the same tree as the serial one; depth limits hold.
#include <gtest/gtest.h>

#include "brute_force.hpp"
#include "bvhkit/build/build.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/exec/parallel.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

std::vector<std::pair<std::string, BuildOptions>> new_configurations() {
    std::vector<std::pair<std::string, BuildOptions>> out;
    for (auto& [name, o] : all_builder_configurations())
        if (o.optimize || o.builder == Builder::BottomUp || o.builder == Builder::Insertion ||
            o.builder == Builder::Lbvh)
            out.emplace_back(name, o);
    return out;
}

template <class T>
void check_builders(const std::vector<Triangle<T>>& tris, std::size_t ray_count) {
    std::vector<Aabb<T, 3>> boxes;
    for (const auto& t : tris) boxes.push_back(t.bounds());
    Aabb<T, 3> world;
    for (const auto& b : boxes) world.grow(b);
    const auto rays = test::random_rays<T>(ray_count, world, 7);
    const test::BruteForce<T> reference(tris, rays);
    for (const auto& [name, options] : new_configurations()) {
        SCOPED_TRACE(name);
        const TriangleBvh<T> tree(tris, options);
        ASSERT_NO_THROW(validate(tree.bvh(), boxes));
        EXPECT_LE(statistics(tree.bvh()).depth, max_bvh_depth);
        reference.check(tree, rays);
    }
}

TEST(Builders, EveryNewBuilderMatchesBruteForceOnASoup) {
    check_builders(test::random_soup<float>(test::scaled(3000, 5), 11), test::scaled(2000, 5));
    check_builders(test::random_soup<double>(test::scaled(3000, 5), 12), test::scaled(2000, 5));
}

TEST(Builders, EveryNewBuilderMatchesBruteForceOnASphere) {
    check_builders(mesh_triangles<float>(make_sphere(test::small_scale() ? 3 : 5)),
                   test::scaled(2000, 5));
}

TEST(Builders, SharedTeapot) {
    BVHKIT_REQUIRE_MESH(path, "teapot.obj");
    check_builders(mesh_triangles<float>(read_mesh(path)), test::scaled(2000, 5));
}

TEST(Builders, EdgeCases) {
    for (const auto& [name, options] : new_configurations()) {
        SCOPED_TRACE(name);
        // Empty, one, two, and many identical primitives (all Morton codes equal).
        for (std::size_t n : {0, 1, 2, 3, 1000}) {
            std::vector<Aabb3f> boxes(n, Aabb3f({0, 0, 0}, {1, 1, 1}));
            std::vector<Vec3f> centroids(n, Vec3f(0.5f));
            const auto bvh = build_bvh<float, 3>(boxes, centroids, options);
            ASSERT_NO_THROW(validate(bvh, boxes)) << n;
        }
        // Non-finite and empty boxes are skipped, as by every builder.
        std::vector<Aabb3f> boxes{Aabb3f({0, 0, 0}, {1, 1, 1}), Aabb3f(),
                                  Aabb3f({2, 2, 2}, {3, 3, 3}), Aabb3f({5, 5, 5}, {6, 6, 6})};
        boxes[2].min[1] = std::numeric_limits<float>::quiet_NaN();
        std::vector<Vec3f> centroids;
        for (const auto& b : boxes) centroids.push_back(b.centroid());
        BuildReport report;
        const auto bvh = build_bvh<float, 3>(boxes, centroids, options, &report);
        ASSERT_NO_THROW(validate(bvh, boxes));
        EXPECT_EQ(report.skipped, (std::vector<std::uint32_t>{1, 2}));
    }
}

TEST(Builders, DepthLimitIsRespected) {
    const auto tris = test::random_soup<float>(2000, 3);
    std::vector<Aabb3f> boxes;
    for (const auto& t : tris) boxes.push_back(t.bounds());
    for (auto [name, options] : new_configurations()) {
        SCOPED_TRACE(name);
        options.max_depth = 4;
        const TriangleBvh<float> tree(tris, options);
        ASSERT_NO_THROW(validate(tree.bvh(), boxes));
        EXPECT_LE(statistics(tree.bvh()).depth, 4u);
    }
}

TEST(Builders, OptimizerNeverRaisesSahCost) {
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
        const auto tris = test::random_soup<float>(test::scaled(4000, 4), seed);
        std::vector<Aabb3f> boxes;
        for (const auto& t : tris) boxes.push_back(t.bounds());
        for (auto [name, options] : all_builder_configurations()) {
            if (options.optimize) continue;
            SCOPED_TRACE(name);
            const TriangleBvh<float> plain(tris, options);
            auto bvh = plain.bvh();
            const double before = sah_cost(bvh);
            const auto report =
                optimize_reinsertion(bvh, std::span<const Aabb3f>(boxes), ReinsertionOptions{});
            ASSERT_NO_THROW(validate(bvh, boxes));
            EXPECT_LE(sah_cost(bvh), before);
            EXPECT_DOUBLE_EQ(report.cost_before, before);
            if (!report.kept) {
                EXPECT_EQ(sah_cost(bvh), before);
            }
        }
    }
}

TEST(Builders, OptimizerLowersTheCostOfAPoorTree) {
    const auto tris = test::random_soup<float>(test::scaled(4000, 4), 5);
    BuildOptions options = parse_builder("mean-longest");
    const double plain = sah_cost(TriangleBvh<float>(tris, options).bvh());
    options.optimize = true;
    const double optimized = sah_cost(TriangleBvh<float>(tris, options).bvh());
    EXPECT_LT(optimized, 0.995 * plain);
}

TEST(Builders, ParallelBuildsEqualSerial) {
    if (!have_parallel()) GTEST_SKIP() << "bvhkit built without oneTBB";
    const auto tris = test::random_soup<float>(test::scaled(60000, 10), 9);
    for (const auto& [name, options] : all_builder_configurations()) {
        if (options.optimize) continue;
        SCOPED_TRACE(name);
        BuildOptions serial = options, parallel = options;
        serial.threads = 1;
        parallel.threads = 0;
        const auto a = TriangleBvh<float>(tris, serial).bvh();
        const auto b = TriangleBvh<float>(tris, parallel).bvh();
        ASSERT_EQ(a.nodes.size(), b.nodes.size());
        EXPECT_EQ(a.primitive_indices, b.primitive_indices);
        for (std::size_t i = 0; i < a.nodes.size(); ++i) {
            ASSERT_EQ(a.nodes[i].first, b.nodes[i].first);
            ASSERT_EQ(a.nodes[i].count, b.nodes[i].count);
            ASSERT_EQ(a.nodes[i].bounds, b.nodes[i].bounds);
        }
    }
}

TEST(Builders, ParseNames) {
    for (const auto& [name, options] : all_builder_configurations()) {
        const BuildOptions o = parse_builder(name);
        EXPECT_EQ(o.builder, options.builder) << name;
        EXPECT_EQ(o.optimize, options.optimize) << name;
    }
    EXPECT_TRUE(parse_builder("lbvh+opt").optimize);
    EXPECT_THROW(parse_builder("lbvh+"), Error);
}

}  // namespace
}  // namespace bvhkit

// The parallel top-down builders (binned SAH, sweep SAH, the classic rules): with threads = 1, 2
// and 0 they build the same tree bit for bit (nodes and primitive indices), it passes validate(),
// and its SAH cost is the serial one. Sizes run from one primitive to 200k, past every threshold
// of the parallel driver (subtree cutoff, parallel binning, stable partition). Without oneTBB the
// same tests check that threads != 1 falls back to the serial build.
#include <gtest/gtest.h>

#include "bvhkit/build/build.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

/// Every top-down configuration without the optimizer: binned SAH, sweep SAH, axis x point rules.
std::vector<std::pair<std::string, BuildOptions>> top_down_configurations() {
    std::vector<std::pair<std::string, BuildOptions>> out;
    for (auto& [name, o] : all_builder_configurations())
        if (!o.optimize && (o.builder == Builder::BinnedSah || o.builder == Builder::SweepSah ||
                            o.builder == Builder::TopDown))
            out.emplace_back(name, o);
    // Leaves in blocks of four, as TriangleBvh builds for its four-wide layout.
    BuildOptions blocks;
    blocks.costs.leaf_block = 4;
    out.emplace_back("binned-sah, leaf blocks of 4", blocks);
    return out;
}

template <class T, std::size_t N>
void expect_same_tree(const Bvh<Aabb<T, N>>& a, const Bvh<Aabb<T, N>>& b) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.primitive_indices, b.primitive_indices);
    for (std::size_t i = 0; i < a.nodes.size(); ++i) {
        ASSERT_EQ(a.nodes[i].first, b.nodes[i].first) << "node " << i;
        ASSERT_EQ(a.nodes[i].count, b.nodes[i].count) << "node " << i;
        ASSERT_EQ(a.nodes[i].bounds, b.nodes[i].bounds) << "node " << i;
    }
}

/// Builds with threads = 1, 2 and 0 and checks the three trees against each other.
template <class T, std::size_t N>
void check_thread_counts(const std::vector<Aabb<T, N>>& boxes,
                         const std::vector<Vec<T, N>>& centroids, BuildOptions options) {
    options.threads = 1;
    BuildReport serial_report;
    const auto serial = build_bvh<T, N>(boxes, centroids, options, &serial_report);
    ASSERT_NO_THROW(validate(serial, std::span<const Aabb<T, N>>(boxes)));
    for (unsigned threads : {2u, 0u}) {
        SCOPED_TRACE("threads = " + std::to_string(threads));
        options.threads = threads;
        BuildReport report;
        const auto parallel = build_bvh<T, N>(boxes, centroids, options, &report);
        ASSERT_NO_THROW(validate(parallel, std::span<const Aabb<T, N>>(boxes)));
        EXPECT_EQ(report.skipped, serial_report.skipped);
        expect_same_tree(serial, parallel);
        EXPECT_EQ(sah_cost(serial), sah_cost(parallel));
    }
}

template <class T>
void check_triangles(const std::vector<Triangle<T>>& tris, const BuildOptions& options) {
    std::vector<Aabb<T, 3>> boxes;
    std::vector<Vec<T, 3>> centroids;
    for (const auto& t : tris) {
        boxes.push_back(t.bounds());
        centroids.push_back(t.centroid());
    }
    check_thread_counts<T, 3>(boxes, centroids, options);
}

TEST(ParallelBuild, RandomSoupsOfEverySize) {
    std::uint64_t seed = 100;
    for (std::size_t n : {1, 2, 3, 9, 100, 4097, 20000, 70000, 200000}) {
        // A quarter under the sanitizers: the largest soup still passes every threshold.
        const std::size_t count = test::scaled(n, 4);
        const auto tris = test::random_soup<float>(count, ++seed);
        for (const auto& [name, options] : top_down_configurations()) {
            // The full sweep is O(n log^2 n): the largest soup only for the others.
            if (options.builder == Builder::SweepSah && count > test::scaled(70000, 4)) continue;
            SCOPED_TRACE(name + ", " + std::to_string(count) + " triangles");
            check_triangles(tris, options);
        }
    }
}

TEST(ParallelBuild, DoublePrecisionAndTwoDimensions) {
    check_triangles(test::random_soup<double>(test::scaled(60000, 10), 7), BuildOptions{});
    test::Random rng(8);
    std::vector<Aabb2f> boxes(test::scaled(60000, 10));
    std::vector<Vec2f> centroids;
    for (auto& b : boxes) {
        const Vec2f c(float(rng.uniform()), float(rng.uniform()));
        const float r = float(0.01 * rng.uniform());
        b = Aabb2f(c - Vec2f(r), c + Vec2f(r));
        centroids.push_back(b.centroid());
    }
    for (const char* name : {"binned-sah", "sweep-sah", "median-longest", "mean-variance"}) {
        SCOPED_TRACE(name);
        check_thread_counts<float, 2>(boxes, centroids, parse_builder(name));
    }
}

TEST(ParallelBuild, LimitsAndDegenerateInput) {
    const std::size_t n = test::scaled(100000, 10);
    const auto tris = test::random_soup<float>(n, 21);
    for (const auto& [name, base] : top_down_configurations()) {
        if (base.builder == Builder::SweepSah) continue;  // same driver; slow at this size
        SCOPED_TRACE(name);
        BuildOptions options = base;
        options.max_depth = 3;  // large leaves made by nodes the parallel driver splits itself
        check_triangles(tris, options);
        options = base;
        options.max_leaf_size = 20000;  // the rule may ask for a leaf of a large node
        check_triangles(tris, options);
    }
    // Every centroid the same: the driver's fallback halves large ranges (nth_element).
    std::vector<Aabb3f> same(n, Aabb3f({0, 0, 0}, {1, 1, 1}));
    std::vector<Vec3f> centre(n, Vec3f(0.5f));
    check_thread_counts<float, 3>(same, centre, BuildOptions{});
    // Skipped boxes and a centroid outside its box take usable_primitives' serial path.
    std::vector<Aabb3f> boxes;
    std::vector<Vec3f> centroids;
    for (const auto& t : tris) {
        boxes.push_back(t.bounds());
        centroids.push_back(t.centroid());
    }
    boxes[n / 3].min[1] = std::numeric_limits<float>::quiet_NaN();
    boxes[n / 2] = Aabb3f();
    centroids[n - 1] = Vec3f(5.0f);
    check_thread_counts<float, 3>(boxes, centroids, BuildOptions{});
    BuildReport report;
    BuildOptions options;
    options.threads = 0;
    (void)build_bvh<float, 3>(boxes, centroids, options, &report);
    EXPECT_EQ(report.skipped,
              (std::vector<std::uint32_t>{std::uint32_t(n / 3), std::uint32_t(n / 2)}));
}

TEST(ParallelBuild, SharedBunny) {
    BVHKIT_REQUIRE_MESH(path, "stanford-bunny.obj");
    const auto tris = mesh_triangles<float>(read_mesh(path));
    for (const auto& [name, options] : top_down_configurations()) {
        if (test::small_scale() && options.builder == Builder::SweepSah) continue;
        SCOPED_TRACE(name);
        check_triangles(tris, options);
    }
}

TEST(ParallelBuild, SharedIgea) {
    if (test::small_scale()) GTEST_SKIP() << "269k triangles: Release only";
    BVHKIT_REQUIRE_MESH(path, "igea.ply");
    check_triangles(mesh_triangles<float>(read_mesh(path)), BuildOptions{});
}

}  // namespace
}  // namespace bvhkit

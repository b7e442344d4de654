// Every builder's tree must pass validate() on random soups, degenerate sets and extreme
// coordinates.
#include <gtest/gtest.h>

#include <functional>

#include "bvhkit/build/build.hpp"
#include "bvhkit/build/refit.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

template <class T>
struct Boxes {
    std::vector<Aabb<T, 3>> boxes;
    std::vector<Vec<T, 3>> centroids;
    explicit Boxes(const std::vector<Triangle<T>>& tris) {
        for (const auto& t : tris) {
            boxes.push_back(t.bounds());
            centroids.push_back(t.centroid());
        }
    }
};

template <class T>
AabbBvh<T, 3> build_and_validate(const std::vector<Triangle<T>>& tris, const BuildOptions& o,
                                 BuildReport* report = nullptr) {
    const Boxes<T> in(tris);
    AabbBvh<T, 3> bvh = build_bvh<T, 3>(in.boxes, in.centroids, o, report);
    validate(bvh, in.boxes);
    return bvh;
}

std::vector<std::pair<std::string, BuildOptions>> configurations() {
    return all_builder_configurations();
}

}  // namespace

TEST(Build, EveryBuilderValidatesOnRandomSoupsFromOneTo100k) {
    for (const auto& [name, options] : configurations()) {
        for (std::size_t n : {1u, 2u, 3u, 7u, 100u, 1000u, 10000u, 100000u}) {
            if (test::small_scale() && n > 10000) continue;
            SCOPED_TRACE(name + " n=" + std::to_string(n));
            const auto tris = test::random_soup<float>(n, n * 31 + 7);
            const auto bvh = build_and_validate(tris, options);
            const auto s = statistics(bvh);
            EXPECT_EQ(s.primitive_count, n);
            EXPECT_LE(s.depth, max_bvh_depth);
            if (n == 1) {
                EXPECT_EQ(bvh.nodes.size(), 1u);
            }
            EXPECT_EQ(bvh.nodes.size(), 2 * s.leaf_count - 1);  // a full binary tree
        }
    }
}

TEST(Build, DoublePrecisionAndTwoDimensions) {
    const auto tris = test::random_soup<double>(5000, 99);
    for (const auto& [name, options] : configurations()) {
        SCOPED_TRACE(name);
        build_and_validate(tris, options);
        // 2D: the triangles' xy shadows as boxes.
        std::vector<Aabb2d> boxes;
        std::vector<Vec2d> centroids;
        for (const auto& t : tris) {
            const auto b = t.bounds();
            boxes.emplace_back(Vec2d(b.min[0], b.min[1]), Vec2d(b.max[0], b.max[1]));
            centroids.push_back(boxes.back().centroid());
        }
        const auto bvh2 = build_bvh<double, 2>(boxes, centroids, options);
        validate(bvh2, boxes);
    }
}

TEST(Build, DegenerateSetsTerminateAndValidate) {
    const Trianglef tri{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const std::vector<std::pair<std::string, std::vector<Trianglef>>> sets = {
        {"all centroids equal", std::vector<Trianglef>(3000, tri)},
        {"zero-area points",
         std::vector<Trianglef>(500, Trianglef{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}})},
        {"zero-area segments on a line",
         [] {
             std::vector<Trianglef> v;
             for (int i = 0; i < 1000; ++i) {
                 const float x = float(i);
                 v.push_back({{x, 0, 0}, {x + 0.5f, 0, 0}, {x + 0.25f, 0, 0}});
             }
             return v;
         }()},
        {"huge coordinates",
         [] {
             auto v = test::random_soup<float>(2000, 5);
             for (auto& t : v) t = {t.p0 * 1e30f, t.p1 * 1e30f, t.p2 * 1e30f};
             return v;
         }()},
        {"tiny coordinates",
         [] {
             auto v = test::random_soup<float>(2000, 6);
             for (auto& t : v) t = {t.p0 * 1e-30f, t.p1 * 1e-30f, t.p2 * 1e-30f};
             return v;
         }()},
        {"one triangle", {tri}},
    };
    for (const auto& [name, tris] : sets)
        for (const auto& [builder, options] : configurations()) {
            SCOPED_TRACE(name + " / " + builder);
            const auto bvh = build_and_validate(tris, options);
            EXPECT_LE(statistics(bvh).depth, max_bvh_depth);
        }
}

TEST(Build, EmptyInputGivesAnEmptyTree) {
    for (const auto& [name, options] : configurations()) {
        const auto bvh = build_and_validate(std::vector<Trianglef>{}, options);
        EXPECT_TRUE(bvh.empty());
        EXPECT_TRUE(bvh.primitive_indices.empty());
    }
}

TEST(Build, NonFiniteTrianglesAreSkippedAndReportedOrRejected) {
    auto tris = test::random_soup<float>(1000, 21);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    tris[3].p1[0] = nan;
    tris[500].p2[2] = inf;
    tris[999].p0[1] = -inf;
    for (const auto& [name, options] : configurations()) {
        SCOPED_TRACE(name);
        BuildReport report;
        const auto bvh = build_and_validate(tris, options, &report);
        EXPECT_EQ(report.skipped, (std::vector<std::uint32_t>{3, 500, 999}));
        EXPECT_EQ(bvh.primitive_indices.size(), 997u);
        BuildOptions strict = options;
        strict.non_finite = NonFinitePolicy::Reject;
        try {
            build_and_validate(tris, strict);
            ADD_FAILURE() << "Reject did not throw";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("primitive 3"), std::string::npos) << e.what();
        }
    }
    // All of them non-finite: an empty tree, everything reported.
    std::vector<Trianglef> bad(10, Trianglef{{nan, 0, 0}, {0, 0, 0}, {1, 1, 1}});
    BuildReport report;
    EXPECT_TRUE(build_and_validate(bad, {}, &report).empty());
    EXPECT_EQ(report.skipped.size(), 10u);
}

TEST(Build, DepthLimitAndLeafSizeAreHonoured) {
    const auto tris = test::random_soup<float>(20000, 8);
    for (auto [name, options] : configurations()) {
        SCOPED_TRACE(name);
        options.max_depth = 6;
        const auto shallow = build_and_validate(tris, options);
        EXPECT_LE(statistics(shallow).depth, 6u);
        options.max_depth = max_bvh_depth;
        options.max_leaf_size = 2;
        const auto small = statistics(build_and_validate(tris, options));
        EXPECT_LE(small.leaf_size_histogram.size(), 3u);
    }
}

TEST(Build, SahCostOfStatisticsMatchesADirectSum) {
    const auto tris = test::random_soup<double>(3000, 12);
    const auto bvh = build_and_validate(tris, {});
    // Recompute the SAH cost from the definition with the depth-first walk.
    double by_hand = 0;
    const double root = bvh.nodes[0].bounds.area();
    for_each_node_depth_first(bvh, [&](std::uint32_t i, std::uint32_t) {
        const auto& n = bvh.nodes[i];
        by_hand += n.bounds.area() / root * (n.is_leaf() ? n.count : 1.0);
    });
    EXPECT_NEAR(statistics(bvh).sah_cost, by_hand, 1e-9 * by_hand);
    // Histogram and leaf walk agree.
    std::size_t leaves = 0, prims = 0;
    for_each_leaf(bvh, [&](std::uint32_t i, std::uint32_t) {
        ++leaves;
        prims += bvh.nodes[i].count;
    });
    const auto s = statistics(bvh);
    EXPECT_EQ(leaves, s.leaf_count);
    EXPECT_EQ(prims, 3000u);
    std::size_t from_histogram = 0;
    for (std::size_t k = 0; k < s.leaf_size_histogram.size(); ++k)
        from_histogram += k * s.leaf_size_histogram[k];
    EXPECT_EQ(from_histogram, 3000u);
    // Breadth-first visits every node once, depths never decrease.
    std::vector<int> seen(bvh.nodes.size(), 0);
    std::uint32_t last_depth = 0;
    for_each_node_breadth_first(bvh, [&](std::uint32_t i, std::uint32_t d) {
        ++seen[i];
        EXPECT_GE(d, last_depth);
        last_depth = d;
    });
    for (int v : seen) EXPECT_EQ(v, 1);
    std::size_t at_depth_total = 0;
    for (std::uint32_t d = 0; d <= s.depth; ++d) at_depth_total += nodes_at_depth(bvh, d).size();
    EXPECT_EQ(at_depth_total, bvh.nodes.size());
    EXPECT_EQ(nodes_at_depth(bvh, 1), (std::vector<std::uint32_t>{1, 2}));
}

TEST(Build, SweepSahIsNoWorseThanBinned) {
    for (std::uint64_t seed : {1, 2, 3}) {
        const auto tris = test::random_soup<float>(20000, seed);
        BuildOptions binned, sweep;
        sweep.builder = Builder::SweepSah;
        const double cb = statistics(build_and_validate(tris, binned)).sah_cost;
        const double cs = statistics(build_and_validate(tris, sweep)).sah_cost;
        EXPECT_LE(cs, cb * 1.0001) << "seed " << seed;
    }
}

TEST(Build, ValidateCatchesBrokenTrees) {
    const auto tris = test::random_soup<float>(100, 4);
    const Boxes<float> in(tris);
    const auto good = build_bvh<float, 3>(in.boxes, in.centroids);
    auto expect_invalid = [&](auto mutate) {
        auto bad = good;
        mutate(bad);
        EXPECT_THROW(validate(bad, in.boxes), Error);
    };
    expect_invalid([](Bvh3f& b) { b.nodes[1].bounds.max[0] -= 0.1f; });  // box too small
    expect_invalid([](Bvh3f& b) { b.primitive_indices[0] = b.primitive_indices[1]; });
    expect_invalid([](Bvh3f& b) { b.primitive_indices.pop_back(); });
    expect_invalid([](Bvh3f& b) { b.nodes[0].first = 0; });           // child before parent
    expect_invalid([](Bvh3f& b) { b.primitive_indices[5] = 1000; });  // out of range
}

TEST(Refit, MovedVerticesGiveAValidTreeOfTheSameShape) {
    auto tris = test::random_soup<float>(5000, 44);
    BuildOptions o;
    auto bvh = build_and_validate(tris, o);
    const auto shape = bvh.nodes.size();
    test::Random rng(45);
    for (auto& t : tris)
        for (Vec3f* p : {&t.p0, &t.p1, &t.p2})
            *p += Vec3f(float(rng.uniform(-0.1, 0.1)), float(rng.uniform(-0.1, 0.1)),
                        float(rng.uniform(-0.1, 0.1)));
    const Boxes<float> moved(tris);
    EXPECT_THROW(validate(bvh, moved.boxes), Error);  // stale boxes no longer enclose
    refit(bvh, std::span<const Aabb3f>(moved.boxes));
    validate(bvh, moved.boxes);
    EXPECT_EQ(bvh.nodes.size(), shape);
}

TEST(BuildOptions, EveryInvalidFieldIsRejectedByName) {
    const auto tris = test::random_soup<float>(200, 31);
    const Boxes<float> in(tris);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<std::pair<std::string, std::function<void(BuildOptions&)>>> cases = {
        {"bin_count", [](BuildOptions& o) { o.bin_count = 0; }},
        {"bin_count", [](BuildOptions& o) { o.bin_count = 1; }},
        {"bin_count", [](BuildOptions& o) { o.bin_count = 257; }},
        {"bin_count", [](BuildOptions& o) { o.bin_count = 0xFFFFFFFFu; }},
        {"max_leaf_size", [](BuildOptions& o) { o.max_leaf_size = 0; }},
        {"max_depth", [](BuildOptions& o) { o.max_depth = max_bvh_depth + 1; }},
        {"max_depth", [](BuildOptions& o) { o.max_depth = 0xFFFFFFFFu; }},
        {"costs.traversal", [nan](BuildOptions& o) { o.costs.traversal = nan; }},
        {"costs.traversal", [](BuildOptions& o) { o.costs.traversal = -1; }},
        {"costs.traversal", [inf](BuildOptions& o) { o.costs.traversal = inf; }},
        {"costs.intersection", [nan](BuildOptions& o) { o.costs.intersection = nan; }},
        {"costs.intersection", [](BuildOptions& o) { o.costs.intersection = 0; }},
        {"costs.intersection", [](BuildOptions& o) { o.costs.intersection = -2; }},
        {"ploc_radius", [](BuildOptions& o) { o.ploc_radius = 0; }},
        {"ploc_radius", [](BuildOptions& o) { o.ploc_radius = max_ploc_radius + 1; }},
        {"ploc_radius", [](BuildOptions& o) { o.ploc_radius = 1u << 30; }},
        {"builder", [](BuildOptions& o) { o.builder = static_cast<Builder>(99); }},
        {"axis_rule", [](BuildOptions& o) { o.axis_rule = static_cast<SplitAxis>(7); }},
        {"point_rule", [](BuildOptions& o) { o.point_rule = static_cast<SplitPoint>(7); }},
        {"non_finite", [](BuildOptions& o) { o.non_finite = static_cast<NonFinitePolicy>(7); }},
    };
    for (const auto& [base_name, base] : configurations())
        for (const auto& [field, set] : cases) {
            SCOPED_TRACE(base_name + " / " + field);
            BuildOptions o = base;
            set(o);
            try {
                (void)build_bvh<float, 3>(in.boxes, in.centroids, o);
                ADD_FAILURE() << "accepted";
            } catch (const Error& e) {
                const std::string what = e.what();
                EXPECT_NE(what.find("BuildOptions::" + field + " "), std::string::npos) << what;
                EXPECT_NE(what.find("valid"), std::string::npos) << what;
            }
        }
    // The ends of each range are accepted.
    for (const auto& [base_name, base] : configurations()) {
        SCOPED_TRACE(base_name);
        BuildOptions o = base;
        o.bin_count = 2;
        o.max_leaf_size = 1;
        o.max_depth = 0;
        o.ploc_radius = 1;
        o.costs = {0.0, 1e-3};
        EXPECT_NO_THROW(validate(build_bvh<float, 3>(in.boxes, in.centroids, o), in.boxes));
        o.bin_count = 256;
        o.max_depth = max_bvh_depth;
        o.ploc_radius = max_ploc_radius;
        o.max_leaf_size = 0xFFFFFFFFu;
        EXPECT_NO_THROW(validate(build_bvh<float, 3>(in.boxes, in.centroids, o), in.boxes));
    }
}

TEST(BuildOptions, HugeThreadCountsAreClampedToTheHardware) {
    // 2^18 and more threads crashed inside oneTBB, 2^16 took ~1 GB: now clamped, same tree.
    const auto tris = test::random_soup<float>(test::scaled(20000, 10), 32);
    const Boxes<float> in(tris);
    for (const auto& [name, base] : configurations()) {
        if (base.optimize) continue;
        SCOPED_TRACE(name);
        BuildOptions serial = base, huge = base;
        serial.threads = 1;
        huge.threads = 0xFFFFFFFFu;
        const auto a = build_bvh<float, 3>(in.boxes, in.centroids, serial);
        const auto b = build_bvh<float, 3>(in.boxes, in.centroids, huge);
        EXPECT_EQ(a.primitive_indices, b.primitive_indices);
        ASSERT_EQ(a.nodes.size(), b.nodes.size());
        huge.threads = 1u << 18;
        EXPECT_NO_THROW(validate(build_bvh<float, 3>(in.boxes, in.centroids, huge), in.boxes));
    }
    EXPECT_GE(hardware_threads(), 1u);
}

TEST(Build, ValidateKnowsTheSkippedPrimitives) {
    auto tris = test::random_soup<float>(300, 33);
    tris[7].p1[0] = std::numeric_limits<float>::quiet_NaN();
    for (const auto& [name, options] : configurations()) {
        SCOPED_TRACE(name);
        const TriangleBvh<float> tree(tris, options);
        ASSERT_EQ(tree.skipped(), (std::vector<std::uint32_t>{7}));
        // Boxes grown point by point with min/max that drop the NaN: primitive 7 gets a finite
        // box, but the build skipped it. With the skipped list it is no error.
        std::vector<Aabb3f> boxes;
        for (const auto& t : tris) {
            Aabb3f b;
            for (const Vec3f& p : {t.p0, t.p1, t.p2})
                for (std::size_t a = 0; a < 3; ++a)
                    if (!std::isnan(p[a])) {
                        b.min[a] = std::min(b.min[a], p[a]);
                        b.max[a] = std::max(b.max[a], p[a]);
                    }
            boxes.push_back(b);
        }
        ASSERT_TRUE(boxes[7].is_finite());
        EXPECT_THROW(validate(tree.bvh(), boxes), Error);
        EXPECT_NO_THROW(validate(tree.bvh(), boxes, tree.skipped()));
        // Still strict: a listed primitive must be absent, an unlisted usable one present.
        const std::vector<std::uint32_t> wrong{8};
        EXPECT_THROW(validate(tree.bvh(), boxes, wrong), Error);
    }
    // A finite but empty box (min > max) is skipped by the build and accepted absent.
    std::vector<Aabb3f> boxes{Aabb3f({0, 0, 0}, {1, 1, 1}), Aabb3f({2, 2, 2}, {1, 1, 1}),
                              Aabb3f({3, 3, 3}, {4, 4, 4})};
    std::vector<Vec3f> centroids{{0.5f, 0.5f, 0.5f}, {1.5f, 1.5f, 1.5f}, {3.5f, 3.5f, 3.5f}};
    BuildReport report;
    const auto bvh = build_bvh<float, 3>(boxes, centroids, {}, &report);
    EXPECT_EQ(report.skipped, (std::vector<std::uint32_t>{1}));
    EXPECT_NO_THROW(validate(bvh, boxes));
    EXPECT_NO_THROW(validate(bvh, boxes, report.skipped));
}

TEST(Build, ExtremeFiniteInputIsFreeOfUndefinedBehaviour) {
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    // The bin of a coordinate is clamped before it is converted: inf and NaN (0 * inf) included.
    EXPECT_EQ(bin_of(inf, 0.0f, 1.0f, 16), 15u);
    EXPECT_EQ(bin_of(3e38f, -3e38f, 16.0f, 16), 15u);  // (c - origin) overflows to inf
    EXPECT_EQ(bin_of(nan, 0.0f, 1.0f, 16), 0u);
    EXPECT_EQ(bin_of(1e-40f, 1e-40f, inf, 16), 0u);  // 0 * inf
    EXPECT_EQ(bin_of(-inf, 0.0f, 1.0f, 16), 0u);
    EXPECT_EQ(bin_of(7.5f, 0.0f, 1.0f, 16), 7u);
    // Morton codes of centroids in bounds of infinite or denormal extent.
    const Aabb3f huge({-3e38f, -3e38f, -3e38f}, {3e38f, 3e38f, 3e38f});
    EXPECT_EQ(morton_code(Vec3f(-3e38f), huge), 0u);
    (void)morton_code(Vec3f(3e38f), Aabb3f(Vec3f(-inf), Vec3f(inf)));
    const Aabb3f tiny(Vec3f(1e-45f), Vec3f(1e-40f));
    EXPECT_EQ(morton_code(Vec3f(1e-40f), tiny), morton_code(Vec3f(1e-40f), tiny));

    // Whole builds: extents near 3e38 (their float extent overflows), denormal extents, both.
    std::vector<Trianglef> sets[3];
    test::Random rng(34);
    for (int k = 0; k < 600; ++k) {
        const float s = float(rng.uniform(1e37, 3e38)) * (k % 2 ? 1.0f : -1.0f);
        sets[0].push_back({{-s, s, 0}, {s, -s, s}, {0.5f * s, 0, -s}});
        const float d = float(rng.uniform(1e-45, 1e-40));
        sets[1].push_back({{d, 0, 0}, {0, d, 2 * d}, {d, d, 0}});
        sets[2].push_back(k % 2 ? sets[0].back() : sets[1].back());
    }
    for (const auto& tris : sets)
        for (const auto& [name, options] : configurations()) {
            SCOPED_TRACE(name);
            const Boxes<float> in(tris);
            const auto bvh = build_bvh<float, 3>(in.boxes, in.centroids, options);
            ASSERT_NO_THROW(validate(bvh, in.boxes));
            EXPECT_EQ(bvh.primitive_indices.size(), tris.size());
            std::uint32_t largest_leaf = 0;
            for (const auto& node : bvh.nodes)
                largest_leaf = std::max(largest_leaf, node.is_leaf() ? node.count : 0u);
            EXPECT_LE(largest_leaf, options.max_leaf_size);
        }
}

// Unit tests of DynamicTree: the basic operations, input errors, degenerate inputs (zero-size
// boxes, identical boxes, sorted insertion along a line), both insertion strategies, rebuild and
// optimize.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "test_geometry.hpp"
#include "test_support.hpp"

namespace {

using bvhkit::Aabb2f;
using bvhkit::Aabb3d;
using bvhkit::DynamicTree;
using bvhkit::InsertionStrategy;
using bvhkit::ProxyId;
using bvhkit::Vec2f;

using bvhkit::test::box2;

std::vector<ProxyId> query_ids(const DynamicTree<float, 2>& t, const Aabb2f& b) {
    std::vector<ProxyId> ids;
    t.query(b, [&](ProxyId id) {
        ids.push_back(id);
        return true;
    });
    std::sort(ids.begin(), ids.end());
    return ids;
}

TEST(DynamicTree, CreateQueryMoveDestroy) {
    DynamicTree<float, 2> t;
    const ProxyId a = t.create(box2(0, 0), 7);
    const ProxyId b = t.create(box2(5, 0), 8);
    const ProxyId c = t.create(box2(0.5f, 0.5f), 9);
    t.validate();
    EXPECT_EQ(t.size(), 3u);
    EXPECT_EQ(t.user_data(b), 8u);
    EXPECT_EQ(query_ids(t, box2(0.6f, 0.6f, 0.1f, 0.1f)), (std::vector<ProxyId>{a, c}));
    EXPECT_TRUE(t.fat_box(a).contains(t.box(a)));

    // A small move stays inside the fat box; a far one restructures.
    EXPECT_FALSE(t.move(a, box2(0.05f, 0), {0.05f, 0}));
    EXPECT_TRUE(t.move(a, box2(20, 20)));
    t.validate();
    EXPECT_EQ(query_ids(t, box2(0.6f, 0.6f, 0.1f, 0.1f)), (std::vector<ProxyId>{c}));
    t.destroy(c);
    t.validate();
    EXPECT_FALSE(t.contains(c));
    const ProxyId d = t.create(box2(1, 1));
    EXPECT_EQ(d.index(), c.index()) << "slots are reused";
    EXPECT_EQ(d.generation(), c.generation() + 1) << "with the next generation";
    EXPECT_FALSE(t.contains(c));
    t.destroy(a);
    t.destroy(b);
    t.destroy(d);
    t.validate();
    EXPECT_TRUE(t.empty());
    EXPECT_EQ(t.height(), 0);
}

TEST(DynamicTree, FindPairsReportsEachPairOnceSorted) {
    DynamicTree<float, 2> t;
    std::vector<ProxyId> ids;
    for (int i = 0; i < 5; ++i) ids.push_back(t.create(box2(float(i) * 0.5f, 0)));
    std::vector<bvhkit::ProxyPair> pairs;
    t.find_pairs(pairs);
    // Boxes [0.5 i, 0.5 i + 1]: i and j overlap (touching counts) when |i - j| <= 2.
    std::vector<bvhkit::ProxyPair> expect;
    for (int i = 0; i < 5; ++i)
        for (int j = i + 1; j < 5; ++j)
            if (j - i <= 2) expect.push_back({ids[i], ids[j]});
    EXPECT_EQ(pairs, expect);
    t.find_pairs(pairs);
    EXPECT_TRUE(pairs.empty()) << "nothing moved since the last call";
    t.move(ids[4], box2(2.0f, 0.1f));
    t.find_pairs(pairs);
    EXPECT_EQ(pairs, (std::vector<bvhkit::ProxyPair>{{ids[2], ids[4]}, {ids[3], ids[4]}}));
}

TEST(DynamicTree, InputErrorsNameTheValue) {
    DynamicTree<float, 2> t;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    try {
        t.create(Aabb2f({0, nan}, {1, 1}));
        FAIL() << "NaN accepted";
    } catch (const bvhkit::Error& e) {
        EXPECT_NE(std::string(e.what()).find("min.y is nan"), std::string::npos) << e.what();
    }
    EXPECT_THROW(t.create(Aabb2f({0, 0}, {inf, 1})), bvhkit::Error);
    try {
        t.create(Aabb2f({2, 0}, {1, 1}));
        FAIL() << "min > max accepted";
    } catch (const bvhkit::Error& e) {
        EXPECT_NE(std::string(e.what()).find("min.x = 2 > max.x = 1"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW(t.destroy(ProxyId(0, 0)), bvhkit::Error);
    EXPECT_THROW(t.destroy(bvhkit::kNullProxy), bvhkit::Error);
    const ProxyId a = t.create(box2(0, 0));
    EXPECT_THROW(t.move(a, box2(0, 0), {nan, 0}), bvhkit::Error);
    EXPECT_THROW(t.move(ProxyId(a.index() + 1, 0), box2(0, 0)), bvhkit::Error);
    t.destroy(a);
    try {
        t.destroy(a);
        FAIL() << "double destroy accepted";
    } catch (const bvhkit::Error& e) {
        EXPECT_NE(std::string(e.what()).find("proxy id 0 was destroyed"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW(t.move(a, box2(0, 0)), bvhkit::Error);
    EXPECT_THROW(t.user_data(a), bvhkit::Error);
    t.validate();  // failed calls left the tree intact
    bvhkit::DynamicTreeOptions<float> bad;
    bad.margin_absolute = -1;
    EXPECT_THROW((DynamicTree<float, 2>{bad}), bvhkit::Error);
}

// The known worst case of incremental insertion: boxes inserted in sorted order along a line turn
// a tree without rotations into a list. With rotations (Kopta et al. 2012) and either strategy the
// height must stay logarithmic.
class SortedLine : public ::testing::TestWithParam<InsertionStrategy> {};

TEST_P(SortedLine, HeightStaysLogarithmic) {
    bvhkit::DynamicTreeOptions<float> o;
    o.insertion = GetParam();
    DynamicTree<float, 2> t(o);
    const int n = int(bvhkit::test::scaled(10000, 5));
    for (int i = 0; i < n; ++i) t.create(box2(float(i), 0));
    t.validate();
    const double bound = 2.5 * std::log2(double(n)) + 4;
    EXPECT_LE(t.height(), bound) << "n = " << n;
    // Remove every other one: still balanced and valid.
    for (int i = 0; i < n; i += 2) t.destroy(ProxyId(i, 0));  // a fresh tree: slot i
    t.validate();
    EXPECT_LE(t.height(), bound);
}
INSTANTIATE_TEST_SUITE_P(Strategies, SortedLine,
                         ::testing::Values(InsertionStrategy::Greedy,
                                           InsertionStrategy::BranchAndBound,
                                           InsertionStrategy::Guided));

TEST(DynamicTree, WithoutRotationsSortedLineDegenerates) {
    // The same input without rotations: shows the rotations are what keep the tree balanced.
    bvhkit::DynamicTreeOptions<float> o;
    o.rotate = false;
    o.insertion = InsertionStrategy::Greedy;
    DynamicTree<float, 2> t(o);
    for (int i = 0; i < 200; ++i) t.create(box2(float(i), 0));
    t.validate();
    EXPECT_GT(t.height(), 50);
}

TEST(DynamicTree, ZeroSizeAndIdenticalBoxes) {
    bvhkit::DynamicTreeOptions<float> o;
    o.margin_absolute = 0;  // zero-size leaves with zero-size fat boxes
    DynamicTree<float, 2> t(o);
    std::vector<ProxyId> ids;
    for (int i = 0; i < 1000; ++i) ids.push_back(t.create(Aabb2f({3, 4}, {3, 4})));
    for (int i = 0; i < 1000; ++i) ids.push_back(t.create(box2(1, 1)));
    t.validate();
    EXPECT_LE(t.height(), 60);
    int found = 0;
    t.query_point(Vec2f{3, 4}, [&](ProxyId) { return ++found, true; });
    EXPECT_EQ(found, 1000);
    found = 0;
    t.query_point(Vec2f{1.5f, 1.5f}, [&](ProxyId) { return ++found, true; });
    EXPECT_EQ(found, 1000);
    std::vector<bvhkit::ProxyPair> pairs;
    t.find_pairs(pairs);
    EXPECT_EQ(pairs.size(), 2u * (1000u * 999u / 2u));
    t.rebuild();
    t.validate();
    t.optimize(100);
    t.validate();
    for (ProxyId id : ids) t.destroy(id);
    t.validate();
}

TEST(DynamicTree, RayWithZeroDirectionComponents) {
    DynamicTree<float, 2> t;
    const ProxyId a = t.create(box2(0, 0));  // [0,1]^2
    const ProxyId b = t.create(box2(3, 0));  // [3,4]x[0,1]
    const ProxyId c = t.create(box2(0, 3));  // [0,1]x[3,4]
    const auto hits = [&](Vec2f o, Vec2f d, float maxf) {
        std::vector<ProxyId> ids;
        t.ray_cast(o, d, maxf, [&](ProxyId id, float) {
            ids.push_back(id);
            return -1.0f;
        });
        std::sort(ids.begin(), ids.end());
        return ids;
    };
    // Along +x on y = 0.5: a and b. With -0 in y as well.
    EXPECT_EQ(hits({-1, 0.5f}, {10, 0}, 1), (std::vector<ProxyId>{a, b}));
    EXPECT_EQ(hits({-1, 0.5f}, {10, -0.0f}, 1), (std::vector<ProxyId>{a, b}));
    // Exactly on the slab plane y = 0 and y = 1 (touching counts): still a and b, no NaN.
    EXPECT_EQ(hits({-1, 0}, {10, 0}, 1), (std::vector<ProxyId>{a, b}));
    EXPECT_EQ(hits({-1, 1}, {10, -0.0f}, 1), (std::vector<ProxyId>{a, b}));
    // Along -y on x = 0 (on a's and c's left edge).
    EXPECT_EQ(hits({0, 10}, {0, -20}, 1), (std::vector<ProxyId>{a, c}));
    EXPECT_EQ(hits({-0.0f, 10}, {-0.0f, -20}, 1), (std::vector<ProxyId>{a, c}));
    // Too short a segment, and one clipped by the callback.
    EXPECT_EQ(hits({-1, 0.5f}, {10, 0}, 0.05f), (std::vector<ProxyId>{}));
    std::vector<ProxyId> clipped;
    t.ray_cast(Vec2f{-1, 0.5f}, Vec2f{10, 0}, 1.0f, [&](ProxyId id, float) {
        clipped.push_back(id);
        return id == a ? 0.2f
                       : -1.0f;  // a is hit at 0.1: clip there, so b (at 0.4) is never reported
    });
    EXPECT_EQ(clipped.back(), a);
    // All-zero direction: only boxes containing the origin.
    EXPECT_EQ(hits({0.5f, 0.5f}, {0, 0}, 1), (std::vector<ProxyId>{a}));
}

TEST(DynamicTree, CastsNeverLengthenTheSegmentAndVisitNearerFirst) {
    DynamicTree<float, 2> t;
    std::vector<ProxyId> row;
    for (int i = 0; i < 64; ++i) row.push_back(t.create(box2(float(2 * i), 0)));
    // From x = -1 along +x: boxes at 2i, entry fraction (2i + 1) / 200. A callback asking for a
    // longer segment than it has (0.9 from max 0.5) leaves it at 0.5: the boxes beyond 0.5 were
    // dropped when their subtrees were clipped, and none is reported.
    std::vector<ProxyId> seen;
    t.ray_cast(Vec2f{-1, 0.5f}, Vec2f{200, 0}, 0.5f, [&](ProxyId id, float) {
        seen.push_back(id);
        return 0.9f;
    });
    ASSERT_FALSE(seen.empty());
    for (const ProxyId id : seen) EXPECT_LT(id.index(), 50) << "beyond the segment";
    // A closest-hit callback gets the nearest box first: the walk opens the nearer child first.
    std::vector<ProxyId> first;
    t.ray_cast(Vec2f{-1, 0.5f}, Vec2f{200, 0}, 1.0f, [&](ProxyId id, float) {
        first.push_back(id);
        return 0.0f;
    });
    EXPECT_EQ(first, (std::vector<ProxyId>{row[0]}));
}

TEST(DynamicTree, BoxCastAndStats) {
    DynamicTree<double, 3> t;
    const ProxyId a = t.create(Aabb3d({5, 0, 0}, {6, 1, 1}));
    t.create(Aabb3d({5, 5, 5}, {6, 6, 6}));
    std::vector<ProxyId> ids;
    bvhkit::QueryStats st;
    t.box_cast(
        Aabb3d({0, 0.9, 0.9}, {1, 1.9, 1.9}), {10, 0, 0}, 1.0,
        [&](ProxyId id, double) { return ids.push_back(id), -1.0; }, &st);
    EXPECT_EQ(ids, (std::vector<ProxyId>{a}));
    EXPECT_GE(st.nodes_visited, 1u);
    EXPECT_EQ(st.leaves_tested, 1u);
    ids.clear();
    t.box_cast(Aabb3d({0, 1.1, 1.1}, {1, 2, 2}), {10, 0, 0}, 1.0,
               [&](ProxyId id, double) { return ids.push_back(id), -1.0; });
    EXPECT_TRUE(ids.empty());
}

TEST(DynamicTree, EnlargeThenPartialRebuild) {
    DynamicTree<float, 2> t;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0, 100);
    std::vector<ProxyId> ids;
    for (int i = 0; i < 500; ++i) ids.push_back(t.create(box2(u(rng), u(rng))));
    const double before = t.sah_cost();
    for (int k = 0; k < 100; ++k) EXPECT_TRUE(t.enlarge(ids[k], box2(u(rng), u(rng))));
    t.validate();
    EXPECT_GT(t.sah_cost(), before);
    t.rebuild(false);
    t.validate();
    const double partial = t.sah_cost();
    t.rebuild(true);
    t.validate();
    EXPECT_LE(t.sah_cost(), partial * 1.5);
    EXPECT_EQ(t.optimize(50), 50);
    t.validate();
}

TEST(DynamicTree, BranchAndBoundBeatsGuidedBeatsGreedyOnCost) {
    // Random insertion order: the exact best sibling gives the cheapest tree, the guided descent
    // one within a few percent of it, the greedy descent a much costlier one.
    const InsertionStrategy strategies[3] = {
        InsertionStrategy::Greedy, InsertionStrategy::BranchAndBound, InsertionStrategy::Guided};
    double cost[3];
    for (int s = 0; s < 3; ++s) {
        bvhkit::DynamicTreeOptions<float> o;
        o.insertion = strategies[s];
        DynamicTree<float, 2> t(o);
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(0, 300);
        for (int i = 0; i < 5000; ++i) t.create(box2(u(rng), u(rng)));
        t.validate();
        cost[s] = t.sah_cost();
    }
    EXPECT_LT(cost[1], cost[0]);
    EXPECT_LE(cost[1], cost[2]);
    EXPECT_LT(cost[2], 1.1 * cost[1]);
    EXPECT_LT(cost[2], 0.8 * cost[0]);
}

TEST(DynamicTree, ShiftOriginAndStats) {
    DynamicTree<float, 2> t;
    const ProxyId a = t.create(box2(10, 10));
    t.create(box2(20, 10));
    t.shift_origin({10, 10});
    t.validate();
    EXPECT_EQ(t.box(a), box2(0, 0));
    const auto s = t.stats();
    EXPECT_EQ(s.proxies, 2u);
    EXPECT_EQ(s.nodes, 3u);
    EXPECT_EQ(s.height, 1);
    EXPECT_GT(s.memory_bytes, 0u);
    EXPECT_NEAR(s.area_ratio, 1.0, 1e-6);  // one internal node: the root
}

}  // namespace

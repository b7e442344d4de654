// DynamicTree on extreme but finite input: trees far taller than 2^15 (nested boxes without
// rotations), boxes whose extents or margins overflow float areas, boxes reaching FLT_MAX, and
// shift_origin near the end of the float range. Every answer is checked against brute force over
// the test's own copy of the boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "test_support.hpp"

namespace {

using bvhkit::DynamicTree;
using bvhkit::ProxyId;

template <class Tree, class Box>
std::vector<ProxyId> tree_query(const Tree& t, const Box& q) {
    std::vector<ProxyId> ids;
    t.query(q, [&](ProxyId id) { return ids.push_back(id), true; });
    std::sort(ids.begin(), ids.end());
    return ids;
}

/// Overlap written out per axis (touching counts), independent of Aabb::overlaps.
template <class Box>
bool brute_overlap(const Box& a, const Box& b) {
    for (std::size_t i = 0; i < Box::dimension; ++i)
        if (a.max[i] < b.min[i] || b.max[i] < a.min[i]) return false;
    return true;
}

template <class Box>
std::vector<ProxyId> brute_query(const std::vector<Box>& boxes, const std::vector<ProxyId>& ids,
                                 const Box& q) {
    std::vector<ProxyId> out;
    for (std::size_t k = 0; k < boxes.size(); ++k)
        if (brute_overlap(boxes[k], q)) out.push_back(ids[k]);
    std::sort(out.begin(), out.end());
    return out;
}

// 10^5 nested squares inserted from the smallest out, no rotations: each new box is best placed
// as the root's sibling, so the tree is a list of height n - 1, past the old 16-bit height.
TEST(DynamicTreeExtreme, NestedBoxesTallerThanInt16) {
    bvhkit::DynamicTreeOptions<float> o;
    o.rotate = false;
    DynamicTree<float, 2> t(o);
    const int n = bvhkit::test::small_scale() ? 40000 : 100000;  // both above 32,767
    std::vector<bvhkit::Aabb2f> boxes;
    std::vector<ProxyId> ids;
    for (int i = 0; i < n; ++i) {
        const float r = float(i + 1);
        boxes.push_back({{-r, -r}, {r, r}});
        ids.push_back(t.create(boxes.back()));
    }
    t.validate();
    EXPECT_GT(t.height(), 32767);
    for (const float x : {0.0f, 0.5f, 1000.5f, 39999.5f, float(n) - 0.5f, float(n) + 5})
        EXPECT_EQ(tree_query(t, bvhkit::Aabb2f({x, 0}, {x, 0.25f})),
                  brute_query(boxes, ids, bvhkit::Aabb2f({x, 0}, {x, 0.25f})))
            << "x = " << x;
    // Removals (each walks up the list: a few hundred, spread over the depths) keep it valid.
    for (int i = 0; i < n; i += n / 300) t.destroy(ids[i]);
    t.validate();
    EXPECT_EQ(tree_query(t, bvhkit::Aabb2f({0, 0}, {0, 0})).size(), t.size());
}

// 10^5 boxes of extent 1e20 scattered over 1e22 (3D float: every area overflows float, so costs
// computed in float all tie at inf and the tree used to become a list).
TEST(DynamicTreeExtreme, HugeBoxesStayBalanced) {
    DynamicTree<float, 3> t;
    const int n = int(bvhkit::test::scaled(100000, 10));
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> pos(-1e22f, 1e22f), ext(1e19f, 1e20f);
    std::vector<bvhkit::Aabb3f> boxes;
    std::vector<ProxyId> ids;
    for (int i = 0; i < n; ++i) {
        bvhkit::Vec3f lo{pos(rng), pos(rng), pos(rng)};
        boxes.push_back({lo, lo + bvhkit::Vec3f{ext(rng), ext(rng), ext(rng)}});
        ids.push_back(t.create(boxes.back()));
    }
    t.validate();
    EXPECT_LE(t.height(), 2.5 * std::log2(double(n)) + 8);
    EXPECT_TRUE(std::isfinite(t.sah_cost()));
    for (int q = 0; q < 200; ++q) {
        const bvhkit::Vec3f lo{pos(rng), pos(rng), pos(rng)};
        const bvhkit::Aabb3f box(lo, lo + bvhkit::Vec3f{2e21f, 2e21f, 2e21f});
        ASSERT_EQ(tree_query(t, box), brute_query(boxes, ids, box)) << "query " << q;
    }
}

// A fat margin of 1e19 makes every fat box's float area overflow: the tree must stay balanced.
TEST(DynamicTreeExtreme, HugeMarginStaysBalanced) {
    bvhkit::DynamicTreeOptions<float> o;
    o.margin_absolute = 1e19f;
    DynamicTree<float, 3> t(o);
    const int n = int(bvhkit::test::scaled(20000, 10));
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> pos(0, 1000);
    for (int i = 0; i < n; ++i) {
        const bvhkit::Vec3f lo{pos(rng), pos(rng), pos(rng)};
        t.create(bvhkit::Aabb3f(lo, lo + bvhkit::Vec3f{1, 1, 1}));
    }
    t.validate();
    EXPECT_LE(t.height(), 2.5 * std::log2(double(n)) + 8);
    t.rebuild();
    t.validate();
    EXPECT_LE(t.height(), 2.5 * std::log2(double(n)) + 8);
}

// Boxes reaching FLT_MAX, with and without a relative margin and a displacement: the fat box is
// finite and contains the box, and queries anywhere find the huge box.
TEST(DynamicTreeExtreme, BoxesReachingFloatMax) {
    const float big = std::numeric_limits<float>::max();
    for (const float relative : {0.0f, 0.5f}) {
        bvhkit::DynamicTreeOptions<float> o;
        o.margin_relative = relative;
        DynamicTree<float, 2> t(o);
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> pos(-100, 100);
        for (int i = 0; i < 199; ++i) {
            const float x = pos(rng), y = pos(rng);
            t.create(bvhkit::Aabb2f({x, y}, {x + 1, y + 1}));
        }
        const bvhkit::Aabb2f huge({-3e38f, -big}, {3e38f, big});
        const ProxyId h = t.create(huge);
        t.validate();
        for (int i = 0; i < 2; ++i) {
            const bvhkit::Aabb2f fat = t.fat_box(h);
            for (std::size_t a = 0; a < 2; ++a)
                EXPECT_TRUE(std::isfinite(fat.min[a]) && std::isfinite(fat.max[a]));
            EXPECT_TRUE(fat.contains(huge));
            for (int q = 0; q < 200; ++q) {
                const float x = pos(rng), y = pos(rng);
                const auto ids = tree_query(t, bvhkit::Aabb2f({x, y}, {x + 0.5f, y + 0.5f}));
                ASSERT_TRUE(std::binary_search(ids.begin(), ids.end(), h)) << q;
            }
            t.move(h, huge, bvhkit::Vec2f{3e38f, -3e38f});  // stretch overflows too
            t.validate();
        }
        EXPECT_TRUE(std::isfinite(t.sah_cost()));
    }
}

// shift_origin that would push a proxy's box to inf is refused and changes nothing; one that only
// pushes fat boxes past FLT_MAX clamps them, and later moves work.
TEST(DynamicTreeExtreme, ShiftOriginAtTheEndOfTheRange) {
    bvhkit::DynamicTreeOptions<float> o;
    o.margin_absolute = 1e37f;
    DynamicTree<float, 2> t(o);
    const bvhkit::Aabb2f near_max({3e38f, 0}, {3.3e38f, 1});
    const ProxyId a = t.create(near_max);
    const ProxyId b = t.create(bvhkit::Aabb2f({0, 0}, {1, 1}));
    EXPECT_THROW(t.shift_origin(bvhkit::Vec2f{-1e38f, 0}), bvhkit::Error);
    EXPECT_EQ(t.box(a), near_max) << "a refused shift changes nothing";
    t.validate();
    t.shift_origin(bvhkit::Vec2f{-1e36f, 0});  // the fat box passes FLT_MAX: clamped
    t.validate();
    const bvhkit::Aabb2f shifted = t.box(a);
    EXPECT_TRUE(std::isfinite(t.fat_box(a).max[0]));
    EXPECT_NO_THROW(t.move(a, shifted, bvhkit::Vec2f{1e30f, 0}));
    EXPECT_NO_THROW(t.move(b, t.box(b)));
    t.validate();
    std::vector<bvhkit::ProxyPair> pairs;
    t.find_pairs(pairs);
    EXPECT_TRUE(pairs.empty());
}

}  // namespace

namespace {

// A NaN in any query input used to match every proxy (each comparison with NaN is false, so no box
// was ever rejected). Now it throws an Error naming the argument, and infinite or empty query boxes
// keep a defined answer.
TEST(DynamicTreeExtreme, NanQueriesAreRefused) {
    using bvhkit::Aabb2f;
    using bvhkit::Vec2f;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    DynamicTree<float, 2> t;
    for (int i = 0; i < 20; ++i) t.create(Aabb2f({float(i), 0}, {float(i) + 1, 1}));
    int reported = 0;
    const auto count = [&](ProxyId) { return ++reported, true; };
    const auto count_cast = [&](ProxyId, float) { return ++reported, -1.0f; };
    const auto expect_error = [&](auto&& call, const char* needle) {
        try {
            call();
            ADD_FAILURE() << needle << ": NaN accepted";
        } catch (const bvhkit::Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    expect_error([&] { t.query(Aabb2f({nan, 0}, {1, 1}), count); }, "box.min[0] is nan");
    expect_error([&] { t.query(Aabb2f({0, 0}, {1, nan}), count); }, "box.max[1] is nan");
    expect_error([&] { t.query_point(Vec2f{0.5f, nan}, count); }, "p[1] is nan");
    expect_error(
        [&] {
            t.ray_cast(Vec2f{nan, 0.5f}, Vec2f{1, 0}, 1.0f, count_cast);
        },
        "origin[0] is nan");
    expect_error(
        [&] {
            t.ray_cast(Vec2f{-1, 0.5f}, Vec2f{nan, nan}, 1.0f, count_cast);
        },
        "direction[0] is nan");
    expect_error(
        [&] {
            t.ray_cast(Vec2f{-1, 0.5f}, Vec2f{1, 0}, nan, count_cast);
        },
        "max_fraction is nan");
    expect_error(
        [&] {
            t.box_cast(Aabb2f({nan, 0}, {1, 1}), Vec2f{1, 0}, 1.0f, count_cast);
        },
        "min.x is nan");
    expect_error(
        [&] {
            t.box_cast(Aabb2f({0, 0}, {1, 1}), Vec2f{0, nan}, 1.0f, count_cast);
        },
        "translation[1] is nan");
    expect_error(
        [&] {
            t.box_cast(Aabb2f({0, 0}, {1, 1}), Vec2f{1, 0}, nan, count_cast);
        },
        "max_fraction is nan");
    EXPECT_EQ(reported, 0);
    // Defined answers for infinite and empty input.
    t.query(Aabb2f({-inf, -inf}, {inf, inf}), count);
    EXPECT_EQ(reported, 20);
    reported = 0;
    t.query(Aabb2f({3, 1}, {2, 0}), count);  // min > max: empty
    EXPECT_EQ(reported, 0);
    t.ray_cast(Vec2f{-1, 0.5f}, Vec2f{1, 0}, inf, count_cast);  // unbounded ray
    EXPECT_EQ(reported, 20);
    reported = 0;
    t.query_point(Vec2f{inf, 0.5f}, count);
    EXPECT_EQ(reported, 0);
    // Non-finite boxes on create and move were already refused; still are.
    EXPECT_THROW(t.create(Aabb2f({0, 0}, {inf, 1})), bvhkit::Error);
    EXPECT_THROW(t.move(ProxyId(0, 0), Aabb2f({nan, 0}, {1, 1})), bvhkit::Error);
    t.validate();
}

}  // namespace

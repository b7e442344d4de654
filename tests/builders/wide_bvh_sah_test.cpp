// collapse_to_wide_sah (bvh/wide_bvh_sah.hpp): the trees it makes pass validate(), and without
// fill_lanes its leaf children are a cut of the binary tree of least cost. The reference lists
// every cut of small trees one by one and prices each from scratch in long double (the code prices
// node by node, bottom up, in double); the two minima must agree to a relative 1e-9, far above
// the rounding of sums of a few hundred positive terms in either precision and far below the
// gap between two different cuts' costs on these trees. Then child_overlap
// (build/spatial_split_choice.hpp) against areas worked out by hand, and which meshes it sends to
// spatial splits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "bvhkit/build/build.hpp"
#include "bvhkit/build/spatial_split_choice.hpp"
#include "bvhkit/bvh/wide_bvh_sah.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

Bvh<Aabb<float, 3>> build_over(const std::vector<Triangle<float>>& tris, std::uint32_t max_leaf) {
    std::vector<Aabb<float, 3>> boxes;
    std::vector<Vec<float, 3>> centroids;
    for (const auto& t : tris)
        boxes.push_back(t.bounds()), centroids.push_back(boxes.back().centroid());
    BuildOptions o;
    o.max_leaf_size = max_leaf;
    return build_bvh<float, 3>(boxes, centroids, o);
}

std::vector<Aabb<float, 3>> slot_boxes_of(const Bvh<Aabb<float, 3>>& bvh,
                                          const std::vector<Triangle<float>>& tris) {
    std::vector<Aabb<float, 3>> out;
    for (std::uint32_t i : bvh.primitive_indices) out.push_back(tris[i].bounds());
    return out;
}

long double area_ld(const Aabb<float, 3>& b) {
    const long double x = (long double)b.max[0] - b.min[0], y = (long double)b.max[1] - b.min[1],
                      z = (long double)b.max[2] - b.min[2];
    return 2 * (x * y + y * z + z * x);
}

/// The reference: every cut of the binary tree (a set of subtrees that covers its leaves once),
/// each as the list of its leaf-child roots.
struct Cuts {
    const Bvh<Aabb<float, 3>>& bvh;
    std::vector<std::vector<std::uint32_t>> of(std::uint32_t n) const {
        std::vector<std::vector<std::uint32_t>> out{{n}};
        if (bvh.nodes[n].is_leaf()) return out;
        for (const auto& l : of(bvh.nodes[n].left()))
            for (const auto& r : of(bvh.nodes[n].right())) {
                out.push_back(l);
                out.back().insert(out.back().end(), r.begin(), r.end());
            }
        return out;
    }
};

/// Primitives, and groups of four slots, under each node, counted leaf by leaf from the top.
void count_under(const Bvh<Aabb<float, 3>>& bvh, std::uint32_t n, std::uint32_t& prims,
                 std::uint32_t& fours) {
    const auto& b = bvh.nodes[n];
    if (b.is_leaf()) {
        prims += b.count;
        fours += (b.count + 3) / 4;
        return;
    }
    count_under(bvh, b.left(), prims, fours);
    count_under(bvh, b.right(), prims, fours);
}

/// A cut's cost from scratch: each inner node above the cut carries costs.node / (W - 1) of its
/// area, each leaf child its area times its groups of group_lanes; +inf if a leaf child that is
/// not a binary leaf holds more than max_leaf primitives.
long double cut_cost(const Bvh<Aabb<float, 3>>& bvh, const std::vector<std::uint32_t>& cut, int w,
                     const WideCollapseCosts& costs) {
    std::vector<std::uint8_t> below(bvh.nodes.size(), 0);  // in a leaf child (root included)
    long double total = 0;
    for (std::uint32_t root : cut) {
        std::uint32_t prims = 0, fours = 0;
        count_under(bvh, root, prims, fours);
        if (!bvh.nodes[root].is_leaf() && prims > costs.max_leaf)
            return std::numeric_limits<long double>::infinity();
        const std::uint32_t groups = (4 * fours + costs.group_lanes - 1) / costs.group_lanes;
        total += area_ld(bvh.nodes[root].bounds) * (long double)costs.group * groups;
        std::vector<std::uint32_t> todo{root};
        while (!todo.empty()) {
            const std::uint32_t k = todo.back();
            todo.pop_back();
            below[k] = 1;
            if (!bvh.nodes[k].is_leaf())
                todo.insert(todo.end(), {bvh.nodes[k].left(), bvh.nodes[k].right()});
        }
    }
    for (std::size_t k = 0; k < bvh.nodes.size(); ++k)
        if (!below[k])
            total += area_ld(bvh.nodes[k].bounds) * (long double)costs.node / (long double)(w - 1);
    return total;
}

/// The cut collapse_to_wide_sah made: the binary node whose slots each leaf child holds (a
/// subtree's slots are a contiguous run in the builders' layout).
std::vector<std::uint32_t> chosen_cut(const Bvh<Aabb<float, 3>>& bvh,
                                      const std::vector<std::uint32_t>& leaf_child_slots_min,
                                      const std::vector<std::uint32_t>& leaf_child_slots_count) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> by_run;  // (first, count)
    std::vector<std::uint32_t> first(bvh.nodes.size()), count(bvh.nodes.size());
    for (std::size_t i = bvh.nodes.size(); i-- > 0;) {
        const auto& b = bvh.nodes[i];
        first[i] = b.is_leaf() ? b.first : std::min(first[b.left()], first[b.right()]);
        count[i] = b.is_leaf() ? b.count : count[b.left()] + count[b.right()];
        // Unique: an inner node holds more slots than either child.
        by_run.emplace(std::make_pair(first[i], count[i]), std::uint32_t(i));
    }
    std::vector<std::uint32_t> cut;
    for (std::size_t k = 0; k < leaf_child_slots_min.size(); ++k) {
        const auto it = by_run.find({leaf_child_slots_min[k], leaf_child_slots_count[k]});
        EXPECT_NE(it, by_run.end()) << "a leaf child that is no subtree's run of slots";
        if (it != by_run.end()) cut.push_back(it->second);
    }
    return cut;
}

template <int W>
void check_least_cost(const std::vector<Triangle<float>>& tris, const WideCollapseCosts& costs) {
    SCOPED_TRACE("W " + std::to_string(W) + ", node cost " + std::to_string(costs.node) +
                 ", max_leaf " + std::to_string(costs.max_leaf));
    const auto bvh = build_over(tris, 2);
    const auto wide = collapse_to_wide_sah<float, W>(bvh, costs, false);
    ASSERT_NO_THROW(validate(wide, slot_boxes_of(bvh, tris)));
    std::vector<std::uint32_t> mins, counts;
    for (const auto& node : wide.nodes)
        for (int c = 0; c < W; ++c) {
            if (!node.has(c) || !node.is_leaf(c)) continue;
            std::uint32_t lo = ~0u, n = 0;
            for (std::size_t i = std::size_t(node.child[c]) * 4;
                 i < (std::size_t(node.child[c]) + node.groups[c]) * 4; ++i)
                if (wide.group_slots[i] != invalid_index)
                    lo = std::min(lo, wide.group_slots[i]), ++n;
            mins.push_back(lo), counts.push_back(n);
        }
    const long double chosen = cut_cost(bvh, chosen_cut(bvh, mins, counts), W, costs);
    long double least = std::numeric_limits<long double>::infinity();
    for (const auto& cut : Cuts{bvh}.of(0)) least = std::min(least, cut_cost(bvh, cut, W, costs));
    ASSERT_TRUE(std::isfinite(least));
    EXPECT_LE(std::fabs(chosen - least), 1e-9L * least)
        << "chosen " << (double)chosen << ", least " << (double)least;
}

TEST(WideCollapseSah, LeafChildrenAreTheCutOfLeastCost) {
    // Small trees (12 to 24 binary leaves: the cuts are listed one by one), soups of tiny and
    // large triangles that overlap, needles, and a mesh far from the origin.
    std::vector<std::vector<Triangle<float>>> sets;
    for (std::uint64_t seed = 1; seed <= 6; ++seed)
        sets.push_back(test::random_soup<float>(24, seed));
    sets.push_back(test::random_needles(24, 7));
    auto far = test::random_soup<float>(24, 8);
    for (auto& t : far)
        t.p0 += Vec<float, 3>(1e5f), t.p1 += Vec<float, 3>(1e5f), t.p2 += Vec<float, 3>(1e5f);
    sets.push_back(far);
    for (const auto& tris : sets)
        for (double node : {0.5, 4.0, 32.0, 1000.0})
            for (std::uint32_t max_leaf : {8u, 64u}) {
                WideCollapseCosts costs;
                costs.node = node;
                costs.max_leaf = max_leaf;
                costs.group_lanes = 8;
                check_least_cost<8>(tris, costs);
                costs.group_lanes = 4;
                check_least_cost<4>(tris, costs);
            }
}

TEST(WideCollapseSah, LargeTreesValidateWithAndWithoutFilledLanes) {
    const auto tris = test::random_soup<float>(test::scaled(20000, 10), 9);
    const auto bvh = build_over(tris, 8);
    const auto slots = slot_boxes_of(bvh, tris);
    for (double node : {1.0, 32.0})
        for (bool fill : {false, true}) {
            WideCollapseCosts costs;
            costs.node = node;
            ASSERT_NO_THROW(validate(collapse_to_wide_sah<float, 8>(bvh, costs, fill), slots));
            costs.group_lanes = 4;
            ASSERT_NO_THROW(validate(collapse_to_wide_sah<float, 4>(bvh, costs, fill), slots));
        }
    // A higher node cost never makes smaller leaves: fewer wide nodes.
    WideCollapseCosts cheap, dear;
    cheap.node = 1, dear.node = 32;
    const std::size_t cheap_nodes = collapse_to_wide_sah<float, 8>(bvh, cheap).nodes.size();
    const std::size_t dear_nodes = collapse_to_wide_sah<float, 8>(bvh, dear).nodes.size();
    EXPECT_GT(cheap_nodes, dear_nodes);
}

TEST(WideCollapseSah, EmptyTreeAndBadCosts) {
    EXPECT_TRUE(
        (collapse_to_wide_sah<float, 8>(Bvh<Aabb<float, 3>>{}, WideCollapseCosts{}).empty()));
    const auto bvh = build_over(test::random_soup<float>(50, 10), 2);
    for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
        WideCollapseCosts c;
        c.node = bad;
        EXPECT_THROW((collapse_to_wide_sah<float, 8>(bvh, c)), Error);
        c = {};
        c.group = bad;
        EXPECT_THROW((collapse_to_wide_sah<float, 8>(bvh, c)), Error);
    }
    WideCollapseCosts c;
    c.group_lanes = 6;
    EXPECT_THROW((collapse_to_wide_sah<float, 8>(bvh, c)), Error);
}

/// A tree of a root and two leaves with the given boxes.
Bvh<Aabb<float, 3>> two_leaves(const Aabb<float, 3>& a, const Aabb<float, 3>& b) {
    Bvh<Aabb<float, 3>> bvh;
    bvh.nodes.resize(3);
    Aabb<float, 3> root = a;
    root.grow(b);
    bvh.nodes[0].bounds = root;
    bvh.nodes[0].first = 1, bvh.nodes[0].count = 0;
    bvh.nodes[1].bounds = a, bvh.nodes[1].first = 0, bvh.nodes[1].count = 1;
    bvh.nodes[2].bounds = b, bvh.nodes[2].first = 1, bvh.nodes[2].count = 1;
    bvh.primitive_indices = {0, 1};
    return bvh;
}

TEST(SpatialSplitChoice, ChildOverlapByHand) {
    // [0,2]^3 and [1,3]^3 share [1,2]^3: area 6 over the root [0,3]^3's 54.
    EXPECT_DOUBLE_EQ(child_overlap(two_leaves({{0, 0, 0}, {2, 2, 2}}, {{1, 1, 1}, {3, 3, 3}})),
                     6.0 / 54);
    // Apart on x (the other two axes overlap fully): nothing shared.
    EXPECT_EQ(child_overlap(two_leaves({{0, 0, 0}, {1, 1, 1}}, {{2, 0, 0}, {3, 1, 1}})), 0.0);
    // Touching at x = 1: the shared face, 1 x 1 counted twice (both sides), over the root's 10.
    EXPECT_DOUBLE_EQ(child_overlap(two_leaves({{0, 0, 0}, {1, 1, 1}}, {{1, 0, 0}, {2, 1, 1}})),
                     2.0 / 10);
    // The same box twice: the whole.
    EXPECT_DOUBLE_EQ(child_overlap(two_leaves({{5, 5, 5}, {6, 7, 8}}, {{5, 5, 5}, {6, 7, 8}})),
                     1.0);
    EXPECT_EQ(child_overlap(Bvh<Aabb<float, 3>>{}), 0.0);
}

TEST(SpatialSplitChoice, SoupsAndRoomsSplitScansDoNot) {
    const auto overlap_of = [](const TriangleMesh& mesh) {
        std::vector<Triangle<float>> tris;
        for (std::size_t i = 0; i < mesh.triangle_count(); ++i)
            tris.push_back(triangle_at<float>(mesh, i));
        return child_overlap(build_over(tris, 8));
    };
    EXPECT_TRUE(spatial_splits_pay(overlap_of(make_procedural("soup:n=20000"))));
    EXPECT_TRUE(spatial_splits_pay(overlap_of(make_procedural("room:objects=200"))));
    EXPECT_FALSE(spatial_splits_pay(overlap_of(make_procedural("sphere:subdiv=5"))));
    EXPECT_FALSE(spatial_splits_pay(overlap_of(make_procedural("terrain:n=128"))));
}

}  // namespace
}  // namespace bvhkit

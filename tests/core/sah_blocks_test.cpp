// Leaves priced in blocks (SahCosts::leaf_block) and the partition the top-down builders share:
// each judged by its definition, computed here apart from the builder's arithmetic.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "bvhkit/build/build.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

struct Input {
    std::vector<Aabb3f> boxes;
    std::vector<Vec3f> centroids;
    BuildInput<float, 3> view() const { return {boxes, centroids}; }
};

Input input_of(const std::vector<Trianglef>& tris) {
    Input in;
    for (const auto& t : tris) {
        in.boxes.push_back(t.bounds());
        in.centroids.push_back(t.centroid());
    }
    return in;
}

/// Inner nodes holding at most `limit` primitives below them.
std::size_t inner_nodes_of_at_most(const AabbBvh<float, 3>& bvh, std::uint32_t limit) {
    std::vector<std::uint32_t> under(bvh.nodes.size());
    std::size_t small = 0;
    for (std::size_t i = bvh.nodes.size(); i-- > 0;) {  // children come after their parents
        const auto& n = bvh.nodes[i];
        under[i] = n.is_leaf() ? n.count : under[n.left()] + under[n.right()];
        small += !n.is_leaf() && under[i] <= limit;
    }
    return small;
}

}  // namespace

TEST(SahBlocks, StatisticsCountLeafTestsInBlocks) {
    const auto tris = test::random_soup<float>(3000, 21);
    const Input in = input_of(tris);
    for (std::uint32_t block : {1u, 3u, 4u, 8u}) {
        SCOPED_TRACE(block);
        BuildOptions o;
        o.costs.leaf_block = block;
        o.max_leaf_size = 16;
        const auto bvh = build_bvh<float, 3>(in.boxes, in.centroids, o);
        validate(bvh, in.boxes);
        double by_hand = 0;
        const double root = bvh.nodes[0].bounds.area();
        for (const auto& n : bvh.nodes)
            by_hand += n.bounds.area() / root *
                       (n.is_leaf() ? std::ceil(double(n.count) / double(block)) : 1.0);
        EXPECT_NEAR(statistics(bvh, o.costs).sah_cost, by_hand, 1e-9 * by_hand);
    }
    SahCosts automatic;  // 0: one primitive a test outside TriangleBvh
    EXPECT_EQ(automatic.leaf_tests(5), 5u);
}

// With a split costing at least a test (traversal >= intersection), a node that fits one block is
// a leaf whatever its split; a node of two blocks or more still splits where the SAH says so.
TEST(SahBlocks, NodesOfOneBlockAreLeavesAndLargerOnesStillSplit) {
    for (auto builder : {Builder::BinnedSah, Builder::SweepSah}) {
        SCOPED_TRACE(to_string(builder));
        const auto tris = test::random_soup<float>(20000, 22);
        const Input in = input_of(tris);
        BuildOptions o;
        o.builder = builder;
        o.costs.leaf_block = 4;
        const auto bvh = build_bvh<float, 3>(in.boxes, in.centroids, o);
        validate(bvh, in.boxes);
        EXPECT_EQ(inner_nodes_of_at_most(bvh, 4), 0u);
        std::size_t leaves_past_block = 0;
        for (const auto& n : bvh.nodes) leaves_past_block += n.is_leaf() && n.count > 4;
        const auto s = statistics(bvh);
        EXPECT_LE(s.leaf_size_histogram.size(), 9u);  // max_leaf_size 8
        // Leaves of two blocks exist: the SAH keeps some five to eight whole.
        EXPECT_GT(leaves_past_block, 0u);
        // The same input with cheaper traversal splits nodes of one block again where the SAH
        // says so: the shortcut is off.
        o.costs.traversal = 0.25;
        const auto cheap = build_bvh<float, 3>(in.boxes, in.centroids, o);
        validate(cheap, in.boxes);
        EXPECT_GT(inner_nodes_of_at_most(cheap, 4), 0u);
    }
}

// A flat node (zero area) keeps the SAH's rule for flat nodes: it splits, blocks or not.
TEST(SahBlocks, FlatNodesOfOneBlockStillSplit) {
    Input in;
    for (int k = 0; k < 4; ++k) {  // four collinear segments along x
        const float x = float(2 * k);
        in.boxes.push_back(Aabb3f({x, 0, 0}, {x + 1, 0, 0}));
        in.centroids.push_back({x + 0.5f, 0, 0});
    }
    for (auto builder : {Builder::BinnedSah, Builder::SweepSah}) {
        SCOPED_TRACE(to_string(builder));
        BuildOptions o;
        o.builder = builder;
        o.costs.leaf_block = 4;
        const auto bvh = build_bvh<float, 3>(in.boxes, in.centroids, o);
        validate(bvh, in.boxes);
        EXPECT_GT(bvh.nodes.size(), 1u);
    }
    SahCosts huge;
    huge.leaf_block = 64;
    EXPECT_EQ(huge.leaf_tests(0xFFFFFFFEu), 0x4000000u);  // no overflow near 2^32
    EXPECT_EQ(huge.leaf_tests(0xFFFFFFFFu), 0x4000000u);
    EXPECT_EQ(huge.leaf_tests(65), 2u);
}

TEST(SahBlocks, TriangleBvhPricesLeavesByItsLayout) {
    const TriangleMesh mesh = make_procedural("sphere:subdiv=4");
    TriangleBvhOptions binary;
    binary.ray_layout = RayLayout::Binary;
    const TriangleBvh<float> wide(mesh), flat(mesh, binary);
    BuildOptions ones;
    ones.costs.leaf_block = 1;
    const TriangleBvh<float> wide_ones(mesh, ones);
    if (wide.traces_wide()) {
        // Leaves of up to a block: fewer, larger leaves than with one triangle a test.
        EXPECT_LT(wide.bvh().nodes.size(), wide_ones.bvh().nodes.size());
        EXPECT_GT(statistics(wide.bvh()).average_leaf_size(),
                  statistics(wide_ones.bvh()).average_leaf_size());
    }
    // The binary layout tests one triangle at a time: the tree of one triangle a test.
    EXPECT_EQ(flat.bvh().nodes.size(), wide_ones.bvh().nodes.size());
}

TEST(SahBlocks, TriangleBvhBlocksAreAsWideAsItsGroups) {
    const TriangleMesh mesh = make_procedural("sphere:subdiv=4");
    TriangleBvhOptions four;
    four.ray_layout = RayLayout::Wide4;
    const TriangleBvh<float> chosen(mesh), wide4(mesh, four);
    if (!wide4.traces_wide()) GTEST_SKIP() << "no wide ray layout on this CPU";
    // A node of one block is a leaf (traversal >= intersection), and larger ones still split.
    ASSERT_EQ(wide4.ray_width(), 4);
    EXPECT_EQ(inner_nodes_of_at_most(wide4.bvh(), 4), 0u);
    EXPECT_GT(inner_nodes_of_at_most(wide4.bvh(), 8), 0u);
    if (chosen.ray_width() == 8) {  // blocks of eight: nodes of five to eight do not split either
        EXPECT_EQ(inner_nodes_of_at_most(chosen.bvh(), 8), 0u);
        EXPECT_GT(inner_nodes_of_at_most(chosen.bvh(), 16), 0u);
        EXPECT_LT(chosen.bvh().nodes.size(), wide4.bvh().nodes.size());
    }
    // Never a block above max_leaf_size: the tree is the one of blocks that size.
    TriangleBvhOptions small, small_blocks;
    small.max_leaf_size = small_blocks.max_leaf_size = 3;
    small_blocks.costs.leaf_block = 3;
    const TriangleBvh<float> a(mesh, small), b(mesh, small_blocks);
    EXPECT_EQ(a.bvh().primitive_indices, b.bvh().primitive_indices);
    ASSERT_EQ(a.bvh().nodes.size(), b.bvh().nodes.size());
    for (std::size_t i = 0; i < a.bvh().nodes.size(); ++i)
        ASSERT_TRUE(a.bvh().nodes[i].bounds == b.bvh().nodes[i].bounds) << "node " << i;
}

TEST(SahBlocks, BlocksBeyond64AreRejectedByName) {
    const Input in = input_of(test::random_soup<float>(10, 1));
    BuildOptions o;
    o.costs.leaf_block = 65;
    try {
        (void)build_bvh<float, 3>(in.boxes, in.centroids, o);
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("BuildOptions::costs.leaf_block"), std::string::npos)
            << e.what();
    }
    o.costs.leaf_block = 64;
    const auto build = [&] { return build_bvh<float, 3>(in.boxes, in.centroids, o); };
    EXPECT_NO_THROW((void)build());
}

// The partition by bin compares (c - origin) * scale with bin + 1 instead of converting to a bin;
// it must send each primitive where bin_of does, on coordinates at and beside every bin boundary,
// beyond the clamps, denormal and huge. Both sides' bounds must be the exact unions.
TEST(Partition, ByBinAgreesWithBinOfAndGathersExactBounds) {
    test::Random rng(23);
    const float denormal = 1e-40f, huge = 3e38f;
    struct Mapping {
        float origin, scale;
        std::uint32_t count;
    };
    const std::vector<Mapping> mappings = {{0.0f, 1.0f, 16},
                                           {-3.0f, 0.37f, 7},
                                           {1e-38f, 1e38f, 4},
                                           {-huge, 16.0f / huge, 16},
                                           {denormal, std::numeric_limits<float>::infinity(), 5},
                                           {1e6f, 3.0f, 256}};
    for (const Mapping& m : mappings) {
        std::vector<float> xs;
        for (std::uint32_t b = 0; b <= m.count; ++b) {
            const float at = m.origin + float(b) / m.scale;
            for (float x : {at, std::nextafter(at, -huge), std::nextafter(at, huge)})
                if (std::isfinite(x)) xs.push_back(x);
        }
        for (int k = 0; k < 200; ++k)
            xs.push_back(m.origin + float(rng.uniform(-2, double(m.count) + 2)) / m.scale);
        for (float x : {-huge, huge, 0.0f, -0.0f, denormal, -denormal, m.origin}) xs.push_back(x);
        Input in;
        for (float x : xs) {
            if (!std::isfinite(x)) continue;
            const float y = float(rng.uniform(-1, 1)), z = float(rng.uniform(-1, 1));
            in.centroids.push_back({x, y, z});
            in.boxes.push_back(Aabb3f({x, y - 1, z - 0.5f}, {x, y + 1, z + 2}));
        }
        for (std::uint32_t bin = 0; bin + 1 < m.count; ++bin) {
            SCOPED_TRACE("origin " + std::to_string(m.origin) + " bin " + std::to_string(bin));
            Split<float> s;
            s.kind = Split<float>::Kind::AtBin;
            s.axis = 0;
            s.bin_origin = m.origin, s.bin_scale = m.scale, s.bin_count = m.count, s.bin = bin;
            std::vector<std::uint32_t> order(in.boxes.size());
            for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
            RangeBounds<float, 3> left, right;
            const std::uint32_t k =
                partition_primitives(in.view(), std::span<std::uint32_t>(order), s, left, right);
            Aabb3f lb, rb, lc, rc;
            std::vector<int> seen(order.size(), 0);
            for (std::uint32_t j = 0; j < order.size(); ++j) {
                const std::uint32_t i = order[j];
                ++seen[i];
                const bool goes_left =
                    bin_of(in.centroids[i][0], m.origin, m.scale, m.count) <= bin;
                ASSERT_EQ(goes_left, j < k) << "x " << in.centroids[i][0];
                (goes_left ? lb : rb).grow(in.boxes[i]);
                (goes_left ? lc : rc).grow(in.centroids[i]);
            }
            for (int v : seen) ASSERT_EQ(v, 1);
            EXPECT_EQ(left.boxes.box(), lb);
            EXPECT_EQ(right.boxes.box(), rb);
            EXPECT_EQ(left.centroids.box(), lc);
            EXPECT_EQ(right.centroids.box(), rc);
        }
    }
}

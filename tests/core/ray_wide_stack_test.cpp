// The eight-wide walks' pushes (query/ray_wide_stack.hpp): the sorting network sorts every input
// (checked on every 0-1 input, which by the 0-1 principle of sorting networks covers every input,
// and on random keys with repeats and extremes); a closest-hit push makes the nearest hit lane
// current and stacks every other hit lane, with its own child, groups and distance, so that they
// pop nearest first; an any-hit push takes the first hit lane and stacks the others so that they
// pop in lane order. The walks' answers do not depend on this order (only ties between equally
// distant triangles do), so only these tests see a network or a key that orders wrongly.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "bvhkit/query/ray_wide.hpp"
#include "random_geometry.hpp"

using namespace bvhkit;

#if BVHKIT_RAY_AVX2
namespace {

[[gnu::target("avx2")]] void network_sort(const std::int32_t* in, std::int32_t* out) {
    alignas(32) std::uint32_t v[8];
    std::copy(in, in + 8, v);
    detail::sort8_descending(simd::Int<8>::load(v)).store(v);
    std::copy(v, v + 8, out);
}

/// Where the pushes ask for lines: anywhere readable (the entries' own addresses are not).
const char* no_line(const detail::WideEntry&) {
    static const char lines[192] = {};
    return lines;
}

[[gnu::target("avx2")]] void push_nearest(const float* entry, unsigned mask, const RayNode<8>& node,
                                          detail::WideEntry& current, detail::WideStack8& stack,
                                          std::uint32_t& size) {
    alignas(32) std::uint32_t hit[8];
    for (int c = 0; c < 8; ++c) hit[c] = (mask >> c) & 1u;
    detail::push_nearest_first8(simd::Float<8>::load_unaligned(entry),
                                simd::Int<8>::load(hit) == simd::Int<8>(1), mask, node, current,
                                stack, size, no_line);
}

[[gnu::target("avx2")]] void push_lane_order(const float* entry, unsigned mask,
                                             const RayNode<8>& node, detail::WideEntry& current,
                                             detail::WideStack8& stack, std::uint32_t& size) {
    detail::push_in_lane_order8(simd::Float<8>::load_unaligned(entry), mask, node, current, stack,
                                size, no_line);
}

void expect_sorted_by_network(std::vector<std::int32_t> keys) {
    std::int32_t out[8];
    network_sort(keys.data(), out);
    std::sort(keys.begin(), keys.end(), [](std::int32_t a, std::int32_t b) { return a > b; });
    for (int i = 0; i < 8; ++i) ASSERT_EQ(out[i], keys[i]) << "position " << i;
}

/// A node whose lanes name distinct children and group counts, so that a lane moved to the
/// stack with another lane's fields shows.
RayNode<8> numbered_node() {
    RayNode<8> node{};
    for (int c = 0; c < 8; ++c) {
        node.child[c] = 100 + 7 * std::uint32_t(c);
        node.groups[c] = std::uint32_t(c % 3);
    }
    return node;
}

/// Whether a and b lie within eight units in the last place of the larger: the distances the
/// push may order by lane instead.
bool near_tie(float a, float b) {
    const float big = std::max(std::fabs(a), std::fabs(b));
    const float ulp = std::nextafter(big, std::numeric_limits<float>::infinity()) - big;
    return std::fabs(double(a) - double(b)) <= 8.0 * double(ulp);
}

}  // namespace

TEST(WideStack, SortingNetworkSortsEveryInput) {
    if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
    for (unsigned bits = 0; bits < 256; ++bits) {
        std::vector<std::int32_t> keys(8);
        for (int i = 0; i < 8; ++i) keys[i] = (bits >> i) & 1u;
        expect_sorted_by_network(keys);
    }
    test::Random rng(7);
    const std::int32_t extremes[] = {std::numeric_limits<std::int32_t>::min(),
                                     std::numeric_limits<std::int32_t>::max(), -1, 0, 1};
    for (int round = 0; round < 20000; ++round) {
        std::vector<std::int32_t> keys(8);
        for (auto& k : keys) {
            const std::uint32_t pick = rng.below(4);
            k = pick == 0   ? extremes[rng.below(5)]
                : pick == 1 ? std::int32_t(rng.below(4))  // many repeats
                            : std::int32_t(std::uint32_t(rng.uniform() * 4294967296.0));
        }
        expect_sorted_by_network(keys);
    }
}

TEST(WideStack, NearestHitIsCurrentAndTheOthersPopNearestFirst) {
    if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
    const RayNode<8> node = numbered_node();
    test::Random rng(11);
    constexpr float inf = std::numeric_limits<float>::infinity();
    const float specials[] = {0.0f,
                              -0.0f,
                              1.0f,
                              -1.0f,
                              1e-30f,
                              -1e-30f,
                              3e38f,
                              -3e38f,
                              inf,
                              -inf,
                              std::numeric_limits<float>::denorm_min()};
    for (int round = 0; round < 20000; ++round) {
        float entry[8];
        for (float& t : entry) {
            const std::uint32_t pick = rng.below(4);
            t = pick == 0   ? specials[rng.below(11)]
                : pick == 1 ? float(rng.below(3))                               // exact ties
                : pick == 2 ? std::nextafter(1.0f, 2.0f * float(rng.below(2)))  // near ties
                            : float(rng.uniform(-1e3, 1e3));
        }
        const unsigned mask = 1u + rng.below(255);
        detail::WideStack8 stack;
        // Two older entries below: a push must leave them as they were.
        stack.child[0] = 1, stack.groups[0] = 0, stack.t[0] = 5.0f;
        stack.child[1] = 2, stack.groups[1] = 1, stack.t[1] = 6.0f;
        std::uint32_t size = 2;
        detail::WideEntry current{};
        push_nearest(entry, mask, node, current, stack, size);
        const int hits = __builtin_popcount(mask);
        ASSERT_EQ(size, 2u + std::uint32_t(hits) - 1);
        EXPECT_TRUE(stack.child[0] == 1 && stack.groups[0] == 0 && stack.t[0] == 5.0f);
        EXPECT_TRUE(stack.child[1] == 2 && stack.groups[1] == 1 && stack.t[1] == 6.0f);
        // Pop order: current, then the stack from the top down.
        std::vector<detail::WideEntry> order{current};
        for (std::uint32_t i = size; i-- > 2;) order.push_back(stack.entry(i));
        unsigned seen = 0;
        for (const detail::WideEntry& e : order) {
            const int lane = int(e.child - 100) / 7;
            ASSERT_TRUE(lane >= 0 && lane < 8 && node.child[lane] == e.child);
            ASSERT_TRUE((mask >> lane) & 1u) << "lane " << lane << " was not hit";
            ASSERT_FALSE((seen >> lane) & 1u) << "lane " << lane << " twice";
            seen |= 1u << lane;
            EXPECT_EQ(e.groups, node.groups[lane]);
            EXPECT_EQ(std::bit_cast<std::uint32_t>(e.t), std::bit_cast<std::uint32_t>(entry[lane]));
        }
        EXPECT_EQ(seen, mask);
        for (std::size_t i = 1; i < order.size(); ++i)
            EXPECT_TRUE(order[i - 1].t <= order[i].t || near_tie(order[i - 1].t, order[i].t))
                << order[i - 1].t << " pops before " << order[i].t;
    }
}

TEST(WideStack, AnyHitPushKeepsLaneOrder) {
    if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
    const RayNode<8> node = numbered_node();
    const float entry[8] = {7, 6, 5, 4, 3, 2, 1, 0};
    for (unsigned mask = 1; mask < 256; ++mask) {
        detail::WideStack8 stack;
        std::uint32_t size = 3;
        detail::WideEntry current{};
        push_lane_order(entry, mask, node, current, stack, size);
        std::vector<int> lanes;
        for (int c = 0; c < 8; ++c)
            if ((mask >> c) & 1u) lanes.push_back(c);
        ASSERT_EQ(current.child, node.child[lanes[0]]);
        EXPECT_EQ(current.t, entry[lanes[0]]);
        ASSERT_EQ(size, 3u + lanes.size() - 1);
        // They pop in lane order: the second lane on top.
        for (std::size_t k = 1; k < lanes.size(); ++k) {
            const detail::WideEntry e = stack.entry(std::uint32_t(size - k));
            EXPECT_EQ(e.child, node.child[lanes[k]]);
            EXPECT_EQ(e.groups, node.groups[lanes[k]]);
            EXPECT_EQ(e.t, entry[lanes[k]]);
        }
    }
}
#endif

#if BVHKIT_SIMD
// The four-wide walk's any-hit push: the first hit lane becomes current, the others pop in lane
// order (the layout's order for occlusion rays), each with its own child, groups and distance.
TEST(WideStack, FourWideAnyHitPushKeepsLaneOrder) {
    RayNode<4> node{};
    for (int c = 0; c < 4; ++c) {
        node.child[c] = 200 + 5 * std::uint32_t(c);
        node.groups[c] = std::uint32_t(c % 2);
    }
    const float entry[4] = {3, 2, 1, 0};
    const auto no_line4 = [](const detail::WideEntry&) {
        static const char lines[192] = {};
        return lines;
    };
    for (unsigned mask = 1; mask < 16; ++mask) {
        detail::WideEntry stack[8];
        std::uint32_t size = 2;
        detail::WideEntry current{};
        detail::take_hits_unordered(mask, entry, node, current, stack, size, no_line4);
        std::vector<int> lanes;
        for (int c = 0; c < 4; ++c)
            if ((mask >> c) & 1u) lanes.push_back(c);
        ASSERT_EQ(current.child, node.child[lanes[0]]);
        ASSERT_EQ(size, 2u + lanes.size() - 1);
        for (std::size_t k = 1; k < lanes.size(); ++k) {  // popped from the top: lane order
            const detail::WideEntry& e = stack[size - k];
            EXPECT_EQ(e.child, node.child[lanes[k]]) << "mask " << mask;
            EXPECT_EQ(e.groups, node.groups[lanes[k]]);
            EXPECT_EQ(e.t, entry[lanes[k]]);
        }
    }
}
#endif

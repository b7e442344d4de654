// traverse_depth_first (bvh/traverse.hpp) against a recursive pre-order walk of the same tree,
// with random pruning and early stops; TraversalStack's bounds; LeafSlot's explicitness.
#include <gtest/gtest.h>

#include <type_traits>
#include <vector>

#include "bvhkit/build/build.hpp"
#include "bvhkit/bvh/traverse.hpp"
#include "bvhkit/math/random.hpp"

using namespace bvhkit;

namespace {

using Node = BvhNode<Aabb<float, 3>>;

// The reference: recursive, pre-order, `first` child first.
template <FirstChild first>
bool recurse(const std::vector<Node, NodeAllocator<Node>>& nodes, std::uint32_t k,
             const std::vector<char>& pruned, std::size_t stop_after,
             std::vector<std::uint32_t>& entered, std::vector<std::uint32_t>& leaves) {
    entered.push_back(k);
    if (pruned[k]) return true;
    const Node& n = nodes[k];
    if (n.is_leaf()) {
        leaves.push_back(k);
        return leaves.size() != stop_after;
    }
    const std::uint32_t a = first == FirstChild::Left ? n.left() : n.right();
    const std::uint32_t b = first == FirstChild::Left ? n.right() : n.left();
    return recurse<first>(nodes, a, pruned, stop_after, entered, leaves) &&
           recurse<first>(nodes, b, pruned, stop_after, entered, leaves);
}

template <FirstChild first>
void check_against_recursion(const Bvh<Aabb<float, 3>>& bvh, SplitMix64& rng) {
    for (int trial = 0; trial < 50; ++trial) {
        std::vector<char> pruned(bvh.nodes.size());
        for (auto& p : pruned) p = rng.below(8) == 0;
        const std::size_t stop_after = trial % 3 ? 0 : 1 + rng.below(20);
        std::vector<std::uint32_t> want_entered, want_leaves;
        const bool want =
            recurse<first>(bvh.nodes, 0, pruned, stop_after, want_entered, want_leaves);
        std::vector<std::uint32_t> entered, leaves;
        const bool got = traverse_depth_first<first>(
            bvh,
            [&](std::uint32_t k, const Node& n) {
                EXPECT_EQ(&n, &bvh.nodes[k]);
                entered.push_back(k);
                return !pruned[k];
            },
            [&](const Node& leaf) {
                leaves.push_back(std::uint32_t(&leaf - bvh.nodes.data()));
                return leaves.size() != stop_after;
            });
        ASSERT_EQ(got, want);
        ASSERT_EQ(entered, want_entered);
        ASSERT_EQ(leaves, want_leaves);
    }
}

}  // namespace

TEST(Traverse, EntersNodesInRecursivePreOrder) {
    SplitMix64 rng(11);
    std::vector<Aabb<float, 3>> boxes(3000);
    std::vector<Vec3f> centroids(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        const Vec3f c(float(rng.below(1000)), float(rng.below(1000)), float(rng.below(1000)));
        boxes[i] = Aabb<float, 3>(c, c + Vec3f(1.0f));
        centroids[i] = c;
    }
    BuildOptions options;
    options.max_leaf_size = 3;
    const auto bvh = build_bvh<float, 3>(boxes, centroids, options);
    check_against_recursion<FirstChild::Left>(bvh, rng);
    check_against_recursion<FirstChild::Right>(bvh, rng);
}

TEST(Traverse, EmptyTreeEntersNothing) {
    const Bvh<Aabb<float, 3>> empty;
    int calls = 0;
    EXPECT_TRUE(traverse_depth_first(
        empty, [&](std::uint32_t, const Node&) { return ++calls, true; },
        [&](const Node&) { return ++calls, true; }));
    EXPECT_EQ(calls, 0);
}

TEST(Traverse, LeafSlotsAreNotNumbers) {
    static_assert(!std::is_convertible_v<LeafSlot, std::uint32_t>);
    static_assert(!std::is_convertible_v<std::uint32_t, LeafSlot>);
    Node leaf;
    leaf.first = 5;
    leaf.count = 3;
    std::vector<std::uint32_t> slots;
    for (const LeafSlot s : leaf_slots(leaf)) slots.push_back(s.value);
    EXPECT_EQ(slots, (std::vector<std::uint32_t>{5, 6, 7}));
}

TEST(TraversalStack, PushPopAndBound) {
    FixedStack<int, 3> stack;
    EXPECT_TRUE(stack.empty());
    stack.push(1);
    stack.push_if(2, false);  // written, not kept
    stack.push_if(3, true);
    EXPECT_EQ(stack.size(), 2u);
    EXPECT_EQ(stack.pop(), 3);
    EXPECT_EQ(stack.pop(), 1);
    EXPECT_TRUE(stack.empty());
#if !defined(NDEBUG)
    EXPECT_THROW(stack.pop(), Error);
    stack.push(1);
    stack.push(2);
    stack.push(3);
    EXPECT_THROW(stack.push(4), Error);
#endif
}

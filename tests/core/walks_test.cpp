// walk_depth_first with an opener (walk/walks.hpp) against a recursive pre-order walk: random trees
// whose nodes have one to three children, visited in an order chosen per node, some dropped by the
// opener and some refused by enter(), with handles that carry their depth. The skeleton must ask
// enter() of the same nodes and hand over the same leaves in the same order, carry the payload
// down, and stop where on_leaf() says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bvhkit/math/random.hpp"
#include "bvhkit/walk/walks.hpp"

using namespace bvhkit;

namespace walks_test {

struct TreeNode {
    std::vector<std::uint32_t> children;  // empty: a leaf
    bool is_leaf() const { return children.empty(); }
};

struct Ref {
    std::uint32_t node;
    std::uint32_t depth;
};

struct Event {
    bool leaf;  // false: an enter() call
    std::uint32_t node, depth;
    bool operator==(const Event&) const = default;
};

struct VectorStack {
    std::vector<Ref> items;
    std::size_t most = 0;
    void push(const Ref& r) {
        items.push_back(r);
        most = std::max(most, items.size());
    }
    Ref pop() {
        const Ref r = items.back();
        items.pop_back();
        return r;
    }
    bool empty() const { return items.empty(); }
    void clear() { items.clear(); }
};

std::vector<TreeNode> random_tree(SplitMix64& rng, std::uint32_t target) {
    std::vector<TreeNode> nodes(1);
    std::vector<std::uint32_t> open{0};
    while (!open.empty() && nodes.size() < target) {
        const std::size_t pick = rng.next() % open.size();
        const std::uint32_t n = open[pick];
        open.erase(open.begin() + std::ptrdiff_t(pick));
        const std::uint32_t count = 1 + std::uint32_t(rng.next() % 3);
        for (std::uint32_t k = 0; k < count; ++k) {
            nodes[n].children.push_back(std::uint32_t(nodes.size()));
            open.push_back(std::uint32_t(nodes.size()));
            nodes.emplace_back();
        }
    }
    return nodes;
}

// The query's rules, shared by the skeleton's callbacks and the recursive reference.
bool refused(const Ref& r) {
    return (r.node * 7 + r.depth) % 5 == 0 && r.node != 0;
}
bool dropped(std::uint32_t child) {
    return child % 4 == 3;
}
bool reversed(std::uint32_t node) {
    return node % 2 == 1;
}

std::vector<std::uint32_t> order(const TreeNode& n, std::uint32_t node) {
    std::vector<std::uint32_t> kept;
    for (const std::uint32_t c : n.children)
        if (!dropped(c)) kept.push_back(c);
    if (reversed(node)) std::reverse(kept.begin(), kept.end());
    return kept;
}

// Returns false once `stop_after` leaves were taken.
bool recursive(const std::vector<TreeNode>& nodes, Ref r, std::vector<Event>& events,
               std::size_t stop_after) {
    events.push_back({false, r.node, r.depth});
    if (refused(r)) return true;
    if (nodes[r.node].is_leaf()) {
        events.push_back({true, r.node, r.depth});
        std::size_t leaves = 0;
        for (const Event& e : events) leaves += e.leaf;
        return leaves < stop_after;
    }
    for (const std::uint32_t c : order(nodes[r.node], r.node))
        if (!recursive(nodes, {c, r.depth + 1}, events, stop_after)) return false;
    return true;
}

TEST(WalkDepthFirstOpener, EqualsRecursivePreOrder) {
    SplitMix64 rng(2026);
    for (int trial = 0; trial < 300; ++trial) {
        const std::vector<TreeNode> nodes = random_tree(rng, 1 + std::uint32_t(rng.next() % 200));
        const std::size_t stop_after = trial % 3 == 0 ? std::size_t(1 + rng.next() % 10) : SIZE_MAX;
        std::vector<Event> expected;
        const bool expected_done = recursive(nodes, {0, 0}, expected, stop_after);

        std::vector<Event> got;
        std::size_t leaves = 0;
        const auto enter = [&](const Ref& r) {
            got.push_back({false, r.node, r.depth});
            return !refused(r);
        };
        const auto on_leaf = [&](const Ref& r) {
            got.push_back({true, r.node, r.depth});
            return ++leaves < stop_after;
        };
        const auto open = [&](Ref& r, VectorStack& stack) -> bool {
            const std::vector<std::uint32_t> kept = order(nodes[r.node], r.node);
            if (kept.empty()) return false;
            for (std::size_t k = kept.size() - 1; k >= 1; --k) stack.push({kept[k], r.depth + 1});
            r = {kept[0], r.depth + 1};
            return true;
        };
        VectorStack stack;
        stack.push({12345, 0});  // the walk clears what a caller left
        const bool done = walk_depth_first(CarryingNodes<TreeNode, Ref>{nodes.data(), {0, 0}},
                                           stack, enter, on_leaf, open);
        ASSERT_EQ(done, expected_done) << "trial " << trial;
        ASSERT_EQ(got, expected) << "trial " << trial;
        // The gone-on-with child is never pushed: at most two entries a level (three children
        // a node), plus the entry the caller left, which the walk clears before it starts.
        std::uint32_t depth = 0;
        for (const Event& e : expected) depth = std::max(depth, std::uint32_t(e.depth));
        EXPECT_LE(stack.most, 2 * std::size_t(depth) + 1);
    }
}

}  // namespace walks_test

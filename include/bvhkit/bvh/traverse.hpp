#pragma once
// traverse_depth_first: walk_depth_first (walk/walks.hpp) over a Bvh's nodes, handing the callbacks
// the node as well as its index: `enter(index, node)` says whether the walk goes into a node (the
// root included); a leaf it goes into is handed to `on_leaf(node)`, which returns false to stop
// the whole walk. FirstChild says which child is entered first; the nodes are entered in the
// order of a recursive pre-order walk.
//
// Used by the overlap queries (query/overlap.hpp), within_radius (query/nearest.hpp) and the
// convex shape's collision test (query/convex_mesh.hpp).
//
// Leaves hand out leaf slots (positions in primitive_indices): LeafSlot keeps them apart from
// primitive indices, so a callback cannot take one for the other by mistake.
#include <cstdint>
#include <span>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/traversal_stack.hpp"
#include "bvhkit/walk/walks.hpp"

namespace bvhkit {

/// A position in Bvh::primitive_indices (and in anything stored in leaf order), as opposed to a
/// primitive index (a position in the caller's primitives). Explicit both ways: only .value turns
/// one back into a number.
struct LeafSlot {
    std::uint32_t value = 0;
    constexpr LeafSlot() = default;
    constexpr explicit LeafSlot(std::uint32_t v) : value(v) {}
    friend constexpr bool operator==(LeafSlot, LeafSlot) = default;
    friend constexpr auto operator<=>(LeafSlot, LeafSlot) = default;
};

/// The slots of a leaf, [first, first + count), for range-for.
struct LeafSlots {
    struct Iterator {
        std::uint32_t at;
        constexpr LeafSlot operator*() const { return LeafSlot(at); }
        constexpr Iterator& operator++() {
            ++at;
            return *this;
        }
        friend constexpr bool operator==(Iterator, Iterator) = default;
    };
    std::uint32_t first = 0, count = 0;
    constexpr Iterator begin() const { return {first}; }
    constexpr Iterator end() const { return {first + count}; }
};

template <class Volume>
constexpr LeafSlots leaf_slots(const BvhNode<Volume>& leaf) {
    return {leaf.first, leaf.count};
}

/// Walks `nodes` (a Bvh's, root at 0) depth first; see the top of this file. Returns false when
/// on_leaf stopped the walk. No allocation: the stack is the caller's (usually a local).
template <FirstChild first = FirstChild::Left, class Node, class Enter, class OnLeaf>
bool traverse_depth_first(std::span<const Node> nodes, TraversalStack& stack, Enter&& enter,
                          OnLeaf&& on_leaf) {
    if (nodes.empty()) return true;
    const Node* n = nodes.data();
    return walk_depth_first(
        BvhNodes<Node>{n}, stack, [&](std::uint32_t i) { return enter(i, n[i]); },
        [&](std::uint32_t i) { return on_leaf(n[i]); }, first);
}

/// The same over a whole Bvh.
template <FirstChild first = FirstChild::Left, class Volume, class Enter, class OnLeaf>
bool traverse_depth_first(const Bvh<Volume>& bvh, Enter&& enter, OnLeaf&& on_leaf) {
    TraversalStack stack;
    return traverse_depth_first<first>(std::span<const BvhNode<Volume>>(bvh.nodes), stack, enter,
                                       on_leaf);
}

}  // namespace bvhkit

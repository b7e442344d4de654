#pragma once
// Bvh<Volume>: the static tree as one flat array of nodes plus an array of primitive indices, and
// nothing else.
//
// Layout: node 0 is the root. An internal node names its first child; the two children are adjacent
// (first, first + 1), so one index names both. Siblings are allocated together when their parent is
// split, and the builders split depth first, so the array is in depth-first order of sibling pairs
// and every child has a larger index than its parent (which is what lets refit run as one reverse
// pass). A leaf names a run [first, first + count) of `primitive_indices`; count == 0 marks an
// internal node. With Aabb<float, 3> a node is 32 bytes: two cache-line halves per sibling pair.
#include <cstdint>
#include <span>
#include <vector>

#include "bvhkit/bvh/node_allocator.hpp"
#include "bvhkit/math/aabb.hpp"

namespace bvhkit {

/// The deepest tree the builders make and the traversals accept (the fixed traversal stack's size).
inline constexpr std::uint32_t max_bvh_depth = 64;

template <class Volume>
struct BvhNode {
    Volume bounds;
    std::uint32_t first = 0;  // leaf: first primitive slot; internal: index of the first child
    std::uint32_t count = 0;  // number of primitives in a leaf; 0 for an internal node

    constexpr bool is_leaf() const { return count != 0; }
    constexpr std::uint32_t left() const { return first; }
    constexpr std::uint32_t right() const { return first + 1; }
};

static_assert(sizeof(BvhNode<Aabb<float, 3>>) == 32, "a 3D float node is 32 bytes");

template <class Volume>
struct Bvh {
    using VolumeType = Volume;
    using Node = BvhNode<Volume>;

    std::vector<Node, NodeAllocator<Node>> nodes;  // nodes[0] is the root; empty for an empty tree
    std::vector<std::uint32_t> primitive_indices;  // leaf slots -> the caller's primitive indices

    bool empty() const { return nodes.empty(); }
    const Node& root() const { return nodes.front(); }
};

/// A Bvh's two arrays seen in place, owned elsewhere: a Bvh's own (bvh_view()) or a mapped file's
/// (io/mapped_triangle_bvh.hpp). The ray walk and the structure checks read trees through it.
template <class Volume>
struct BvhView {
    using VolumeType = Volume;
    using Node = BvhNode<Volume>;
    std::span<const Node> nodes;
    std::span<const std::uint32_t> primitive_indices;
    bool empty() const { return nodes.empty(); }
    const Node& root() const { return nodes.front(); }
};

template <class Volume>
BvhView<Volume> bvh_view(const Bvh<Volume>& bvh) {
    return {bvh.nodes, bvh.primitive_indices};
}

/// A Bvh's nodes as a BinaryNodeView (walk/walks.hpp) for the walk skeletons: a node by its
/// index, the root at 0, an inner node's children at left() and left() + 1.
template <class Node>
struct BvhNodes {
    using Ref = std::uint32_t;
    const Node* nodes;
    constexpr Ref root() const { return 0; }
    constexpr bool is_leaf(Ref r) const { return nodes[r].is_leaf(); }
    constexpr Ref child(Ref r, unsigned k) const { return nodes[r].left() + k; }
    constexpr const Node& node(Ref r) const { return nodes[r]; }
};

template <class Node>
BvhNodes<Node> bvh_nodes(std::span<const Node> nodes) {
    return {nodes.data()};
}

template <class T, std::size_t N>
using AabbBvh = Bvh<Aabb<T, N>>;
using Bvh2f = AabbBvh<float, 2>;
using Bvh3f = AabbBvh<float, 3>;
using Bvh2d = AabbBvh<double, 2>;
using Bvh3d = AabbBvh<double, 3>;

}  // namespace bvhkit

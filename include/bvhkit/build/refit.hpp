#pragma once
// Refit: after primitives move (a deforming mesh), recompute every node's box bottom-up without
// changing the tree's shape. Children always sit after their parent in the array, so one reverse
// pass over it sees every child before its parent. Linear time, no allocation.
//
// The tree's quality degrades as primitives drift from where they were when it was built; rebuild
// when the SAH cost has grown a lot. A primitive whose new box is non-finite contributes nothing
// (it can never be hit); rebuild to drop it from the tree for good.
#include <concepts>
#include <span>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"

namespace bvhkit {

/// `primitive_box(i)` returns the current box of primitive i (the caller's index).
template <class T, std::size_t N, class BoxOf>
requires std::invocable<BoxOf&, std::uint32_t>
void refit(Bvh<Aabb<T, N>>& bvh, BoxOf&& primitive_box) {
    for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
        auto& node = bvh.nodes[n];
        Aabb<T, N> box;
        if (node.is_leaf()) {
            for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
                const Aabb<T, N> b = primitive_box(bvh.primitive_indices[s]);
                if (b.is_finite()) box.grow(b);
            }
        } else {
            box = unite(bvh.nodes[node.left()].bounds, bvh.nodes[node.right()].bounds);
        }
        node.bounds = box;
    }
}

template <class T, std::size_t N>
void refit(Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes) {
    refit(bvh, [&](std::uint32_t i) { return primitive_boxes[i]; });
}
template <class T, std::size_t N>
void refit(Bvh<Aabb<T, N>>& bvh, const std::vector<Aabb<T, N>>& primitive_boxes) {
    refit(bvh, std::span<const Aabb<T, N>>(primitive_boxes));
}

}  // namespace bvhkit

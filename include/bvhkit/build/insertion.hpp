#pragma once
// Insertion build: the primitives are added one at a time to a growing tree, each next to the
// sibling that raises the SAH cost least, found exactly by branch and bound, and the ancestors are
// rotated on the way up (Bittner, Hapala, Havran 2013 for the search; Kopta et al. 2012 for the
// rotations): the dynamic tree's insertion algorithm run on a static set, on the same LinkedTree
// (bvh/linked_tree.hpp), without fat margins.
//
// Order matters: inserting in spatial order grows lopsided trees, so the primitives go in a
// deterministic pseudo-random order (a fixed seed). Slower than the top-down builders (each insert
// searches the tree) and, without the optimizer, usually a little worse by SAH than binned SAH.
#include "bvhkit/build/flatten.hpp"
#include "bvhkit/build/options.hpp"
#include "bvhkit/bvh/linked_tree.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// Nodes the sibling search of the insertion builder and the reinsertion optimizer expands at most
/// per insertion. Ordinary input needs far fewer (the bound prunes early); heavily overlapping
/// boxes (coincident centroids) weaken the bound until the exact search visits most of the tree,
/// a quadratic build. Beyond this the best sibling found so far is taken.
inline constexpr std::size_t insertion_max_expansions = tuning::insertion_max_expansions;

template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_insertion(std::span<const Aabb<T, N>> boxes,
                                std::span<const std::uint32_t> indices,
                                const BuildOptions& options) {
    const std::size_t n = indices.size();
    if (n == 0) return {};
    // Fisher-Yates with SplitMix64: the same order on every platform.
    std::vector<std::uint32_t> order(indices.begin(), indices.end());
    SplitMix64 rng(0x1A5E27);
    for (std::size_t k = n; k > 1; --k) std::swap(order[k - 1], order[rng.next() % k]);
    InsertionOptions insertion;
    insertion.strategy = InsertionStrategy::BranchAndBound;
    insertion.float_costs = false;
    insertion.max_expansions = insertion_max_expansions;
    LinkedTree<T, N> linked;
    linked.reserve(2 * n - 1);
    for (std::size_t k = 0; k < n; ++k)  // a leaf's value: its position in `order`
        linked.insert(linked.make_leaf(boxes[order[k]], static_cast<std::int32_t>(k)), insertion);
    BinaryTree tree;
    tree.order = std::move(order);
    tree.reserve(linked.capacity());
    for (std::size_t i = 0; i < linked.capacity(); ++i) {
        const auto& v = linked.node(std::int32_t(i));
        if (v.is_leaf())
            tree.add_leaf(static_cast<std::uint32_t>(v.value()), 1);
        else
            tree.add_internal(static_cast<std::uint32_t>(v.child1),
                              static_cast<std::uint32_t>(v.child2));
    }
    tree.root = static_cast<std::uint32_t>(linked.root());
    return flatten(tree, boxes, {options.max_leaf_size, options.max_depth, options.costs});
}

}  // namespace bvhkit

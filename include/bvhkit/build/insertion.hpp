#pragma once
// Insertion build: the primitives are added one at a time to a growing tree, each next to the
// sibling that raises the SAH cost least, found exactly by branch and bound, and the ancestors are
// rotated on the way up (Bittner, Hapala, Havran 2013 for the search; Kopta et al. 2012 for the
// rotations): the dynamic tree's insertion algorithm run on a static set. It reuses the dynamic
// tree's own search and rotations (dynamic/tree_insertion.hpp) on a pool without fat margins.
//
// Order matters: inserting in spatial order grows lopsided trees, so the primitives go in a
// deterministic pseudo-random order (a fixed seed). Slower than the top-down builders (each insert
// searches the tree) and, without the optimizer, usually a little worse by SAH than binned SAH.
#include "bvhkit/build/flatten.hpp"
#include "bvhkit/build/options.hpp"
#include "bvhkit/dynamic/tree_insertion.hpp"
#include "bvhkit/math/random.hpp"

namespace bvhkit {

/// Nodes the sibling search of the insertion builder and the reinsertion optimizer expands at most
/// per insertion. Ordinary input needs far fewer (the bound prunes early); heavily overlapping
/// boxes (coincident centroids) weaken the bound until the exact search visits most of the tree,
/// a quadratic build. Beyond this the best sibling found so far is taken.
inline constexpr std::size_t insertion_max_expansions = 64;

template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_insertion(std::span<const Aabb<T, N>> boxes,
                                std::span<const std::uint32_t> indices,
                                const BuildOptions& options) {
    using Node = dynamic_detail::Node<T, N>;
    constexpr std::int32_t null = dynamic_detail::kNullNode;
    const std::size_t n = indices.size();
    if (n == 0) return {};
    // Fisher-Yates with SplitMix64: the same order on every platform.
    std::vector<std::uint32_t> order(indices.begin(), indices.end());
    SplitMix64 rng(0x1A5E27);
    for (std::size_t k = n; k > 1; --k) std::swap(order[k - 1], order[rng.next() % k]);
    std::vector<Node> nodes(2 * n - 1);
    std::vector<dynamic_detail::SiblingCandidate<double>> heap;
    std::int32_t root = null;
    std::int32_t next = 0;
    for (std::size_t k = 0; k < n; ++k) {
        const std::int32_t leaf = next++;
        Node& ln = nodes[std::size_t(leaf)];
        ln.box = boxes[order[k]];
        ln.child1 = null;
        ln.child2 = static_cast<std::int32_t>(k);  // position in `order`
        ln.height = 0;
        if (root == null) {
            root = leaf;
            continue;
        }
        const std::int32_t sibling = dynamic_detail::find_sibling_branch_and_bound(
            nodes.data(), root, ln.box, heap, insertion_max_expansions);
        const std::int32_t parent = next++;
        const std::int32_t old_parent = nodes[std::size_t(sibling)].parent;
        Node& p = nodes[std::size_t(parent)];
        p.parent = old_parent;
        p.child1 = sibling;
        p.child2 = leaf;
        nodes[std::size_t(sibling)].parent = parent;
        nodes[std::size_t(leaf)].parent = parent;
        dynamic_detail::refit(nodes.data(), parent);
        if (old_parent == null) {
            root = parent;
            continue;
        }
        Node& op = nodes[std::size_t(old_parent)];
        (op.child1 == sibling ? op.child1 : op.child2) = parent;
        // Up to the root, or to the first node whose box and height stay and that does not
        // rotate: nothing above it changes then.
        for (std::int32_t i = old_parent; i != null; i = nodes[std::size_t(i)].parent) {
            Node& v = nodes[std::size_t(i)];
            const Aabb<T, N> before = v.box;
            const std::int32_t c1 = v.child1;
            const auto height = v.height;  // ties descend by height: keep heights exact
            dynamic_detail::refit(nodes.data(), i);
            dynamic_detail::rotate(nodes.data(), i);
            if (i != old_parent && v.box == before && v.child1 == c1 && v.height == height) break;
        }
    }
    BinaryTree tree;
    tree.order = std::move(order);
    tree.reserve(nodes.size());
    for (const Node& v : nodes) {
        if (v.is_leaf())
            tree.add_leaf(static_cast<std::uint32_t>(v.child2), 1);
        else
            tree.add_internal(static_cast<std::uint32_t>(v.child1),
                              static_cast<std::uint32_t>(v.child2));
    }
    tree.root = static_cast<std::uint32_t>(root);
    return flatten(tree, boxes, {options.max_leaf_size, options.max_depth, options.costs});
}

}  // namespace bvhkit

#pragma once
// Optimizer: reinsertion of badly placed subtrees (Bittner, Hapala, Havran 2013, "Fast
// insertion-based optimization of bounding volume hierarchies"). Works on any Bvh, whatever built
// it, keeping its leaves as they are and changing only the internal nodes above them.
//
// Each pass ranks every node X (leaves included) by how badly it looks placed, A(P)^2 / A(X) with P
// its parent (P is large, so X is paid for high up, and much larger than X, so X shares it with
// something far away), and takes the worst `batch` of them. X is detached (its sibling takes P's
// place) and inserted again next to the sibling that raises the SAH cost least, found exactly by
// the dynamic tree's branch and bound (dynamic/tree_insertion.hpp), with P reused as the new
// parent. X's old place is among the candidates, so no move raises the cost (the paper reinserts
// X's two children instead, which explores more but can lose). Passes repeat until one gains less
// than `min_gain` of the cost, or `max_passes`.
//
// The tree is laid out again with flatten() (which also caps the depth and may collapse subtrees
// into leaves where the SAH says so) and kept only if its SAH cost is lower than the input's; the
// input tree is returned untouched otherwise, so the optimizer never raises the cost.
#include <algorithm>

#include "bvhkit/build/flatten.hpp"
#include "bvhkit/build/insertion.hpp"
#include "bvhkit/build/options.hpp"
#include "bvhkit/dynamic/tree_insertion.hpp"

namespace bvhkit {

struct ReinsertionOptions {
    std::uint32_t max_passes = 8;
    double batch_fraction = 0.05;  // of the nodes, per pass
    double min_gain = 0.002;       // stop when a pass lowers the cost by less (relative)
    FlattenOptions flatten{};
};

struct ReinsertionReport {
    double cost_before = 0, cost_after = 0;  // SAH cost (statistics.hpp) of input and output
    std::uint32_t passes = 0;
    std::size_t reinsertions = 0;
    bool kept = false;  // the optimized tree was better and replaced the input
};

namespace reinsertion_detail {

template <class T, std::size_t N>
double internal_area(const std::vector<dynamic_detail::Node<T, N>>& nodes) {
    double s = 0;
    for (const auto& v : nodes)
        if (!v.is_leaf()) s += double(v.box.area());
    return s;
}

/// Refits from i up to the root (no rotations: the search already chose).
template <class T, std::size_t N>
void refit_up(dynamic_detail::Node<T, N>* nodes, std::int32_t i) {
    for (; i != dynamic_detail::kNullNode; i = nodes[i].parent) dynamic_detail::refit(nodes, i);
}

}  // namespace reinsertion_detail

/// Optimizes `bvh` in place (or leaves it as it is when no better tree was found); `boxes` are the
/// primitive boxes it was built over.
template <class T, std::size_t N>
ReinsertionReport optimize_reinsertion(Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> boxes,
                                       const ReinsertionOptions& options = {}) {
    using Node = dynamic_detail::Node<T, N>;
    constexpr std::int32_t null = dynamic_detail::kNullNode;
    ReinsertionReport report;
    report.cost_before = report.cost_after = sah_cost(bvh, options.flatten.costs);
    if (bvh.nodes.size() < 7) return report;  // nothing to move in a tree this small

    // The Bvh as a pool with parent links: same indices; a leaf remembers its own index.
    std::vector<Node> nodes(bvh.nodes.size());
    for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
        const auto& b = bvh.nodes[i];
        nodes[i].box = b.bounds;
        if (b.is_leaf()) {
            nodes[i].child1 = null;
            nodes[i].child2 = static_cast<std::int32_t>(i);
        } else {
            nodes[i].child1 = static_cast<std::int32_t>(b.left());
            nodes[i].child2 = static_cast<std::int32_t>(b.right());
            nodes[b.left()].parent = nodes[b.right()].parent = static_cast<std::int32_t>(i);
        }
    }
    for (std::size_t i = nodes.size(); i-- > 0;)  // children after parents: heights bottom-up
        if (!nodes[i].is_leaf()) dynamic_detail::refit(nodes.data(), std::int32_t(i));
    std::int32_t root = 0;

    std::vector<dynamic_detail::SiblingCandidate<double>> heap;
    std::vector<std::pair<double, std::int32_t>> ranked;
    // Puts the detached subtree `x` back next to its best sibling, with `parent` as the new node.
    const auto insert = [&](std::int32_t x, std::int32_t parent) {
        const std::int32_t s = dynamic_detail::find_sibling_branch_and_bound(
            nodes.data(), root, nodes[x].box, heap, insertion_max_expansions);
        const std::int32_t old_parent = nodes[s].parent;
        Node& p = nodes[parent];
        p.parent = old_parent;
        p.child1 = s;
        p.child2 = x;
        nodes[s].parent = parent;
        nodes[x].parent = parent;
        if (old_parent == null) {
            root = parent;
        } else {
            Node& op = nodes[old_parent];
            (op.child1 == s ? op.child1 : op.child2) = parent;
        }
        reinsertion_detail::refit_up(nodes.data(), parent);
    };

    // How badly x looks placed: its parent is large (x is paid for high up) and much larger than
    // x itself (x shares it with something far away): A(P) * A(P) / A(x).
    const auto inefficiency = [&](std::int32_t x) {
        const double ap = double(nodes[nodes[x].parent].box.area());
        return ap * ap / std::max(double(nodes[x].box.area()), 1e-300);
    };
    double cost = reinsertion_detail::internal_area(nodes);
    for (std::uint32_t pass = 0; pass < options.max_passes; ++pass) {
        ranked.clear();
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            const Node& x = nodes[i];
            if (std::int32_t(i) == root || x.parent == root) continue;
            ranked.emplace_back(inefficiency(std::int32_t(i)), std::int32_t(i));
        }
        if (ranked.empty()) break;
        const std::size_t batch = std::clamp<std::size_t>(
            std::size_t(options.batch_fraction * double(ranked.size())), 1, ranked.size());
        const auto worse = [](const auto& a, const auto& b) {
            return a.first != b.first ? a.first > b.first : a.second < b.second;
        };
        std::partial_sort(ranked.begin(), ranked.begin() + std::ptrdiff_t(batch), ranked.end(),
                          worse);
        for (std::size_t k = 0; k < batch; ++k) {
            const std::int32_t x = ranked[k].second;
            // Earlier moves in this pass may have changed x's place; skip what no longer fits.
            if (x == root || nodes[x].parent == null || nodes[x].parent == root) continue;
            // Detach x: its sibling takes its parent's place, the ancestors shrink.
            const std::int32_t p = nodes[x].parent;
            const std::int32_t g = nodes[p].parent;
            const std::int32_t s = nodes[p].child1 == x ? nodes[p].child2 : nodes[p].child1;
            nodes[s].parent = g;
            Node& gn = nodes[g];
            (gn.child1 == p ? gn.child1 : gn.child2) = s;
            reinsertion_detail::refit_up(nodes.data(), g);
            nodes[x].parent = null;
            insert(x, p);
            ++report.reinsertions;
        }
        ++report.passes;
        const double now = reinsertion_detail::internal_area(nodes);
        const double gain = (cost - now) / std::max(cost, 1e-300);
        cost = now;
        if (gain < options.min_gain) break;
    }

    BinaryTree tree;
    tree.order = bvh.primitive_indices;
    tree.reserve(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (nodes[i].is_leaf())
            tree.add_leaf(bvh.nodes[i].first, bvh.nodes[i].count);
        else
            tree.add_internal(std::uint32_t(nodes[i].child1), std::uint32_t(nodes[i].child2));
    }
    tree.root = std::uint32_t(root);
    Bvh<Aabb<T, N>> optimized = flatten(tree, boxes, options.flatten);
    const double after = sah_cost(optimized, options.flatten.costs);
    if (after < report.cost_before) {
        bvh = std::move(optimized);
        report.cost_after = after;
        report.kept = true;
    }
    return report;
}

}  // namespace bvhkit

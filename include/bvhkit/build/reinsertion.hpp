#pragma once
// Optimizer: reinsertion of badly placed subtrees (Bittner, Hapala, Havran 2013, "Fast
// insertion-based optimization of bounding volume hierarchies"). Works on any Bvh, whatever built
// it, keeping its leaves as they are and changing only the internal nodes above them.
//
// Each pass ranks every node X (leaves included) by how badly it looks placed, A(P)^2 / A(X) with P
// its parent (P is large, so X is paid for high up, and much larger than X, so X shares it with
// something far away), and takes the worst `batch` of them. X is detached (its sibling takes P's
// place) and inserted again next to the sibling that raises the SAH cost least, found exactly by
// the branch and bound of the linked tree (bvh/linked_tree.hpp), with P reused as the new
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

/// Optimizes `bvh` in place (or leaves it as it is when no better tree was found); `boxes` are the
/// primitive boxes it was built over.
template <class T, std::size_t N>
ReinsertionReport optimize_reinsertion(Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> boxes,
                                       const ReinsertionOptions& options = {}) {
    ReinsertionReport report;
    report.cost_before = report.cost_after = sah_cost(bvh, options.flatten.costs);
    if (bvh.nodes.size() < 7) return report;  // nothing to move in a tree this small

    // The Bvh as a linked tree: same indices; a leaf's value is its own index. Every detach()
    // frees x's parent and the insert() that follows takes that node again, so the pool stays full
    // and the leaves keep their indices.
    LinkedTree<T, N> linked;
    linked.assign(bvh);
    InsertionOptions insertion;
    insertion.strategy = InsertionStrategy::BranchAndBound;
    insertion.rotate = false;  // the search already chose
    insertion.float_costs = false;
    insertion.max_expansions = insertion_max_expansions;
    const auto parent = [&](std::int32_t x) { return linked.node(x).parent; };

    // How badly x looks placed: its parent is large (x is paid for high up) and much larger than
    // x itself (x shares it with something far away): A(P) * A(P) / A(x).
    const auto inefficiency = [&](std::int32_t x) {
        const double ap = double(linked.node(parent(x)).box.area());
        return ap * ap / std::max(double(linked.node(x).box.area()), 1e-300);
    };
    std::vector<std::pair<double, std::int32_t>> ranked;
    double cost = linked.sah_cost();
    for (std::uint32_t pass = 0; pass < options.max_passes; ++pass) {
        ranked.clear();
        for (std::size_t i = 0; i < linked.capacity(); ++i) {
            const auto x = std::int32_t(i);
            if (x == linked.root() || parent(x) == linked.root()) continue;
            ranked.emplace_back(inefficiency(x), x);
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
            if (x == linked.root() || parent(x) == linked::null || parent(x) == linked.root())
                continue;
            linked.detach(x, false);
            linked.insert(x, insertion);
            ++report.reinsertions;
        }
        ++report.passes;
        const double now = linked.sah_cost();
        const double gain = (cost - now) / std::max(cost, 1e-300);
        cost = now;
        if (gain < options.min_gain) break;
    }

    BinaryTree tree;
    tree.order = bvh.primitive_indices;
    tree.reserve(linked.capacity());
    for (std::size_t i = 0; i < linked.capacity(); ++i) {
        const auto& v = linked.node(std::int32_t(i));
        if (v.is_leaf())
            tree.add_leaf(bvh.nodes[i].first, bvh.nodes[i].count);
        else
            tree.add_internal(std::uint32_t(v.child1), std::uint32_t(v.child2));
    }
    tree.root = std::uint32_t(linked.root());
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

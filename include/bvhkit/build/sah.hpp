#pragma once
// The surface area heuristic, written once for every builder (binned, sweep, and later insertion
// and the dynamic tree). With a ray hitting a node, the chance it also hits a child is
// A(child)/A(node) (Goldsmith and Salmon 1987; MacDonald and Booth 1990), so
//   split cost = C_trav + C_isect * (A_L N_L + A_R N_R) / A_node,   leaf cost = C_isect * N,
// where N counts a leaf's tests: its primitives, or blocks of them (SahCosts::leaf_block).
#include "bvhkit/bvh/statistics.hpp"

namespace bvhkit {

/// The part of the split cost that varies between candidate splits of one node: A_L N_L + A_R N_R,
/// the counts in leaf tests (SahCosts::leaf_tests).
template <class T>
inline T sah_partial_cost(const SahCosts& costs, T left_area, std::uint32_t left_count,
                          T right_area, std::uint32_t right_count) {
    return left_area * T(costs.leaf_tests(left_count)) +
           right_area * T(costs.leaf_tests(right_count));
}

/// True when a node of `count` primitives and area `node_area` is a leaf whatever its split: it
/// fits one leaf test, and a split costs C_trav plus at least one test on a child, no less than
/// the one test of the leaf. A flat node is left to sah_split_beats_leaf, which splits it.
template <class T>
inline bool sah_leaf_certain(const SahCosts& costs, std::uint32_t count, T node_area) {
    return count <= costs.block() && costs.traversal >= costs.intersection && node_area > T(0);
}

/// True when splitting (with the best partial cost found) is cheaper than a leaf of `count`.
template <class T>
inline bool sah_split_beats_leaf(const SahCosts& costs, T best_partial_cost, T node_area,
                                 std::uint32_t count) {
    const double leaf = costs.intersection * costs.leaf_tests(count);
    // A flat node (zero area) gives no information; split it if the children are smaller sets.
    if (!(node_area > T(0))) return true;
    const double split =
        costs.traversal + costs.intersection * double(best_partial_cost) / node_area;
    return split < leaf;
}

}  // namespace bvhkit

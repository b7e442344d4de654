#pragma once
// The surface area heuristic, written once for every builder (binned, sweep, and later insertion
// and the dynamic tree). With a ray hitting a node, the chance it also hits a child is
// A(child)/A(node) (Goldsmith and Salmon 1987; MacDonald and Booth 1990), so
//   split cost = C_trav + C_isect * (A_L N_L + A_R N_R) / A_node,   leaf cost = C_isect * N.
#include "bvhkit/bvh/statistics.hpp"

namespace bvhkit {

/// The part of the split cost that varies between candidate splits of one node: A_L N_L + A_R N_R.
template <class T>
inline T sah_partial_cost(T left_area, std::uint32_t left_count, T right_area,
                          std::uint32_t right_count) {
    return left_area * T(left_count) + right_area * T(right_count);
}

/// True when splitting (with the best partial cost found) is cheaper than a leaf of `count`.
template <class T>
inline bool sah_split_beats_leaf(const SahCosts& costs, T best_partial_cost, T node_area,
                                 std::uint32_t count) {
    const double leaf = costs.intersection * count;
    // A flat node (zero area) gives no information; split it if the children are smaller sets.
    if (!(node_area > T(0))) return true;
    const double split =
        costs.traversal + costs.intersection * double(best_partial_cost) / node_area;
    return split < leaf;
}

}  // namespace bvhkit

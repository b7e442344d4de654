#pragma once
// collapse_to_wide_sah: the collapse of bvh/wide_bvh.hpp with each leaf child chosen by a surface
// area cost rather than by a primitive count. Bottom up over the binary tree, a subtree becomes
// one leaf child where testing all its groups costs no more than opening it: a share of a wide
// node's test plus the best of its two halves (the SAH of Goldsmith and Salmon 1987 and MacDonald
// and Booth 1990, priced for wide nodes and groups as in Wald et al. 2008, "Getting rid of
// packets"). Where the boxes of a subtree overlap little (a scanned surface), its halves cost about
// what the whole does and large leaves win; where they overlap (a triangle soup, the walls and
// floors of a building) a ray meets most of the halves' boxes anyway and the subtree opens.
#include <cmath>
#include <cstdint>
#include <vector>

#include "bvhkit/bvh/wide_bvh.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit {

/// What collapse_to_wide_sah weighs, in any one unit (only the ratio of the costs matters).
struct WideCollapseCosts {
    double node = 1;                // one wide node's test (all its lanes at once)
    double group = 1;               // one triangle group's test (all its lanes at once)
    std::uint32_t group_lanes = 8;  // primitives a group holds (4 or 8)
    std::uint32_t max_leaf = 64;    // a leaf child never holds more primitives than this
};

namespace wide_detail {

/// For each binary node, whether collapse_to_wide_sah makes it a leaf child once reached: the
/// costs' decision, bottom up (children follow their parents in bvh.nodes).
template <int W, class T>
std::vector<std::uint8_t> sah_leaf_choice(const Bvh<Aabb<T, 3>>& bvh,
                                          const WideCollapseCosts& costs) {
    const auto& nodes = bvh.nodes;
    const std::size_t n = nodes.size();
    std::vector<std::uint8_t> leaf(n, 0);
    std::vector<double> best(n, 0);
    // Groups of four slots under each node (a leaf child pads each binary leaf to four, see
    // append_leaf_groups), and primitives under it.
    std::vector<std::uint32_t> fours(n, 0);
    const std::vector<std::uint32_t> under = primitives_under(bvh);
    // A wide node replaces W - 1 inner binary nodes: each opened one carries that share of its
    // test.
    const double open_share = costs.node / double(W - 1);
    const std::uint32_t lanes = costs.group_lanes;
    for (std::size_t i = n; i-- > 0;) {
        const auto& b = nodes[i];
        fours[i] = b.is_leaf() ? (b.count + 3) / 4 : fours[b.left()] + fours[b.right()];
        const double area = double(b.bounds.area());
        const double groups = double((4 * std::uint64_t(fours[i]) + lanes - 1) / lanes);
        const double as_leaf = area * costs.group * groups;
        if (b.is_leaf()) {
            leaf[i] = 1;
            best[i] = as_leaf;
            continue;
        }
        const double opened = area * open_share + best[b.left()] + best[b.right()];
        leaf[i] = under[i] <= costs.max_leaf && as_leaf <= opened;
        best[i] = leaf[i] ? as_leaf : opened;
    }
    return leaf;
}

}  // namespace wide_detail

/// Collapses `bvh` into a WideSlotBvh<T, W> as collapse_to_wide does, with each subtree made a
/// leaf child where the costs say its groups cost no more than its nodes (see above), and never
/// one of more than costs.max_leaf primitives. Throws Error on costs that are not positive and
/// finite or a group_lanes other than 4 or 8.
template <class T, int W = 4>
WideSlotBvh<T, W> collapse_to_wide_sah(const Bvh<Aabb<T, 3>>& bvh, const WideCollapseCosts& costs,
                                       bool fill_lanes = false) {
    if (!(costs.node > 0 && std::isfinite(costs.node) && costs.group > 0 &&
          std::isfinite(costs.group)))
        throw Error("collapse_to_wide_sah: costs must be positive and finite");
    if (costs.group_lanes != 4 && costs.group_lanes != 8)
        throw Error("collapse_to_wide_sah: group_lanes must be 4 or 8");
    if (bvh.empty()) return {};
    const std::vector<std::uint8_t> leaf = wide_detail::sah_leaf_choice<W>(bvh, costs);
    const auto opens = [&](std::uint32_t n) { return !leaf[n]; };
    return wide_detail::collapse<T, W>(bvh, opens, fill_lanes);
}

}  // namespace bvhkit

#pragma once
// The lane order of a wide ray layout's nodes, chosen for occlusion rays. An any-hit walk may take
// a node's hit children in any order, and it stops at the first triangle it meets, so it takes
// them in lane order (query/ray_wide_stack.hpp) and the layout puts first the children most
// likely to end the walk soon: by the odds that a ray through the child's box meets one of its
// triangles, over the expected cost of finding out, highest first (Ize and Hansen 2011, "RTSAH
// traversal order for occlusion rays"). Closest hits sort the children by distance at every
// node, so this order costs them nothing; in a city it puts the ground ahead of the towers.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <vector>

#include "bvhkit/math/aabb.hpp"
#include "bvhkit/primitives/hit.hpp"

namespace bvhkit {

namespace detail {

/// Lane c's box (a lane with a child), in double so that its area cannot overflow.
template <class Node>
Aabb<double, 3> lane_box(const Node& n, int c) {
    return {{n.lo[0][c], n.lo[1][c], n.lo[2][c]}, {n.lo[3][c], n.lo[4][c], n.lo[5][c]}};
}

/// About twice the area of a leaf's triangles (its groups from `first`, `count` of them): each
/// lane's |e1 x e2| by its L1 norm, within a factor of sqrt(3) of the Euclidean one. Without a
/// square root the loop over a group's lanes vectorizes; the layout is made again at every
/// refit, which pays for this. Padding lanes have corners at 0 and count 0.
template <class Group>
double leaf_crossed_area(const Group* groups, std::uint32_t first, std::uint32_t count) {
    constexpr int L = Group::lanes;
    double sum = 0.0;
    for (std::uint32_t g = first; g < first + count; ++g) {
        const auto& c = groups[g].corner;  // c[3 * k + axis][lane]
        float lane_sum[L];
        for (int l = 0; l < L; ++l) {
            const float ax = c[3][l] - c[0][l], ay = c[4][l] - c[1][l], az = c[5][l] - c[2][l];
            const float bx = c[6][l] - c[0][l], by = c[7][l] - c[1][l], bz = c[8][l] - c[2][l];
            lane_sum[l] = std::fabs(ay * bz - az * by) + std::fabs(az * bx - ax * bz) +
                          std::fabs(ax * by - ay * bx);
        }
        for (int l = 0; l < L; ++l) sum += double(lane_sum[l]);
    }
    return sum;
}

}  // namespace detail

/// Reorders the lanes of every node of `layout` for occlusion rays (see above), empty lanes last.
/// The odds of a child are those of a random line through its box meeting its triangles: twice
/// their area over the box's surface area (Cauchy-Crofton), at most 1 (the area by
/// leaf_crossed_area; 0 for a box of no area). Its cost is the surface area cost of its subtree
/// in the collapse's units: `node_cost` a node and `group_cost` a group of triangles, both
/// positive.
/// `nodes` are RayNode<W> (query/ray_wide_layout.hpp), `groups` the layout's triangle groups.
template <class Nodes, class Group>
void order_lanes_for_occlusion(Nodes& nodes, const Group* groups, double node_cost,
                               double group_cost) {
    using Node = typename Nodes::value_type;
    constexpr int W = int(std::size(Node{}.child));
    // Per node, once its lanes are ordered: its triangles' area and its subtree's cost.
    std::vector<double> area(nodes.size(), 0.0), cost(nodes.size(), 0.0);
    // Children lie after their parents (collapse_to_wide): backwards, every child comes first.
    for (std::size_t i = nodes.size(); i-- > 0;) {
        Node& n = nodes[i];
        double lane_area[W] = {}, lane_cost[W] = {}, box[W] = {}, key[W];
        Aabb<double, 3> node_bounds;  // empty, grown by each child's box
        for (int c = 0; c < W; ++c) {
            key[c] = -1.0;  // empty lanes last
            if (n.child[c] == invalid_index) continue;
            const Aabb<double, 3> child_box = detail::lane_box(n, c);
            node_bounds.grow(child_box);
            box[c] = child_box.area();
            const bool leaf = n.groups[c] > 0;
            lane_area[c] = leaf ? detail::leaf_crossed_area(groups, n.child[c], n.groups[c])
                                : area[n.child[c]];
            lane_cost[c] = leaf ? group_cost * n.groups[c] : cost[n.child[c]];
            // A box of no area (a segment, a point) holds only triangles of no area, never hit.
            const double odds =
                box[c] > 0.0 ? std::min(1.0, lane_area[c] / box[c]) : (lane_area[c] > 0.0);
            key[c] = odds / lane_cost[c];
            // Coordinates near float's limits can make an area or a cost inf or NaN: such a
            // lane goes after the others with children, so that the sort sees a strict order.
            if (!(key[c] >= 0.0) || key[c] == std::numeric_limits<double>::infinity()) key[c] = 0.0;
        }
        const double node_box = node_bounds.area();
        cost[i] = node_cost;
        for (int c = 0; c < W; ++c)
            if (n.child[c] != invalid_index) {
                area[i] += lane_area[c];
                cost[i] += (node_box > 0.0 ? box[c] / node_box : 1.0) * lane_cost[c];
            }
        // Highest key first, equal keys in lane order: an insertion sort of at most eight lanes
        // (std::stable_sort would allocate a buffer at every node).
        int order[W];
        for (int c = 0; c < W; ++c) {
            int j = c;
            for (; j > 0 && key[order[j - 1]] < key[c]; --j) order[j] = order[j - 1];
            order[j] = c;
        }
        const Node old = n;
        for (int c = 0; c < W; ++c) {
            for (int r = 0; r < 6; ++r) n.lo[r][c] = old.lo[r][order[c]];
            n.child[c] = old.child[order[c]];
            n.groups[c] = old.groups[order[c]];
        }
    }
}

}  // namespace bvhkit

#pragma once
// Visiting a BSP's polygons in visibility order from an eye point (Fuchs, Kedem and Naylor 1980):
// at each node, the subtree on the eye's side, then the node's own polygons, then the far subtree.
// Front to back, a polygon that hides part of another from the eye comes first; back to front (the
// painter's order) it comes last. The order is exact between cells; inside a leaf that holds
// several polygons (a build halted by leaf_size or max_depth) they come in stored order.
#include <cstdint>

#include "bvhkit/bsp/bsp_tree.hpp"
#include "bvhkit/bsp/stack.hpp"

namespace bvhkit {

namespace bsp_detail {

template <class T, std::size_t N, class F>
void visit_in_order(const BspTree<T, N>& tree, const Vec<T, N>& eye, bool front_to_back, F&& f) {
    struct Entry {
        std::uint32_t node;
        bool emit;  // the node's own polygons, its subtrees already scheduled
    };
    const auto& nodes = tree.nodes();
    BspTraversalStack<Entry> stack(2 * tree.statistics().depth + 4);
    stack.push({0, false});
    while (!stack.empty()) {
        const Entry e = stack.pop();
        const BspNode<T, N>& n = nodes[e.node];
        if (e.emit || n.is_leaf()) {
            for (std::uint32_t i = n.first; i < n.first + n.count; ++i) f(i);
            continue;
        }
        // An eye inside the thick plane sees the node's polygons edge on: either side is right.
        const bool eye_front = n.plane.distance(eye) >= T(0);
        const std::uint32_t near = eye_front ? n.front : n.back;
        const std::uint32_t far = eye_front ? n.back : n.front;
        stack.push({front_to_back ? far : near, false});
        stack.push({e.node, true});
        stack.push({front_to_back ? near : far, false});
    }
}

}  // namespace bsp_detail

/// Calls f(polygon index) for every stored polygon, nearest the eye first (polygons().polygons
/// [index].source is the input triangle).
template <class T, std::size_t N, class F>
void for_each_front_to_back(const BspTree<T, N>& tree, const Vec<T, N>& eye, F&& f) {
    bsp_detail::visit_in_order(tree, eye, true, f);
}

/// Calls f(polygon index) for every stored polygon, farthest from the eye first (painter's order).
template <class T, std::size_t N, class F>
void for_each_back_to_front(const BspTree<T, N>& tree, const Vec<T, N>& eye, F&& f) {
    bsp_detail::visit_in_order(tree, eye, false, f);
}

}  // namespace bvhkit

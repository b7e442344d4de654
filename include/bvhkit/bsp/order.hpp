#pragma once
// Visiting a BSP's polygons in visibility order from an eye point (Fuchs, Kedem and Naylor 1980):
// at each node, the subtree on the eye's side, then the node's own polygons, then the far subtree.
// Front to back, a polygon that hides part of another from the eye comes first; back to front (the
// painter's order) it comes last. The order is exact between cells; inside a leaf that holds
// several polygons (a build halted by leaf_size or max_depth) they come in stored order.
//
// A pre-order walk (walk_depth_first, walk/walks.hpp) of a tree whose inner nodes have three
// children: the near subtree, the node's own polygons as a leaf, the far subtree.
#include <cstdint>

#include "bvhkit/bsp/bsp_tree.hpp"
#include "bvhkit/bsp/stack.hpp"
#include "bvhkit/walk/walks.hpp"

namespace bvhkit {

namespace bsp_detail {

/// A node of the visit: a whole subtree, or (emit) only the node's own polygons.
struct OrderRef {
    std::uint32_t node;
    bool emit;
};

template <class T, std::size_t N>
struct OrderNodes {
    using Ref = OrderRef;
    const BspNode<T, N>* nodes;
    Ref root() const { return {0, false}; }
    bool is_leaf(const Ref& r) const { return r.emit || nodes[r.node].is_leaf(); }
};

template <class T, std::size_t N, class F>
void visit_in_order(const BspTree<T, N>& tree, const Vec<T, N>& eye, bool front_to_back, F&& f) {
    const auto& nodes = tree.nodes();
    const auto on_leaf = [&](const OrderRef& r) {
        const BspNode<T, N>& n = nodes[r.node];
        for (std::uint32_t i = n.first; i < n.first + n.count; ++i) f(i);
        return true;
    };
    // The first subtree is gone on with; the node's own polygons, then the other subtree, wait.
    const auto open = [&](OrderRef& r, BspTraversalStack<OrderRef>& stack) -> bool {
        const BspNode<T, N>& n = nodes[r.node];
        // An eye inside the thick plane sees the node's polygons edge on: either side is right.
        const bool eye_front = n.plane.distance(eye) >= T(0);
        const std::uint32_t near = eye_front ? n.front : n.back;
        const std::uint32_t far = eye_front ? n.back : n.front;
        stack.push({front_to_back ? far : near, false});
        stack.push({r.node, true});
        r = {front_to_back ? near : far, false};
        return true;
    };
    BspTraversalStack<OrderRef> stack(2 * tree.statistics().depth + 4);
    walk_depth_first(OrderNodes<T, N>{nodes.data()}, stack, EnterAll{}, on_leaf, open);
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

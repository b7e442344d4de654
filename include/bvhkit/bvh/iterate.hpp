#pragma once
// Walking a Bvh's nodes: depth-first (pre-order), breadth-first (level by level), leaves only, and
// the nodes at a given depth. Callbacks receive (node index, depth); the root has depth 0. These
// walks are for inspection and tools, not hot paths: they use a growable stack or queue.
#include <deque>

#include "bvhkit/bvh/bvh.hpp"

namespace bvhkit {

template <class Volume, class F>
void for_each_node_depth_first(const Bvh<Volume>& bvh, F&& visit) {
    if (bvh.empty()) return;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0u, 0u}};
    while (!stack.empty()) {
        const auto [index, depth] = stack.back();
        stack.pop_back();
        visit(index, depth);
        const auto& node = bvh.nodes[index];
        if (!node.is_leaf()) {
            stack.emplace_back(node.right(),
                               depth + 1);  // right pushed first: left is visited first
            stack.emplace_back(node.left(), depth + 1);
        }
    }
}

template <class Volume, class F>
void for_each_node_breadth_first(const Bvh<Volume>& bvh, F&& visit) {
    if (bvh.empty()) return;
    std::deque<std::pair<std::uint32_t, std::uint32_t>> queue{{0u, 0u}};
    while (!queue.empty()) {
        const auto [index, depth] = queue.front();
        queue.pop_front();
        visit(index, depth);
        const auto& node = bvh.nodes[index];
        if (!node.is_leaf()) {
            queue.emplace_back(node.left(), depth + 1);
            queue.emplace_back(node.right(), depth + 1);
        }
    }
}

template <class Volume, class F>
void for_each_leaf(const Bvh<Volume>& bvh, F&& visit) {
    for_each_node_depth_first(bvh, [&](std::uint32_t index, std::uint32_t depth) {
        if (bvh.nodes[index].is_leaf()) visit(index, depth);
    });
}

template <class Volume>
std::vector<std::uint32_t> nodes_at_depth(const Bvh<Volume>& bvh, std::uint32_t wanted) {
    std::vector<std::uint32_t> out;
    for_each_node_breadth_first(bvh, [&](std::uint32_t index, std::uint32_t depth) {
        if (depth == wanted) out.push_back(index);
    });
    return out;
}

}  // namespace bvhkit

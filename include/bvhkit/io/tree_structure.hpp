#pragma once
// check_tree_structure(): what a loaded tree must satisfy before any query may walk it, whatever
// its boxes hold. Loaders run it even when the caller opts out of validate(), which adds the
// geometric checks (enclosure, finite boxes, each primitive once): a tree that passes this one can
// give wrong answers but cannot make a query read out of range, overflow the traversal stack or
// loop. Linear time; allocates two bytes per node and per slot.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit::serial_detail {

/// Children in range and after their parent, every node reached exactly once from the root (no
/// cycle, no shared child), depth <= max_bvh_depth, leaf runs non-empty and tiling the slots
/// exactly, every primitive index < primitive_count (callers index their own arrays with it).
template <class Volume>
void check_tree_structure(const Bvh<Volume>& bvh, std::uint64_t primitive_count, const char* what) {
    auto fail = [&](const std::string& m) { throw Error(std::string(what) + ": " + m); };
    const std::size_t node_count = bvh.nodes.size(), slot_count = bvh.primitive_indices.size();
    for (std::size_t s = 0; s < slot_count; ++s)
        if (bvh.primitive_indices[s] >= primitive_count)
            fail("slot " + std::to_string(s) + " names primitive " +
                 std::to_string(bvh.primitive_indices[s]) + " of " +
                 std::to_string(primitive_count));
    if (node_count == 0) {
        if (slot_count) fail("no nodes but " + std::to_string(slot_count) + " slots");
        return;
    }
    std::vector<std::uint8_t> node_seen(node_count, 0), slot_seen(slot_count, 0);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0u, 0u}};
    node_seen[0] = 1;
    while (!stack.empty()) {
        const auto [index, depth] = stack.back();
        stack.pop_back();
        const auto& node = bvh.nodes[index];
        const std::string name = "node " + std::to_string(index);
        if (depth > max_bvh_depth) fail(name + " is deeper than " + std::to_string(max_bvh_depth));
        if (node.is_leaf()) {
            if (std::uint64_t(node.first) + node.count > slot_count)
                fail(name + ": leaf run out of range");
            for (std::uint32_t s = node.first; s < node.first + node.count; ++s)
                if (slot_seen[s]++) fail(name + ": slot " + std::to_string(s) + " in two leaves");
            continue;
        }
        // first > index keeps every path going forward, so no cycle; node_seen forbids sharing.
        if (node.first <= index || std::uint64_t(node.first) + 1 >= node_count)
            fail(name + ": children " + std::to_string(node.first) + " out of order or range");
        for (const std::uint32_t c : {node.left(), node.right()}) {
            if (node_seen[c]++) fail("node " + std::to_string(c) + " has two parents");
            stack.emplace_back(c, depth + 1);
        }
    }
    for (std::size_t i = 0; i < node_count; ++i)
        if (!node_seen[i]) fail("node " + std::to_string(i) + " is unreachable");
    for (std::size_t s = 0; s < slot_count; ++s)
        if (!slot_seen[s]) fail("slot " + std::to_string(s) + " is in no leaf");
}

}  // namespace bvhkit::serial_detail

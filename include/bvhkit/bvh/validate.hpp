#pragma once
// validate(): checks every invariant of a Bvh against the primitive boxes it was built from, and
// throws bvhkit::Error naming the first broken one. Tests call it after every build and refit.
//
// Invariants: children indices are in range and larger than the parent's (the layout refit relies
// on); every node is reached exactly once from the root; depth <= max_bvh_depth; leaf runs are
// non-empty and tile `primitive_indices` exactly; every primitive index is in range and appears
// once; every primitive with a finite, non-empty box is in the tree and none with a non-finite or
// empty box is (the builders' rule; a primitive listed as skipped must be absent); each node's box
// encloses its children's boxes and its primitives' boxes.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit {

/// The tree's shape, whatever its boxes hold: children in range and after their parent, every node
/// reached exactly once from the root (no cycle, no shared child), depth <= max_bvh_depth, leaf
/// runs non-empty and tiling the slots exactly. A tree that passes cannot make a walk read out of
/// range, overflow its stack or loop. fail(message) must throw; on_slot(node, slot) and
/// on_child(node, child) add the caller's checks. Linear; two bytes per node and per slot.
template <class Tree, class Fail, class OnSlot, class OnChild>  // Tree: a Bvh or a BvhView
void check_structure(const Tree& bvh, Fail&& fail, OnSlot&& on_slot, OnChild&& on_child) {
    const std::size_t node_count = bvh.nodes.size(), slot_count = bvh.primitive_indices.size();
    if (node_count == 0) {
        if (slot_count) fail("no nodes but " + std::to_string(slot_count) + " primitive slots");
        return;
    }
    std::vector<std::uint8_t> node_seen(node_count, 0), slot_seen(slot_count, 0);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0u, 0u}};
    node_seen[0] = 1;
    while (!stack.empty()) {
        // Plain variables, not a structured binding: clang 14 cannot capture one in a lambda.
        const std::uint32_t index = stack.back().first, depth = stack.back().second;
        stack.pop_back();
        const auto& node = bvh.nodes[index];
        const auto name = [&] { return "node " + std::to_string(index); };
        if (depth > max_bvh_depth)
            fail(name() + " is deeper than " + std::to_string(max_bvh_depth));
        if (node.is_leaf()) {
            if (std::uint64_t(node.first) + node.count > slot_count)
                fail(name() + ": leaf run out of range");
            for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
                if (slot_seen[s]++)
                    fail(name() + ": primitive slot " + std::to_string(s) + " in two leaves");
                on_slot(node, s);
            }
            continue;
        }
        // first > index keeps every path going forward, so no cycle; node_seen forbids sharing.
        if (node.first <= index || std::uint64_t(node.first) + 1 >= node_count)
            fail(name() + ": children " + std::to_string(node.first) + " out of order or range");
        for (const std::uint32_t c : {node.left(), node.right()}) {
            if (node_seen[c]++) fail("node " + std::to_string(c) + " has two parents");
            on_child(node, c);
            stack.emplace_back(c, depth + 1);
        }
    }
    for (std::size_t i = 0; i < node_count; ++i)
        if (!node_seen[i]) fail("node " + std::to_string(i) + " is unreachable");
    for (std::size_t s = 0; s < slot_count; ++s)
        if (!slot_seen[s]) fail("primitive slot " + std::to_string(s) + " is in no leaf");
}

/// `skipped`: the primitives the build left out (BuildReport::skipped, TriangleBvh::skipped()),
/// which must be absent whatever `primitive_boxes` says of them (a box computed elsewhere may have
/// lost the NaN that made the build skip it); any primitive whose box is non-finite or empty may be
/// absent without being listed (the builders' rule); every other one must be in the tree.
template <class T, std::size_t N>
void validate(BvhView<Aabb<T, N>> bvh, std::span<const Aabb<T, N>> primitive_boxes,
              std::span<const std::uint32_t> skipped) {
    auto fail = [](const std::string& what) { throw Error("Bvh::validate: " + what); };
    std::vector<std::uint8_t> primitive_seen(primitive_boxes.size(), 0);
    const auto usable = [&](std::size_t p) {
        return primitive_boxes[p].is_finite() && !primitive_boxes[p].is_empty();
    };
    for (std::uint32_t p : bvh.primitive_indices) {
        if (p >= primitive_boxes.size())
            fail("primitive index " + std::to_string(p) + " out of range (" +
                 std::to_string(primitive_boxes.size()) + " primitives)");
        if (primitive_seen[p]++) fail("primitive " + std::to_string(p) + " appears twice");
        if (!usable(p))
            fail("primitive " + std::to_string(p) +
                 " has a non-finite or empty box but is in the tree");
    }
    std::vector<std::uint8_t> listed(primitive_boxes.size(), 0);
    for (std::uint32_t p : skipped) {
        if (p >= primitive_boxes.size())
            fail("skipped primitive " + std::to_string(p) + " out of range");
        if (primitive_seen[p])
            fail("primitive " + std::to_string(p) + " is listed as skipped but is in the tree");
        listed[p] = 1;
    }
    for (std::size_t p = 0; p < primitive_boxes.size(); ++p)
        if (!primitive_seen[p] && !listed[p] && usable(p))
            fail("primitive " + std::to_string(p) + " is missing from the tree");

    check_structure(
        bvh, fail,
        [&](const auto& leaf, std::uint32_t s) {
            if (!leaf.bounds.contains(primitive_boxes[bvh.primitive_indices[s]]))
                fail("node " + std::to_string(&leaf - bvh.nodes.data()) +
                     " does not enclose primitive " + std::to_string(bvh.primitive_indices[s]));
        },
        [&](const auto& node, std::uint32_t c) {
            if (!node.bounds.contains(bvh.nodes[c].bounds))
                fail("node " + std::to_string(&node - bvh.nodes.data()) +
                     " does not enclose its child " + std::to_string(c));
        });
}

template <class T, std::size_t N>
void validate(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
              std::span<const std::uint32_t> skipped = {}) {
    validate(bvh_view(bvh), primitive_boxes, skipped);
}

template <class T, std::size_t N>
void validate(const Bvh<Aabb<T, N>>& bvh, const std::vector<Aabb<T, N>>& primitive_boxes,
              std::span<const std::uint32_t> skipped = {}) {
    validate(bvh_view(bvh), std::span<const Aabb<T, N>>(primitive_boxes), skipped);
}

}  // namespace bvhkit

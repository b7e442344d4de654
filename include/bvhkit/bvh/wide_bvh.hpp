#pragma once
// WideSlotBvh<T, W = 4>: a binary Bvh of 3D boxes collapsed into nodes of up to W children whose
// boxes lie side by side, one array per axis and bound, so that one SIMD instruction measures a
// point against all of them (W = 4 for SSE, 8 for AVX) (the wide layout of Wald, Benthin and
// Boulos 2008, "Getting rid of packets", and Dammertz et al. 2008, "Shallow bounding volume
// hierarchies"). Half as many levels as the binary tree means half as many dependent loads on a
// walk that misses the caches at every node.
//
// A leaf child is a run of groups of four leaf slots of the binary tree (its primitive slots, in
// groups so that a caller can store four primitives side by side too); invalid_index pads a
// group. A binary subtree of at most `leaf_limit` primitives becomes one leaf child, which is
// what lets small binary leaves share a group.
#include <string>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/primitives/hit.hpp"  // invalid_index

namespace bvhkit {

template <class T, int W = 4>
struct alignas(64) WideSlotNode {
    static constexpr int width = W;
    T lo[3][W];  // lo[axis][child]: the children's boxes
    T hi[3][W];
    std::uint32_t
        child[W];  // inner child: node index; leaf child: first group; invalid_index: no child
    std::uint32_t groups[W];  // leaf child: how many groups; 0 for an inner child or none

    bool is_leaf(int c) const { return groups[c] != 0; }
    bool has(int c) const { return child[c] != invalid_index; }
    Aabb<T, 3> box(int c) const {
        return Aabb<T, 3>({lo[0][c], lo[1][c], lo[2][c]}, {hi[0][c], hi[1][c], hi[2][c]});
    }
};

template <class T, int W = 4>
struct WideSlotBvh {
    std::vector<WideSlotNode<T, W>> nodes;   // nodes[0] is the root; empty for an empty tree
    std::vector<std::uint32_t> group_slots;  // four slots a group; invalid_index pads

    bool empty() const { return nodes.empty(); }
    std::size_t group_count() const { return group_slots.size() / 4; }
};

// The former names, kept for one release: "WideBvh" read as the ray layout's WideRayBvh
// (query/ray_wide_layout.hpp), a different format (its leaves hold triangles, these slots).
template <class T, int W = 4>
using WideNode [[deprecated("use WideSlotNode")]] = WideSlotNode<T, W>;
template <class T>
using WideNode4 [[deprecated("use WideSlotNode")]] = WideSlotNode<T, 4>;
template <class T, int W = 4>
using WideBvh [[deprecated("use WideSlotBvh")]] = WideSlotBvh<T, W>;
template <class T>
using WideBvh4 [[deprecated("use WideSlotBvh")]] = WideSlotBvh<T, 4>;

namespace wide_detail {

/// Primitives under each binary node.
template <class T>
std::vector<std::uint32_t> primitives_under(const Bvh<Aabb<T, 3>>& bvh) {
    const auto& nodes = bvh.nodes;
    std::vector<std::uint32_t> under(nodes.size(), 0);
    // Children come after their parents: a reverse pass sees both children first.
    for (std::size_t i = nodes.size(); i-- > 0;)
        under[i] =
            nodes[i].is_leaf() ? nodes[i].count : under[nodes[i].left()] + under[nodes[i].right()];
    return under;
}

/// The children a wide node takes for binary node b (which opens): its two children, then, while
/// fewer than W, the one of largest area among those that `opens` accepts is replaced by its two
/// children. Returns how many lanes were filled.
template <int W, class T, class Opens>
int pick_lanes(const Bvh<Aabb<T, 3>>& bvh, std::uint32_t b, Opens&& opens,
               std::uint32_t (&lanes)[W]) {
    const auto& nodes = bvh.nodes;
    lanes[0] = nodes[b].left(), lanes[1] = nodes[b].right();
    int size = 2;
    while (size < W) {
        int pick = -1;
        for (int c = 0; c < size; ++c)
            if (opens(lanes[c]) &&
                (pick < 0 || nodes[lanes[c]].bounds.area() > nodes[lanes[pick]].bounds.area()))
                pick = c;
        if (pick < 0) break;
        const std::uint32_t opened = lanes[pick];
        lanes[pick] = nodes[opened].left();
        lanes[size++] = nodes[opened].right();
    }
    return size;
}

/// Appends the slots of every binary leaf under n to `group_slots`, padded to a group of four;
/// sets the leaf child's first group and group count. `todo` is scratch.
template <class T>
void append_leaf_groups(const Bvh<Aabb<T, 3>>& bvh, std::uint32_t n,
                        std::vector<std::uint32_t>& group_slots, std::vector<std::uint32_t>& todo,
                        std::uint32_t& first, std::uint32_t& groups) {
    first = std::uint32_t(group_slots.size() / 4);
    todo.assign(1, n);
    while (!todo.empty()) {
        const auto& b = bvh.nodes[todo.back()];
        todo.pop_back();
        if (b.is_leaf()) {
            for (std::uint32_t s = b.first; s < b.first + b.count; ++s) group_slots.push_back(s);
        } else {
            todo.insert(todo.end(), {b.right(), b.left()});
        }
    }
    while (group_slots.size() % 4) group_slots.push_back(invalid_index);
    groups = std::uint32_t(group_slots.size() / 4) - first;
}

}  // namespace wide_detail

namespace wide_detail {

/// collapse_to_wide's loop: `opens(n)` says whether binary node n becomes a wide node (else a leaf
/// child); with `fill_lanes`, any inner binary node may open to fill a node's lanes.
template <class T, int W, class Opens>
WideSlotBvh<T, W> collapse(const Bvh<Aabb<T, 3>>& bvh, Opens&& opens, bool fill_lanes) {
    WideSlotBvh<T, W> out;
    if (bvh.empty()) return out;
    const auto& nodes = bvh.nodes;
    const auto fills = [&](std::uint32_t n) { return !nodes[n].is_leaf(); };
    out.group_slots.reserve(bvh.primitive_indices.size() + bvh.primitive_indices.size() / 2);
    std::vector<std::uint32_t> todo;
    // Work items: (binary node, wide node to fill). Preorder, so a parent precedes its children.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> work{{0, 0}};
    out.nodes.reserve(nodes.size() / 3 + 1);
    out.nodes.emplace_back();
    while (!work.empty()) {
        const auto [b, w] = work.back();
        work.pop_back();
        std::uint32_t lanes[W];
        lanes[0] = b;
        const int size = !opens(b)    ? 1
                         : fill_lanes ? pick_lanes<W>(bvh, b, fills, lanes)
                                      : pick_lanes<W>(bvh, b, opens, lanes);
        WideSlotNode<T, W> node{};
        for (int c = 0; c < W; ++c) {
            node.child[c] = invalid_index;
            for (int a = 0; a < 3; ++a) node.lo[a][c] = T(0), node.hi[a][c] = T(0);
        }
        for (int c = 0; c < size; ++c) {
            const std::uint32_t n = lanes[c];
            for (int a = 0; a < 3; ++a)
                node.lo[a][c] = nodes[n].bounds.min[a], node.hi[a][c] = nodes[n].bounds.max[a];
            if (opens(n)) {
                node.child[c] = std::uint32_t(out.nodes.size());
                out.nodes.emplace_back();
                work.emplace_back(n, node.child[c]);
            } else {
                append_leaf_groups(bvh, n, out.group_slots, todo, node.child[c], node.groups[c]);
            }
        }
        out.nodes[w] = node;
    }
    return out;
}

}  // namespace wide_detail

/// Collapses `bvh` into a WideSlotBvh<T, W>. An inner binary node takes up to W children by
/// opening, of its children and grandchildren, the one of largest area until W or none is left to
/// open; a subtree of at most `leaf_limit` primitives becomes one leaf child. With `fill_lanes`,
/// any inner binary node may open to fill a node's lanes, also one of at most `leaf_limit`
/// primitives (whose halves then become two leaf children): the nodes come out full, as a builder
/// that splits the largest child until the node is full makes them, where without it a node whose
/// children are all small enough to be leaves stays at two or three lanes (igea, eight wide,
/// leaf_limit 8: 3.7 lanes a node on average without, 6.9 with).
template <class T, int W = 4>
WideSlotBvh<T, W> collapse_to_wide(const Bvh<Aabb<T, 3>>& bvh, std::uint32_t leaf_limit = 4,
                                   bool fill_lanes = false) {
    if (bvh.empty()) return {};
    const std::vector<std::uint32_t> under = wide_detail::primitives_under(bvh);
    const auto opens = [&](std::uint32_t n) {
        return !bvh.nodes[n].is_leaf() && under[n] > leaf_limit;
    };
    return wide_detail::collapse<T, W>(bvh, opens, fill_lanes);
}

/// Throws Error unless `wide` holds every slot of [0, slot_boxes.size()) exactly once, each inside
/// its leaf child's box, and every inner child's box holds its node's boxes.
template <class T, int W>
void validate(const WideSlotBvh<T, W>& wide, const std::vector<Aabb<T, 3>>& slot_boxes) {
    const auto fail = [](const std::string& what) { throw Error("WideSlotBvh: " + what); };
    if (wide.empty()) {
        if (!slot_boxes.empty())
            fail("empty tree over " + std::to_string(slot_boxes.size()) + " slots");
        return;
    }
    if (wide.group_slots.size() % 4) fail("group_slots is not a whole number of groups");
    std::vector<std::uint8_t> seen(slot_boxes.size(), 0), reached(wide.nodes.size(), 0);
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
        const std::uint32_t w = stack.back();
        stack.pop_back();
        if (w >= wide.nodes.size() || reached[w]++)
            fail("node " + std::to_string(w) + " reached twice or out of range");
        const auto& node = wide.nodes[w];
        if (!node.has(0)) fail("node " + std::to_string(w) + " has no first child");
        for (int c = 0; c < W; ++c) {
            if (!node.has(c)) continue;
            const Aabb<T, 3> box = node.box(c);
            if (!node.is_leaf(c)) {
                const std::uint32_t k = node.child[c];
                if (k <= w || k >= wide.nodes.size())
                    fail("child " + std::to_string(k) + " of node " + std::to_string(w));
                for (int d = 0; d < W; ++d)
                    if (wide.nodes[k].has(d) && !box.contains(wide.nodes[k].box(d)))
                        fail("node " + std::to_string(w) + " lane " + std::to_string(c) +
                             " does not hold its child's boxes");
                stack.push_back(k);
                continue;
            }
            const std::size_t end = std::size_t(node.child[c]) + node.groups[c];
            if (end > wide.group_count())
                fail("leaf groups out of range in node " + std::to_string(w));
            for (std::size_t i = std::size_t(node.child[c]) * 4; i < end * 4; ++i) {
                const std::uint32_t s = wide.group_slots[i];
                if (s == invalid_index) continue;
                if (s >= slot_boxes.size() || seen[s]++)
                    fail("slot " + std::to_string(s) + " out of range or held twice");
                if (!box.contains(slot_boxes[s]))
                    fail("slot " + std::to_string(s) + " outside its leaf box");
            }
        }
    }
    for (std::size_t s = 0; s < seen.size(); ++s)
        if (!seen[s]) fail("slot " + std::to_string(s) + " is in no leaf");
    for (std::size_t w = 0; w < reached.size(); ++w)
        if (!reached[w]) fail("node " + std::to_string(w) + " is unreachable");
}

}  // namespace bvhkit

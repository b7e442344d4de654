// WideSlotBvh (bvh/wide_bvh.hpp): collapse_to_wide of every builder's tree passes validate(), and
// keeps what the header promises, checked here independently of validate(): an inner child holds
// more than leaf_limit primitives, a leaf child at most leaf_limit or exactly one binary leaf, a
// leaf child's groups are the fewest that hold its slots (padding only at the end), every group
// belongs to exactly one leaf child, a node with fewer than four children has only leaf children
// (collapse opens until four or none is left to open), and every node but a leaf-only root has at
// least two. Then validate() itself must reject corrupted copies.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>

#include "bvhkit/build/build.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/bvh/wide_bvh.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

template <class T>
std::vector<Aabb<T, 3>> boxes_of(const std::vector<Triangle<T>>& tris) {
    std::vector<Aabb<T, 3>> boxes;
    for (const auto& t : tris) boxes.push_back(t.bounds());
    return boxes;
}

template <class T>
Bvh<Aabb<T, 3>> build(const std::vector<Aabb<T, 3>>& boxes, const BuildOptions& options) {
    std::vector<Vec<T, 3>> centroids;
    for (const auto& b : boxes) centroids.push_back(b.centroid());
    return build_bvh<T, 3>(boxes, centroids, options);
}

/// slot_boxes[s] = the box of the primitive in binary leaf slot s.
template <class T>
std::vector<Aabb<T, 3>> slot_boxes_of(const Bvh<Aabb<T, 3>>& bvh,
                                      const std::vector<Aabb<T, 3>>& boxes) {
    std::vector<Aabb<T, 3>> out;
    for (std::uint32_t i : bvh.primitive_indices) out.push_back(boxes[i]);
    return out;
}

/// The valid slots of a leaf child, in group order.
template <class T>
std::vector<std::uint32_t> leaf_slots(const WideSlotBvh<T>& wide, const WideSlotNode<T>& node,
                                      int c) {
    std::vector<std::uint32_t> out;
    for (std::size_t i = std::size_t(node.child[c]) * 4;
         i < (std::size_t(node.child[c]) + node.groups[c]) * 4; ++i)
        if (wide.group_slots[i] != invalid_index) out.push_back(wide.group_slots[i]);
    return out;
}

/// The structure collapse promises (see the top of the file); returns the primitives under w.
template <class T>
std::size_t check_node(const WideSlotBvh<T>& wide, std::uint32_t w, std::uint32_t leaf_limit,
                       const std::map<std::uint32_t, std::uint32_t>& binary_leaves,
                       std::vector<std::uint8_t>& group_owner, std::size_t& failures) {
    const auto& node = wide.nodes[w];
    const auto expect = [&](bool ok, const std::string& what) {
        if (!ok && failures++ < 5) ADD_FAILURE() << "wide node " << w << ": " << what;
    };
    int children = 0;
    bool only_leaves = true;
    std::size_t total = 0;
    for (int c = 0; c < 4; ++c) {
        if (!node.has(c)) {
            expect(node.groups[c] == 0, "an absent child with groups");
            continue;
        }
        expect(c == children, "a hole before lane " + std::to_string(c));
        ++children;
        if (!node.is_leaf(c)) {
            only_leaves = false;
            const std::size_t under =
                check_node(wide, node.child[c], leaf_limit, binary_leaves, group_owner, failures);
            expect(under > leaf_limit, "inner child " + std::to_string(c) + " holds only " +
                                           std::to_string(under) + " primitives");
            total += under;
            continue;
        }
        const auto slots = leaf_slots(wide, node, c);
        expect(!slots.empty(), "an empty leaf child");
        expect(node.groups[c] == (slots.size() + 3) / 4,
               "leaf child " + std::to_string(c) + " has " + std::to_string(node.groups[c]) +
                   " groups for " + std::to_string(slots.size()) + " slots");
        // Padding only at the end: the first slots.size() entries are the slots.
        const std::size_t base = std::size_t(node.child[c]) * 4;
        for (std::size_t i = 0; i < std::size_t(node.groups[c]) * 4; ++i)
            expect((wide.group_slots[base + i] != invalid_index) == (i < slots.size()),
                   "padding inside leaf child " + std::to_string(c));
        for (std::size_t g = node.child[c]; g < std::size_t(node.child[c]) + node.groups[c]; ++g)
            if (g < group_owner.size()) expect(group_owner[g]++ == 0, "a group in two leaves");
        if (slots.size() > leaf_limit) {
            // Only a single binary leaf may exceed the limit: a contiguous run that is one leaf.
            const auto lo = *std::min_element(slots.begin(), slots.end());
            const auto hi = *std::max_element(slots.begin(), slots.end());
            const auto it = binary_leaves.find(lo);
            expect(hi - lo + 1 == slots.size() && it != binary_leaves.end() &&
                       it->second == slots.size(),
                   "leaf child " + std::to_string(c) + " holds " + std::to_string(slots.size()) +
                       " > leaf_limit slots and is not one binary leaf");
        }
        total += slots.size();
    }
    expect(children >= 1, "no child");
    if (w != 0) expect(children >= 2, "an inner node with one child");
    expect(children == 4 || only_leaves, "fewer than four children, one of them inner");
    return total;
}

template <class T>
void check_collapse(const Bvh<Aabb<T, 3>>& bvh, const std::vector<Aabb<T, 3>>& boxes,
                    std::uint32_t leaf_limit) {
    SCOPED_TRACE("leaf_limit " + std::to_string(leaf_limit));
    ASSERT_NO_THROW(validate(bvh, std::span<const Aabb<T, 3>>(boxes)));
    const auto slot_boxes = slot_boxes_of(bvh, boxes);
    const WideSlotBvh<T> wide = collapse_to_wide(bvh, leaf_limit);
    ASSERT_NO_THROW(validate(wide, slot_boxes));
    ASSERT_EQ(wide.empty(), bvh.empty());
    // Eight wide (the AVX ray layout): every slot once, inside its boxes, and the same leaf
    // children (the subtrees that do not open do not depend on the width).
    const WideSlotBvh<T, 8> wide8 = collapse_to_wide<T, 8>(bvh, leaf_limit);
    ASSERT_NO_THROW(validate(wide8, slot_boxes));
    EXPECT_EQ(wide8.group_count(), wide.group_count());
    // Lanes filled by opening small subtrees too (the eight-wide ray layout): still every slot
    // once, inside its boxes, and no node fuller than its width.
    ASSERT_NO_THROW(validate(collapse_to_wide<T, 8>(bvh, leaf_limit, true), slot_boxes));
    ASSERT_NO_THROW(validate(collapse_to_wide<T, 4>(bvh, leaf_limit, true), slot_boxes));
    if (wide.empty()) return;
    // Binary leaves reached from the root: first slot -> count.
    std::map<std::uint32_t, std::uint32_t> binary_leaves;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
        const auto& n = bvh.nodes[stack.back()];
        stack.pop_back();
        if (n.is_leaf())
            binary_leaves[n.first] = n.count;
        else
            stack.insert(stack.end(), {n.left(), n.right()});
    }
    std::vector<std::uint8_t> group_owner(wide.group_count(), 0);
    std::size_t failures = 0;
    const std::size_t total = check_node(wide, 0, leaf_limit, binary_leaves, group_owner, failures);
    EXPECT_EQ(total, slot_boxes.size());
    EXPECT_EQ(std::count(group_owner.begin(), group_owner.end(), 0), 0)
        << "groups that belong to no leaf child";
    // The root opens exactly when the binary root is inner and holds more than leaf_limit.
    const bool root_opens = !bvh.root().is_leaf() && slot_boxes.size() > leaf_limit;
    EXPECT_EQ(wide.nodes[0].has(1), root_opens);
}

template <class T>
void check_every_builder(const std::vector<Triangle<T>>& tris) {
    const auto boxes = boxes_of(tris);
    for (const auto& [name, options] : all_builder_configurations()) {
        SCOPED_TRACE(name);
        const auto bvh = build(boxes, options);
        for (std::uint32_t limit : {1u, 4u, 8u}) check_collapse(bvh, boxes, limit);
    }
}

TEST(WideSlotBvh, EveryBuilderOnASoupFloatAndDouble) {
    check_every_builder(test::random_soup<float>(test::scaled(3000, 5), 21));
    check_every_builder(test::random_soup<double>(test::scaled(3000, 5), 22));
}

TEST(WideSlotBvh, EveryBuilderOnSharedBunny) {
    BVHKIT_REQUIRE_MESH(path, "stanford-bunny.obj");
    check_every_builder(mesh_triangles<float>(read_mesh(path)));
}

TEST(WideSlotBvh, EveryBuilderOnSharedFandisk) {
    BVHKIT_REQUIRE_MESH(path, "fandisk.obj");
    const TriangleMesh mesh = read_mesh(path);
    check_every_builder(mesh_triangles<float>(mesh));
    check_every_builder(mesh_triangles<double>(mesh));
}

TEST(WideSlotBvh, LargeLeavesSmallLeavesAndSkippedPrimitives) {
    auto tris = test::random_soup<float>(test::scaled(2000, 5), 23);
    // A few primitives with NaN corners: the builders leave them out, so slots < primitives.
    for (std::size_t i = 0; i < tris.size(); i += 97)
        tris[i].p1[1] = std::numeric_limits<float>::quiet_NaN();
    const auto boxes = boxes_of(tris);
    BuildOptions shallow;  // depth 3: leaves of hundreds of primitives, far over any leaf_limit
    shallow.max_depth = 3;
    BuildOptions singles;  // one primitive a leaf: small leaves share groups
    singles.max_leaf_size = 1;
    for (const BuildOptions& o : {shallow, singles}) {
        const auto bvh = build(boxes, o);
        ASSERT_LT(bvh.primitive_indices.size(), tris.size());
        for (std::uint32_t limit : {1u, 2u, 4u, 5u, 8u, 64u}) check_collapse(bvh, boxes, limit);
    }
    // With single-primitive binary leaves and leaf_limit 8, leaf children gather up to 8 of them:
    // fewer groups than binary leaves.
    const auto bvh = build(boxes, singles);
    const auto wide = collapse_to_wide(bvh, 8);
    EXPECT_LT(wide.group_count(), bvh.primitive_indices.size() / 2);
}

TEST(WideSlotBvh, EmptyAndOnePrimitive) {
    const Bvh<Aabb3f> empty;
    const auto wide = collapse_to_wide(empty);
    EXPECT_TRUE(wide.empty());
    EXPECT_EQ(wide.group_count(), 0u);
    EXPECT_NO_THROW(validate(wide, std::vector<Aabb3f>{}));
    // An empty wide tree over some slots is not valid.
    EXPECT_THROW(validate(wide, std::vector<Aabb3f>{Aabb3f({0, 0, 0}, {1, 1, 1})}), Error);

    for (std::uint32_t limit : {1u, 4u}) {
        const std::vector<Aabb3d> boxes{Aabb3d({1, 2, 3}, {4, 5, 6})};
        const auto bvh = build(boxes, BuildOptions{});
        const auto one = collapse_to_wide(bvh, limit);
        ASSERT_EQ(one.nodes.size(), 1u);
        EXPECT_TRUE(one.nodes[0].has(0));
        EXPECT_TRUE(one.nodes[0].is_leaf(0));
        EXPECT_FALSE(one.nodes[0].has(1));
        EXPECT_EQ(one.nodes[0].groups[0], 1u);
        EXPECT_EQ(one.group_slots,
                  (std::vector<std::uint32_t>{0, invalid_index, invalid_index, invalid_index}));
        const Aabb3d got = one.nodes[0].box(0);
        EXPECT_EQ(got.min, boxes[0].min);
        EXPECT_EQ(got.max, boxes[0].max);
        EXPECT_NO_THROW(validate(one, boxes));
    }
}

/// A wide tree with several levels and padded groups, and its slot boxes, for corrupting.
struct Corruptible {
    std::vector<Aabb3f> slot_boxes;
    WideSlotBvh<float> wide;
    Corruptible() {
        const auto tris = test::random_soup<float>(2000, 24);
        const auto boxes = boxes_of(tris);
        const auto bvh = build(boxes, BuildOptions{});
        slot_boxes = slot_boxes_of(bvh, boxes);
        wide = collapse_to_wide(bvh, 4);
    }
    /// The union of the boxes under child c of node w (its slots' boxes, or its child's boxes).
    Aabb3f content(std::uint32_t w, int c) const {
        const auto& node = wide.nodes[w];
        Aabb3f u;
        if (node.is_leaf(c)) {
            for (std::uint32_t s : leaf_slots(wide, node, c)) u.grow(slot_boxes[s]);
        } else {
            for (int d = 0; d < 4; ++d)
                if (wide.nodes[node.child[c]].has(d)) u.grow(wide.nodes[node.child[c]].box(d));
        }
        return u;
    }
    /// Shrinks the box of the first child (leaf or inner as asked) to its low face on an axis
    /// where its content reaches past that face; false when there is none.
    bool shrink(bool leaf, WideSlotBvh<float>& out) const {
        out = wide;
        for (std::uint32_t w = 0; w < wide.nodes.size(); ++w)
            for (int c = 0; c < 4; ++c) {
                const auto& node = wide.nodes[w];
                if (!node.has(c) || node.is_leaf(c) != leaf) continue;
                const Aabb3f u = content(w, c);
                for (int a = 0; a < 3; ++a)
                    if (u.max[a] > node.lo[a][c]) {
                        out.nodes[w].hi[a][c] = node.lo[a][c];
                        return true;
                    }
            }
        return false;
    }
};

TEST(WideSlotBvh, ValidateRejectsCorruptedTrees) {
    const Corruptible t;
    ASSERT_NO_THROW(validate(t.wide, t.slot_boxes));
    ASSERT_GT(t.wide.nodes.size(), 4u);
    WideSlotBvh<float> bad;

    // A leaf lane's box shrunk below its slots' boxes; an inner lane's below its child's boxes.
    ASSERT_TRUE(t.shrink(true, bad));
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "leaf box shrunk";
    ASSERT_TRUE(t.shrink(false, bad));
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "inner box shrunk";

    // A slot twice: a padding entry given the slot before it (same leaf, so inside its box).
    bad = t.wide;
    bool padded = false;
    for (std::size_t i = 1; i < bad.group_slots.size() && !padded; ++i)
        if (bad.group_slots[i] == invalid_index && bad.group_slots[i - 1] != invalid_index) {
            bad.group_slots[i] = bad.group_slots[i - 1];
            padded = true;
        }
    ASSERT_TRUE(padded) << "no padding to put a duplicate in";
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "slot duplicated into padding";
    // A slot overwritten by another (one held twice, one dropped).
    bad = t.wide;
    bad.group_slots[1] = bad.group_slots[0];
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "slot overwritten";
    // A slot dropped: the entry made padding.
    bad = t.wide;
    for (std::uint32_t& s : bad.group_slots)
        if (s != invalid_index) {
            s = invalid_index;
            break;
        }
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "slot dropped";
    // A slot out of range.
    bad = t.wide;
    bad.group_slots[0] = std::uint32_t(t.slot_boxes.size());
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "slot out of range";
    // More slots than the tree holds.
    auto more = t.slot_boxes;
    more.push_back(more.front());
    EXPECT_THROW(validate(t.wide, more), Error) << "a slot in no leaf";

    // A child pointed at an earlier node: itself, the root, its parent.
    std::uint32_t parent = invalid_index, node = invalid_index;
    int lane = -1;
    for (std::uint32_t w = 0; w < t.wide.nodes.size() && lane < 0; ++w)
        for (int c = 0; c < 4 && lane < 0; ++c)
            if (t.wide.nodes[w].has(c) && !t.wide.nodes[w].is_leaf(c)) {
                const std::uint32_t k = t.wide.nodes[w].child[c];
                for (int d = 0; d < 4; ++d)
                    if (t.wide.nodes[k].has(d) && !t.wide.nodes[k].is_leaf(d)) {
                        parent = w, node = k, lane = d;
                        break;
                    }
            }
    ASSERT_GE(lane, 0) << "no inner node with an inner child";
    for (std::uint32_t target : {node, 0u, parent}) {
        bad = t.wide;
        bad.nodes[node].child[lane] = target;
        EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "child pointed at node " << target;
    }
    // Out of range, and an inner child turned into a leaf with groups out of range.
    bad = t.wide;
    bad.nodes[node].child[lane] = std::uint32_t(bad.nodes.size());
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "child out of range";
    bad = t.wide;
    bad.nodes[node].groups[lane] = std::uint32_t(bad.group_count() + 1);
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "groups out of range";
    // A node no child names, and a root without a first child.
    bad = t.wide;
    bad.nodes.push_back(bad.nodes.back());
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "unreachable node";
    bad = t.wide;
    bad.nodes[0].child[0] = invalid_index;
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "no first child";
    // group_slots not a whole number of groups.
    bad = t.wide;
    bad.group_slots.push_back(invalid_index);
    EXPECT_THROW(validate(bad, t.slot_boxes), Error) << "partial group";
}

}  // namespace
}  // namespace bvhkit

#pragma once
// Self-collision of one mesh: every pair of its triangles that intersect (triangle_triangle.hpp's
// rules) and share no vertex index. Triangles that share a vertex index are neighbours that touch
// by construction and are left out; a mesh whose copies of one corner are separate vertices
// (unwelded) reports its neighbours, so weld it first.
//
// The traversal is walk_pairs (walk/walks.hpp), the tree against itself, in one frame: a node
// paired with itself opens into its children's self pairs and the pair of its two children; each
// unordered pair of triangles is tested once.
#include <algorithm>

#include "bvhkit/query/pairs_model.hpp"
#include "bvhkit/walk/walks.hpp"

namespace bvhkit {

/// Fills `contacts` (cleared first) with the intersecting pairs, triangle_a < triangle_b, segments
/// in the model's frame. Returns whether any was found.
template <BoundingVolume V, class Stats = NoStats>
bool self_collide(const CollisionModel<V>& m, std::vector<Contact<typename V::Scalar>>& contacts,
                  Stats&& stats = {}) {
    using T = typename V::Scalar;
    using Traits = VolumeTraits<V>;
    contacts.clear();
    const auto& nodes = m.bvh().nodes;
    if (nodes.empty()) return false;
    const auto tris = m.slot_triangles();
    const auto ids = m.slot_vertex_ids();
    const auto test = [&](std::uint32_t s, std::uint32_t t) {
        stats.primitive();
        for (std::uint32_t i : ids[s])
            for (std::uint32_t j : ids[t])
                if (i == j) return;
        const TriangleIntersection<T> x = intersect_triangles(tris[s], tris[t]);
        if (!x.hit) return;
        std::uint32_t ta = m.triangle_id(s), tb = m.triangle_id(t);
        if (ta > tb) std::swap(ta, tb);
        contacts.push_back({ta, tb, x.p, x.q, x.coplanar});
    };
    const auto overlap = [&](std::uint32_t x, std::uint32_t y) {
        stats.node();
        return Traits::overlaps(nodes[x].bounds, nodes[y].bounds);
    };
    const auto on_leaves = [&](const detail::NodePair& p) {
        const auto& na = nodes[p.a];
        const auto& nb = nodes[p.b];
        if (p.a == p.b) {
            for (std::uint32_t s = na.first; s < na.first + na.count; ++s)
                for (std::uint32_t t = s + 1; t < na.first + na.count; ++t) test(s, t);
        } else {
            for (std::uint32_t s = na.first; s < na.first + na.count; ++s)
                for (std::uint32_t t = nb.first; t < nb.first + nb.count; ++t) test(s, t);
        }
        return true;
    };
    // The descent rule: a node with itself opens into its children's self pairs and the pair of
    // its two children; another pair opens its larger node (never a leaf).
    const auto open = [&](const detail::NodePair& p, auto& stack) {
        const auto& na = nodes[p.a];
        const auto& nb = nodes[p.b];
        if (p.a == p.b) {
            stack.push({na.left(), na.left()});
            stack.push({na.right(), na.right()});
            if (overlap(na.left(), na.right())) stack.push({na.left(), na.right()});
            return;
        }
        const bool open_a =
            nb.is_leaf() || (!na.is_leaf() && Traits::size(na.bounds) >= Traits::size(nb.bounds));
        if (open_a) {
            if (overlap(na.left(), p.b)) stack.push({na.left(), p.b});
            if (overlap(na.right(), p.b)) stack.push({na.right(), p.b});
        } else {
            if (overlap(p.a, nb.left())) stack.push({p.a, nb.left()});
            if (overlap(p.a, nb.right())) stack.push({p.a, nb.right()});
        }
    };
    FixedStack<detail::NodePair, detail::pair_stack_size> pairs;
    const BvhNodes<BvhNode<V>> view{nodes.data()};
    walk_pairs(view, view, pairs, detail::NodePair{0, 0}, EnterAll{}, on_leaves, open);
    std::sort(contacts.begin(), contacts.end(), [](const auto& x, const auto& y) {
        return x.triangle_a != y.triangle_a ? x.triangle_a < y.triangle_a
                                            : x.triangle_b < y.triangle_b;
    });
    return !contacts.empty();
}

}  // namespace bvhkit

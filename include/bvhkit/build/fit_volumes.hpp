#pragma once
// Any bounding volume over a tree shape made by the AABB builders: the topology (nodes' first and
// count, primitive_indices) is copied and each node's volume is fitted to the triangles of its
// subtree, which occupy one contiguous run of leaf slots. So every builder serves every volume
// type, and the AABB path (build_bvh, the ray queries) is untouched.
//
// refit_volumes() is the same fitting after the triangles moved (a deforming mesh), in one reverse
// pass over the nodes: volumes whose merge is exact (Aabb, Kdop) merge their children; the others
// (Sphere, Obb) re-fit each node to its run, which is tighter than merging children's volumes; a
// volume with a fit_tree() (ConvexHull) fits each parent from data its children kept.
#include <span>
#include <type_traits>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/volumes/bounding_volume.hpp"

namespace bvhkit {

/// The run [first, second) of leaf slots under each node.
template <class V>
std::vector<std::pair<std::uint32_t, std::uint32_t>> node_slot_runs(const Bvh<V>& bvh) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> runs(bvh.nodes.size());
    for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
        const auto& node = bvh.nodes[n];
        if (node.is_leaf()) {
            runs[n] = {node.first, node.first + node.count};
        } else {
            const auto& l = runs[node.left()];
            const auto& r = runs[node.right()];
            runs[n] = {std::min(l.first, r.first), std::max(l.second, r.second)};
        }
    }
    return runs;
}

/// Refits `bvh` to `slot_triangles` (slot_triangles[s] is the triangle in leaf slot s, i.e. the
/// caller's triangle primitive_indices[s]). One reverse pass; children before parents.
template <BoundingVolume V>
void refit_volumes(Bvh<V>& bvh, std::span<const Triangle<typename V::Scalar>> slot_triangles) {
    using Traits = VolumeTraits<V>;
    if constexpr (requires { Traits::fit_tree(bvh.nodes, slot_triangles); }) {
        // The volume fits a parent from what it kept of its children (ConvexHull).
        Traits::fit_tree(bvh.nodes, slot_triangles);
    } else if constexpr (Traits::merge_is_tight) {
        for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
            auto& node = bvh.nodes[n];
            node.bounds =
                node.is_leaf()
                    ? Traits::fit(slot_triangles.subspan(node.first, node.count))
                    : Traits::merge(bvh.nodes[node.left()].bounds, bvh.nodes[node.right()].bounds);
        }
    } else {
        const auto runs = node_slot_runs(bvh);
        for (std::size_t n = bvh.nodes.size(); n-- > 0;)
            bvh.nodes[n].bounds =
                Traits::fit(slot_triangles.subspan(runs[n].first, runs[n].second - runs[n].first));
    }
}

/// A Bvh<V> with the shape of `topology` (any AABB tree over the same triangles).
template <BoundingVolume V, class T>
Bvh<V> fit_volumes(const AabbBvh<T, 3>& topology, std::span<const Triangle<T>> slot_triangles) {
    static_assert(std::is_same_v<typename V::Scalar, T>);
    Bvh<V> out;
    out.primitive_indices = topology.primitive_indices;
    out.nodes.resize(topology.nodes.size());
    for (std::size_t n = 0; n < topology.nodes.size(); ++n) {
        out.nodes[n].first = topology.nodes[n].first;
        out.nodes[n].count = topology.nodes[n].count;
    }
    refit_volumes(out, slot_triangles);
    return out;
}

}  // namespace bvhkit

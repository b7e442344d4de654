#pragma once
// The wide ray layouts of TriangleBvh<float>: RayNode (a node's children's boxes one array per
// axis and bound), WideRayBvh (the nodes and the leaves' triangle groups) and make_wide_ray_bvh,
// which derives them from the binary tree. WideRayView is what the walks (query/ray_wide.hpp)
// read: spans over a WideRayBvh's arrays, or over a mapped file's sections
// (io/mapped_triangle_bvh.hpp).
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "bvhkit/bvh/huge_page_allocator.hpp"
#include "bvhkit/bvh/wide_bvh.hpp"
#include "bvhkit/bvh/wide_bvh_sah.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_group.hpp"
#include "bvhkit/query/ray_wide_occlusion_order.hpp"
#include "bvhkit/simd/config.hpp"
#include "bvhkit/tuning.hpp"

// The eight-wide walk is compiled, for CPUs that turn out to have AVX2, where the SIMD layer has
// eight lanes.
#define BVHKIT_RAY_AVX2 BVHKIT_SIMD_AVX2

namespace bvhkit {

template <int W>
struct alignas(64) RayNode {
    float lo[6][W];  // lo[axis][lane] the box's min, +inf in an empty lane; lo[3 + axis][lane] its
                     // max, -inf in an empty lane (one array, so a ray picks its planes by index)
    std::uint32_t child[W];   // inner: node index; leaf: first group; empty: invalid_index
    std::uint32_t groups[W];  // leaf: how many groups (>= 1); inner or empty: 0
};

/// The triangle groups of the layout of width W: as wide as the walk's registers.
template <int W>
using RayGroup = TriangleGroup<W == 8 ? 8 : 4>;

/// A wide ray layout where it lies, read only: nodes[0] is the root.
template <int W>
struct WideRayView {
    using Group = RayGroup<W>;
    std::span<const RayNode<W>> nodes;
    std::span<const Group> groups;

    bool empty() const { return nodes.empty(); }
    /// The layout's size: what a walk reads from.
    std::size_t bytes() const {
        return nodes.size() * sizeof(RayNode<W>) + groups.size() * sizeof(Group);
    }
};

template <int W>
struct WideRayBvh {
    using Group = RayGroup<W>;
    // On huge pages once large (bvh/huge_page_allocator.hpp): incoherent rays read both at random.
    std::vector<RayNode<W>, HugePageAllocator<RayNode<W>>> nodes;  // nodes[0] is the root
    std::vector<Group, HugePageAllocator<Group>> groups;

    bool empty() const { return nodes.empty(); }
    /// The layout's size: what a walk reads from.
    std::size_t bytes() const { return view().bytes(); }
    WideRayView<W> view() const { return {nodes, groups}; }
    operator WideRayView<W>() const { return view(); }  // NOLINT: the walks take either
};

/// Whether this CPU runs the eight-wide walk (AVX2), asked once.
inline bool cpu_has_avx2() {
#if BVHKIT_RAY_AVX2
    static const bool has = [] {
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") != 0;
    }();
    return has;
#else
    return false;
#endif
}

/// Orders the lanes of `layout` for occlusion rays (query/ray_wide_occlusion_order.hpp) with the
/// costs make_wide_ray_bvh collapses by: what it does last, and what a load does to a layout
/// stored in the collapse's own order.
template <int W>
void order_for_occlusion(WideRayBvh<W>& layout) {
    order_lanes_for_occlusion(layout.nodes, layout.groups.data(),
                              W == 8 ? tuning::wide8_node_cost : tuning::wide4_node_cost, 1.0);
}

/// The ray layout of width W of a binary tree whose leaf slot s holds triangle_at_slot(s); its
/// groups name that triangle index_at_slot(s) (TriangleGroup::slot), which a hit reports. Its
/// lanes are ordered for occlusion rays unless `occlusion_order` is false (the collapse's own
/// order, as layouts were made before: for tests of files written then).
template <int W, class TriangleAtSlot, class IndexAtSlot>
WideRayBvh<W> make_wide_ray_bvh(const Bvh<Aabb<float, 3>>& bvh, TriangleAtSlot&& triangle_at_slot,
                                IndexAtSlot&& index_at_slot, bool occlusion_order = true) {
    WideRayBvh<W> out;
    // Every node's lanes filled (collapse_to_wide's fill_lanes), and each leaf child chosen by
    // the surface area cost of collapse_to_wide_sah in the layout's own units, a node's clip
    // against a group's test (tuning.hpp): the leaves grow where the tree's boxes overlap little
    // and stay small where they overlap much, up to a limit.
    WideCollapseCosts costs;
    costs.node = W == 8 ? tuning::wide8_node_cost : tuning::wide4_node_cost;
    costs.group = 1;
    costs.group_lanes = WideRayBvh<W>::Group::lanes;
    costs.max_leaf = W == 8 ? tuning::wide8_leaf_limit : tuning::wide4_leaf_limit;
    const WideSlotBvh<float, W> wide = collapse_to_wide_sah<float, W>(bvh, costs, true);
    out.nodes.resize(wide.nodes.size());
    constexpr float inf = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < wide.nodes.size(); ++i) {
        const WideSlotNode<float, W>& w = wide.nodes[i];
        RayNode<W>& n = out.nodes[i];
        for (int c = 0; c < W; ++c) {
            for (int a = 0; a < 3; ++a) {
                n.lo[a][c] = w.has(c) ? w.lo[a][c] : inf;
                n.lo[3 + a][c] = w.has(c) ? w.hi[a][c] : -inf;
            }
            n.child[c] = w.child[c];
            n.groups[c] = w.has(c) ? w.groups[c] : 0;
        }
    }
    // collapse_to_wide's groups are of four slots, a leaf child's slots in a run of them padded
    // at its end only; here each run is cut again into groups of the layout's width, kept in the
    // runs' order. A group of eight holds the slots of two consecutive groups of four.
    constexpr std::size_t lanes = WideRayBvh<W>::Group::lanes;
    // The groups of the layout's width that a run of `run` groups of four fills.
    const auto cut = [&](std::uint32_t run) {
        return std::uint32_t((4 * std::size_t(run) + lanes - 1) / lanes);
    };
    std::vector<std::uint32_t> run_of(wide.group_count(), 0), first_of(wide.group_count(), 0);
    for (const WideSlotNode<float, W>& w : wide.nodes)
        for (int c = 0; c < W; ++c)
            if (w.has(c) && w.groups[c] > 0) run_of[w.child[c]] = w.groups[c];
    std::size_t group_count = 0;
    for (std::size_t g = 0; g < run_of.size(); g += run_of[g]) {
        if (run_of[g] == 0) throw Error("make_wide_ray_bvh: a group outside every leaf");
        first_of[g] = std::uint32_t(group_count);
        group_count += cut(run_of[g]);
    }
    out.groups.resize(group_count);
    for (std::size_t g = 0; g < run_of.size(); g += run_of[g]) {
        const std::size_t first = first_of[g];
        const std::size_t slots = 4 * std::size_t(run_of[g]), padded = cut(run_of[g]) * lanes;
        for (std::size_t k = 0; k < padded; ++k) {
            const std::uint32_t s = k < slots ? wide.group_slots[4 * g + k] : invalid_index;
            auto& group = out.groups[first + k / lanes];
            if (s == invalid_index)
                group.clear(int(k % lanes));
            else
                group.set(int(k % lanes), triangle_at_slot(s), index_at_slot(s));
        }
    }
    for (std::size_t i = 0; i < wide.nodes.size(); ++i)
        for (int c = 0; c < W; ++c)
            if (out.nodes[i].groups[c] > 0) {
                const std::uint32_t g = out.nodes[i].child[c];
                out.nodes[i].child[c] = first_of[g];
                out.nodes[i].groups[c] = cut(run_of[g]);
            }
    if (occlusion_order) order_for_occlusion(out);
    return out;
}

}  // namespace bvhkit

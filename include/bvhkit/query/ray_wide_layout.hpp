#pragma once
// The wide ray layouts of TriangleBvh<float>: RayNode (a node's children's boxes one array per
// axis and bound), WideRayBvh (the nodes and the leaves' triangle groups) and make_wide_ray_bvh,
// which derives them from the binary tree. The walks over them are in query/ray_wide.hpp.
#include <cstdint>
#include <limits>
#include <vector>

#include "bvhkit/bvh/huge_page_allocator.hpp"
#include "bvhkit/bvh/wide_bvh.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_group.hpp"

#if defined(__SSE2__) && defined(__x86_64__) && defined(__GNUC__)
#define BVHKIT_RAY_AVX2 1  // the eight-wide walk is compiled, for CPUs that turn out to have AVX2
#else
#define BVHKIT_RAY_AVX2 0
#endif

namespace bvhkit {

template <int W>
struct alignas(64) RayNode {
    float lo[6][W];  // lo[axis][lane] the box's min, +inf in an empty lane; lo[3 + axis][lane] its
                     // max, -inf in an empty lane (one array, so a ray picks its planes by index)
    std::uint32_t child[W];   // inner: node index; leaf: first group; empty: invalid_index
    std::uint32_t groups[W];  // leaf: how many groups (>= 1); inner or empty: 0
};

template <int W>
struct WideRayBvh {
    using Group = TriangleGroup<W == 8 ? 8 : 4>;  // as wide as the walk's registers
    // On huge pages once large (bvh/huge_page_allocator.hpp): incoherent rays read both at random.
    std::vector<RayNode<W>, HugePageAllocator<RayNode<W>>> nodes;  // nodes[0] is the root
    std::vector<Group, HugePageAllocator<Group>> groups;

    bool empty() const { return nodes.empty(); }
    /// The layout's size: what a walk reads from.
    std::size_t bytes() const {
        return nodes.size() * sizeof(RayNode<W>) + groups.size() * sizeof(Group);
    }
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

/// The ray layout of width W of a binary tree whose leaf slot s holds triangle_at_slot(s); its
/// groups name that triangle index_at_slot(s) (TriangleGroup::slot), which a hit reports.
template <int W, class TriangleAtSlot, class IndexAtSlot>
WideRayBvh<W> make_wide_ray_bvh(const Bvh<Aabb<float, 3>>& bvh, TriangleAtSlot&& triangle_at_slot,
                                IndexAtSlot&& index_at_slot) {
    WideRayBvh<W> out;
    // Every node's lanes filled (collapse_to_wide's fill_lanes), and a lane of up to leaf_limit
    // triangles not opened further is a leaf child. Against leaf limit 8 without filling (3.7
    // lanes an eight-wide node on igea, 16k nodes, 4.2 MB), 1M random rays, closest hit, against
    // Embree 3 in the same run: eight wide, igea 0.72-0.81x -> 0.88-0.97x, bunny 0.69x ->
    // 0.74-0.77x, spot, dragon and teapot +1-4%; four wide, igea 0.67-0.71x -> 0.79-0.80x
    // (occlusion 0.74-0.78x -> 0.91-1.04x), bunny, spot and dragon within noise. Leaf limits 16-32
    // measured within noise of 24. (Four wide without filling, leaf limit 2 / 4 / 8 / 16, ms: igea
    // 861 / 736 / 637 / 583, spot 296 (4) / 268 (8) / 273 (16); the binary walk 853 and 380.)
    // Eight wide, leaves in blocks of four (2026-11-26, 1M random rays, one thread): leaf limit
    // 24 / 48 / 64, closest hit, ms: the 1.3M-triangle displaced sphere 586 / 456-489 / 458,
    // bunny 141-143 / 141-143 / 144-146, igea 246 / 241-247 / 244-250; R1 and occlusion within
    // noise on bunny and igea, the sphere's occlusion 517 / 384-407. Once the tree outgrows the
    // caches, a node costs more than the groups of a larger leaf, which lie side by side. Four
    // wide, 48 was mixed (bunny 5% faster, the sphere 6% slower): it keeps 24. With the tree's
    // leaves priced in blocks of eight (2026-11-27, 500,000 rays), 32 / 48 / 64 on igea R2:
    // 130-133 / 119-121 / 119-120 ms, bunny and the 5k sphere within noise.
    constexpr std::uint32_t leaf_limit = W == 8 ? 48 : 24;
    const WideBvh<float, W> wide = collapse_to_wide<float, W>(bvh, leaf_limit, true);
    out.nodes.resize(wide.nodes.size());
    constexpr float inf = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < wide.nodes.size(); ++i) {
        const WideNode<float, W>& w = wide.nodes[i];
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
    for (const WideNode<float, W>& w : wide.nodes)
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
    return out;
}

}  // namespace bvhkit

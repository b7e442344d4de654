#pragma once
// Rays through a wide tree of float triangles: the layouts TriangleBvh<float> traces by default,
// made from its binary tree by collapse_to_wide (bvh/wide_bvh.hpp). W = 4 runs on SSE2 (every
// x86-64); W = 8 on AVX2. The walk is written once for both (query/ray_wide_walk.hpp) on the
// SIMD layer (simd/), and compiled once per instruction set by simd/per_isa.hpp: the eight-wide
// one for AVX2 within the default build, chosen at run time when the CPU has AVX2
// (cpu_has_avx2), so one binary serves both.
//
// A node holds its children's boxes one array per axis and bound, so one SIMD pass clips the ray
// against all of them (Wald, Benthin and Boulos 2008; Dammertz et al. 2008). The near and far
// planes are chosen once per ray (SlabConstants). For a closest hit the hit children are visited
// nearest first: the others go on a stack with their entry distances, and an entry farther than
// the closest hit so far is dropped when popped, without reading its node (an any-hit query
// takes them in lane order, which the layout chose for occlusion rays). The stacks and pushes are
// in query/ray_wide_stack.hpp, the layouts in query/ray_wide_layout.hpp. A leaf child is a run of
// triangle groups as wide as the walk: four triangles tested at once in the four-wide walk, eight
// in the eight-wide one (primitives/triangle_group_kernels.hpp), with the answers of the scalar
// watertight test.
//
// An empty lane has the inverted box (+inf, -inf), which every ray misses; rays with a subnormal
// direction component (a NaN reciprocal, which the slab test ignores) take the binary tree instead,
// since an ignored axis could let them into an empty lane.
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include "bvhkit/primitives/triangle_group.hpp"
#include "bvhkit/query/ray_wide_layout.hpp"
#include "bvhkit/query/ray_wide_stack.hpp"
#include "bvhkit/query/stats.hpp"
#include "bvhkit/simd/simd.hpp"

namespace bvhkit {

#if BVHKIT_SIMD
namespace detail {

template <int L, class Stats>
void count_lanes(const TriangleGroup<L>& g, Stats& stats) {
    for (std::uint32_t s : g.slot)
        if (s != invalid_index) stats.primitive();
}

// The ray's constants for the slab test: origin, reciprocal direction, the reciprocal scaled for
// the far planes (the conservative rounding of math/ray.hpp), and which row of RayNode::lo holds
// each axis's near and far planes. The rows are chosen per ray at run time rather than by one
// compiled walk per octant: incoherent rays then share one copy of the walk, and pay neither the
// dispatch's mispredicted indirect jump nor the branches that computed the octant.
struct alignas(16) SlabConstants {
    // Lane 3 of each row is a fourth axis that restricts nothing (origin 0, direction 1), so that
    // meets() can clip four lanes at once; the walks read lanes 0-2.
    float origin[4], inv[4], inv_far[4];
    std::uint32_t near[4], far[4];
    SlabConstants() = default;  // unset: a place for a ray's constants, written later
    /// For a ray wide_ray_usable accepts: no subnormal direction component, so 1 / d is what
    /// RaySlabData holds (an infinity for a zero of either sign, finite otherwise).
    explicit SlabConstants(const Ray<float, 3>& ray) {
        constexpr float s = 1.0f + 2.0f * rounding_gamma<float>(3);
        // All axes at once: the same IEEE quotients and products as one axis at a time. The
        // fields are read one by one: one 16-byte load of a ray the caller has just written
        // spans several of its stores, which the CPU cannot forward (rays made just before each
        // call would wait for those stores to retire).
        using F = simd::Float<4>;
        using I = simd::Int<4>;
        const F d = F::lanes(ray.direction[0], ray.direction[1], ray.direction[2], 1.0f);
        const F r = F(1.0f) / d;
        F::lanes(ray.origin[0], ray.origin[1], ray.origin[2], 0.0f).store(origin);
        r.store(inv);
        (r * F(s)).store(inv_far);
        // -0 counts as negative, as in RaySlabData: its -inf reciprocal meets the planes in the
        // right order. A negative axis reads its near plane from the max row (a + 3).
        const I negative = simd::bits_of(d).shift_right_arithmetic<31>() & I(3);
        (I::lanes(0, 1, 2, 3) + negative).store(near);
        (I::lanes(3, 4, 5, 6) - negative).store(far);
    }

    /// Whether the ray can meet `box` in [tmin, tmax], by the walks' own slab test and rounding:
    /// a box inside this one gives an interval inside this one's, so a miss here is a miss of
    /// everything in it. TriangleBvh tests the tree's bounds so before a walk: a ray that misses
    /// a mesh's bounds (most camera rays around a model) then costs this test and no set-up of
    /// the walk (the watertight ray and the stack took more than half of such a ray's time).
    bool meets(const Aabb<float, 3>& box, float tmin, float tmax) const {
        const float inf = std::numeric_limits<float>::infinity();
        // Lane 3 goes from 0 along 1 through [-inf, inf]: it restricts nothing.
        using F = simd::Float<4>;
        const F lo = F::lanes(box.min[0], box.min[1], box.min[2], -inf);
        const F hi = F::lanes(box.max[0], box.max[1], box.max[2], inf);
        const F o = F::load(origin);
        // A ray that starts in the box at tmin = 0 meets it (the walk's clip keeps such a box:
        // both plane distances have the right sign whatever their rounding). Rays cast from
        // inside a model's bounds, the incoherent sets among them, skip the clip below.
        const unsigned inside = ((lo <= o) & (o <= hi)).bits();
        if (inside == 15 && tmin == 0.0f) return true;
        // 1 / d has d's sign, -0 included (1 / -0 = -inf): negative axes take the max as near.
        const F inverse = F::load(inv);
        const simd::Mask<4> negative = simd::sign_mask(simd::bits_of(inverse));
        const F near_plane = select(negative, hi, lo);
        const F far_plane = select(negative, lo, hi);
        // As in the walks, max/min keep their second operand when the first is NaN (0 * inf).
        F t0 = max((near_plane - o) * inverse, F(tmin));
        F t1 = min((far_plane - o) * F::load(inv_far), F(tmax));
        t0 = max(t0, t0.shuffle<2, 3, 0, 1>());
        t0 = max(t0, t0.shuffle<1, 0, 3, 2>());
        t1 = min(t1, t1.shuffle<2, 3, 0, 1>());
        t1 = min(t1, t1.shuffle<1, 0, 3, 2>());
        return t0.first() <= t1.first();
    }
};

/// Whether a hit at t on triangle `slot` replaces the closest hit so far (best_t on triangle
/// best_slot), for a hit the test found within the range, so t <= best_t. At an equal t the lower
/// triangle index wins: the closest hit is then the least (t, index) of the triangles the ray
/// meets, whatever order the leaves are tested in, so a walk that visits them in another order
/// (the packets of query/ray_octant_stream.hpp) answers as the one-ray walk does. Both visit
/// every leaf whose box the ray meets at or before the closest t (their pops drop only entries
/// strictly beyond it), so both test the winner.
inline bool closer_hit(float t, std::uint32_t slot, float best_t, std::uint32_t best_slot) {
    return t < best_t || (t == best_t && slot < best_slot);
}

}  // namespace detail
#endif
}  // namespace bvhkit

// The walk, its clip and its leaf tests: detail::sse2 for four lanes, detail::avx2 for eight.
#define BVHKIT_SIMD_KERNELS "bvhkit/query/ray_wide_walk.hpp"
#include "bvhkit/simd/per_isa.hpp"  // IWYU pragma: keep

namespace bvhkit {
#if BVHKIT_SIMD

/// Closest hit through a wide tree: on a hit, `hit_group` and `hit_lane` say where the triangle
/// lies (its index is hit_group->slot[hit_lane], its corners hit_group->triangle(hit_lane): both
/// at hand in a line the test just read, where the caller's own arrays would cost two more cache
/// misses); hit_group is null on a miss. The ray must be one wide_ray_usable accepts, and an
/// eight-wide tree needs cpu_has_avx2().
template <int W, class Stats = NoStats>
bool closest_hit_wide(WideRayView<W> tree, const Ray<float, 3>& ray_in,
                      const detail::SlabConstants& k, const WatertightRay<float>& prep,
                      TriangleHit<float>& best, const typename WideRayView<W>::Group*& hit_group,
                      int& hit_lane, Stats&& stats = {}) {
#if BVHKIT_SIMD_AVX2
    if constexpr (W == 8)
        return detail::avx2::closest_hit(tree, ray_in, k, prep, best, hit_group, hit_lane, stats);
    else
#else
    // No eight lanes in this build (cpu_has_avx2 is false, so no such tree is walked).
    if constexpr (W == 8)
        return false;
    else
#endif
        return detail::sse2::closest_hit(tree, ray_in, k, prep, best, hit_group, hit_lane, stats);
}

/// Any hit through a wide tree (same conditions as closest_hit_wide).
template <int W, class Stats = NoStats>
bool any_hit_wide(WideRayView<W> tree, const Ray<float, 3>& ray_in,
                  const WatertightRay<float>& prep, Stats&& stats = {}) {
    // The slab constants from the caller's ray, before the copy the walk reads: read from the
    // copy, its direction straddled the two stores that wrote it (a store-forwarding stall).
    const detail::SlabConstants k(ray_in);
#if BVHKIT_SIMD_AVX2
    if constexpr (W == 8)
        return detail::avx2::any_hit(tree, ray_in, k, prep, stats);
    else
#else
    if constexpr (W == 8)
        return false;  // as in closest_hit_wide
    else
#endif
        return detail::sse2::any_hit(tree, ray_in, k, prep, stats);
}

/// Every hit through a wide tree in the ray's range, in no particular order: on_hit(group, lane,
/// hit) -> bool (false ends the walk), the triangle as in closest_hit_wide (same conditions).
template <int W, class OnHit, class Stats = NoStats>
void all_hits_wide(WideRayView<W> tree, const Ray<float, 3>& ray_in, const detail::SlabConstants& k,
                   const WatertightRay<float>& prep, OnHit&& on_hit, Stats&& stats = {}) {
#if BVHKIT_SIMD_AVX2
    if constexpr (W == 8)
        detail::avx2::all_hits(tree, ray_in, k, prep, on_hit, stats);
    else
#else
    if constexpr (W == 8)
        return;  // as in closest_hit_wide
    else
#endif
        detail::sse2::all_hits(tree, ray_in, k, prep, on_hit, stats);
}
#endif

/// Whether the wide walk serves `ray`: traceable, and no direction component subnormal (whose
/// reciprocal the slab test would ignore, letting the ray into empty lanes).
inline bool wide_ray_usable(const Ray<float, 3>& ray) {
#if BVHKIT_SIMD
    // The same tests on all components at once (per component they were a large share of a
    // camera ray's instructions): |x| < inf is false for NaN and inf; a direction component is
    // 0 or at least the least normal float; at least one is not 0.
    using F = simd::Float<4>;
    const F o = abs(F::lanes(ray.origin[0], ray.origin[1], ray.origin[2], 0));
    const F d = abs(F::lanes(ray.direction[0], ray.direction[1], ray.direction[2], 0));
    const F inf(std::numeric_limits<float>::infinity());
    const F zero = F::zero();
    const unsigned finite = ((o < inf) & (d < inf)).bits();
    const unsigned normal = ((d == zero) | (d >= F(std::numeric_limits<float>::min()))).bits();
    const unsigned moves = (d > zero).bits();
    return (finite & normal) == 15 && moves != 0 && ray.tmin <= ray.tmax;
#else
    if (!is_traceable(ray)) return false;
    for (int a = 0; a < 3; ++a)
        if (std::fpclassify(ray.direction[a]) == FP_SUBNORMAL) return false;
    return true;
#endif
}

}  // namespace bvhkit

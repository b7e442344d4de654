#pragma once
// Rays through a wide tree of float triangles: the layouts TriangleBvh<float> traces by default,
// made from its binary tree by collapse_to_wide (bvh/wide_bvh.hpp). W = 4 runs on SSE2 (every
// x86-64); W = 8 on AVX2, compiled into the default build with a function target attribute and
// chosen at run time when the CPU has AVX2 (cpu_has_avx2), so one binary serves both.
//
// A node holds its children's boxes one array per axis and bound, so one SIMD pass clips the ray
// against all of them (Wald, Benthin and Boulos 2008; Dammertz et al. 2008). The near and far
// planes are chosen once per ray (SlabConstants). For a closest hit the hit children are visited
// nearest first: the others go on a stack with their entry distances, and an entry farther than
// the closest hit so far is dropped when popped, without reading its node (an any-hit query
// pushes them unordered). The stacks and pushes are in query/ray_wide_stack.hpp, the layouts in
// query/ray_wide_layout.hpp. A leaf child is a run of triangle groups as wide as the walk: four
// triangles tested at once in the four-wide walk, eight in the eight-wide one
// (primitives/triangle_group.hpp), with the answers of the scalar watertight test.
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

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace bvhkit {

#if defined(__SSE2__)
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
        const __m128 d = _mm_setr_ps(ray.direction[0], ray.direction[1], ray.direction[2], 1.0f);
        const __m128 r = _mm_div_ps(_mm_set1_ps(1.0f), d);
        _mm_store_ps(origin, _mm_setr_ps(ray.origin[0], ray.origin[1], ray.origin[2], 0.0f));
        _mm_store_ps(inv, r);
        _mm_store_ps(inv_far, _mm_mul_ps(r, _mm_set1_ps(s)));
        // -0 counts as negative, as in RaySlabData: its -inf reciprocal meets the planes in the
        // right order. A negative axis reads its near plane from the max row (a + 3).
        const __m128i negative =
            _mm_and_si128(_mm_srai_epi32(_mm_castps_si128(d), 31), _mm_set1_epi32(3));
        _mm_store_si128(reinterpret_cast<__m128i*>(near),
                        _mm_add_epi32(_mm_setr_epi32(0, 1, 2, 3), negative));
        _mm_store_si128(reinterpret_cast<__m128i*>(far),
                        _mm_sub_epi32(_mm_setr_epi32(3, 4, 5, 6), negative));
    }

    /// Whether the ray can meet `box` in [tmin, tmax], by the walks' own slab test and rounding:
    /// a box inside this one gives an interval inside this one's, so a miss here is a miss of
    /// everything in it. TriangleBvh tests the tree's bounds so before a walk: a ray that misses
    /// a mesh's bounds (most camera rays around a model) then costs this test and no set-up of
    /// the walk (the watertight ray and the stack took more than half of such a ray's time).
    bool meets(const Aabb<float, 3>& box, float tmin, float tmax) const {
        const float inf = std::numeric_limits<float>::infinity();
        // Lane 3 goes from 0 along 1 through [-inf, inf]: it restricts nothing.
        const __m128 lo = _mm_setr_ps(box.min[0], box.min[1], box.min[2], -inf);
        const __m128 hi = _mm_setr_ps(box.max[0], box.max[1], box.max[2], inf);
        const __m128 o = _mm_load_ps(origin);
        // A ray that starts in the box at tmin = 0 meets it (the walk's clip keeps such a box:
        // both plane distances have the right sign whatever their rounding). Rays cast from
        // inside a model's bounds, the incoherent sets among them, skip the clip below.
        const int inside = _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(lo, o), _mm_cmple_ps(o, hi)));
        if (inside == 15 && tmin == 0.0f) return true;
        // 1 / d has d's sign, -0 included (1 / -0 = -inf): negative axes take the max as near.
        const __m128 inverse = _mm_load_ps(inv);
        const __m128 negative = _mm_castsi128_ps(_mm_srai_epi32(_mm_castps_si128(inverse), 31));
        const __m128 near_plane = _mm_or_ps(_mm_and_ps(negative, hi), _mm_andnot_ps(negative, lo));
        const __m128 far_plane = _mm_or_ps(_mm_and_ps(negative, lo), _mm_andnot_ps(negative, hi));
        // As in the walks, maxps/minps keep their second operand when the first is NaN (0 * inf).
        __m128 t0 = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(near_plane, o), inverse), _mm_set1_ps(tmin));
        __m128 t1 = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(far_plane, o), _mm_load_ps(inv_far)),
                               _mm_set1_ps(tmax));
        t0 = _mm_max_ps(t0, _mm_shuffle_ps(t0, t0, _MM_SHUFFLE(1, 0, 3, 2)));
        t0 = _mm_max_ps(t0, _mm_shuffle_ps(t0, t0, _MM_SHUFFLE(2, 3, 0, 1)));
        t1 = _mm_min_ps(t1, _mm_shuffle_ps(t1, t1, _MM_SHUFFLE(1, 0, 3, 2)));
        t1 = _mm_min_ps(t1, _mm_shuffle_ps(t1, t1, _MM_SHUFFLE(2, 3, 0, 1)));
        return _mm_comile_ss(t0, t1);
    }
};

// The walks: calls on_leaf(first_group, groups) (on_leaf.wide8 in walk8), which may shrink
// ray.tmax and returns true to stop; OnLeaf::any_hit says whether the order of the hit children
// is free. maxps/minps return their second operand when either is NaN, and the accumulators never
// are, so a 0 * inf plane distance does not restrict the interval (as in the scalar test).
template <class OnLeaf, class Stats>
void walk4(WideRayView<4> tree, Ray<float, 3>& ray, const SlabConstants& k, WideEntry* stack,
           OnLeaf& on_leaf, Stats& stats) {
    __m128 origin[3], inv[3], inv_far[3];
    for (int a = 0; a < 3; ++a) {
        origin[a] = _mm_set1_ps(k.origin[a]);
        inv[a] = _mm_set1_ps(k.inv[a]);
        inv_far[a] = _mm_set1_ps(k.inv_far[a]);
    }
    const RayNode<4>* nodes = tree.nodes.data();
    const TriangleGroup4* groups = tree.groups.data();
    const auto line = [&](const WideEntry& e) { return entry_address(nodes, groups, e); };
    std::uint32_t size = 0;
    WideEntry current{0, 0, ray.tmin};
    const __m128 tmin = _mm_set1_ps(ray.tmin);
    __m128 tmax = _mm_set1_ps(ray.tmax);
    while (true) {
        if (current.groups == 0) {
            const RayNode<4>& node = nodes[current.child];
            for (std::uint32_t c : node.child)  // boxes measured, as the binary walk counts
                if (c != invalid_index) stats.node();
            __m128 t0 = tmin, t1 = tmax;
            for (int a = 0; a < 3; ++a) {
                const __m128 near = _mm_load_ps(node.lo[k.near[a]]);
                const __m128 far = _mm_load_ps(node.lo[k.far[a]]);
                t0 = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(near, origin[a]), inv[a]), t0);
                t1 = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(far, origin[a]), inv_far[a]), t1);
            }
            const unsigned mask = unsigned(_mm_movemask_ps(_mm_cmple_ps(t0, t1)));
            if (mask != 0) {
                alignas(16) float entry[4];
                _mm_store_ps(entry, t0);
                if constexpr (OnLeaf::any_hit)
                    take_hits_unordered(mask, entry, node, current, stack, size, line);
                else
                    take_hits(mask, entry, node, current, stack, size, line);
                continue;
            }
        } else {
            if (on_leaf(current.child, current.groups)) return;
            tmax = _mm_set1_ps(ray.tmax);
        }
        if (!pop(stack, size, ray.tmax, current)) return;
    }
}

#if BVHKIT_RAY_AVX2
/// One axis of the eight-wide slab test: [t0, t1] narrowed to the ray's stretch between the near
/// and far planes of the eight boxes. Every eight-wide clip goes through it (clip8, the octant
/// streams), so that all of them round alike.
[[gnu::target("avx2"), gnu::always_inline]] inline void clip_axis8(__m256 near, __m256 far,
                                                                   __m256 origin, __m256 inv,
                                                                   __m256 inv_far, __m256& t0,
                                                                   __m256& t1) {
    t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(near, origin), inv), t0);
    t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(far, origin), inv_far), t1);
}

/// An eight-wide node's clip: all ones in the lanes the ray meets, whose entry distances `t0` then
/// holds (t0 comes in as the ray's tmin, t1 as its tmax). The ray's constants come as registers
/// (origin, inv and inv_far per axis) and as the rows of its near and far planes
/// (SlabConstants::near and far).
[[gnu::target("avx2"), gnu::always_inline]] inline __m256 clip8(
    const RayNode<8>& node, const __m256* origin, const __m256* inv, const __m256* inv_far,
    const std::uint32_t* near_row, const std::uint32_t* far_row, __m256& t0, __m256 t1) {
    for (int a = 0; a < 3; ++a)
        clip_axis8(_mm256_load_ps(node.lo[near_row[a]]), _mm256_load_ps(node.lo[far_row[a]]),
                   origin[a], inv[a], inv_far[a], t0, t1);
    return _mm256_cmp_ps(t0, t1, _CMP_LE_OQ);
}

// walk4 in AVX registers. It is written out again because its AVX intrinsics must sit in a function
// that carries the target attribute itself (GCC will not inline them into a lambda or a generic
// helper of the default target), and walk4 must not carry it.
template <class OnLeaf, class Stats>
[[gnu::target("avx2")]] void walk8(WideRayView<8> tree, Ray<float, 3>& ray, const SlabConstants& k,
                                   WideStack8& stack, OnLeaf& on_leaf, Stats& stats) {
    __m256 origin[3], inv[3], inv_far[3];
    for (int a = 0; a < 3; ++a) {
        origin[a] = _mm256_set1_ps(k.origin[a]);
        inv[a] = _mm256_set1_ps(k.inv[a]);
        inv_far[a] = _mm256_set1_ps(k.inv_far[a]);
    }
    const RayNode<8>* nodes = tree.nodes.data();
    const TriangleGroup8* groups = tree.groups.data();
    const auto line = [&](const WideEntry& e) { return entry_address(nodes, groups, e); };
    std::uint32_t size = 0;
    WideEntry current{0, 0, ray.tmin};
    const __m256 tmin = _mm256_set1_ps(ray.tmin);
    __m256 tmax = _mm256_set1_ps(ray.tmax);
    while (true) {
        if (current.groups == 0) {
            const RayNode<8>& node = nodes[current.child];
            for (std::uint32_t c : node.child)
                if (c != invalid_index) stats.node();
            __m256 entry = tmin;
            const __m256 hit = clip8(node, origin, inv, inv_far, k.near, k.far, entry, tmax);
            const unsigned mask = unsigned(_mm256_movemask_ps(hit));
            if (mask != 0) {
                if constexpr (OnLeaf::any_hit)
                    push_in_lane_order8(entry, mask, node, current, stack, size, line);
                else
                    push_nearest_first8(entry, hit, mask, node, current, stack, size, line);
                ask_for_top8(stack, size, line);
                continue;
            }
        } else {
            if (on_leaf.wide8(current.child, current.groups)) return;
            tmax = _mm256_set1_ps(ray.tmax);
        }
        if (!pop8(stack, size, ray.tmax, current)) return;
        ask_for_top8(stack, size, line);
    }
}
#endif

/// The walk of `tree` for `ray`.
template <int W, class OnLeaf, class Stats>
void traverse_wide_ray(WideRayView<W> tree, Ray<float, 3>& ray, const SlabConstants& k,
                       OnLeaf&& on_leaf, Stats& stats) {
    if constexpr (W == 4) {
        WideStack4 stack;
        walk4(tree, ray, k, stack, on_leaf, stats);
    } else {
        static_assert(W == 8);
#if BVHKIT_RAY_AVX2
        WideStack8 stack;
        walk8(tree, ray, k, stack, on_leaf, stats);
#endif
    }
}

}  // namespace detail

namespace detail {

// The leaf tests of the two queries, for groups of Group (TriangleGroup4 or TriangleGroup8):
// operator() for walk4, wide8 for walk8, which tests a leaf's groups of eight in AVX registers
// (intersect_watertight8); named structs rather than lambdas because wide8 must carry the AVX2
// target itself to be inlined into walk8. Each is used only with its width's groups.
template <class Group, class Stats>
struct ClosestLeaves {
    static constexpr bool any_hit = false;  // the walk visits hit children nearest first
    const Group* groups;
    const WatertightRay<float>& prep;
    Ray<float, 3>& ray;
    TriangleHit<float>& best;
    const Group*& hit_group;
    int& hit_lane;
    Stats& stats;

    /// A hit in group g becomes the closest so far, and the range shrinks to it.
    auto record(std::uint32_t g) {
        return [this, g](int lane, const TriangleHit<float>& h) {
            best = h;
            hit_group = groups + g;
            hit_lane = lane;
            return h.t;
        };
    }
    bool operator()(std::uint32_t first, std::uint32_t count) {
        const WatertightRay4 r4(prep);  // made per leaf: the eight-wide walk does not need it
        for (std::uint32_t g = first; g < first + count; ++g) {
            count_lanes(groups[g], stats);
            intersect_watertight4(r4, groups[g], ray.tmin, ray.tmax, record(g));
        }
        return false;
    }
#if BVHKIT_RAY_AVX2
    [[gnu::target("avx2"), gnu::always_inline]] inline bool wide8(std::uint32_t first,
                                                                  std::uint32_t count) {
        for (std::uint32_t g = first; g < first + count; ++g) {
            count_lanes(groups[g], stats);
            intersect_watertight8(prep, groups[g], ray.tmin, ray.tmax, record(g));
        }
        return false;
    }
#endif
};

template <class Group, class Stats>
struct AnyLeaves {
    static constexpr bool any_hit = true;  // the walk visits hit children in any order
    const Group* groups;
    const WatertightRay<float>& prep;
    const Ray<float, 3>& ray;
    bool& found;
    Stats& stats;

    /// Any hit ends the search.
    auto record() {
        return [this](int, const TriangleHit<float>& h) {
            found = true;
            return h.t;
        };
    }
    bool operator()(std::uint32_t first, std::uint32_t count) {
        const WatertightRay4 r4(prep);
        for (std::uint32_t g = first; g < first + count && !found; ++g) {
            count_lanes(groups[g], stats);
            float tmax = ray.tmax;
            intersect_watertight4(r4, groups[g], ray.tmin, tmax, record());
        }
        return found;
    }
#if BVHKIT_RAY_AVX2
    [[gnu::target("avx2"), gnu::always_inline]] inline bool wide8(std::uint32_t first,
                                                                  std::uint32_t count) {
        for (std::uint32_t g = first; g < first + count && !found; ++g) {
            count_lanes(groups[g], stats);
            float tmax = ray.tmax;
            intersect_watertight8(prep, groups[g], ray.tmin, tmax, record());
        }
        return found;
    }
#endif
};

}  // namespace detail

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
    Ray<float, 3> ray = ray_in;
    hit_group = nullptr;
    hit_lane = 0;
    detail::ClosestLeaves<typename WideRayView<W>::Group, std::remove_reference_t<Stats>> leaves{
        tree.groups.data(), prep, ray, best, hit_group, hit_lane, stats};
    detail::traverse_wide_ray(tree, ray, k, leaves, stats);
    return hit_group != nullptr;
}

/// Any hit through a wide tree (same conditions as closest_hit_wide).
template <int W, class Stats = NoStats>
bool any_hit_wide(WideRayView<W> tree, const Ray<float, 3>& ray_in,
                  const WatertightRay<float>& prep, Stats&& stats = {}) {
    // The slab constants from the caller's ray, before the copy the walk reads: read from the
    // copy, its direction straddled the two stores that wrote it (a store-forwarding stall).
    const detail::SlabConstants k(ray_in);
    Ray<float, 3> ray = ray_in;
    bool found = false;
    detail::AnyLeaves<typename WideRayView<W>::Group, std::remove_reference_t<Stats>> leaves{
        tree.groups.data(), prep, ray, found, stats};
    detail::traverse_wide_ray(tree, ray, k, leaves, stats);
    return found;
}
#endif

/// Whether the wide walk serves `ray`: traceable, and no direction component subnormal (whose
/// reciprocal the slab test would ignore, letting the ray into empty lanes).
inline bool wide_ray_usable(const Ray<float, 3>& ray) {
#if defined(__SSE2__)
    // The same tests on all components at once (per component they were a large share of a
    // camera ray's instructions): |x| < inf is false for NaN and inf; a direction component is
    // 0 or at least the least normal float; at least one is not 0.
    const __m128 sign = _mm_set1_ps(-0.0f);
    const __m128 o =
        _mm_andnot_ps(sign, _mm_setr_ps(ray.origin[0], ray.origin[1], ray.origin[2], 0));
    const __m128 d =
        _mm_andnot_ps(sign, _mm_setr_ps(ray.direction[0], ray.direction[1], ray.direction[2], 0));
    const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    const __m128 zero = _mm_setzero_ps();
    const int finite = _mm_movemask_ps(_mm_and_ps(_mm_cmplt_ps(o, inf), _mm_cmplt_ps(d, inf)));
    const int normal = _mm_movemask_ps(_mm_or_ps(
        _mm_cmpeq_ps(d, zero), _mm_cmpge_ps(d, _mm_set1_ps(std::numeric_limits<float>::min()))));
    const int moves = _mm_movemask_ps(_mm_cmpgt_ps(d, zero));
    return (finite & normal) == 15 && moves != 0 && ray.tmin <= ray.tmax;
#else
    if (!is_traceable(ray)) return false;
    for (int a = 0; a < 3; ++a)
        if (std::fpclassify(ray.direction[a]) == FP_SUBNORMAL) return false;
    return true;
#endif
}

}  // namespace bvhkit

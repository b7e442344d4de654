#pragma once
// Ray queries over a Bvh of boxes: closest hit, any hit (occlusion) and all hits, each within the
// ray's [tmin, tmax], in 2D and 3D.
//
// One traversal serves all three (traverse_ray): iterative, with a fixed stack of max_bvh_depth
// entries (each internal node on the current path pushes at most one), nearer child first. A pushed
// child remembers its entry distance, so once a closer hit has shrunk tmax the popped subtree is
// skipped without touching its node.
//
// Each takes the tree as a BvhView (a Bvh's own arrays, or a mapped file's) or as a Bvh.
//
// Primitive tests are the caller's: `test(slot, ray, hit)` tests the primitive in leaf slot `slot`
// (bvh.primitive_indices[slot] is the caller's index) against `ray`, whose tmax is the closest hit
// so far, and on a hit fills `hit` and returns true. TriangleBvh (triangle_bvh.hpp) and the span
// overloads below supply it. A test that also has `normal(slot)` gives the reported hits their
// geometric normal (Hit::normal); otherwise it is zero.
//
// A ray that is not traceable (math/ray.hpp: a NaN or infinite origin or direction component, a
// zero direction, or tmin > tmax or NaN) misses at once, without visiting a node.
#include <span>
#include <utility>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/traversal_stack.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/hit.hpp"
#include "bvhkit/primitives/primitive.hpp"
#include "bvhkit/query/ray_pair_test.hpp"
#include "bvhkit/query/stats.hpp"

namespace bvhkit {

/// Walks the nodes `ray` meets, nearer first; calls on_leaf(node) for each leaf it reaches, which
/// may shrink ray.tmax and returns true to stop the walk. The loop is instantiated once per ray
/// octant, so the slab test's choice of near and far planes is made at compile time.
template <class T, std::size_t N, class OnLeaf, class Stats = NoStats>
void traverse_ray(BvhView<Aabb<T, N>> bvh, Ray<T, N>& ray, OnLeaf&& on_leaf, Stats&& stats = {}) {
    if (bvh.empty() || !is_traceable(ray)) return;
    traverse_ray(bvh, ray, RaySlabData<T, N>(ray), on_leaf, stats);
}
/// The same with the slab data made by the caller from `ray`, for a tree that is not empty and a
/// traceable ray (the caller checks both). closest_hit and the others make it from their caller's
/// ray before copying that ray for the walk to narrow: read from the fresh copy, the direction
/// straddled the two stores that wrote it, a store-forwarding stall on every ray.
template <class T, std::size_t N, class OnLeaf, class Stats>
void traverse_ray(BvhView<Aabb<T, N>> bvh, Ray<T, N>& ray, const RaySlabData<T, N>& slab,
                  OnLeaf&& on_leaf, Stats&& stats) {
    struct Entry {
        std::uint32_t node;
        T t_entry;
    };
    // One stack for all eight octant instances, outside them: each with its own 512-byte array,
    // GCC's stack-frame growth limit stopped it from inlining them into the dispatch in a large
    // file (the bench's), and the out-of-line walk is slower.
    FixedStack<Entry, max_bvh_depth> stack;
    slab.with_octant([&](auto octant) {
        constexpr unsigned O = decltype(octant)::value;
        const RayPairTest<T, N> pair_test(slab, octant);
        const auto* nodes = bvh.nodes.data();
        // The root's own box needs a test only when it is a leaf: an internal root's children lie
        // inside it, so testing them decides as much.
        if (nodes[0].is_leaf()) {
            T t0 = ray.tmin, t1 = ray.tmax;
            stats.node();
            if (!slab.template clip<O>(nodes[0].bounds, t0, t1)) return;
        }
        std::uint32_t current = 0;
        auto interval = pair_test.interval(ray.tmin, ray.tmax);  // made again after each leaf
        while (true) {
            const auto& node = nodes[current];
            if (node.is_leaf()) {
                if (on_leaf(node)) return;
                interval = pair_test.interval(ray.tmin, ray.tmax);
            } else {
                const std::uint32_t left = node.left();  // the right child is left + 1
                T entry[2];
                const unsigned hits = pair_test.template test<O>(nodes + left, interval, entry);
                stats.node();
                stats.node();
                if (hits) {
                    // Descend without data-dependent branches (they mispredict on incoherent rays):
                    // the far child is always written to the stack, and kept only when both hit.
                    const bool both = hits == 3u;
                    const bool right_first = hits == 2u || (both && entry[1] < entry[0]);
                    stack.push_if(Entry{left + !right_first, entry[right_first ? 0 : 1]}, both);
                    current = left + right_first;
                    // Ask now for the lines read next: the near child's children, and when both
                    // children are hit, the far child's children, read when it is popped (its
                    // node is in the line just tested, so the address costs nothing). For a leaf
                    // `first` is a primitive slot and the address meaningless, which a prefetch
                    // tolerates (it never faults).
                    __builtin_prefetch(nodes + nodes[current].first);
                    if (both) __builtin_prefetch(nodes + nodes[left + !right_first].first);
                    continue;
                }
            }
            // Pop the next subtree that can still hold something within [tmin, tmax].
            Entry next;
            do {
                if (stack.empty()) return;
                next = stack.pop();
            } while (next.t_entry > ray.tmax);
            current = next.node;
        }
    });
}

/// Closest hit: `test(slot, ray, TriangleHit&)`, see above. Returns a miss (Hit::primitive ==
/// invalid_index, t = inf) when nothing is hit within [tmin, tmax].
namespace detail {
template <class T, std::size_t N, class Test>
Hit<T, N> make_hit(const Test& test, std::uint32_t slot, std::uint32_t primitive,
                   const TriangleHit<T>& h) {
    Hit<T, N> hit{h.t, primitive, h.u, h.v};
    if constexpr (requires { hit.normal = test.normal(slot); }) hit.normal = test.normal(slot);
    return hit;
}
}  // namespace detail

template <class T, std::size_t N, class Test, class Stats = NoStats>
Hit<T, N> closest_hit(BvhView<Aabb<T, N>> bvh, const Ray<T, N>& ray_in, Test&& test,
                      Stats&& stats = {}) {
    if (bvh.empty() || !is_traceable(ray_in)) return Hit<T, N>{};
    const RaySlabData<T, N> slab(ray_in);
    Ray<T, N> ray = ray_in;
    // The test's output is a local of the leaf loop, which the compiler keeps in registers; the
    // best hit is copied out only on a hit (faster than one record shared by reference).
    struct Best {
        TriangleHit<T> hit;
        std::uint32_t slot = invalid_index;
    } best;
    traverse_ray(
        bvh, ray, slab,
        [&](const auto& leaf) {
            for (std::uint32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
                stats.primitive();
                TriangleHit<T> h;
                // The test takes t up to ray.tmax, the best t so far: at an equal t the lower
                // primitive index is kept, the rule of every walk (closer_hit, ray_wide.hpp), so
                // which of two triangles hit at one t is named does not depend on the walk.
                if (test(s, ray, h) &&
                    (best.slot == invalid_index || h.t < best.hit.t ||
                     (h.t == best.hit.t &&
                      bvh.primitive_indices[s] < bvh.primitive_indices[best.slot]))) {
                    ray.tmax = h.t;
                    best.hit = h;
                    best.slot = s;
                }
            }
            return false;
        },
        stats);
    if (best.slot == invalid_index) return Hit<T, N>{};
    return detail::make_hit<T, N>(test, best.slot, bvh.primitive_indices[best.slot], best.hit);
}

/// Any hit (occlusion): true as soon as some primitive is hit within [tmin, tmax].
template <class T, std::size_t N, class Test, class Stats = NoStats>
bool any_hit(BvhView<Aabb<T, N>> bvh, const Ray<T, N>& ray_in, Test&& test, Stats&& stats = {}) {
    if (bvh.empty() || !is_traceable(ray_in)) return false;
    const RaySlabData<T, N> slab(ray_in);
    Ray<T, N> ray = ray_in;
    bool found = false;
    traverse_ray(
        bvh, ray, slab,
        [&](const auto& leaf) {
            for (std::uint32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
                stats.primitive();
                TriangleHit<T> h;
                if (test(s, ray, h)) return found = true;
            }
            return false;
        },
        stats);
    return found;
}

/// All hits within [tmin, tmax], in no particular order: on_hit(const Hit<T, N>&) returns true to
/// go on, false to stop.
template <class T, std::size_t N, class Test, class OnHit, class Stats = NoStats>
void all_hits(BvhView<Aabb<T, N>> bvh, const Ray<T, N>& ray_in, Test&& test, OnHit&& on_hit,
              Stats&& stats = {}) {
    if (bvh.empty() || !is_traceable(ray_in)) return;
    const RaySlabData<T, N> slab(ray_in);
    Ray<T, N> ray = ray_in;
    TriangleHit<T> h;
    traverse_ray(
        bvh, ray, slab,
        [&](const auto& leaf) {
            for (std::uint32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
                stats.primitive();
                if (test(s, ray, h) &&
                    !on_hit(detail::make_hit<T, N>(test, s, bvh.primitive_indices[s], h)))
                    return true;
            }
            return false;
        },
        stats);
}

// The same four over a Bvh's own arrays.
template <class T, std::size_t N, class... Args>
void traverse_ray(const Bvh<Aabb<T, N>>& bvh, Ray<T, N>& ray, Args&&... args) {
    traverse_ray(bvh_view(bvh), ray, std::forward<Args>(args)...);
}
template <class T, std::size_t N, class... Args>
Hit<T, N> closest_hit(const Bvh<Aabb<T, N>>& bvh, const Ray<T, N>& ray, Args&&... args) {
    return closest_hit(bvh_view(bvh), ray, std::forward<Args>(args)...);
}
template <class T, std::size_t N, class... Args>
bool any_hit(const Bvh<Aabb<T, N>>& bvh, const Ray<T, N>& ray, Args&&... args) {
    return any_hit(bvh_view(bvh), ray, std::forward<Args>(args)...);
}
template <class T, std::size_t N, class... Args>
void all_hits(const Bvh<Aabb<T, N>>& bvh, const Ray<T, N>& ray, Args&&... args) {
    all_hits(bvh_view(bvh), ray, std::forward<Args>(args)...);
}

/// The primitive test for a span of RayPrimitives indexed as the tree was built over them.
template <RayPrimitive P>
auto primitive_ray_test(const Bvh<Aabb<typename P::Scalar, primitive_dimension<P>>>& bvh,
                        std::span<const P> primitives) {
    using T = typename P::Scalar;
    return [&bvh, primitives](std::uint32_t slot, const Ray<T, primitive_dimension<P>>& ray,
                              TriangleHit<T>& out) {
        const auto h = primitives[bvh.primitive_indices[slot]].intersect(ray);
        if (h) out = *h;
        return h.has_value();
    };
}

}  // namespace bvhkit

#pragma once
// Nearest-primitive queries over a Bvh of boxes: the closest primitive to a point, the k closest,
// and all within a radius (the distance queries of proximity work).
//
// Closest and k closest walk best-first (the usual best-first rule for nearest queries): a min-heap
// of nodes keyed by the squared distance from the point to their box, and a search radius that
// shrinks as closer primitives are found; a node farther than the radius is never opened, and the
// walk ends when the nearest node left is. Popping a node descends straight into its nearer child
// and only queues the farther one, which halves the heap traffic. The heap lives in a
// NearestScratch the caller keeps (one per thread), so queries allocate nothing once it has grown.
// A distance functor may also offer prefetch(slot), called for each leaf within the radius when
// it is first seen (the walk may open it later).
//
// The primitive's distance is the caller's: `distance(slot, point, bound)` returns the squared
// distance from `point` to the primitive in leaf slot `slot` (bvh.primitive_indices[slot] is the
// caller's index), or any value above `bound` when it is farther than `bound` (so a cheap test
// can reject it without the exact distance). ClosestPointMesh (closest_point_mesh.hpp) supplies it
// for triangles. A functor whose rounded distances can fall below the boxes' (Ericson's closest
// point can land an ulp outside the triangle's box) offers widen(point, bound): the walks then
// prune boxes against that larger bound, and accept primitives against the bound itself.
//
// Keys wider than T: squared distances leave T's range long before the distances do (a float
// point 2e19 from a primitive, or primitives 1e-23 apart, give inf or 0 and every candidate
// ties). k_nearest and within_radius therefore rank by whatever the functor returns, its key K
// (double or long double for T = float, say, or a key that is not a squared distance at all, such
// as ClosestPointMesh's for far points), compare and return keys in K and only prune boxes in T:
// widen(point, key) turns a key into a squared radius in T that is no smaller than any box within
// reach (inf where it is past T's range: the walk then opens every box it meets, which is slower
// but never drops a primitive). Without widen, a key is taken for a squared distance and rounded
// up to T. A functor returning T keeps T's range.
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include "bvhkit/bvh/sibling_pair.hpp"
#include "bvhkit/bvh/traverse.hpp"
#include "bvhkit/primitives/hit.hpp"
#include "bvhkit/query/stats.hpp"

namespace bvhkit {

/// A node waiting in the best-first heap.
template <class T>
struct NearestEntry {
    T distance_squared;
    std::uint32_t node;
};

/// Reusable storage of the nearest queries: keep one per thread.
template <class T>
struct NearestScratch {
    std::vector<NearestEntry<T>> heap;
    std::vector<std::pair<T, std::uint32_t>> candidates;  // closest point: (float estimate, slot)
};

/// The result of a nearest query: the leaf slot of the primitive (invalid_index when none lies
/// within the search radius) and its squared distance.
template <class T>
struct NearestSlot {
    std::uint32_t slot = invalid_index;
    T distance_squared = std::numeric_limits<T>::infinity();
    explicit operator bool() const { return slot != invalid_index; }
};

namespace nearest_detail {

/// The key a distance functor ranks by: the type it returns.
template <class Distance, class T, std::size_t N>
using key_of = std::decay_t<std::invoke_result_t<Distance&, std::uint32_t, const Vec<T, N>&, T>>;

/// x rounded up to T: inf past T's largest value (and NaN for NaN).
template <class T, class K>
T round_up_key(K x) {
    if constexpr (std::is_same_v<K, T>) {
        return x;
    } else {
        if (x != x) return std::numeric_limits<T>::quiet_NaN();
        if (x > K(std::numeric_limits<T>::max())) return std::numeric_limits<T>::infinity();
        if (x < -K(std::numeric_limits<T>::max())) return -std::numeric_limits<T>::max();
        T y = T(x);
        if (K(y) < x) y = std::nextafter(y, std::numeric_limits<T>::infinity());
        return y;
    }
}

/// The squared radius in T to prune boxes with, for a search radius (a key) of `radius2`.
template <class Distance, class T, std::size_t N, class K>
T prune_radius2(const Distance& distance, const Vec<T, N>& p, K radius2) {
    if constexpr (requires { distance.widen(p, radius2); })
        return distance.widen(p, radius2);
    else
        return round_up_key<T>(radius2);
}

/// The best-first walk (walk_best_first, walk/walks.hpp). `radius2()` is the current squared search
/// radius (it shrinks as on_slot(slot, d2) finds closer primitives).
template <class T, std::size_t N, class Radius, class OnSlot, class Stats>
void best_first(const Bvh<Aabb<T, N>>& bvh, const Vec<T, N>& p, NearestScratch<T>& scratch,
                Radius&& radius2, OnSlot&& on_slot, Stats&& stats) {
    if (bvh.empty()) return;
    const auto* nodes = bvh.nodes.data();
    MinHeap4 heap(scratch.heap, [](const NearestEntry<T>& e) { return e.distance_squared; });
    stats.node();
    const T root_d2 = nodes[0].bounds.distance_squared(p);
    if (root_d2 > radius2()) return;
    heap.push({root_d2, 0});
    const auto hopeless = [&](T d2) { return d2 > radius2(); };  // every node left is farther
    walk_best_first(heap, hopeless, [&](NearestEntry<T>& e, auto& queue) {
        const auto& node = nodes[e.node];
        if (node.is_leaf()) {
            for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
                stats.primitive();
                on_slot(s);
            }
            return Step::Pop;
        }
        const std::uint32_t l = node.left();
        T d[2];
        pair_distances_squared(nodes + l, p, d);
        stats.node();
        stats.node();
        const bool right_nearer = d[1] < d[0];
        const std::uint32_t near = l + right_nearer, far = l + !right_nearer;
        const T dl = d[right_nearer], dr = d[!right_nearer];
        const T r2 = radius2();
        // A child within the radius is likely to be opened (now or from the heap): ask for its
        // children's line, or its leaf's first primitive, before it is needed. Queries jump
        // around a tree far larger than the caches, so this hides a miss per node.
        for (int c = 0; c < 2; ++c) {
            if (d[c] > r2) continue;
            const auto& child = nodes[l + c];
            if (child.is_leaf()) {
                if constexpr (requires { on_slot.prefetch(0u); }) on_slot.prefetch(child.first);
            } else {
                __builtin_prefetch(nodes + child.first);
            }
        }
        if (dr <= r2) queue.push({dr, far});
        if (dl > r2) return Step::Pop;
        e.node = near;  // the nearer child goes on without a trip through the heap
        return Step::Continue;
    });
}

}  // namespace nearest_detail

/// The primitive nearest to `p` within sqrt(max_distance_squared) (inclusive). Of primitives at
/// exactly the same distance, the one found first wins.
template <class T, std::size_t N, class Distance, class Stats = NoStats>
NearestSlot<T> nearest(const Bvh<Aabb<T, N>>& bvh, const Vec<T, N>& p, Distance&& distance,
                       NearestScratch<T>& scratch,
                       T max_distance_squared = std::numeric_limits<T>::infinity(),
                       Stats&& stats = {}) {
    NearestSlot<T> best;
    T radius2 = max_distance_squared;
    struct OnSlot {
        Distance& distance;
        const Vec<T, N>& p;
        NearestSlot<T>& best;
        T& radius2;
        void operator()(std::uint32_t s) {
            const T d2 = distance(s, p, radius2);
            if (d2 < best.distance_squared && d2 <= radius2) {
                best = {s, d2};
                radius2 = d2;
            }
        }
        void prefetch(std::uint32_t s) {
            if constexpr (requires { distance.prefetch(s); }) distance.prefetch(s);
        }
    };
    nearest_detail::best_first(
        bvh, p, scratch, [&] { return nearest_detail::prune_radius2(distance, p, radius2); },
        OnSlot{distance, p, best, radius2}, stats);
    return best;
}

/// The k primitives nearest to `p` (fewer when the tree holds fewer), nearest first, as (key,
/// leaf slot) in `out`; the key is what `distance` returns (K, a squared distance in T or wider:
/// see the file's comment), and `out`'s key type must hold it. Of primitives with equal keys the
/// one in the lower slot comes first.
template <class T, std::size_t N, class Distance, class K, class Stats = NoStats>
void k_nearest(const Bvh<Aabb<T, N>>& bvh, const Vec<T, N>& p, std::size_t k, Distance&& distance,
               NearestScratch<T>& scratch, std::vector<std::pair<K, std::uint32_t>>& out,
               std::type_identity_t<K> max_key = std::numeric_limits<K>::infinity(),
               Stats&& stats = {}) {
    static_assert(std::is_convertible_v<nearest_detail::key_of<Distance, T, N>, K>,
                  "k_nearest: out's key type must hold what the distance functor returns");
    out.clear();
    if (k == 0) return;
    // `out` itself is the max-heap of the k best so far (the caller keeps it, so it stays grown).
    auto& best = out;
    K radius = max_key;
    T prune2 = nearest_detail::prune_radius2(distance, p, radius);
    nearest_detail::best_first(
        bvh, p, scratch, [&] { return prune2; },
        [&](std::uint32_t s) {
            const K key = distance(s, p, radius);
            if (!(key <= radius)) return;  // NaN included
            if (best.size() == k) {
                if (!(std::pair<K, std::uint32_t>(key, s) < best.front())) return;
                std::pop_heap(best.begin(), best.end());
                best.pop_back();
            }
            best.emplace_back(key, s);
            std::push_heap(best.begin(), best.end());
            if (best.size() == k && best.front().first < radius) {
                radius = best.front().first;
                prune2 = nearest_detail::prune_radius2(distance, p, radius);
            }
        },
        stats);
    std::sort_heap(best.begin(), best.end());
}

/// Every primitive within `radius` of `p` (inclusive): on_found(LeafSlot, key) returns true to go
/// on, false to stop; the key is what `distance` returns, compared with radius^2 taken in the
/// key's type (for a float tree and a double key, exactly). Depth first (bvh/traverse.hpp; the
/// order does not matter here). A negative or NaN radius holds nothing (no ball has it): no
/// primitive is reported. (`distance` still takes the slot as a number: it is the functor
/// nearest() and k_nearest() share.)
template <class T, std::size_t N, class Distance, class OnFound, class Stats = NoStats>
bool within_radius(const Bvh<Aabb<T, N>>& bvh, const Vec<T, N>& p, T radius, Distance&& distance,
                   OnFound&& on_found, Stats&& stats = {}) {
    if (!(radius >= T(0))) return true;
    using K = nearest_detail::key_of<Distance, T, N>;
    const K r2 = K(radius) * K(radius);
    const T prune2 = nearest_detail::prune_radius2(distance, p, r2);
    const auto enter = [&](std::uint32_t, const BvhNode<Aabb<T, N>>& node) {
        stats.node();
        return node.bounds.distance_squared(p) <= prune2;
    };
    const auto on_leaf = [&](const BvhNode<Aabb<T, N>>& leaf) {
        for (const LeafSlot s : leaf_slots(leaf)) {
            stats.primitive();
            const K d2 = distance(s.value, p, r2);
            if (d2 <= r2 && !on_found(s, d2)) return false;
        }
        return true;
    };
    return traverse_depth_first(bvh, enter, on_leaf);
}

}  // namespace bvhkit

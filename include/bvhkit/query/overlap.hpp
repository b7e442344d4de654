#pragma once
// Overlap queries over a Bvh of boxes: every primitive whose box overlaps a box, meets a sphere
// (ball) or contains a point (touching counts), in 2D and 3D. These test primitive *boxes*; an
// exact test against the primitive itself is the caller's, inside the callback.
//
// Traversal as in query/ray.hpp: iterative, a fixed stack of max_bvh_depth entries (each internal
// node on the path pushes one child), no allocation. on_hit(std::uint32_t primitive) returns true
// to go on, false to stop the query early (the function then returns false).
//
// Batch versions answer many queries (in parallel with oneTBB, see exec/executor.hpp) into one
// compressed list: the hits of query q are hits[offsets[q] .. offsets[q + 1]), in traversal order,
// the same for any number of threads.
#include <span>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/traverse.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/query/stats.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// Walks every node for which node_test(box) holds; calls on_hit(primitive index) for each
/// primitive whose box passes prim_test(box). Returns false when on_hit stopped the walk.
template <class T, std::size_t N, class NodeTest, class PrimTest, class OnHit,
          class Stats = NoStats>
bool overlap_walk(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                  NodeTest&& node_test, PrimTest&& prim_test, OnHit&& on_hit, Stats&& stats = {}) {
    const auto enter = [&](std::uint32_t, const BvhNode<Aabb<T, N>>& node) {
        stats.node();
        return node_test(node.bounds);
    };
    const auto on_leaf = [&](const BvhNode<Aabb<T, N>>& leaf) {
        for (const LeafSlot s : leaf_slots(leaf)) {
            const std::uint32_t p = bvh.primitive_indices[s.value];
            stats.primitive();
            if (prim_test(primitive_boxes[p]) && !on_hit(p)) return false;
        }
        return true;
    };
    return traverse_depth_first(bvh, enter, on_leaf);
}

/// Primitives whose box overlaps `box`.
template <class T, std::size_t N, class OnHit, class Stats = NoStats>
bool query_box(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
               const Aabb<T, N>& box, OnHit&& on_hit, Stats&& stats = {}) {
    const auto test = [&](const Aabb<T, N>& b) { return b.overlaps(box); };
    return overlap_walk(bvh, primitive_boxes, test, test, on_hit, stats);
}

/// Primitives whose box meets the ball of `radius` around `center`.
template <class T, std::size_t N, class OnHit, class Stats = NoStats>
bool query_sphere(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                  const Vec<T, N>& center, T radius, OnHit&& on_hit, Stats&& stats = {}) {
    const T r2 = radius * radius;
    const auto test = [&](const Aabb<T, N>& b) { return b.distance_squared(center) <= r2; };
    return overlap_walk(bvh, primitive_boxes, test, test, on_hit, stats);
}

/// Primitives whose box contains `point`.
template <class T, std::size_t N, class OnHit, class Stats = NoStats>
bool query_point(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                 const Vec<T, N>& point, OnHit&& on_hit, Stats&& stats = {}) {
    const auto test = [&](const Aabb<T, N>& b) { return b.contains(point); };
    return overlap_walk(bvh, primitive_boxes, test, test, on_hit, stats);
}

/// The hits of many queries: hits[offsets[q] .. offsets[q + 1]) for query q.
struct BatchHits {
    std::vector<std::size_t> offsets;
    std::vector<std::uint32_t> hits;
    std::span<const std::uint32_t> of(std::size_t q) const {
        return {hits.data() + offsets[q], offsets[q + 1] - offsets[q]};
    }
};

namespace overlap_detail {

/// Runs query(q, push) for every q; chunks of queries collect into their own lists, joined in
/// order, so the result does not depend on the threads.
template <class Query>
BatchHits run_batch(std::size_t count, const Executor& exec, Query&& query) {
    constexpr std::size_t grain = tuning::overlap_batch_grain;
    const std::size_t chunks = (count + grain - 1) / grain;
    std::vector<std::vector<std::uint32_t>> chunk_hits(chunks);
    std::vector<std::size_t> counts(count);
    exec.parallel_for(count, grain, [&](std::size_t b, std::size_t e) {
        auto& out = chunk_hits[b / grain];
        for (std::size_t q = b; q < e; ++q) {
            const std::size_t before = out.size();
            query(q, [&](std::uint32_t p) {
                out.push_back(p);
                return true;
            });
            counts[q] = out.size() - before;
        }
    });
    BatchHits result;
    result.offsets.resize(count + 1);
    result.offsets[0] = 0;
    for (std::size_t q = 0; q < count; ++q) result.offsets[q + 1] = result.offsets[q] + counts[q];
    result.hits.reserve(result.offsets[count]);
    for (auto& c : chunk_hits) result.hits.insert(result.hits.end(), c.begin(), c.end());
    return result;
}

}  // namespace overlap_detail

template <class T, std::size_t N>
BatchHits query_boxes(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                      std::span<const Aabb<T, N>> queries, const Executor& exec) {
    return overlap_detail::run_batch(queries.size(), exec, [&](std::size_t q, auto&& push) {
        query_box(bvh, primitive_boxes, queries[q], push);
    });
}

template <class T, std::size_t N>
BatchHits query_spheres(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                        std::span<const Vec<T, N>> centers, std::span<const T> radii,
                        const Executor& exec) {
    return overlap_detail::run_batch(centers.size(), exec, [&](std::size_t q, auto&& push) {
        query_sphere(bvh, primitive_boxes, centers[q], radii[q], push);
    });
}

template <class T, std::size_t N>
BatchHits query_points(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                       std::span<const Vec<T, N>> points, const Executor& exec) {
    return overlap_detail::run_batch(points.size(), exec, [&](std::size_t q, auto&& push) {
        query_point(bvh, primitive_boxes, points[q], push);
    });
}

// The same on `threads` threads (0 = all, 1 = serial).
template <class T, std::size_t N>
BatchHits query_boxes(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                      std::span<const Aabb<T, N>> queries, unsigned threads = 0) {
    return query_boxes(bvh, primitive_boxes, queries, Executor(threads));
}

template <class T, std::size_t N>
BatchHits query_spheres(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                        std::span<const Vec<T, N>> centers, std::span<const T> radii,
                        unsigned threads = 0) {
    return query_spheres(bvh, primitive_boxes, centers, radii, Executor(threads));
}

template <class T, std::size_t N>
BatchHits query_points(const Bvh<Aabb<T, N>>& bvh, std::span<const Aabb<T, N>> primitive_boxes,
                       std::span<const Vec<T, N>> points, unsigned threads = 0) {
    return query_points(bvh, primitive_boxes, points, Executor(threads));
}

}  // namespace bvhkit

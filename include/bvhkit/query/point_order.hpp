#pragma once
// spatial_order: the indices of a batch of query points sorted along a Morton curve over the
// batch's bounding box, so that points answered one after another lie close together and find
// the tree's nodes and triangles still in cache. Closest-point batches gain from it, the sort
// included, random points more than a grid in row order (docs/proximity.md); rays gained nothing
// from the like (docs/benchmarks.md, "Ray measurements").
//
// The sort is a radix sort of 32-bit keys (ten bits an axis), stable, so points in one cell keep
// their order and the result is the same on every run and thread count. Points with a NaN or
// infinite coordinate go last (of their run of spatial_order_run points).
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "bvhkit/build/morton.hpp"  // morton_spread3
#include "bvhkit/error.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/primitives/hit.hpp"  // invalid_index
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// The most points spatial_order sorts as one run: a larger batch is sorted in consecutive runs
/// of this many, each along its own curve, so the sort's buffers stay bounded (16 bytes a point)
/// whatever the batch, in runs dense enough that neighbours still share the tree (tuning.hpp).
inline constexpr std::size_t spatial_order_run = tuning::spatial_order_run;

namespace point_order_detail {

/// Sorts items[0, count) by their bits [shift, end), stably, eight bits a pass from the least
/// significant, using spare[0, count); the result ends in items.
inline void radix_sort(std::uint64_t* items, std::uint64_t* spare, std::size_t count, int shift,
                       int end) {
    std::uint64_t *from = items, *to = spare;
    for (; shift < end; shift += 8) {
        std::array<std::size_t, 257> start{};
        for (std::size_t k = 0; k < count; ++k) ++start[(from[k] >> shift & 255) + 1];
        if (start[(from[0] >> shift & 255) + 1] == count) continue;  // one digit: no pass
        for (int d = 0; d < 256; ++d) start[d + 1] += start[d];
        for (std::size_t k = 0; k < count; ++k) to[start[from[k] >> shift & 255]++] = from[k];
        std::swap(from, to);
    }
    if (from != items) std::copy(from, from + count, items);
}

}  // namespace point_order_detail

/// The order in which to answer n points, point(i) giving point i (a Vec<T, 3>): a permutation
/// of 0 .. n - 1; see above. `run`: the points sorted together (spatial_order_run). `exec`: an
/// Executor, or anything with its parallel_for(count, grain, body); the order is the same for
/// every thread count.
template <class PointAt, class Exec>
std::vector<std::uint32_t> spatial_order(std::size_t n, PointAt&& point, const Exec& exec,
                                         std::size_t run = spatial_order_run) {
    using V = std::remove_cvref_t<decltype(point(std::size_t(0)))>;
    using Box = Aabb<typename V::Scalar, 3>;
    if (n >= std::size_t(invalid_index))
        throw Error("spatial_order: " + std::to_string(n) +
                    " points, more than 32-bit indices hold");
    run = std::max<std::size_t>(run, 1);
    constexpr std::size_t grain = tuning::spatial_order_grain;
    std::vector<std::uint32_t> order(n);
    std::vector<std::uint64_t> items, spare;
    std::vector<Box> chunk_bounds;
    for (std::size_t first = 0; first < n; first += run) {
        const std::size_t count = std::min(run, n - first);
        // The box of the finite points, a box per chunk of `grain` points then their union: the
        // same box in any order. Chunk c writes only box c, however the executor splits.
        const std::size_t chunks = (count + grain - 1) / grain;
        chunk_bounds.assign(chunks, Box{});
        exec.parallel_for(chunks, 1, [&](std::size_t b, std::size_t e) {
            for (std::size_t c = b; c < e; ++c)
                for (std::size_t k = c * grain; k < std::min(count, (c + 1) * grain); ++k)
                    if (const V p = point(first + k); is_finite(p)) chunk_bounds[c].grow(p);
        });
        Box bounds;
        for (const Box& box : chunk_bounds) bounds.grow(box);
        // Item: key in the high half, index in the low half. The key interleaves ten bits an
        // axis of the point's cell in the box, 1024 cells an axis (x highest); a non-finite
        // point's key is 2^30. A flat axis has one cell.
        double scale[3];
        for (int a = 0; a < 3; ++a) {
            const double extent = double(bounds.max[a]) - double(bounds.min[a]);
            scale[a] = extent > 0 ? 1024.0 / extent : 0.0;
        }
        items.resize(count);
        spare.resize(count);
        exec.parallel_for(count, grain, [&](std::size_t b, std::size_t e) {
            for (std::size_t k = b; k < e; ++k) {
                const std::size_t i = first + k;
                const V p = point(i);
                std::uint64_t key = std::uint64_t(1) << 30;
                if (is_finite(p)) {
                    key = 0;
                    for (int a = 0; a < 3; ++a) {
                        const double x = (double(p[a]) - double(bounds.min[a])) * scale[a];
                        const std::uint64_t cell = x < 1023.0 ? std::uint64_t(x > 0 ? x : 0) : 1023;
                        key |= morton_spread3(cell) << (2 - a);
                    }
                }
                items[k] = key << 32 | i;
            }
        });
        // A stable sort by the key. A large run: one pass on the key's bits 23-30 (the Morton
        // code's top seven bits and the non-finite flag) into at most 129 buckets, then each
        // bucket sorted on the bits below, least significant first: the same order as one sort
        // from the least significant digit, with the buckets sorted in parallel, most of them
        // small enough to stay in cache (points bunched in a few coarse cells leave few buckets
        // to share out). A small run is one sort: 129 buckets would cost more than they save.
        constexpr int top = 55;
        if (count < tuning::spatial_order_one_sort_below) {
            point_order_detail::radix_sort(items.data(), spare.data(), count, 32, 64);
        } else {
            std::array<std::size_t, 257> start{};
            for (const std::uint64_t item : items) ++start[(item >> top) + 1];
            for (int d = 0; d < 256; ++d) start[d + 1] += start[d];
            {
                std::array<std::size_t, 257> next = start;
                for (const std::uint64_t item : items) spare[next[item >> top]++] = item;
            }
            items.swap(spare);
            exec.parallel_for(256, 1, [&](std::size_t b, std::size_t e) {
                for (std::size_t d = b; d < e; ++d)
                    if (start[d + 1] - start[d] > 1)
                        point_order_detail::radix_sort(items.data() + start[d],
                                                       spare.data() + start[d],
                                                       start[d + 1] - start[d], 32, top);
            });
        }
        exec.parallel_for(count, grain, [&](std::size_t b, std::size_t e) {
            for (std::size_t k = b; k < e; ++k) order[first + k] = std::uint32_t(items[k]);
        });
    }
    return order;
}
template <class T, class Exec>
std::vector<std::uint32_t> spatial_order(std::span<const Vec<T, 3>> points, const Exec& exec,
                                         std::size_t run = spatial_order_run) {
    return spatial_order(
        points.size(), [&](std::size_t i) { return points[i]; }, exec, run);
}

/// Batches from this many points on are answered in spatial_order; smaller ones as they come
/// (their sort would cost about what it saves; tuning.hpp).
inline constexpr std::size_t spatial_order_from = tuning::spatial_order_from;

/// The order to answer a batch of n points in: spatial_order from spatial_order_from points on,
/// else 0 .. n - 1.
template <class PointAt, class Exec>
std::vector<std::uint32_t> batch_order(std::size_t n, PointAt&& point, const Exec& exec) {
    if (n >= spatial_order_from) return spatial_order(n, point, exec);
    std::vector<std::uint32_t> order(n);
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    return order;
}

/// Calls chunk(indices) for consecutive runs of at most `grain` point indices of batch_order,
/// covering every point once, spread over `exec`. A body that writes only the results of the
/// indices it is given answers the same for every thread count and either order.
template <class T, class Chunk>
void for_point_chunks(std::span<const Vec<T, 3>> points, const Executor& exec, std::size_t grain,
                      Chunk&& chunk) {
    const std::vector<std::uint32_t> order = batch_order(
        points.size(), [&](std::size_t i) { return points[i]; }, exec);
    exec.parallel_for(order.size(), grain, [&](std::size_t b, std::size_t e) {
        chunk(std::span<const std::uint32_t>(order.data() + b, e - b));
    });
}

}  // namespace bvhkit

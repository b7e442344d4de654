#pragma once
// The top-down builder behind LinkedTree::rebuild(): binned SAH over the kept subtrees' centroids,
// partitioned in place in one flat array. Each internal node is made as soon as its two children
// are, from the boxes and heights the recursion hands up, so that making it writes the pool and
// reads nothing there. Nothing is allocated per node; the recursion's depth is bounded.
//
// Only the longest axis is binned, with few bins (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies"), the range to bin is taken from the boxes' bounds rather than
// found by a pass over the centroids, and small ranges are split at their middle: on a dynamic
// tree's many small boxes each of these costs a few tenths of a percent of SAH cost (figures in
// docs/dynamic.md) and saves a pass over the items.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "bvhkit/bvh/linked_tree_sah.hpp"

namespace bvhkit::linked {

/// One kept subtree: its box and its node in the linked tree.
template <class T, std::size_t N>
struct RebuildItem {
    Aabb<T, N> box;
    std::int32_t node;
};

/// A subtree the builder has made (or a kept one): its root node, box and height.
template <class T, std::size_t N>
struct RebuiltSubtree {
    Aabb<T, N> box;
    std::int32_t node;
    std::int32_t height;
};

namespace rebuild_detail {

inline constexpr int kBins = 8;
/// Ranges this small are split at the middle of their centroids' longest axis: the binning's fixed
/// cost per node (clearing and sweeping the bins) outweighs its gain there.
inline constexpr std::size_t kSmall = 6;
/// Past this depth a range is split in halves by count: SAH on adversarial inputs (centroids at
/// exponentially growing distances) could peel one item per level, and the recursion must stay
/// shallow. A balanced tree over 2^31 items is 31 deep, so well-spread inputs never reach it.
inline constexpr int kMaxSahDepth = 64;
/// Ranges from this size up are binned into several sets of bins (bin_items), smaller ones into
/// one: merging the sets is a fixed cost per node.
inline constexpr std::size_t kSetsFrom = 128;

/// What the builder sorts by along an axis: a multiple of the centroid. min + max (one addition)
/// where every coordinate lies within a quarter of the type's range; past that (`Far`) it could
/// overflow, and a quarter of each is used, whose differences stay finite too.
template <bool Far, class T>
inline T centre_key(T min, T max) {
    if constexpr (Far) {
        return min * T(0.25) + max * T(0.25);
    } else {
        return min + max;
    }
}

/// Bounds of the centre keys of a range (at least: those of a box holding them all serve).
template <class T, std::size_t N, bool Far>
struct CentreBounds {
    T lo[N], hi[N];

    /// Bounds holding the centre key of every box inside `b` (rounding is monotonic).
    static CentreBounds of_box(const Aabb<T, N>& b) {
        CentreBounds c;
        for (std::size_t a = 0; a < N; ++a)
            c.lo[a] = centre_key<Far>(b.min[a], b.min[a]),
            c.hi[a] = centre_key<Far>(b.max[a], b.max[a]);
        return c;
    }
    static CentreBounds of_items(const RebuildItem<T, N>* items, std::size_t count) {
        CentreBounds c;
        for (std::size_t a = 0; a < N; ++a)
            c.lo[a] = std::numeric_limits<T>::max(), c.hi[a] = std::numeric_limits<T>::lowest();
        for (std::size_t k = 0; k < count; ++k)
            for (std::size_t a = 0; a < N; ++a) {
                const T x = centre_key<Far>(items[k].box.min[a], items[k].box.max[a]);
                c.lo[a] = x < c.lo[a] ? x : c.lo[a];
                c.hi[a] = x > c.hi[a] ? x : c.hi[a];
            }
        return c;
    }
    std::size_t longest_axis() const {
        std::size_t axis = 0;
        for (std::size_t a = 1; a < N; ++a)
            if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
        return axis;
    }
};

/// Hoare's partition (every swap moves two items to their sides) of the items, and of their bin
/// numbers alongside when `bins` is given. Returns how many items goes_left(k) held for.
template <class T, std::size_t N, class GoesLeft>
std::size_t partition(RebuildItem<T, N>* items, std::uint8_t* bins, std::size_t count,
                      GoesLeft&& goes_left) {
    std::size_t first = 0, last = count;
    for (;;) {
        while (first < last && goes_left(first)) ++first;
        while (first < last && !goes_left(last - 1)) --last;
        if (first >= last) return first;
        std::swap(items[first], items[last - 1]);
        if (bins) std::swap(bins[first], bins[last - 1]);
        ++first, --last;
    }
}

template <class T, std::size_t N, class Link>
RebuiltSubtree<T, N> join(const RebuiltSubtree<T, N>& a, const RebuiltSubtree<T, N>& b,
                          Link& link) {
    RebuiltSubtree<T, N> p;
    p.box = unite(a.box, b.box);
    p.height = 1 + std::max(a.height, b.height);
    p.node = link(a.node, b.node, p.box, p.height);
    return p;
}

/// Puts every item's bin number in `bins`, and each bin's bounds and count in `bounds` and
/// `counts`. Consecutive items often fall in the same bin (the kept subtrees come in the old tree's
/// order, which is spatial): with one set of bins each would wait for the last one's update to come
/// back from memory. With Sets sets, item k updating set k % Sets, Sets updates are in flight.
template <std::size_t Sets, bool Far, class T, std::size_t N>
void bin_items(const RebuildItem<T, N>* items, std::uint8_t* bins, std::size_t count,
               std::size_t axis, T origin, T scale, Aabb<T, N> (&bounds)[kBins],
               std::size_t (&counts)[kBins]) {
    Aabb<T, N> set_bounds[Sets][kBins];
    std::uint32_t set_counts[Sets][kBins] = {};
    for (std::size_t j = 0; j < Sets; ++j)
        for (int b = 0; b < kBins; ++b)
            for (std::size_t a = 0; a < N; ++a)
                set_bounds[j][b].min[a] = std::numeric_limits<T>::max(),
                set_bounds[j][b].max[a] = std::numeric_limits<T>::lowest();
    for (std::size_t k = 0; k < count; ++k) {
        const Aabb<T, N>& box = items[k].box;
        // >= 0 as origin bounds every half centroid; +inf past the float range
        const T f = (centre_key<Far>(box.min[axis], box.max[axis]) - origin) * scale;
        const int b = f < T(kBins - 1) ? int(f) : kBins - 1;
        bins[k] = std::uint8_t(b);
        Aabb<T, N>& bin = set_bounds[k % Sets][b];
        ++set_counts[k % Sets][b];
        for (std::size_t a = 0; a < N; ++a) {
            bin.min[a] = box.min[a] < bin.min[a] ? box.min[a] : bin.min[a];
            bin.max[a] = box.max[a] > bin.max[a] ? box.max[a] : bin.max[a];
        }
    }
    for (int b = 0; b < kBins; ++b) {
        bounds[b] = set_bounds[0][b];
        counts[b] = set_counts[0][b];
        for (std::size_t j = 1; j < Sets; ++j) {
            bounds[b] = unite(bounds[b], set_bounds[j][b]);
            counts[b] += set_counts[j][b];
        }
    }
}

template <class T, std::size_t N, bool Far, class Link, class HeightOf>
struct Builder {
    Link& link;
    HeightOf& height_of;

    RebuiltSubtree<T, N> one(const RebuildItem<T, N>& item) const {
        return {item.box, item.node, height_of(item.node)};
    }

    /// Small ranges: split at the middle of the longest axis of the centroids.
    RebuiltSubtree<T, N> small(RebuildItem<T, N>* items, std::size_t count) const {
        if (count == 1) return one(items[0]);
        if (count == 2) return join(one(items[0]), one(items[1]), link);
        const auto cb = CentreBounds<T, N, Far>::of_items(items, count);
        const std::size_t axis = cb.longest_axis();
        const T pivot = cb.lo[axis] * T(0.5) + cb.hi[axis] * T(0.5);
        std::size_t mid =
            partition(items, static_cast<std::uint8_t*>(nullptr), count, [&](std::size_t k) {
                const auto& b = items[k].box;
                return centre_key<Far>(b.min[axis], b.max[axis]) < pivot;
            });
        if (mid == 0 || mid == count) mid = count / 2;
        return join(small(items, mid), small(items + mid, count - mid), link);
    }

    /// `cb` bounds the range's centre keys; `bins` is scratch beside the items, a byte each.
    RebuiltSubtree<T, N> build(RebuildItem<T, N>* items, std::uint8_t* bins, std::size_t count,
                               const CentreBounds<T, N, Far>& cb, int depth) const {
        if (count <= kSmall) return small(items, count);
        const std::size_t axis = cb.longest_axis();
        const T extent = cb.hi[axis] - cb.lo[axis];
        const T scale = T(kBins) / extent;
        if (extent > T(0) && scale <= std::numeric_limits<T>::max() && depth < kMaxSahDepth) {
            const T origin = cb.lo[axis];
            Aabb<T, N> bounds[kBins];
            std::size_t counts[kBins];
            if (count >= kSetsFrom)
                bin_items<4, Far>(items, bins, count, axis, origin, scale, bounds, counts);
            else
                bin_items<1, Far>(items, bins, count, axis, origin, scale, bounds, counts);
            // Sweep from the right: the cost of every plane's right side; then from the left.
            double right_cost[kBins];
            Aabb<T, N> right_box[kBins];
            {
                Aabb<T, N> acc = bounds[kBins - 1];
                std::size_t n = 0;
                for (int b = kBins - 1; b > 0; --b) {
                    if (b < kBins - 1) acc = unite(acc, bounds[b]);
                    n += counts[b];
                    right_box[b] = acc;
                    right_cost[b] = n == 0 ? -1.0 : box_area<double>(acc) * double(n);
                }
            }
            double best = std::numeric_limits<double>::infinity();
            int plane = -1;  // items of bins < plane go left
            Aabb<T, N> left_box;
            {
                Aabb<T, N> acc = bounds[0];
                std::size_t n = 0;
                for (int b = 0; b < kBins - 1; ++b) {
                    if (b > 0) acc = unite(acc, bounds[b]);
                    n += counts[b];
                    if (n == 0 || right_cost[b + 1] < 0) continue;
                    const double c = box_area<double>(acc) * double(n) + right_cost[b + 1];
                    if (c < best) best = c, plane = b + 1, left_box = acc;
                }
            }
            if (plane > 0) {
                // In place: the items come in the old tree's order, mostly on their side already.
                const std::size_t mid =
                    partition(items, bins, count, [&](std::size_t k) { return bins[k] < plane; });
                return join(
                    build(items, bins, mid, CentreBounds<T, N, Far>::of_box(left_box), depth + 1),
                    build(items + mid, bins + mid, count - mid,
                          CentreBounds<T, N, Far>::of_box(right_box[plane]), depth + 1),
                    link);
            }
        }
        // All centroids equal, or too deep: halves by count, in whatever order the items are.
        const std::size_t mid = count / 2;
        return join(
            build(items, bins, mid, CentreBounds<T, N, Far>::of_items(items, mid), depth + 1),
            build(items + mid, bins + mid, count - mid,
                  CentreBounds<T, N, Far>::of_items(items + mid, count - mid), depth + 1),
            link);
    }
};

}  // namespace rebuild_detail

/// Builds a binary tree over `items` (reordered in place): link(a, b, box, height) makes the
/// internal node over nodes a and b, whose union box and height it is given, and returns it;
/// height_of(node) is a kept subtree's height. Returns the root (the only item's node when there is
/// one). `items` must not be empty, and every box must be non-empty and finite. `bins`: scratch,
/// resized to one byte per item.
template <class T, std::size_t N, class Link, class HeightOf>
std::int32_t build_binned(std::span<RebuildItem<T, N>> items, std::vector<std::uint8_t>& bins,
                          Link&& link, HeightOf&& height_of) {
    bins.resize(items.size());
    T largest = 0;
    for (const RebuildItem<T, N>& item : items)
        for (std::size_t a = 0; a < N; ++a) {
            largest = std::max(largest, item.box.min[a] < 0 ? -item.box.min[a] : item.box.min[a]);
            largest = std::max(largest, item.box.max[a] < 0 ? -item.box.max[a] : item.box.max[a]);
        }
    const auto run = [&](auto far) {
        constexpr bool Far = decltype(far)::value;
        const rebuild_detail::Builder<T, N, Far, Link, HeightOf> builder{link, height_of};
        return builder
            .build(items.data(), bins.data(), items.size(),
                   rebuild_detail::CentreBounds<T, N, Far>::of_items(items.data(), items.size()), 0)
            .node;
    };
    return largest <= std::numeric_limits<T>::max() / 4 ? run(std::false_type{})
                                                        : run(std::true_type{});
}

}  // namespace bvhkit::linked

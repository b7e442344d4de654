#pragma once
// The partition core every top-down builder shares. A builder only says how to split one node (a
// SplitRule); this driver does the rest: it drops non-finite primitives, keeps the work stack,
// computes node bounds, partitions the primitive indices in place, enforces the halting rules, and
// falls back to a median split when a rule's split would leave one side empty, so no input makes it
// recurse forever.
//
// Halting: a node becomes a leaf when it holds one primitive, when it reaches max_depth, or when
// the rule asks for a leaf and it holds no more than max_leaf_size primitives.
#include <algorithm>
#include <span>
#include <string>

#include "bvhkit/build/box_accumulator.hpp"
#include "bvhkit/build/options.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit {

/// The primitives a builder works on: one box and one centroid per primitive.
template <class T, std::size_t N>
struct BuildInput {
    std::span<const Aabb<T, N>> boxes;
    std::span<const Vec<T, N>> centroids;
};

/// The node a SplitRule is asked about: its primitives (a range of the index array, which the rule
/// may reorder), its box and the box of its primitives' centroids.
template <class T, std::size_t N>
struct SplitTask {
    std::span<std::uint32_t> indices;
    Aabb<T, N> bounds;
    Aabb<T, N> centroid_bounds;
    std::uint32_t depth;
};

/// A rule's answer. Primitives go left when their centroid on `axis` is...
template <class T>
struct Split {
    enum class Kind {
        Leaf,  // ...nowhere: make a leaf (overridden when the node is larger than max_leaf_size)
        AtPosition,  // ...below `position`
        AtBin,       // ...in a bin <= `bin`, bins being floor((c - bin_origin) * bin_scale) clamped
        AtCount,     // ...among the `left_count` smallest (ties broken by primitive index)
    };
    Kind kind = Kind::Leaf;
    std::uint32_t axis = 0;
    T position = 0;
    T bin_origin = 0, bin_scale = 0;
    std::uint32_t bin = 0, bin_count = 0, left_count = 0;

    static Split leaf() { return {}; }
    static Split at_position(std::uint32_t axis, T p) { return {Kind::AtPosition, axis, p}; }
    static Split at_count(std::uint32_t axis, std::uint32_t left) {
        Split s{Kind::AtCount, axis};
        s.left_count = left;
        return s;
    }
};

/// Bin of a coordinate for binned builders; the same function bins and partitions, so both agree.
template <class T>
inline std::uint32_t bin_of(T c, T origin, T scale, std::uint32_t bin_count) {
    const T b = (c - origin) * scale;
    return b <= T(0) ? 0u : std::min(bin_count - 1, static_cast<std::uint32_t>(b));
}

/// The builders' rule for bad input: a primitive whose box is non-finite or empty is left out (or
/// rejected, per options); validate() checks the same rule. A centroid that is not finite (or lies
/// outside its box) is replaced by the box's centre, so the centroid never decides.
template <class T, std::size_t N>
std::vector<std::uint32_t> usable_primitives(BuildInput<T, N>& in, std::vector<Vec<T, N>>& fixed,
                                             const BuildOptions& options, BuildReport* report) {
    if (in.boxes.size() != in.centroids.size())
        throw Error("build: " + std::to_string(in.boxes.size()) + " boxes but " +
                    std::to_string(in.centroids.size()) + " centroids");
    if (in.boxes.size() >= std::size_t(0xFFFFFFFFu))
        throw Error("build: " + std::to_string(in.boxes.size()) + " primitives; at most 2^32 - 2");
    std::vector<std::uint32_t> indices;
    indices.reserve(in.boxes.size());
    for (std::uint32_t i = 0; i < in.boxes.size(); ++i) {
        if (in.boxes[i].is_finite() && !in.boxes[i].is_empty()) {
            indices.push_back(i);
            if (!in.boxes[i].contains(in.centroids[i])) {
                if (fixed.empty()) fixed.assign(in.centroids.begin(), in.centroids.end());
                fixed[i] = in.boxes[i].centroid();
            }
        } else if (options.non_finite == NonFinitePolicy::Reject) {
            throw Error("build: primitive " + std::to_string(i) +
                        " has a non-finite or empty box; NonFinitePolicy::Skip leaves such "
                        "primitives out");
        } else if (report) {
            report->skipped.push_back(i);
        }
    }
    if (!fixed.empty()) in.centroids = fixed;
    return indices;
}

/// Bounds of a range of primitives: their boxes and their centroids.
template <class T, std::size_t N>
struct RangeBounds {
    BoxAccumulator<T, N> boxes, centroids;
    void add(const BuildInput<T, N>& in, std::uint32_t i) {
        boxes.grow(in.boxes[i]);
        centroids.grow_point(in.centroids[i]);
    }
};

/// Reorders `range` so the primitives going left come first, gathering both sides' bounds on the
/// way (each primitive is classified and grown exactly once); returns how many go left.
template <class T, std::size_t N>
std::uint32_t partition_primitives(const BuildInput<T, N>& in, std::span<std::uint32_t> range,
                                   const Split<T>& s, RangeBounds<T, N>& left,
                                   RangeBounds<T, N>& right) {
    using Kind = typename Split<T>::Kind;
    const auto& c = in.centroids;
    const std::uint32_t a = s.axis;
    if (s.kind == Kind::Leaf) return 0;
    if (s.kind == Kind::AtCount) {
        const auto k =
            static_cast<std::uint32_t>(std::min<std::size_t>(s.left_count, range.size()));
        std::nth_element(range.begin(), range.begin() + k, range.end(),
                         [&](std::uint32_t i, std::uint32_t j) {
                             return c[i][a] < c[j][a] || (c[i][a] == c[j][a] && i < j);
                         });
        for (std::uint32_t i = 0; i < range.size(); ++i) (i < k ? left : right).add(in, range[i]);
        return k;
    }
    const auto goes_left = [&](std::uint32_t i) {
        if (s.kind == Kind::AtPosition) return c[i][a] < s.position;
        return bin_of(c[i][a], s.bin_origin, s.bin_scale, s.bin_count) <= s.bin;
    };
    std::uint32_t* first = range.data();
    std::uint32_t* last = range.data() + range.size();
    while (first < last) {
        if (goes_left(*first)) {
            left.add(in, *first++);
        } else {
            std::swap(*first, *--last);
            right.add(in, *last);
        }
    }
    return static_cast<std::uint32_t>(first - range.data());
}

/// Builds over `indices` (from usable_primitives) with `rule` deciding each split.
template <class T, std::size_t N, class SplitRule>
Bvh<Aabb<T, N>> build_top_down(const BuildInput<T, N>& in, std::vector<std::uint32_t> indices,
                               const BuildOptions& options, SplitRule& rule) {
    Bvh<Aabb<T, N>> bvh;
    bvh.primitive_indices = std::move(indices);
    std::vector<std::uint32_t>& idx = bvh.primitive_indices;
    if (idx.empty()) return bvh;

    const std::uint32_t max_depth = std::min(options.max_depth, max_bvh_depth);
    const std::uint32_t max_leaf = std::max<std::uint32_t>(1, options.max_leaf_size);
    bvh.nodes.reserve(2 * idx.size() - 1);
    bvh.nodes.emplace_back();

    struct Work {
        std::uint32_t node, begin, end, depth;
        RangeBounds<T, N> bounds;  // of the range's boxes and centroids, gathered by the parent
    };
    Work root{0, 0, static_cast<std::uint32_t>(idx.size()), 0, {}};
    for (std::uint32_t i : idx) root.bounds.add(in, i);
    std::vector<Work> stack{root};
    while (!stack.empty()) {
        const Work w = stack.back();
        stack.pop_back();
        const Aabb<T, N> bounds = w.bounds.boxes.box();
        const Aabb<T, N> centroid_bounds = w.bounds.centroids.box();
        bvh.nodes[w.node].bounds = bounds;
        const std::uint32_t count = w.end - w.begin;
        auto make_leaf = [&] {
            bvh.nodes[w.node].first = w.begin;
            bvh.nodes[w.node].count = count;
        };
        if (count == 1 || w.depth >= max_depth) {
            make_leaf();
            continue;
        }
        std::span<std::uint32_t> range(idx.data() + w.begin, count);
        const Split<T> split = rule(SplitTask<T, N>{range, bounds, centroid_bounds, w.depth});
        if (split.kind == Split<T>::Kind::Leaf && count <= max_leaf) {
            make_leaf();
            continue;
        }
        RangeBounds<T, N> left, right;
        std::uint32_t left_count = partition_primitives(in, range, split, left, right);
        if (left_count == 0 || left_count == count) {
            // The rule gave no split (or could not split). Fall back to the object median on the
            // centroids' longest axis; if all centroids coincide the order is arbitrary, so halve.
            left = right = RangeBounds<T, N>{};
            left_count = partition_primitives(
                in, range,
                Split<T>::at_count(static_cast<std::uint32_t>(centroid_bounds.largest_axis()),
                                   count / 2),
                left, right);
        }
        const auto first_child = static_cast<std::uint32_t>(bvh.nodes.size());
        bvh.nodes[w.node].first = first_child;
        bvh.nodes[w.node].count = 0;
        bvh.nodes.emplace_back();
        bvh.nodes.emplace_back();
        // Right pushed first so the left subtree is laid out first (depth-first order).
        stack.push_back({first_child + 1, w.begin + left_count, w.end, w.depth + 1, right});
        stack.push_back({first_child, w.begin, w.begin + left_count, w.depth + 1, left});
    }
    return bvh;
}

}  // namespace bvhkit

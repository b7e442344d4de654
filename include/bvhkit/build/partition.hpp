#pragma once
// The partition step of the top-down builders (build/top_down_core.hpp): what a rule's Split says,
// the bounds of a range of primitives, and the partition of a range by a split, in place or
// stably through a scratch buffer (in parallel chunks for long ranges), gathering both sides'
// bounds in the same pass.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <vector>

#include "bvhkit/build/box_accumulator.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/simd/simd.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// The primitives a builder works on: one box and one centroid per primitive.
template <class T, std::size_t N>
struct BuildInput {
    std::span<const Aabb<T, N>> boxes;
    std::span<const Vec<T, N>> centroids;
};

/// A rule's answer. Primitives go left when their centroid on `axis` is...
template <class T>
struct Split {
    enum class Kind {
        Leaf,  // ...nowhere: make a leaf (overridden when the node is larger than max_leaf_size)
        AtPosition,  // ...below `position`
        AtBin,       // ...in a bin <= `bin`, bins being floor((c - bin_origin) * bin_scale) clamped
                     // to [0, bin_count - 1]; bin < bin_count - 1
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
/// Clamped before converting, so that no value (inf, or NaN from 0 * inf) reaches the conversion:
/// NaN and values <= 0 give bin 0, as the four-lane path's max(b, 0) does.
template <class T>
inline std::uint32_t bin_of(T c, T origin, T scale, std::uint32_t bin_count) {
    const T b = (c - origin) * scale;
    if (!(b > T(0))) return 0u;
    if (!(b < T(bin_count - 1))) return bin_count - 1;
    return static_cast<std::uint32_t>(b);
}

namespace top_down_detail {
/// Primitives per chunk of the parallel passes over a range. Fixed, so what a chunk computes never
/// depends on the thread count.
inline constexpr std::size_t chunk = tuning::partition_chunk;
/// Ranges at least this long are partitioned stably through a scratch buffer (in parallel chunks
/// when the executor allows), shorter ones in place. The choice depends on the size alone, so the
/// order of primitive_indices is the same with any number of threads.
inline constexpr std::size_t stable_partition_from = tuning::stable_partition_from;
}  // namespace top_down_detail

/// Bounds of a range of primitives: their boxes and their centroids.
template <class T, std::size_t N>
struct RangeBounds {
    BoxAccumulator<T, N> boxes, centroids;
    // Forced inline: GCC otherwise calls it out of line from the partition loops, which then run
    // more instructions (docs/benchmarks.md, "Figures behind code comments").
    [[gnu::always_inline]] void add(const BuildInput<T, N>& in, std::uint32_t i) {
        boxes.grow(in.boxes[i]);
        centroids.grow_point(in.centroids[i]);
    }
    void add(const RangeBounds& o) {
        boxes.grow(o.boxes);
        centroids.grow(o.centroids);
    }
};

/// Adds primitive i to `left` when `goes_left`, else to `right`: without a branch for 3D float
/// boxes on x86, where which side a primitive goes is a coin toss the branch predictor loses
/// about half the time. Finite boxes and centroids only (see partition_primitives).
template <class T, std::size_t N>
[[gnu::always_inline]] inline void add_to_side(const BuildInput<T, N>& in, std::uint32_t i,
                                               bool goes_left, RangeBounds<T, N>& left,
                                               RangeBounds<T, N>& right) {
#if BVHKIT_SIMD
    if constexpr (std::is_same_v<T, float> && N == 3) {
        const simd::Float<4> inf(std::numeric_limits<float>::infinity());
        const simd::Mask<4> to_left = simd::Mask<4>::all(goes_left);
        const simd::Float<4> skip_left = where_not(to_left, inf), skip_right = where(to_left, inf);
        left.boxes.grow(in.boxes[i], skip_left);
        right.boxes.grow(in.boxes[i], skip_right);
        left.centroids.grow_point(in.centroids[i], skip_left);
        right.centroids.grow_point(in.centroids[i], skip_right);
        return;
    }
#endif
    (goes_left ? left : right).add(in, i);
}

/// Bounds of the primitives of `range`, in parallel chunks for long ranges (min and max are exact
/// in any order, so the result does not depend on the chunks).
template <class T, std::size_t N>
RangeBounds<T, N> range_bounds(const BuildInput<T, N>& in, std::span<const std::uint32_t> range,
                               const Executor& exec) {
    using top_down_detail::chunk;
    RangeBounds<T, N> all;
    if (!exec.is_parallel() || range.size() < 4 * chunk) {
        for (std::uint32_t i : range) all.add(in, i);
        return all;
    }
    std::vector<RangeBounds<T, N>> part((range.size() + chunk - 1) / chunk);
    exec.parallel_for(range.size(), chunk, [&](std::size_t b, std::size_t e) {
        RangeBounds<T, N>& p = part[b / chunk];
        for (std::size_t k = b; k < e; ++k) p.add(in, range[k]);
    });
    for (const RangeBounds<T, N>& p : part) all.add(p);
    return all;
}

namespace top_down_detail {

/// Stable partition of `range` through `scratch` (as long): the primitives going left keep their
/// order and come first, then the others in their order. The result is unique, so the serial pass
/// and the parallel chunks (each classifies its part into scratch, then copies it to its place)
/// give the same order.
template <class T, std::size_t N, class GoesLeft>
std::uint32_t stable_partition(const BuildInput<T, N>& in, std::span<std::uint32_t> range,
                               std::span<std::uint32_t> scratch, const GoesLeft& goes_left,
                               const Executor& exec, RangeBounds<T, N>& left,
                               RangeBounds<T, N>& right) {
    const std::size_t n = range.size();
    std::uint32_t* const out = range.data();
    std::uint32_t* const tmp = scratch.data();
    if (!exec.is_parallel()) {
        // Left ones move down in place (the write never passes the read), right ones to scratch.
        std::size_t l = 0, r = 0;
        RangeBounds<T, N> lb = left, rb = right;  // in registers (see partition_in_place)
        for (std::size_t k = 0; k < n; ++k) {
            const std::uint32_t i = out[k];
            if (goes_left(i)) {
                out[l++] = i;
                lb.add(in, i);
            } else {
                tmp[r++] = i;
                rb.add(in, i);
            }
        }
        left = lb, right = rb;
        std::copy_n(tmp, r, out + l);
        return static_cast<std::uint32_t>(l);
    }
    struct Part {
        RangeBounds<T, N> left, right;
        std::size_t left_count = 0, left_at = 0, right_at = 0;
    };
    std::vector<Part> parts((n + chunk - 1) / chunk);  // one allocation per large node only
    // A chunk's left primitives go to its part of scratch from the front, the right ones from
    // the back (so reversed).
    exec.parallel_for(n, chunk, [&](std::size_t b, std::size_t e) {
        Part& p = parts[b / chunk];
        std::size_t l = b, r = e;
        for (std::size_t k = b; k < e; ++k) {
            const std::uint32_t i = out[k];
            if (goes_left(i)) {
                tmp[l++] = i;
                p.left.add(in, i);
            } else {
                tmp[--r] = i;
                p.right.add(in, i);
            }
        }
        p.left_count = l - b;
    });
    std::size_t left_total = 0;
    for (Part& p : parts) p.left_at = left_total, left_total += p.left_count;
    std::size_t right_total = left_total;
    for (std::size_t c = 0; c < parts.size(); ++c) {
        parts[c].right_at = right_total;
        right_total += std::min(n, (c + 1) * chunk) - c * chunk - parts[c].left_count;
    }
    exec.parallel_for(n, chunk, [&](std::size_t b, std::size_t e) {
        const Part& p = parts[b / chunk];
        std::copy_n(tmp + b, p.left_count, out + p.left_at);
        std::reverse_copy(tmp + b + p.left_count, tmp + e, out + p.right_at);
    });
    for (const Part& p : parts) {
        left.add(p.left);
        right.add(p.right);
    }
    return static_cast<std::uint32_t>(left_total);
}

}  // namespace top_down_detail

namespace top_down_detail {

/// Partition of `range` by `goes_left`, in place.
template <class T, std::size_t N, class GoesLeft>
std::uint32_t partition_in_place(const BuildInput<T, N>& in, std::span<std::uint32_t> range,
                                 const GoesLeft& goes_left, RangeBounds<T, N>& left,
                                 RangeBounds<T, N>& right) {
    // Lomuto's scheme without a branch: [0, l) goes left, [l, k) right; each primitive is
    // swapped to l and l moves past it when it goes left. Local accumulators: through the
    // references they would live in memory, each grow a store and a reload.
    RangeBounds<T, N> lb = left, rb = right;
    std::uint32_t* const out = range.data();
    std::size_t l = 0;
    for (std::size_t k = 0; k < range.size(); ++k) {
        const std::uint32_t i = out[k];
        const bool g = goes_left(i);
        out[k] = out[l];
        out[l] = i;
        l += g;
        add_to_side(in, i, g, lb, rb);
    }
    left = lb, right = rb;
    return static_cast<std::uint32_t>(l);
}

/// Partitions `range` by `goes_left`: stably through scratch when it is long, else in place.
template <class T, std::size_t N, class GoesLeft>
std::uint32_t partition_by(const BuildInput<T, N>& in, std::span<std::uint32_t> range,
                           std::span<std::uint32_t> scratch, const Executor& exec,
                           const GoesLeft& goes_left, RangeBounds<T, N>& left,
                           RangeBounds<T, N>& right) {
    if (range.size() >= stable_partition_from && scratch.size() >= range.size())
        return stable_partition(in, range, scratch, goes_left, exec, left, right);
    return partition_in_place(in, range, goes_left, left, right);
}

}  // namespace top_down_detail

/// Reorders `range` so the primitives going left come first, gathering both sides' bounds on the
/// way (each primitive is classified and grown exactly once); returns how many go left. A range of
/// at least stable_partition_from primitives is partitioned stably through `scratch` (as long as
/// the range; the drivers always pass it), on `exec`; a shorter one in place. The boxes and
/// centroids must be finite, as usable_primitives leaves them (the in-place pass grows the other
/// side's bounds by coordinate + inf, which an infinite coordinate would turn to NaN), and an AtBin
/// split's bin below bin_count - 1, as BinnedSahRule makes it.
template <class T, std::size_t N>
std::uint32_t partition_primitives(const BuildInput<T, N>& in, std::span<std::uint32_t> range,
                                   const Split<T>& s, RangeBounds<T, N>& left,
                                   RangeBounds<T, N>& right, std::span<std::uint32_t> scratch = {},
                                   const Executor& exec = Executor::serial()) {
    using Kind = typename Split<T>::Kind;
    const auto& c = in.centroids;
    const std::uint32_t a = s.axis;
    switch (s.kind) {
        case Kind::Leaf:
            return 0;
        case Kind::AtCount: {
            const auto k =
                static_cast<std::uint32_t>(std::min<std::size_t>(s.left_count, range.size()));
            std::nth_element(range.begin(), range.begin() + k, range.end(),
                             [&](std::uint32_t i, std::uint32_t j) {
                                 return c[i][a] < c[j][a] || (c[i][a] == c[j][a] && i < j);
                             });
            if (range.size() >= top_down_detail::stable_partition_from) {
                left = range_bounds(in, std::span<const std::uint32_t>(range.first(k)), exec);
                right = range_bounds(in, std::span<const std::uint32_t>(range.subspan(k)), exec);
            } else {
                for (std::uint32_t i = 0; i < range.size(); ++i)
                    (i < k ? left : right).add(in, range[i]);
            }
            return k;
        }
        // One loop per kind, the kind not tested per primitive. The split's fields are copied:
        // read through `s`, they would be reloaded after every index written (they may alias).
        case Kind::AtPosition:
            return top_down_detail::partition_by(
                in, range, scratch, exec,
                [c = c.data(), a, position = s.position](std::uint32_t i) {
                    return c[i][a] < position;
                },
                left, right);
        case Kind::AtBin:
            assert(s.bin + 1 < s.bin_count && s.bin_count <= (1u << 24));
            return top_down_detail::partition_by(
                in, range, scratch, exec,
                // bin_of(x) <= bin exactly when !((x - origin) * scale >= bin + 1): bin + 1 is
                // below the clamp at bin_count - 1, and NaN goes to bin 0 either way.
                [c = c.data(), a, origin = s.bin_origin, scale = s.bin_scale, next = T(s.bin + 1)](
                    std::uint32_t i) { return !((c[i][a] - origin) * scale >= next); },
                left, right);
    }
    return 0;
}

}  // namespace bvhkit

#pragma once
// Binned SAH split (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies"):
// the centroids are dropped into equal bins along each axis, and the SAH is evaluated only at the
// bin boundaries, with one sweep from each side. Linear in the node's size per axis. As in Embree,
// smaller nodes get fewer bins (4 + n / 20, up to bin_count; tuning.hpp): the sweep over bins is a
// per-node cost that would otherwise dominate the many small nodes. Every node is binned, the
// smallest too: an exact sweep there found no cheaper trees and cost build time.
//
// A large node (parallel_binning_from primitives) bins in chunks on several threads when the
// driver's executor allows, each chunk into its own bins, merged afterwards; box unions and
// counts are exact in any order, so the split is the same as binned serially.
#include "bvhkit/build/sah.hpp"
#include "bvhkit/build/top_down_core.hpp"
#include "bvhkit/simd/simd.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

template <class T, std::size_t N>
class BinnedSahRule {
  public:
    static constexpr std::size_t parallel_binning_from = tuning::parallel_binning_from;
    static constexpr std::size_t binning_chunk = tuning::binning_chunk;

    BinnedSahRule(const BuildInput<T, N>& in, const BuildOptions& options)
        : in_(in),
          costs_(options.costs),
          max_bins_(std::clamp<std::uint32_t>(options.bin_count, 2, 256)),
          bins_(2 * N * max_bins_),
          right_area_(max_bins_) {}

    Split<T> operator()(const SplitTask<T, N>& task, const Executor& exec) {
        const auto count = static_cast<std::uint32_t>(task.indices.size());
        if (sah_leaf_certain(costs_, count, task.bounds.area())) return Split<T>::leaf();
        const std::uint32_t bin_count = std::min(
            max_bins_, tuning::binned_sah_min_bins + count / tuning::binned_sah_primitives_per_bin);
        const Aabb<T, N>& cb = task.centroid_bounds;
        T scale[N];
        for (std::size_t a = 0; a < N; ++a) {
            // A finite scale even for denormal extents (bin_count / 1e-44 overflows float).
            const T extent = cb.max[a] - cb.min[a];
            scale[a] = extent > T(0)
                           ? std::min(T(bin_count) / extent, std::numeric_limits<T>::max())
                           : T(0);
        }
        const BinMapping mapping(cb.min, scale, bin_count);
        const std::size_t row = N * bin_count;
        if (exec.is_parallel() && count >= parallel_binning_from) {
            const std::size_t chunks = (count + binning_chunk - 1) / binning_chunk;
            if (chunk_bins_.size() < chunks * 2 * row) chunk_bins_.resize(chunks * 2 * row);
            exec.parallel_for(count, binning_chunk, [&](std::size_t b, std::size_t e) {
                bin_range(task.indices.subspan(b, e - b), mapping,
                          &chunk_bins_[b / binning_chunk * 2 * row]);
            });
            std::fill_n(bins_.begin(), row, Bin{});
            for (std::size_t c = 0; c < chunks; ++c)
                for (std::size_t k = 0; k < row; ++k) {
                    bins_[k].bounds.grow(chunk_bins_[c * 2 * row + k].bounds);
                    bins_[k].count += chunk_bins_[c * 2 * row + k].count;
                }
        } else {
            bin_range(task.indices, mapping, bins_.data());
        }

        T best_cost = std::numeric_limits<T>::infinity();
        Split<T> best = Split<T>::leaf();
        for (std::size_t a = 0; a < N; ++a) {
            if (scale[a] == T(0)) continue;  // all centroids equal on this axis
            const Bin* bins = &bins_[a * bin_count];
            BoxAccumulator<T, N> acc;
            for (std::uint32_t b = bin_count - 1; b > 0; --b) {
                acc.grow(bins[b].bounds);
                right_area_[b] = acc.area();
            }
            acc = BoxAccumulator<T, N>();
            std::uint32_t left_count = 0;
            for (std::uint32_t b = 0; b + 1 < bin_count; ++b) {  // split after bin b
                acc.grow(bins[b].bounds);
                left_count += bins[b].count;
                if (left_count == 0 || left_count == count) continue;
                const T cost = sah_partial_cost(costs_, acc.area(), left_count, right_area_[b + 1],
                                                count - left_count);
                if (cost < best_cost) {
                    best_cost = cost;
                    best.kind = Split<T>::Kind::AtBin;
                    best.axis = static_cast<std::uint32_t>(a);
                    best.bin = b;
                    best.bin_origin = cb.min[a];
                    best.bin_scale = scale[a];
                    best.bin_count = bin_count;
                }
            }
        }
        if (best.kind == Split<T>::Kind::Leaf ||
            !sah_split_beats_leaf(costs_, best_cost, task.bounds.area(), count))
            return Split<T>::leaf();
        return best;
    }

  private:
    // The bins of a centroid on every axis at once; the same arithmetic as bin_of, which
    // partitions.
    struct BinMapping {
        Vec<T, N> origin;
        T scale[N];
        std::uint32_t count;
#if BVHKIT_SIMD
        simd::Float<4> origin4, scale4, last4;  // used for 3D float only
#endif
        BinMapping(const Vec<T, N>& o, const T* s, std::uint32_t c) : origin(o), count(c) {
            for (std::size_t a = 0; a < N; ++a) scale[a] = s[a];
#if BVHKIT_SIMD
            if constexpr (std::is_same_v<T, float> && N == 3) {
                origin4 = BoxAccumulator<float, 3>::load(o);
                scale4 = simd::Float<4>::lanes(s[0], s[1], s[2], 0.0f);
                last4 = simd::Float<4>(float(c - 1));
            }
#endif
        }
        void bins(const Vec<T, N>& c, std::uint32_t out[N]) const {
#if BVHKIT_SIMD
            if constexpr (std::is_same_v<T, float> && N == 3) {
                using F = simd::Float<4>;
                const F t = (BoxAccumulator<float, 3>::load(c) - origin4) * scale4;
                const F clamped = min(max(t, F::zero()), last4);
                alignas(16) std::uint32_t b[4];  // each in [0, count - 1]
                truncate(clamped).store(b);
                for (std::size_t a = 0; a < 3; ++a) out[a] = b[a];
                return;
            }
#endif
            for (std::size_t a = 0; a < N; ++a) out[a] = bin_of(c[a], origin[a], scale[a], count);
        }
    };

    struct Bin {
        BoxAccumulator<T, N> bounds;
        std::uint32_t count = 0;
    };

    /// Bins the primitives of `indices` into the N rows of `mapping.count` bins at `out`, using
    /// as many more after them as scratch. Every other primitive goes to the scratch rows, merged
    /// at the end: one set alone makes a chain of loads and stores through the same bin whenever
    /// neighbouring primitives share one, as they mostly do.
    void bin_range(std::span<const std::uint32_t> indices, const BinMapping& mapping,
                   Bin* out) const {
        const std::size_t row = N * mapping.count;
        Bin* const odd = out + row;
        std::fill_n(out, 2 * row, Bin{});
        // Local copies: through `this` they would be reloaded after every count written.
        const Aabb<T, N>* const boxes = in_.boxes.data();
        const Vec<T, N>* const centroids = in_.centroids.data();
        const BinMapping m = mapping;
        const auto add = [&](std::uint32_t i, Bin* rows) {
            std::uint32_t bin[N];
            m.bins(centroids[i], bin);
            for (std::size_t a = 0; a < N; ++a) {
                Bin& b = rows[a * m.count + bin[a]];
                b.bounds.grow(boxes[i]);
                ++b.count;
            }
        };
        std::size_t k = 0;
        for (; k + 1 < indices.size(); k += 2) {
            add(indices[k], out);
            add(indices[k + 1], odd);
        }
        if (k < indices.size()) add(indices[k], out);
        for (std::size_t b = 0; b < row; ++b) {
            out[b].bounds.grow(odd[b].bounds);
            out[b].count += odd[b].count;
        }
    }

    BuildInput<T, N> in_;
    SahCosts costs_;
    std::uint32_t max_bins_;
    std::vector<Bin> bins_;        // 2N rows of bins (bin_range's), reused for every node
    std::vector<Bin> chunk_bins_;  // 2N rows per chunk of a node binned in parallel
    std::vector<T> right_area_;
};

}  // namespace bvhkit

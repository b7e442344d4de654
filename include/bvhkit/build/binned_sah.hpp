#pragma once
// Binned SAH split (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies"):
// the centroids are dropped into `bin_count` equal bins along each axis, and the SAH is evaluated
// only at the bin boundaries, with one sweep from each side. Linear in the node's size per axis.
// A node no larger than the bin count is handed to the full sweep: there the sweep is both cheaper
// (sorting a handful beats sweeping every bin on every axis) and exact.
#include "bvhkit/build/sweep_sah.hpp"

namespace bvhkit {

template <class T, std::size_t N>
class BinnedSahRule {
  public:
    BinnedSahRule(const BuildInput<T, N>& in, const BuildOptions& options)
        : in_(in),
          costs_(options.costs),
          bin_count_(std::clamp<std::uint32_t>(options.bin_count, 2, 256)),
          bins_(N * bin_count_),
          right_area_(bin_count_),
          small_nodes_(in, options) {}

    Split<T> operator()(const SplitTask<T, N>& task) {
        if (task.indices.size() <= bin_count_) return small_nodes_(task);
        const Aabb<T, N>& cb = task.centroid_bounds;
        T scale[N];
        for (std::size_t a = 0; a < N; ++a) {
            const T extent = cb.max[a] - cb.min[a];
            scale[a] = extent > T(0) ? T(bin_count_) / extent : T(0);
        }
        for (auto& b : bins_) b = Bin{};
        for (std::uint32_t i : task.indices) {
            const Aabb<T, N>& box = in_.boxes[i];
            const Vec<T, N>& c = in_.centroids[i];
            for (std::size_t a = 0; a < N; ++a) {
                Bin& b = bins_[a * bin_count_ + bin_of(c[a], cb.min[a], scale[a], bin_count_)];
                b.bounds.grow(box);
                ++b.count;
            }
        }

        T best_cost = std::numeric_limits<T>::infinity();
        Split<T> best = Split<T>::leaf();
        const auto count = static_cast<std::uint32_t>(task.indices.size());
        for (std::size_t a = 0; a < N; ++a) {
            if (scale[a] == T(0)) continue;  // all centroids equal on this axis
            const Bin* bins = &bins_[a * bin_count_];
            Aabb<T, N> acc;
            for (std::uint32_t b = bin_count_ - 1; b > 0; --b) {
                acc.grow(bins[b].bounds);
                right_area_[b] = acc.area();
            }
            acc = Aabb<T, N>();
            std::uint32_t left_count = 0;
            for (std::uint32_t b = 0; b + 1 < bin_count_; ++b) {  // split after bin b
                acc.grow(bins[b].bounds);
                left_count += bins[b].count;
                if (left_count == 0 || left_count == count) continue;
                const T cost = sah_partial_cost(acc.area(), left_count, right_area_[b + 1],
                                                count - left_count);
                if (cost < best_cost) {
                    best_cost = cost;
                    best.kind = Split<T>::Kind::AtBin;
                    best.axis = static_cast<std::uint32_t>(a);
                    best.bin = b;
                    best.bin_origin = cb.min[a];
                    best.bin_scale = scale[a];
                    best.bin_count = bin_count_;
                }
            }
        }
        if (best.kind == Split<T>::Kind::Leaf ||
            !sah_split_beats_leaf(costs_, best_cost, task.bounds.area(), count))
            return Split<T>::leaf();
        return best;
    }

  private:
    struct Bin {
        Aabb<T, N> bounds;
        std::uint32_t count = 0;
    };
    BuildInput<T, N> in_;
    SahCosts costs_;
    std::uint32_t bin_count_;
    std::vector<Bin> bins_;  // N rows of bin_count_ bins, reused for every node
    std::vector<T> right_area_;
    SweepSahRule<T, N> small_nodes_;
};

}  // namespace bvhkit

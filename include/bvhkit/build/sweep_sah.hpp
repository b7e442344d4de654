#pragma once
// Full-sweep SAH split: on each axis the node's primitives are sorted by centroid and the SAH is
// evaluated between every neighbouring pair (MacDonald and Booth 1990). It considers every split a
// binned builder can make, so its greedy choice is never worse at a node; the price is a sort per
// node and axis (O(n log^2 n) for the whole build).
#include "bvhkit/build/sah.hpp"
#include "bvhkit/build/top_down_core.hpp"

namespace bvhkit {

template <class T, std::size_t N>
class SweepSahRule {
  public:
    SweepSahRule(const BuildInput<T, N>& in, const BuildOptions& options)
        : in_(in), costs_(options.costs) {}

    Split<T> operator()(const SplitTask<T, N>& task) {
        const auto count = static_cast<std::uint32_t>(task.indices.size());
        if (order_.size() < count) {
            order_.resize(count);
            right_area_.resize(count);
        }
        T best_cost = std::numeric_limits<T>::infinity();
        Split<T> best = Split<T>::leaf();
        for (std::size_t a = 0; a < N; ++a) {
            if (!(task.centroid_bounds.max[a] > task.centroid_bounds.min[a])) continue;
            // Sorted by (centroid, index): the order partition_primitives uses for AtCount.
            for (std::uint32_t k = 0; k < count; ++k) {
                const std::uint32_t i = task.indices[k];
                order_[k] = {in_.centroids[i][a], i};
            }
            std::sort(order_.begin(), order_.begin() + count);
            BoxAccumulator<T, N> acc;
            for (std::uint32_t k = count; k-- > 1;) {
                acc.grow(in_.boxes[order_[k].second]);
                right_area_[k] = acc.area();  // area of primitives [k, count)
            }
            acc = BoxAccumulator<T, N>();
            for (std::uint32_t k = 1; k < count; ++k) {  // left = [0, k)
                acc.grow(in_.boxes[order_[k - 1].second]);
                const T cost = sah_partial_cost(acc.area(), k, right_area_[k], count - k);
                if (cost < best_cost) {
                    best_cost = cost;
                    best = Split<T>::at_count(static_cast<std::uint32_t>(a), k);
                }
            }
        }
        if (best.kind == Split<T>::Kind::Leaf ||
            !sah_split_beats_leaf(costs_, best_cost, task.bounds.area(), count))
            return Split<T>::leaf();
        return best;
    }

  private:
    BuildInput<T, N> in_;
    SahCosts costs_;
    std::vector<std::pair<T, std::uint32_t>> order_;  // (centroid, index), reused for every node
    std::vector<T> right_area_;
};

}  // namespace bvhkit

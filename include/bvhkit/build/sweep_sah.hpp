#pragma once
// Full-sweep SAH split: on each axis the node's primitives are sorted by centroid and the SAH is
// evaluated between every neighbouring pair (MacDonald and Booth 1990). It considers every split a
// binned builder can make, so its greedy choice is never worse at a node; the price is a sort per
// node and axis (O(n log^2 n) for the whole build).
//
// A large node (parallel_axes_from primitives) sweeps its axes at the same time when the driver's
// executor allows, each axis in its own buffers; the best split is then taken in the
// serial order (lowest cost, first axis, first position on it), so it is the serial one.
#include "bvhkit/build/sah.hpp"
#include "bvhkit/build/top_down_core.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

template <class T, std::size_t N>
class SweepSahRule {
  public:
    static constexpr std::size_t parallel_axes_from = tuning::parallel_axes_from;

    SweepSahRule(const BuildInput<T, N>& in, const BuildOptions& options)
        : in_(in), costs_(options.costs) {}

    Split<T> operator()(const SplitTask<T, N>& task, const Executor& exec) {
        const auto count = static_cast<std::uint32_t>(task.indices.size());
        if (sah_leaf_certain(costs_, count, task.bounds.area())) return Split<T>::leaf();
        AxisBest best[N];
        if (exec.is_parallel() && count >= parallel_axes_from) {
            if (order_.size() < N * count) {
                order_.resize(N * count);
                right_area_.resize(N * count);
            }
            exec.parallel_for(N, 1, [&](std::size_t b, std::size_t e) {
                for (std::size_t a = b; a < e; ++a)
                    best[a] = sweep(task, a, &order_[a * count], &right_area_[a * count]);
            });
        } else {
            if (order_.size() < count) {
                order_.resize(count);
                right_area_.resize(count);
            }
            for (std::size_t a = 0; a < N; ++a)
                best[a] = sweep(task, a, order_.data(), right_area_.data());
        }
        T best_cost = std::numeric_limits<T>::infinity();
        Split<T> split = Split<T>::leaf();
        for (std::size_t a = 0; a < N; ++a)
            if (best[a].cost < best_cost) {
                best_cost = best[a].cost;
                split = Split<T>::at_count(static_cast<std::uint32_t>(a), best[a].left_count);
            }
        if (split.kind == Split<T>::Kind::Leaf ||
            !sah_split_beats_leaf(costs_, best_cost, task.bounds.area(), count))
            return Split<T>::leaf();
        return split;
    }

  private:
    struct AxisBest {
        T cost = std::numeric_limits<T>::infinity();
        std::uint32_t left_count = 0;
    };

    /// The cheapest split on `axis` (the first of equal costs), sorting into `order` and
    /// `right_area` (count entries each).
    AxisBest sweep(const SplitTask<T, N>& task, std::size_t a, std::pair<T, std::uint32_t>* order,
                   T* right_area) const {
        AxisBest best;
        if (!(task.centroid_bounds.max[a] > task.centroid_bounds.min[a])) return best;
        const auto count = static_cast<std::uint32_t>(task.indices.size());
        // Sorted by (centroid, index): the order partition_primitives uses for AtCount.
        for (std::uint32_t k = 0; k < count; ++k) {
            const std::uint32_t i = task.indices[k];
            order[k] = {in_.centroids[i][a], i};
        }
        std::sort(order, order + count);
        BoxAccumulator<T, N> acc;
        for (std::uint32_t k = count; k-- > 1;) {
            acc.grow(in_.boxes[order[k].second]);
            right_area[k] = acc.area();  // area of primitives [k, count)
        }
        acc = BoxAccumulator<T, N>();
        for (std::uint32_t k = 1; k < count; ++k) {  // left = [0, k)
            acc.grow(in_.boxes[order[k - 1].second]);
            const T cost = sah_partial_cost(costs_, acc.area(), k, right_area[k], count - k);
            if (cost < best.cost) best = {cost, k};
        }
        return best;
    }

    BuildInput<T, N> in_;
    SahCosts costs_;
    std::vector<std::pair<T, std::uint32_t>> order_;  // (centroid, index), reused for every node
    std::vector<T> right_area_;
};

}  // namespace bvhkit

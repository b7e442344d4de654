#pragma once
// The classic top-down split rules (after Ericson, Real-Time Collision
// Detection, 6.2.1): choose an axis (longest extent, or largest centroid variance), then a split
// point on it (object median, object mean, or the spatial median of the node's box). Leaves hold up
// to max_leaf_size primitives; the driver's fallback handles a split point with every centroid on
// one side.
#include "bvhkit/build/top_down_core.hpp"

namespace bvhkit {

template <class T, std::size_t N>
class TopDownRule {
  public:
    TopDownRule(const BuildInput<T, N>& in, const BuildOptions& options)
        : in_(in),
          axis_rule_(options.axis_rule),
          point_rule_(options.point_rule),
          max_leaf_(std::max<std::uint32_t>(1, options.max_leaf_size)) {}

    Split<T> operator()(const SplitTask<T, N>& task) {
        const auto count = static_cast<std::uint32_t>(task.indices.size());
        if (count <= max_leaf_) return Split<T>::leaf();
        Vec<T, N> mean(T(0));
        for (std::uint32_t i : task.indices) mean += in_.centroids[i];
        mean *= T(1) / T(count);

        std::uint32_t axis = static_cast<std::uint32_t>(task.centroid_bounds.largest_axis());
        if (axis_rule_ == SplitAxis::LargestVariance) {
            Vec<T, N> variance(T(0));
            for (std::uint32_t i : task.indices) {
                const Vec<T, N> d = in_.centroids[i] - mean;
                variance += d * d;
            }
            axis = static_cast<std::uint32_t>(largest_axis(variance));
        }
        switch (point_rule_) {
            case SplitPoint::ObjectMedian:
                return Split<T>::at_count(axis, count / 2);
            case SplitPoint::ObjectMean:
                return Split<T>::at_position(axis, mean[axis]);
            case SplitPoint::SpatialMedian:
                return Split<T>::at_position(axis, task.bounds.centroid()[axis]);
        }
        return Split<T>::leaf();
    }

  private:
    BuildInput<T, N> in_;
    SplitAxis axis_rule_;
    SplitPoint point_rule_;
    std::uint32_t max_leaf_;
};

}  // namespace bvhkit

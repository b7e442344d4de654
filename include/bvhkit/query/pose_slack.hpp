#pragma once
// pose_slack: how much the volume tests of two models' pair walk are widened so that the rounding
// of carrying B's triangles into A's frame never hides a contact (query/pairs_model.hpp,
// query/distance.hpp).
#include <limits>

#include "bvhkit/math/transform.hpp"
#include "bvhkit/math/vec.hpp"

namespace bvhkit {

/// The absolute widening of volume tests under `pose` that covers the rounding of carrying B's
/// triangles into A's frame (a few ulps of the largest coordinate involved).
template <class T>
T pose_slack(T scale_a, T scale_b, const Transform<T>& pose) {
    return std::numeric_limits<T>::epsilon() * T(64) *
           (scale_a + scale_b + max_component(bvhkit::max(pose.translation, -pose.translation)));
}

}  // namespace bvhkit

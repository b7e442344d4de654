#pragma once
// pose_slack: how much the volume tests of two models' pair walk are widened so that the rounding
// of carrying B's triangles into A's frame never hides a contact (query/pairs_model.hpp,
// query/distance.hpp).
#include <limits>

#include "bvhkit/math/transform.hpp"
#include "bvhkit/math/vec.hpp"

namespace bvhkit {

/// The absolute widening of volume tests under `pose` that covers the rounding of carrying B's
/// triangles into A's frame (a few ulps of the largest coordinate involved), and what R's distance
/// from a rotation (up to rigid_tolerance, math/transform.hpp) can move a point or a volume's
/// frame: |R - Q| <= 1.5 d for the nearest rotation Q when d = rigid_deviation(R), applied by R
/// and its transpose (the inverse the walk uses), with room to spare.
template <class T>
T pose_slack(T scale_a, T scale_b, const Transform<T>& pose) {
    const T reach =
        scale_a + scale_b + max_component(bvhkit::max(pose.translation, -pose.translation));
    return std::numeric_limits<T>::epsilon() * T(64) * reach +
           T(8 * rigid_deviation(pose.rotation)) * reach;
}

}  // namespace bvhkit

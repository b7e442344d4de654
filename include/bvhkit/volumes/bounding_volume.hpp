#pragma once
// clang-format off
// The BoundingVolume concept, shared by Aabb, Sphere, Obb and Kdop<K>: every operation the tree
// builders and the tree-vs-tree queries need, gathered in VolumeTraits<V> so that a volume type
// from elsewhere (Aabb lives in math/) joins without being edited.
//
//   VolumeTraits<V>::fit(triangles)          the volume of a run of triangles
//   VolumeTraits<V>::merge(a, b)             a volume enclosing both
//   VolumeTraits<V>::merge_is_tight          true when merge(fit(X), fit(Y)) == fit(X u Y)
//                                            (then refit merges children; else it re-fits)
//   VolumeTraits<V>::overlaps(a, b)          both in one frame; touching counts as overlap
//   VolumeTraits<V>::prepare(pose, slack)    per-query constants of a pose (B's frame -> A's)
//   VolumeTraits<V>::overlaps(a, b, prepared) b given in B's frame; may be conservative (never
//                                            says "apart" for volumes that meet)
//   VolumeTraits<V>::size(v)                 squared "radius", what the descend-larger rule
//                                            compares
//   VolumeTraits<V>::distance_lower_bound(a, b, prepared)
//                                            never more than the true distance
//
// `slack` widens every test under a pose by an absolute amount, so that the rounding of a
// triangle transformed into A's frame at a leaf can never make a pair the volumes culled touch.
// clang-format on
#include <concepts>
#include <span>

#include "bvhkit/math/transform.hpp"
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit {

template <class V>
struct VolumeTraits;  // specialized by each volume's header

template <class V>
concept BoundingVolume = requires(const V& a, std::span<const Triangle<typename V::Scalar>> tris,
                                  const Transform<typename V::Scalar>& pose,
                                  typename V::Scalar slack) {
    { VolumeTraits<V>::fit(tris) } -> std::same_as<V>;
    { VolumeTraits<V>::merge(a, a) } -> std::same_as<V>;
    { VolumeTraits<V>::merge_is_tight } -> std::convertible_to<bool>;
    { VolumeTraits<V>::overlaps(a, a) } -> std::same_as<bool>;
    {
        VolumeTraits<V>::overlaps(a, a, VolumeTraits<V>::prepare(pose, slack))
        } -> std::same_as<bool>;
    { VolumeTraits<V>::size(a) } -> std::same_as<typename V::Scalar>;
    {
        VolumeTraits<V>::distance_lower_bound(a, a, VolumeTraits<V>::prepare(pose, slack))
        } -> std::same_as<typename V::Scalar>;
};

/// A pose with the absolute values of its rotation, computed once per query. The tiny epsilon
/// added to |R| keeps the edge-cross-edge axes of the separating-axis test from a false
/// "separated" when two edges are nearly parallel (Gottschalk, Lin, Manocha 1996, section 5).
template <class T>
struct PreparedPose {
    Mat3<T> r;
    Mat3<T> abs_r;
    Vec<T, 3> t;
    T slack = 0;

    PreparedPose() = default;
    PreparedPose(const Transform<T>& pose, T slack_)
        : r(pose.rotation), t(pose.translation), slack(slack_) {
        constexpr T eps = std::numeric_limits<T>::epsilon() * T(16);
        for (std::size_t i = 0; i < 3; ++i)
            for (std::size_t j = 0; j < 3; ++j) abs_r[i][j] = std::fabs(r[i][j]) + eps;
    }
};

namespace detail {

/// Boxes A (half extents ea, its frame) and B (half extents eb, axes = columns of c in A's
/// frame, centre t in A's frame): true when one of the 15 separating axes separates them by more
/// than `slack` (Gottschalk, Lin, Manocha 1996; the axis formulas as in Ericson 4.4.1).
template <class T>
bool boxes_separated(const Mat3<T>& c, const Mat3<T>& abs_c, const Vec<T, 3>& t,
                     const Vec<T, 3>& ea, const Vec<T, 3>& eb, T slack) {
    for (std::size_t i = 0; i < 3; ++i)
        if (std::fabs(t[i]) > ea[i] + dot(abs_c[i], eb) + slack) return true;
    for (std::size_t j = 0; j < 3; ++j) {
        const T ra = ea[0] * abs_c[0][j] + ea[1] * abs_c[1][j] + ea[2] * abs_c[2][j];
        const T p = t[0] * c[0][j] + t[1] * c[1][j] + t[2] * c[2][j];
        if (std::fabs(p) > ra + eb[j] + slack) return true;
    }
    for (std::size_t i = 0; i < 3; ++i) {
        const std::size_t i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (std::size_t j = 0; j < 3; ++j) {
            const std::size_t j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            const T ra = ea[i1] * abs_c[i2][j] + ea[i2] * abs_c[i1][j];
            const T rb = eb[j1] * abs_c[i][j2] + eb[j2] * abs_c[i][j1];
            const T p = t[i2] * c[i1][j] - t[i1] * c[i2][j];
            if (std::fabs(p) > ra + rb + slack) return true;
        }
    }
    return false;
}

/// A lower bound of the boxes' distance: the largest gap along the 15 separating axes (each unit
/// axis's gap is a lower bound; an edge-cross-edge axis A_i x B_j has length sqrt(1 - c_ij^2)),
/// or the gap of their circumscribed spheres when that is larger (boxes meeting corner to corner
/// leave every axis gap small).
template <class T>
T boxes_gap(const Mat3<T>& c, const Mat3<T>& abs_c, const Vec<T, 3>& t, const Vec<T, 3>& ea,
            const Vec<T, 3>& eb) {
    T gap = length(t) - length(ea) - length(eb);
    for (std::size_t i = 0; i < 3; ++i)
        gap = std::max(gap, std::fabs(t[i]) - ea[i] - dot(abs_c[i], eb));
    for (std::size_t j = 0; j < 3; ++j) {
        const T ra = ea[0] * abs_c[0][j] + ea[1] * abs_c[1][j] + ea[2] * abs_c[2][j];
        const T p = t[0] * c[0][j] + t[1] * c[1][j] + t[2] * c[2][j];
        gap = std::max(gap, std::fabs(p) - ra - eb[j]);
    }
    for (std::size_t i = 0; i < 3; ++i) {
        const std::size_t i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (std::size_t j = 0; j < 3; ++j) {
            const T s2 = T(1) - c[i][j] * c[i][j];
            if (s2 < T(1e-4)) continue;  // nearly parallel edges: the face axes cover them
            const std::size_t j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            const T ra = ea[i1] * abs_c[i2][j] + ea[i2] * abs_c[i1][j];
            const T rb = eb[j1] * abs_c[i][j2] + eb[j2] * abs_c[i][j1];
            const T p = t[i2] * c[i1][j] - t[i1] * c[i2][j];
            const T g = std::fabs(p) - ra - rb;
            if (g > gap * std::sqrt(s2)) gap = g / std::sqrt(s2);
        }
    }
    return gap;
}

/// Relative widening of fitted volumes so that the rounding of their own computation never
/// leaves a vertex just outside.
template <class T>
constexpr T fit_pad = std::numeric_limits<T>::epsilon() * T(8);

}  // namespace detail
}  // namespace bvhkit

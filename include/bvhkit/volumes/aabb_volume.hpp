#pragma once
// Aabb<T, 3> as a BoundingVolume. Under a pose, B's box becomes an oriented box in A's frame and
// the test is the exact 15-axis box-box separating-axis test (Gottschalk, Lin, Manocha 1996), so
// the AABB tree answers exactly what an OBB tree would for these boxes. Distance lower bound: the
// largest gap along the 15 axes, or the gap of the circumscribed spheres when larger
// (bounding_volume.hpp, boxes_gap).
#include "bvhkit/math/aabb.hpp"
#include "bvhkit/volumes/bounding_volume.hpp"

namespace bvhkit {

template <class T>
struct VolumeTraits<Aabb<T, 3>> {
    using V = Aabb<T, 3>;
    using Prepared = PreparedPose<T>;
    static constexpr bool merge_is_tight = true;

    static V fit(std::span<const Triangle<T>> tris) {
        V b;
        for (const auto& t : tris) b.grow(t.p0).grow(t.p1).grow(t.p2);
        return b;
    }
    static V merge(const V& a, const V& b) { return unite(a, b); }
    static bool overlaps(const V& a, const V& b) { return a.overlaps(b); }
    static Prepared prepare(const Transform<T>& pose, T slack) { return {pose, slack}; }
    static bool overlaps(const V& a, const V& b, const Prepared& p) {
        const Vec<T, 3> ea = (a.max - a.min) * T(0.5), eb = (b.max - b.min) * T(0.5);
        const Vec<T, 3> t = p.r * ((b.min + b.max) * T(0.5)) + p.t - (a.min + a.max) * T(0.5);
        return !detail::boxes_separated(p.r, p.abs_r, t, ea, eb, p.slack);
    }
    static T size(const V& v) { return length_squared(v.max - v.min); }
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p) {
        const Vec<T, 3> ea = (a.max - a.min) * T(0.5), eb = (b.max - b.min) * T(0.5);
        const Vec<T, 3> t = p.r * ((b.min + b.max) * T(0.5)) + p.t - (a.min + a.max) * T(0.5);
        return std::max(T(0), detail::boxes_gap(p.r, p.abs_r, t, ea, eb) - p.slack);
    }
};

}  // namespace bvhkit

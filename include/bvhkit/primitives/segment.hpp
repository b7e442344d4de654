#pragma once
// Segment<T>: a 2D line segment, the 2D counterpart of a triangle for ray queries (rays through a
// 2D map, line of sight in a 2D game).
#include <optional>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit {

template <class T>
struct Segment {
    using Scalar = T;
    Vec<T, 2> p0, p1;

    Aabb<T, 2> bounds() const { return Aabb<T, 2>::of_points(p0, p1); }
    Vec<T, 2> centroid() const { return (p0 + p1) * T(0.5); }

    /// Solves o + t d = p0 + s (p1 - p0) with 2D cross products. A ray parallel to the segment
    /// (also when collinear with it) misses: it never crosses the segment. The hit's u is s, v is
    /// 0.
    std::optional<TriangleHit<T>> intersect(const Ray<T, 2>& ray) const {
        const Vec<T, 2> e = p1 - p0;
        const T denom = cross(ray.direction, e);
        if (denom == T(0) || !std::isfinite(denom)) return std::nullopt;
        const Vec<T, 2> c = p0 - ray.origin;
        const T t = cross(c, e) / denom;
        const T s = cross(c, ray.direction) / denom;
        if (!(s >= T(0) && s <= T(1) && t >= ray.tmin && t <= ray.tmax)) return std::nullopt;
        return TriangleHit<T>{t, s, T(0)};
    }
};

}  // namespace bvhkit

#pragma once
// ConvexPolytope<T>: the convex hull of a set of points, kept as the hull's vertices (found by the
// project's Quickhull, volumes/quickhull.hpp, with exact orientation tests). Its support point is
// the vertex farthest along the direction, by a scan of the vertices.
//
// Input: at least one point, all finite (otherwise Error). Fewer than four non-coplanar points are
// accepted: the hull of coplanar points is a flat polygon, of collinear points a segment, of one
// point that point. Each is a compact convex set, which is all GJK and EPA ask; a flat shape has no
// interior, so its penetration depth against another shape comes from the other shape's extent
// only.
#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/error.hpp"
#include "bvhkit/math/vec.hpp"
#include "bvhkit/volumes/quickhull.hpp"

namespace bvhkit {

template <class T>
class ConvexPolytope {
  public:
    /// The hull of `points` (local frame); duplicates and interior points are dropped.
    explicit ConvexPolytope(std::span<const Vec<T, 3>> points) {
        if (points.empty()) throw Error("ConvexPolytope: points is empty; a hull needs a point");
        for (std::size_t i = 0; i < points.size(); ++i)
            if (!is_finite(points[i]))
                throw Error("ConvexPolytope: points[" + std::to_string(i) +
                            "] is not finite (NaN or infinity)");
        std::vector<Vec<T, 3>> sorted(points.begin(), points.end());
        std::sort(sorted.begin(), sorted.end(), lexicographic_less<T>);
        sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
        const std::vector<std::uint32_t> hull =
            quickhull_vertices<T>(std::span<const Vec<T, 3>>(sorted));
        vertices_.reserve(hull.size());
        for (std::uint32_t i : hull) vertices_.push_back(sorted[i]);
        for (const Vec<T, 3>& v : vertices_)
            bounding_radius_ = std::max(bounding_radius_, length(v));
    }

    std::span<const Vec<T, 3>> vertices() const { return vertices_; }
    Vec<T, 3> support(const Vec<T, 3>& d) const {
        std::size_t best = 0;
        T best_value = dot(d, vertices_[0]);
        for (std::size_t i = 1; i < vertices_.size(); ++i) {
            const T value = dot(d, vertices_[i]);
            if (value > best_value) {
                best_value = value;
                best = i;
            }
        }
        return vertices_[best];
    }
    Vec<T, 3> core_support(const Vec<T, 3>& d) const { return support(d); }
    T margin() const { return T(0); }
    /// The largest distance of a vertex from the local origin.
    T bounding_radius() const { return bounding_radius_; }

  private:
    std::vector<Vec<T, 3>> vertices_;
    T bounding_radius_ = 0;
};

}  // namespace bvhkit

#pragma once
// ConvexPolytope<T>: the convex hull of a set of points, kept as the hull's vertices (found by the
// project's Quickhull, volumes/quickhull.hpp, with exact orientation tests) with their neighbours
// on the hull's surface. Its support point is found by climbing over the neighbours
// (volumes/hull_support.hpp), from the caller's hint when it has one (GJK and EPA pass the
// previous answer: successive directions are close, so the climb takes a step or two) and by a
// scan for hulls of a few vertices. The support point is an exact maximiser of d . x over the
// vertices; on ties it may be another vertex than a scan would give, with the same value.
//
// Input: at least one point, all finite (otherwise Error). Fewer than four non-coplanar points are
// accepted: the hull of coplanar points is a flat polygon, of collinear points a segment, of one
// point that point. Each is a compact convex set, which is all GJK and EPA ask; a flat shape has no
// interior, so its penetration depth against another shape comes from the other shape's extent
// only.
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/error.hpp"
#include "bvhkit/math/vec.hpp"
#include "bvhkit/volumes/hull_support.hpp"
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
        hull_ = HullSupport<T>(std::span<const Vec<T, 3>>(sorted));
        for (const Vec<T, 3>& v : hull_.vertices())
            bounding_radius_ = std::max(bounding_radius_, length(v));
    }

    std::span<const Vec<T, 3>> vertices() const { return hull_.vertices(); }
    /// The vertices and their neighbours, for callers that climb themselves.
    const HullSupport<T>& hull() const { return hull_; }
    Vec<T, 3> support(const Vec<T, 3>& d) const { return hull_.support(d); }
    /// The support point, starting from vertex `hint` (HullSupport<T>::none: no hint), which is
    /// set to the answer's index for the next call.
    Vec<T, 3> support(const Vec<T, 3>& d, std::uint32_t& hint) const {
        hint = hull_.support_index(d, hint);
        return hull_.vertices()[hint];
    }
    Vec<T, 3> core_support(const Vec<T, 3>& d) const { return support(d); }
    Vec<T, 3> core_support(const Vec<T, 3>& d, std::uint32_t& hint) const {
        return support(d, hint);
    }
    T margin() const { return T(0); }
    /// The largest distance of a vertex from the local origin.
    T bounding_radius() const { return bounding_radius_; }

  private:
    HullSupport<T> hull_;
    T bounding_radius_ = 0;
};

}  // namespace bvhkit

#pragma once
// Plane<T, N>: the oriented plane dot(normal, x) = offset of a BSP node (a line in 2D), with the
// thick-plane classification of points the BSP builder and its traversals share.
//
// A point is "on" the plane when its signed distance lies within [-epsilon, epsilon] (the thick
// plane of the classic BSP literature): without that band, vertices that round to either side of a
// plane they lie on would split polygons into slivers.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "bvhkit/math/vec.hpp"

namespace bvhkit {

template <class T, std::size_t N = 3>
struct Plane {
    Vec<T, N> normal{};  // unit length for planes made by through(); the builder keeps it so
    T offset = 0;

    /// Signed distance of p (positive on the side the normal points to).
    T distance(const Vec<T, N>& p) const { return dot(normal, p) - offset; }

    /// The plane with unit normal through p0, p1, p2 (counter-clockwise seen from the front); a
    /// zero normal for a degenerate triangle (callers drop those first).
    static Plane through(const Vec<T, 3>& p0, const Vec<T, 3>& p1,
                         const Vec<T, 3>& p2) requires(N == 3) {
        const Vec<T, 3> n = cross(p1 - p0, p2 - p0);
        const T len = length(n);
        if (!(len > T(0))) return {};
        Plane pl;
        pl.normal = n / len;
        // The offset from the centroid, not p0: it averages the corners' rounding.
        pl.offset = dot(pl.normal, (p0 + p1 + p2) / T(3));
        return pl;
    }
    /// The line through a and b in 2D with unit normal (dy, -dx): to the right of a -> b, so the
    /// front of a counter-clockwise polygon's edges is its outside. Zero normal for a = b.
    static Plane through(const Vec<T, 2>& a, const Vec<T, 2>& b) requires(N == 2) {
        const Vec<T, 2> d = b - a;
        const T len = length(d);
        if (!(len > T(0))) return {};
        Plane pl;
        pl.normal = Vec<T, 2>(d[1] / len, -d[0] / len);
        pl.offset = dot(pl.normal, (a + b) / T(2));
        return pl;
    }
    /// The axis-aligned plane x[axis] = value, normal +axis.
    static Plane axis_aligned(int axis, T value) {
        Plane pl;
        pl.normal[std::size_t(axis)] = T(1);
        pl.offset = value;
        return pl;
    }
};

/// Where a point or a polygon lies against a thick plane.
enum class Side : std::uint8_t { Front, Back, Coplanar, Spanning };

/// Front, Back or Coplanar (inside the thick plane) for one signed distance.
template <class T>
Side classify_distance(T d, T epsilon) {
    return d > epsilon ? Side::Front : (d < -epsilon ? Side::Back : Side::Coplanar);
}

}  // namespace bvhkit

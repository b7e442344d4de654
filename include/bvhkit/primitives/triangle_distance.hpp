#pragma once
// Distance between two triangles and a closest pair of points. Two triangles that do not meet have
// a closest pair on an edge of one and an edge of the other, or at a corner of one and the face of
// the other; so the distance is the least of 9 segment-segment distances (Ericson, Real-Time
// Collision Detection, 2005, 5.1.9) and 6 point-triangle distances (projection onto the plane, or
// the nearest point of an edge).
// Triangles that meet (triangle_triangle.hpp's rules, exact) are at distance 0, the points at the
// start of their intersection segment. Everything is computed in double (float input converts
// exactly): see docs/accuracy.md for the bound.
//
// Range: the segment step forms fourth powers of the coordinates and the plane test of
// query/distance.hpp sixth powers, which leave double's range for coordinates past about 1e+-75
// and 1e+-51. Every quantity is homogeneous in the coordinates, so a pair whose largest
// |coordinate| lies outside [2^-150, 2^150] is measured after scaling by a power of two (exact)
// that brings it to [1, 2), and the answer scaled back; pairs inside are measured as given.
#include <algorithm>
#include <cmath>
#include <limits>

#include "bvhkit/math/select.hpp"
#include "bvhkit/primitives/closest_point.hpp"
#include "bvhkit/primitives/triangle_triangle.hpp"

namespace bvhkit {

template <class T>
struct SegmentClosest {
    T distance_squared;
    Vec<T, 3> p, q;  // on the first and on the second segment
};

/// Closest points of segments [p1, q1] and [p2, q2] (either may be a point).
template <class T>
SegmentClosest<T> closest_points_segments(const Vec<T, 3>& p1, const Vec<T, 3>& q1,
                                          const Vec<T, 3>& p2, const Vec<T, 3>& q2) {
    const Vec<T, 3> d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    const T a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    const auto clamp01 = [](T x) { return clamp_of(x, T(0), T(1)); };
    T s = 0, t = 0;
    if (a <= T(0) && e <= T(0)) {
        s = t = 0;
    } else if (a <= T(0)) {
        t = clamp01(f / e);
    } else {
        const T c = dot(d1, r);
        if (e <= T(0)) {
            s = clamp01(-c / a);
        } else {
            const T b = dot(d1, d2), denom = a * e - b * b;
            // Parallel segments (denom 0): any s works; take 0 and let t follow.
            s = denom > T(0) ? clamp01((b * f - c * e) / denom) : T(0);
            t = (b * s + f) / e;
            if (t < T(0)) {
                t = 0;
                s = clamp01(-c / a);
            } else if (t > T(1)) {
                t = 1;
                s = clamp01((b - c) / a);
            }
        }
    }
    const Vec<T, 3> c1 = p1 + d1 * s, c2 = p2 + d2 * t;
    return {length_squared(c1 - c2), c1, c2};
}

template <class T>
struct TriangleDistanceResult {
    // In double for float and double triangles: finite for any finite float input (a float
    // distance's square can overflow float), and free of float's cancellation on slivers. For
    // double input the square leaves double's range (inf past 1.3e154, 0 or subnormal below
    // 1e-154); `distance` does not.
    double distance_squared = std::numeric_limits<double>::infinity();
    Vec<T, 3> p{}, q{};  // on the first and on the second triangle (rounded to T)
    double distance = std::numeric_limits<double>::infinity();
};

namespace detail {

/// The point of segment [a, b] nearest p (a when the segment is a point).
inline Vec<double, 3> nearest_on_segment(const Vec<double, 3>& p, const Vec<double, 3>& a,
                                         const Vec<double, 3>& b) {
    const Vec<double, 3> ab = b - a;
    const double l2 = dot(ab, ab);
    if (!(l2 > 0)) return a;
    return a + ab * std::clamp(dot(p - a, ab) / l2, 0.0, 1.0);
}

/// The point of triangle t nearest p, in double: the projection onto the plane when it falls
/// inside (each edge's side tested against the normal), else the nearest point of an edge. No
/// barycentric region tests, whose cancellation grows with the aspect ratio.
inline Vec<double, 3> nearest_on_triangle(const Vec<double, 3>& p, const Vec<double, 3>* t) {
    const Vec<double, 3> n = cross(t[1] - t[0], t[2] - t[0]);
    const double nn = dot(n, n);
    // A subnormal nn has too few bits for the projection to land on the plane: such a triangle
    // (area below 2^-511 of its squared size) is as near as its edges.
    if (nn >= std::numeric_limits<double>::min() && dot(cross(t[1] - t[0], p - t[0]), n) >= 0 &&
        dot(cross(t[2] - t[1], p - t[1]), n) >= 0 && dot(cross(t[0] - t[2], p - t[2]), n) >= 0)
        return p - n * (dot(p - t[0], n) / nn);
    Vec<double, 3> best = nearest_on_segment(p, t[0], t[1]);
    double best2 = length_squared(best - p);
    for (int i = 1; i < 3; ++i) {
        const Vec<double, 3> q = nearest_on_segment(p, t[i], t[(i + 1) % 3]);
        const double d2 = length_squared(q - p);
        if (d2 < best2) best = q, best2 = d2;
    }
    return best;
}

struct FeatureDistance {
    double distance_squared;
    Vec<double, 3> p, q;
};

/// The least of the 9 edge-edge and 6 corner-face distances of two triangles that do not meet,
/// on the coordinates as given.
inline FeatureDistance feature_distance(const Vec<double, 3>* u, const Vec<double, 3>* v) {
    using V = Vec<double, 3>;
    double best2 = std::numeric_limits<double>::infinity();
    V bp{}, bq{};
    const auto take = [&](const V& p, const V& q) {
        const double d2 = length_squared(p - q);
        if (d2 < best2) best2 = d2, bp = p, bq = q;
    };
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const auto s = closest_points_segments(u[i], u[(i + 1) % 3], v[j], v[(j + 1) % 3]);
            take(s.p, s.q);
        }
    for (int i = 0; i < 3; ++i) {
        take(u[i], nearest_on_triangle(u[i], v));
        take(nearest_on_triangle(v[i], u), v[i]);
    }
    return {best2, bp, bq};
}

/// The largest |coordinate| of a triangle.
inline double largest_coordinate(const Triangle<double>& t) {
    return max_component(bvhkit::max(bvhkit::max(abs(t.p0), abs(t.p1)), abs(t.p2)));
}

/// The power of two 2^k to divide a pair's coordinates by, m their largest magnitude: 0 (measured
/// as given) inside [2^-150, 2^150], where the fourth powers of the segment step and the sixth
/// powers of the plane test (m^6 times a few, up to 2^912) stay finite and coordinates of the
/// pair's own size square to normal numbers; outside, the k that brings m to [1, 2). Also 0 for
/// m zero or not finite (nothing to scale).
inline int pair_exponent(double m) {
    if (m >= 0x1p-150 && m <= 0x1p150) [[likely]]
        return 0;
    if (!(m > 0) || !(m < std::numeric_limits<double>::infinity())) return 0;
    return std::ilogb(m);
}

inline Vec<double, 3> scaled_by(const Vec<double, 3>& v, int k) {
    return {std::ldexp(v[0], k), std::ldexp(v[1], k), std::ldexp(v[2], k)};
}

inline Triangle<double> scaled_by(const Triangle<double>& t, int k) {
    return {scaled_by(t.p0, k), scaled_by(t.p1, k), scaled_by(t.p2, k)};
}

}  // namespace detail

/// Distance between triangles a and b (zero-area ones are their segment or point), computed in
/// double on the input coordinates (scaled by a power of two outside [2^-150, 2^150]); the points
/// are rounded to T.
template <class T>
TriangleDistanceResult<T> triangle_distance(const Triangle<T>& a, const Triangle<T>& b);

/// triangle_distance() for triangles already known not to meet (the least of the feature
/// distances; 0 only where rounding makes it so).
template <class T>
TriangleDistanceResult<T> triangle_distance_apart(const Triangle<T>& a, const Triangle<T>& b) {
    using V = Vec<double, 3>;
    const Triangle<double> ta{V(a.p0), V(a.p1), V(a.p2)}, tb{V(b.p0), V(b.p1), V(b.p2)};
    const int k = detail::pair_exponent(
        std::max(detail::largest_coordinate(ta), detail::largest_coordinate(tb)));
    if (k == 0) {
        const V u[3] = {ta.p0, ta.p1, ta.p2}, v[3] = {tb.p0, tb.p1, tb.p2};
        const detail::FeatureDistance f = detail::feature_distance(u, v);
        return {f.distance_squared, Vec<T, 3>(f.p), Vec<T, 3>(f.q), std::sqrt(f.distance_squared)};
    }
    const Triangle<double> sa = detail::scaled_by(ta, -k), sb = detail::scaled_by(tb, -k);
    const V u[3] = {sa.p0, sa.p1, sa.p2}, v[3] = {sb.p0, sb.p1, sb.p2};
    const detail::FeatureDistance f = detail::feature_distance(u, v);
    return {std::ldexp(f.distance_squared, 2 * k), Vec<T, 3>(detail::scaled_by(f.p, k)),
            Vec<T, 3>(detail::scaled_by(f.q, k)), std::ldexp(std::sqrt(f.distance_squared), k)};
}

template <class T>
TriangleDistanceResult<T> triangle_distance(const Triangle<T>& a, const Triangle<T>& b) {
    const TriangleIntersection<T> x = intersect_triangles(a, b);
    if (x.hit) return {0.0, x.p, x.p, 0.0};
    return triangle_distance_apart(a, b);
}

}  // namespace bvhkit

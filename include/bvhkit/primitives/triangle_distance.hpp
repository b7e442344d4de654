#pragma once
// Distance between two triangles and a closest pair of points. Two triangles that do not meet have
// a closest pair on an edge of one and an edge of the other, or at a corner of one and the face of
// the other; so the distance is the least of 9 segment-segment distances (Ericson, Real-Time
// Collision Detection, 2005, 5.1.9) and 6 point-triangle distances (5.1.5, closest_point.hpp).
// Triangles that meet (triangle_triangle.hpp's rules) are at distance 0, the points at the start
// of their intersection segment.
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
    T distance_squared = std::numeric_limits<T>::infinity();
    Vec<T, 3> p{}, q{};  // on the first and on the second triangle
};

template <class T>
TriangleDistanceResult<T> triangle_distance(const Triangle<T>& a, const Triangle<T>& b) {
    TriangleDistanceResult<T> best;
    const TriangleIntersection<T> x = intersect_triangles(a, b);
    if (x.hit) return {T(0), x.p, x.p};
    const Vec<T, 3> u[3] = {a.p0, a.p1, a.p2}, v[3] = {b.p0, b.p1, b.p2};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const auto s = closest_points_segments(u[i], u[(i + 1) % 3], v[j], v[(j + 1) % 3]);
            if (s.distance_squared < best.distance_squared) best = {s.distance_squared, s.p, s.q};
        }
    for (int i = 0; i < 3; ++i) {
        const Vec<T, 3> qb = closest_point(b, u[i]).point;
        const T db = length_squared(qb - u[i]);
        if (db < best.distance_squared) best = {db, u[i], qb};
        const Vec<T, 3> qa = closest_point(a, v[i]).point;
        const T da = length_squared(qa - v[i]);
        if (da < best.distance_squared) best = {da, qa, v[i]};
    }
    return best;
}

}  // namespace bvhkit

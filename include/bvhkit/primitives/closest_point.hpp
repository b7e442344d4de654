#pragma once
// Closest point on a triangle to a point, by the Voronoi regions of the triangle's vertices, edges
// and face (the method of Ericson, Real-Time Collision Detection, 2005, section 5.1.5). Returns the
// point and its barycentric coordinates (u, v): point = (1 - u - v) p0 + u p1 + v p2. Degenerate
// triangles (segments, points) fall into the edge and vertex regions and get a correct closest
// point.
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit {

template <class T>
struct ClosestPoint {
    Vec<T, 3> point;
    T u = 0, v = 0;  // barycentric weights of p1 and p2
};

template <class T>
ClosestPoint<T> closest_point(const Triangle<T>& tri, const Vec<T, 3>& p) {
    const Vec<T, 3> ab = tri.p1 - tri.p0, ac = tri.p2 - tri.p0, ap = p - tri.p0;
    const T d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= T(0) && d2 <= T(0)) return {tri.p0, T(0), T(0)};  // vertex region p0

    const Vec<T, 3> bp = p - tri.p1;
    const T d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= T(0) && d4 <= d3) return {tri.p1, T(1), T(0)};  // vertex region p1

    const T vc = d1 * d4 - d3 * d2;
    // d1 - d3 is |ab|^2: an edge p0-p1 of no length (p0 == p1, as rounding can make) has no
    // region of its own, and the triangle is then the segment p0-p2, handled below.
    if (vc <= T(0) && d1 >= T(0) && d3 <= T(0) && d1 > d3) {  // edge region p0-p1
        const T s = d1 / (d1 - d3);
        return {tri.p0 + ab * s, s, T(0)};
    }

    const Vec<T, 3> cp = p - tri.p2;
    const T d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= T(0) && d5 <= d6) return {tri.p2, T(0), T(1)};  // vertex region p2

    const T vb = d5 * d2 - d1 * d6;
    if (vb <= T(0) && d2 >= T(0) && d6 <= T(0)) {  // edge region p0-p2
        const T s = d2 / (d2 - d6);
        return {tri.p0 + ac * s, T(0), s};
    }

    const T va = d3 * d6 - d5 * d4;
    if (va <= T(0) && (d4 - d3) >= T(0) && (d5 - d6) >= T(0)) {  // edge region p1-p2
        const T s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return {tri.p1 + (tri.p2 - tri.p1) * s, T(1) - s, s};
    }

    // Face region: barycentrics from the three signed sub-areas.
    const T denom = T(1) / (va + vb + vc);
    const T v = vb * denom, w = vc * denom;
    return {tri.p0 + ab * v + ac * w, v, w};
}

}  // namespace bvhkit

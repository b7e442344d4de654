#pragma once
// Closest point on a triangle to a point, by the Voronoi regions of the triangle's vertices, edges
// and face (the method of Ericson, Real-Time Collision Detection, 2005, section 5.1.5). Returns the
// point and its barycentric coordinates (u, v): point = (1 - u - v) p0 + u p1 + v p2. Degenerate
// triangles (segments, points) fall into the edge and vertex regions and get a correct closest
// point. Its region tests cancel on thin triangles (0.5% off in distance on a 0.1 x 122 float
// triangle): closest_point_accurate below is the one the mesh queries use, with a stated bound.
#include <cstdint>
#include <type_traits>

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

/// The type the accurate closest point below computes in: double for float triangles, long double
/// for double ones (where long double is no wider than double, double itself: see the bound).
template <class T>
using AccurateScalar = std::conditional_t<(sizeof(T) < sizeof(double)), double, long double>;

/// The accurate closest point, in AccurateScalar<T>: the squared distance, the point, and its
/// barycentric weights (u, v) of p1 and p2, exactly 0 or 1 where the point is on an edge or a
/// corner.
template <class T>
struct AccurateClosestPoint {
    using W = AccurateScalar<T>;
    W distance_squared = 0;
    Vec<W, 3> point;
    W u = 0, v = 0;
};

namespace closest_detail {

/// The clamped parameter and squared distance of the 2D point (x, y) from the segment from s to
/// s + e, parametrised from s.
template <class W>
inline void segment_2d(W x, W y, W sx, W sy, W ex, W ey, W& t, W& d2) {
    const W wx = x - sx, wy = y - sy, len2 = ex * ex + ey * ey;
    const W along = wx * ex + wy * ey;
    t = along > W(0) ? (along < len2 ? along / len2 : W(1)) : W(0);
    const W rx = wx - t * ex, ry = wy - t * ey;
    d2 = rx * rx + ry * ry;
}

}  // namespace closest_detail

/// Everything closest_point_accurate computes of a triangle before it looks at the point: which
/// edge is longest, the frame's axes x and y, the longest edge's length l1 and the third corner
/// at (cx, cy). A caller that measures the same triangles again and again (ClosestPointMesh)
/// keeps them, and the measure skips two square roots and six divisions; the answers are the
/// same bit for bit.
template <class T>
struct AccurateFrame {
    using W = AccurateScalar<T>;
    enum Kind : std::uint8_t { Full, NotFinite, Point, Segment };
    Vec<W, 3> x, y;
    W l1 = 0, cx = 0, cy = 0;
    std::uint8_t a = 0;  // the longest edge's first corner (0, 1 or 2)
    Kind kind = Full;
};

/// The frame of `tri` (see closest_point_accurate below).
template <class T>
AccurateFrame<T> accurate_frame(const Triangle<T>& tri) {
    using W = AccurateScalar<T>;
    using V = Vec<W, 3>;
    AccurateFrame<T> f;
    const V c[3] = {V(tri.p0), V(tri.p1), V(tri.p2)};
    const W l2[3] = {length_squared(c[1] - c[0]), length_squared(c[2] - c[1]),
                     length_squared(c[0] - c[2])};
    const int a = l2[1] > l2[0] ? (l2[2] > l2[1] ? 2 : 1) : (l2[2] > l2[0] ? 2 : 0);
    const int b = (a + 1) % 3, cc = (a + 2) % 3;
    f.a = std::uint8_t(a);
    if (!std::isfinite(l2[0] + l2[1] + l2[2])) {  // a NaN or infinite corner: no distance
        f.kind = AccurateFrame<T>::NotFinite;
        return f;
    }
    if (!(l2[a] > W(0))) {  // a point
        f.kind = AccurateFrame<T>::Point;
        return f;
    }
    f.l1 = std::sqrt(l2[a]);
    f.x = (c[b] - c[a]) / f.l1;
    const V ac = c[cc] - c[a];
    f.cx = dot(ac, f.x);
    V e2 = ac - f.x * f.cx;
    const W again = dot(e2, f.x);  // Gram-Schmidt twice: orthogonal to rounding
    e2 = e2 - f.x * again, f.cx += again;
    const W cy2 = length_squared(e2);
    // Within rounding of the line (what is left of e2 may be rounding along x itself): a segment,
    // the longest edge, which then holds the third corner moved by at most 64 ulps of |ac|.
    const W tiny = W(64) * std::numeric_limits<W>::epsilon();
    if (!(cy2 > tiny * tiny * l2[cc])) {
        f.kind = AccurateFrame<T>::Segment;
        return f;
    }
    f.cy = std::sqrt(cy2);
    f.y = e2 / f.cy;
    return f;
}

/// closest_point_accurate (below) of `tri` whose frame is `f` (accurate_frame(tri)).
template <class T>
AccurateClosestPoint<T> closest_point_accurate(const Triangle<T>& tri, const AccurateFrame<T>& f,
                                               const Vec<T, 3>& p) {
    using W = AccurateScalar<T>;
    using V = Vec<W, 3>;
    const V c[3] = {V(tri.p0), V(tri.p1), V(tri.p2)}, q(p);
    const int a = f.a, b = (a + 1) % 3, cc = (a + 2) % 3;
    const V ap = q - c[a];
    AccurateClosestPoint<T> r;
    // Barycentrics of the point X + t (Y - X), in p1 and p2 (exact 0 and 1 at the ends).
    const auto on_edge = [&](int from, int to, W t) {
        W w[3] = {0, 0, 0};
        w[from] = W(1) - t, w[to] = t;
        if (t == W(1)) w[from] = 0;
        r.point = t == W(0) ? c[from] : t == W(1) ? c[to] : c[from] + (c[to] - c[from]) * t;
        r.u = w[1], r.v = w[2];
    };
    if (f.kind == AccurateFrame<T>::NotFinite) {
        r.distance_squared = std::numeric_limits<W>::quiet_NaN();
        r.point = V(r.distance_squared);
        return r;
    }
    for (int k = 0; k < 3; ++k)
        if (q == c[k]) {  // p is a corner: distance 0, exactly
            on_edge(k, (k + 1) % 3, W(0));
            return r;
        }
    if (f.kind == AccurateFrame<T>::Point) {
        r.distance_squared = length_squared(ap);
        on_edge(a, b, W(0));
        return r;
    }
    const W l1 = f.l1, cx = f.cx, cy = f.cy;
    const W px = dot(ap, f.x);
    if (f.kind == AccurateFrame<T>::Segment) {
        const W t = px > W(0) ? (px < l1 ? px / l1 : W(1)) : W(0);
        const V off = ap - f.x * (t * l1);
        r.distance_squared = length_squared(off);
        on_edge(a, b, t);
        return r;
    }
    const V z = cross(f.x, f.y);
    const W py = dot(ap, f.y), pz = dot(ap, z);
    // Inside: left of A->B (py >= 0), of B->C and of C->A (2D orientations in the frame).
    const bool inside =
        py >= W(0) && (cx - l1) * py - cy * (px - l1) >= W(0) && cy * px - cx * py >= W(0);
    if (inside) {
        r.distance_squared = pz * pz;
        // p less its height rounds in proportion to |p|; the corner plus the in-plane offset, to
        // the corner and the triangle: the second is the smaller where p is farther from the
        // plane than the triangle is long (a far point's foot stays on the triangle).
        r.point = std::fabs(pz) > l1 ? c[a] + f.x * px + f.y * py : q - z * pz;
        W w[3];
        w[cc] = py / cy;
        w[b] = (px - w[cc] * cx) / l1;
        w[a] = W(1) - w[b] - w[cc];
        r.u = w[1], r.v = w[2];
        return r;
    }
    W t[3], d2[3];
    const W sx[3] = {W(0), l1, cx}, sy[3] = {W(0), W(0), cy};
    const W ex[3] = {l1, cx - l1, -cx}, ey[3] = {W(0), cy, -cy};  // A->B, B->C, C->A
    // The nearest edge. Its squared distance rounds by eps_W d (d + L): from a far point that
    // is more than the gaps between the edges' distances (1e25 from a unit triangle, in long
    // double). There the squared distance less px^2 + py^2, which the three share, ranks them:
    // |X|^2 - 2 (px, py).X, X the edge's closest point, which rounds by eps_W L (L + d). Each
    // is used where its bound is the smaller: the key beyond twice the longest edge (d > L).
    const bool far = px * px + py * py > W(4) * l1 * l1;
    W key[3];
    for (int e = 0; e < 3; ++e) {
        closest_detail::segment_2d(px, py, sx[e], sy[e], ex[e], ey[e], t[e], d2[e]);
        const W x = sx[e] + t[e] * ex[e], y = sy[e] + t[e] * ey[e];
        key[e] = far ? (x * x + y * y) - W(2) * (px * x + py * y) : d2[e];
    }
    const int k = key[1] < key[0] ? (key[2] < key[1] ? 2 : 1) : (key[2] < key[0] ? 2 : 0);
    r.distance_squared = pz * pz + d2[k];
    const int from[3] = {a, b, cc};
    on_edge(from[k], from[(k + 1) % 3], t[k]);
    return r;
}

/// The closest point of the triangle to p without the cancellation of Ericson's region tests,
/// whose error grows with the triangle's aspect ratio (0.5% in distance on a 0.1 x 122 float
/// triangle). In W = AccurateScalar<T>: the longest edge, from its first corner A, gives the unit
/// x axis; the third corner's offset from A, less its part along x (taken off twice, so that the
/// axes stay orthogonal however thin the triangle), the unit y axis; their cross product z. In
/// that frame p and the triangle are 2D plus p's height z; the projection is inside when it is on
/// the inner side of the three edges, else the nearest of the three edges (clamped segments)
/// gives the point. Every step rounds in proportion to the lengths it handles, never to a
/// difference that cancels, so the result is the exact distance to a triangle whose corners moved
/// by a few ulps (of W) of its size. The bound, with d the returned distance, d_true the exact
/// one, L the longest edge, eps_T and eps_W the epsilons of T and W:
///     |d - d_true| <= 2 eps_T d + 96 eps_W (d + L)
/// (64 of the 96 for the cut between thin triangles and segments; the most measured against
/// exact rationals is 1.3 for float and 38 for double: docs/accuracy.md). The distance is
/// returned in W, the point and barycentrics rounded from W. Where long double is double (MSVC,
/// AArch64 Apple), eps_W for double meshes is double's, and coordinates must stay within 1e150.
/// Degenerate triangles: a segment (the longest edge holds the third corner) or a point.
/// (The frame made here: see AccurateFrame above.)
template <class T>
AccurateClosestPoint<T> closest_point_accurate(const Triangle<T>& tri, const Vec<T, 3>& p) {
    return closest_point_accurate(tri, accurate_frame(tri), p);
}

/// The squared distance from p to the triangle as closest_point_accurate computes it, in
/// AccurateScalar<T>.
template <class T>
AccurateScalar<T> distance_squared_accurate(const Triangle<T>& tri, const Vec<T, 3>& p) {
    return closest_point_accurate(tri, p).distance_squared;
}

}  // namespace bvhkit

#pragma once
// Triangle-triangle intersection, decided exactly on the input coordinates (float or double), with
// an intersection segment computed afterwards.
//
// The decision uses orientation signs only (math/predicates.hpp: exact), never a constructed point:
// - each triangle's corners against the other's plane; all strictly on one side: disjoint;
// - otherwise, for two proper (non-zero-area), non-coplanar triangles, both meet the planes'
//   common line in a segment, and those segments overlap exactly when two more orientations have
//   the right signs (Guigue and Devillers 2003, "Fast and robust triangle-triangle overlap test
//   using orientation predicates");
// - coplanar triangles and zero-area ones take the general rule: two closed triangles meet exactly
//   when an edge of one meets the other (an extreme point of their intersection lies on the
//   boundary of one of them), each edge test again by orientation signs (detail below).
//
// Rules (closed triangles: touching counts):
// - Touching at a single vertex or along an edge is an intersection; a vertex shared by two
//   triangles, and a model against its copy at the identity pose, always touch.
// - A zero-area triangle is the segment or point it is (its corners' hull) and meets what that
//   segment or point meets.
// - The segment: for crossing triangles, the overlap of the two cuts along the planes' common line,
//   interpolated in double. For coplanar ones the overlap is an area: the segment runs between the
//   two points of the overlap region (corners inside the other triangle, edge crossings) that are
//   farthest apart, with `coplanar` set. A contact involving a zero-area triangle reports one
//   point of it (p == q). The points are rounded to T; the decision never depends on them.
#include <algorithm>

#include "bvhkit/math/predicates.hpp"
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit {

template <class T>
struct TriangleIntersection {
    bool hit = false;
    bool coplanar = false;
    Vec<T, 3> p{}, q{};  // the intersection segment (p == q for a single touching point)
};

/// (a - p) . ((b - p) x (c - p)), evaluated in T (not exact; orient3d_sign gives the exact sign).
template <class T>
T orient3d(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, const Vec<T, 3>& p) {
    return dot(a - p, cross(b - p, c - p));
}

namespace detail {

// The decision below is written for any corner type P with orient3d_sign, orient3d_signs,
// orient2d_in and coordinate comparison (p[k] < q[k]): Vec<T, 3> here, and corners held as exact
// integers where a pose's rounding must be undone (primitives/posed_triangles.hpp).

/// The two axes kept when axis `drop` is dropped.
inline void kept_axes(std::size_t drop, std::size_t& x, std::size_t& y) {
    x = drop == 0 ? 1 : 0;
    y = drop == 2 ? 1 : 2;
}

template <class T>
int orient2d_in(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, std::size_t drop) {
    std::size_t x, y;
    kept_axes(drop, x, y);
    return orient2d_sign(double(a[x]), double(a[y]), double(b[x]), double(b[y]), double(c[x]),
                         double(c[y]));
}

/// An axis whose dropping keeps triangle t's area (its normal's component on it is non-zero),
/// or 3 when t has zero area. Exact.
template <class P>
std::size_t projection_axis(const P* t) {
    for (std::size_t k = 0; k < 3; ++k)
        if (orient2d_in(t[0], t[1], t[2], k) != 0) return k;
    return 3;
}

/// p within the box of a and b in the plane that drops `drop` (for collinear points: on [a, b]).
template <class P>
bool in_box_2d(const P& p, const P& a, const P& b, std::size_t drop) {
    for (std::size_t k = 0; k < 3; ++k)
        if (k != drop && (p[k] < std::min(a[k], b[k]) || p[k] > std::max(a[k], b[k]))) return false;
    return true;
}

/// Whether closed segments [a, b] and [c, d] (either may be a point) meet in the plane dropping
/// axis `drop`.
template <class P>
bool segments_meet_2d(const P& a, const P& b, const P& c, const P& d, std::size_t drop) {
    const int o1 = orient2d_in(a, b, c, drop), o2 = orient2d_in(a, b, d, drop);
    const int o3 = orient2d_in(c, d, a, drop), o4 = orient2d_in(c, d, b, drop);
    if (o1 * o2 < 0 && o3 * o4 < 0) return true;
    return (o1 == 0 && in_box_2d(c, a, b, drop)) || (o2 == 0 && in_box_2d(d, a, b, drop)) ||
           (o3 == 0 && in_box_2d(a, c, d, drop)) || (o4 == 0 && in_box_2d(b, c, d, drop));
}

/// Whether closed segments [a, b] and [c, d] (either may be a point) meet in space: they must be
/// coplanar, and then they meet exactly when they meet in all three coordinate projections (one
/// of them is one-to-one on a plane holding all four points).
template <class P>
bool segments_meet_3d(const P& a, const P& b, const P& c, const P& d) {
    if (orient3d_sign(a, b, c, d) != 0) return false;
    for (std::size_t k = 0; k < 3; ++k)
        if (!segments_meet_2d(a, b, c, d, k)) return false;
    return true;
}

/// p in closed triangle t, in the plane dropping `drop`, where t has non-zero area.
template <class P>
bool point_in_triangle_2d(const P* t, const P& p, std::size_t drop) {
    const int a = orient2d_in(t[0], t[1], p, drop), b = orient2d_in(t[1], t[2], p, drop),
              c = orient2d_in(t[2], t[0], p, drop);
    return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

/// Whether closed segment [s, e] (maybe a point) meets closed triangle t (maybe of zero area;
/// `axis` is projection_axis(t)).
template <class P>
bool segment_meets_triangle(const P& s, const P& e, const P* t, std::size_t axis) {
    if (axis == 3) {  // t is its corners' hull: the union of its edges
        for (int i = 0; i < 3; ++i)
            if (segments_meet_3d(s, e, t[i], t[(i + 1) % 3])) return true;
        return false;
    }
    const int os = orient3d_sign(t[0], t[1], t[2], s), oe = orient3d_sign(t[0], t[1], t[2], e);
    if (os * oe > 0) return false;
    if (os == 0 && oe == 0) {  // in t's plane: the projection keeping t's area is one-to-one
        if (point_in_triangle_2d(t, s, axis) || point_in_triangle_2d(t, e, axis)) return true;
        for (int i = 0; i < 3; ++i)
            if (segments_meet_2d(s, e, t[i], t[(i + 1) % 3], axis)) return true;
        return false;
    }
    // The segment crosses the plane at one point: inside t when the line through s and e passes
    // on the same side of (or through) each of t's edges.
    const int a = orient3d_sign(s, e, t[0], t[1]), b = orient3d_sign(s, e, t[1], t[2]),
              c = orient3d_sign(s, e, t[2], t[0]);
    return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

/// The general rule: an edge of one triangle meets the other.
template <class P>
bool edges_meet(const P* u, const P* v) {
    const std::size_t au = projection_axis(u), av = projection_axis(v);
    for (int i = 0; i < 3; ++i)
        if (segment_meets_triangle(u[i], u[(i + 1) % 3], v, av)) return true;
    for (int i = 0; i < 3; ++i)
        if (segment_meets_triangle(v[i], v[(i + 1) % 3], u, au)) return true;
    return false;
}

/// The corner of a triangle alone on its side of a plane, from the corners' sides d (not all
/// zero, not all strictly on one side): a corner i with the others on the opposite side or on the
/// plane (side s = d[i]), else the corner on the plane with the others strictly on one side
/// (s = the opposite of theirs). The plane then cuts edges (i, i+1) and (i, i+2).
inline int apex(const int* d, int& s) {
    for (int i = 0; i < 3; ++i) {
        const int j = d[(i + 1) % 3], k = d[(i + 2) % 3];
        if (d[i] != 0 && j != d[i] && k != d[i]) {
            s = d[i];
            return i;
        }
    }
    for (int i = 0; i < 3; ++i)
        if (d[i] == 0) {
            s = -d[(i + 1) % 3];
            return i;
        }
    s = 0;
    return 0;  // not reached for the inputs described
}

/// Guigue-Devillers' reordering: a = u rotated so its apex (apex(), from du: u's corners'
/// sides of v's plane) comes first, b = v likewise from dv, and each one's last two corners
/// swapped where the other's apex is on the negative side, so both apexes read as positive.
template <class P>
void to_apexes(const P* u, const P* v, const int* du, const int* dv, P* a, P* b) {
    int su = 0, sv = 0;
    const int iu = apex(du, su), iv = apex(dv, sv);
    for (int k = 0; k < 3; ++k) {
        a[k] = u[(iu + k) % 3];
        b[k] = v[(iv + k) % 3];
    }
    if (su < 0) std::swap(b[1], b[2]);
    if (sv < 0) std::swap(a[1], a[2]);
}

enum class Meet { None, Crossing, General };

/// The exact decision. On Crossing, a[0..2] and b[0..2] are the triangles reordered so that
/// a[0] is alone on the positive side of b's plane and b[0] on the positive side of a's (see
/// apex()), for the segment construction.
template <class P>
Meet decide(const P* u, const P* v, P* a, P* b) {
    int dv[3], du[3];
    orient3d_signs(u[0], u[1], u[2], v, dv);
    if (dv[0] == dv[1] && dv[1] == dv[2]) return dv[0] == 0 ? Meet::General : Meet::None;
    orient3d_signs(v[0], v[1], v[2], u, du);
    if (du[0] == du[1] && du[1] == du[2]) return du[0] == 0 ? Meet::General : Meet::None;
    // Both have non-zero area (a zero-area triangle puts every point on its "plane") and they
    // are not coplanar. Guigue-Devillers: rotate each so its apex comes first, flip the other's
    // orientation so that the apex is on the positive side; the cuts overlap exactly when
    // orient(a0, a1, b0, b1) <= 0 and orient(a0, a2, b2, b0) <= 0.
    to_apexes(u, v, du, dv, a, b);
    if (orient3d_sign(a[0], a[1], b[0], b[1]) > 0) return Meet::None;
    if (orient3d_sign(a[0], a[2], b[2], b[0]) > 0) return Meet::None;
    return Meet::Crossing;
}

}  // namespace detail

/// Whether the triangle has zero area (its corners are collinear or equal). Exact.
template <class T>
bool is_degenerate(const Triangle<T>& t) {
    const Vec<T, 3> c[3] = {t.p0, t.p1, t.p2};
    return detail::projection_axis(c) == 3;
}

/// Whether the closed triangles meet (the rules above). Exact.
template <class T>
bool triangles_intersect(const Triangle<T>& a, const Triangle<T>& b) {
    const Vec<T, 3> u[3] = {a.p0, a.p1, a.p2}, v[3] = {b.p0, b.p1, b.p2};
    Vec<T, 3> ra[3], rb[3];
    switch (detail::decide(u, v, ra, rb)) {
        case detail::Meet::None:
            return false;
        case detail::Meet::Crossing:
            return true;
        case detail::Meet::General:
            return detail::edges_meet(u, v);
    }
    return false;
}

}  // namespace bvhkit

#include "bvhkit/primitives/triangle_contact.hpp"

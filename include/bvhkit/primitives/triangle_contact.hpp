#pragma once
// The intersection segment of two triangles already known to meet (triangle_triangle.hpp decides
// that exactly). The points are interpolated in double and rounded to T; rounding may move them by
// a few ulps of the coordinates, the decision is unaffected.
#include <type_traits>

#include "bvhkit/primitives/triangle_triangle.hpp"

namespace bvhkit {

namespace detail {

using Vec3x = Vec<double, 3>;

/// Where segment [p, q] meets the plane, from the signed plane values dp, dq of its ends.
inline Vec3x plane_cut_point(const Vec3x& p, const Vec3x& q, double dp, double dq) {
    const double den = dp - dq;
    if (!(den != 0)) return p;
    return p + (q - p) * std::clamp(dp / den, 0.0, 1.0);
}

/// The point of [p, q] nearest the line through c and d (for segments known to meet).
inline Vec3x segment_line_point(const Vec3x& p, const Vec3x& q, const Vec3x& c, const Vec3x& d) {
    const Vec3x d1 = q - p, d2 = d - c, r = p - c;
    const double a = dot(d1, d1), b = dot(d1, d2), e = dot(d2, d2);
    const double den = a * e - b * b;
    if (!(a > 0)) return p;
    if (!(den > 0)) {  // parallel: the end of [p, q] nearest c
        return p + d1 * std::clamp(-dot(d1, r) / a, 0.0, 1.0);
    }
    const double s = (b * dot(d2, r) - dot(d1, r) * e) / den;
    return p + d1 * std::clamp(s, 0.0, 1.0);
}

/// Crossing triangles (decide() gave Crossing: a[0], b[0] apexes): the overlap of their cuts.
template <class T>
TriangleIntersection<T> crossing_segment(const Vec<T, 3>* a, const Vec<T, 3>* b) {
    const Vec3x A[3] = {Vec3x(a[0]), Vec3x(a[1]), Vec3x(a[2])};
    const Vec3x B[3] = {Vec3x(b[0]), Vec3x(b[1]), Vec3x(b[2])};
    const Vec3x na = cross(A[1] - A[0], A[2] - A[0]), nb = cross(B[1] - B[0], B[2] - B[0]);
    double da[3], db[3];
    for (int i = 0; i < 3; ++i) {
        da[i] = dot(nb, A[i] - B[0]);
        db[i] = dot(na, B[i] - A[0]);
    }
    Vec3x sa[2] = {plane_cut_point(A[0], A[1], da[0], da[1]),
                   plane_cut_point(A[0], A[2], da[0], da[2])};
    Vec3x sb[2] = {plane_cut_point(B[0], B[1], db[0], db[1]),
                   plane_cut_point(B[0], B[2], db[0], db[2])};
    const Vec3x line = cross(na, nb);
    const auto at = [&](const Vec3x& p) { return dot(line, p); };
    if (at(sa[0]) > at(sa[1])) std::swap(sa[0], sa[1]);
    if (at(sb[0]) > at(sb[1])) std::swap(sb[0], sb[1]);
    Vec3x lo = at(sa[0]) >= at(sb[0]) ? sa[0] : sb[0];
    Vec3x hi = at(sa[1]) <= at(sb[1]) ? sa[1] : sb[1];
    if (at(lo) > at(hi)) lo = hi = (lo + hi) * 0.5;  // rounding of a touching contact
    return {true, false, Vec<T, 3>(lo), Vec<T, 3>(hi)};
}

/// Coplanar triangles of non-zero area, compared in the projection dropping `drop` (one-to-one
/// on their plane): corners inside the other triangle and edge crossings; the farthest pair.
template <class T>
TriangleIntersection<T> coplanar_segment(const Vec<T, 3>* u, const Vec<T, 3>* v, std::size_t drop) {
    Vec3x pts[15];
    int n = 0;
    for (int i = 0; i < 3; ++i) {
        if (point_in_triangle_2d(v, u[i], drop)) pts[n++] = Vec3x(u[i]);
        if (point_in_triangle_2d(u, v[i], drop)) pts[n++] = Vec3x(v[i]);
    }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const Vec<T, 3>&a = u[i], &b = u[(i + 1) % 3], &c = v[j], &d = v[(j + 1) % 3];
            if (segments_meet_2d(a, b, c, d, drop) && n < 15)
                pts[n++] = segment_line_point(Vec3x(a), Vec3x(b), Vec3x(c), Vec3x(d));
        }
    if (n == 0) pts[n++] = Vec3x(u[0]);  // not reached when the triangles meet
    int far = 0;
    double best = -1;
    for (int k = 0; k < n; ++k) {
        const double d2 = length_squared(pts[k] - pts[0]);
        if (d2 > best) best = d2, far = k;
    }
    return {true, true, Vec<T, 3>(pts[0]), Vec<T, 3>(pts[far])};
}

/// A point where u, of zero area, meets v (or the other way round): a corner of one on the
/// other, else an edge of one crossing the other's plane inside it, else two edges that meet.
template <class T>
Vec3x degenerate_contact(const Vec<T, 3>* u, const Vec<T, 3>* v) {
    const std::size_t au = projection_axis(u), av = projection_axis(v);
    for (int i = 0; i < 3; ++i) {
        if (segment_meets_triangle(u[i], u[i], v, av)) return Vec3x(u[i]);
        if (segment_meets_triangle(v[i], v[i], u, au)) return Vec3x(v[i]);
    }
    for (int side = 0; side < 2; ++side) {
        const Vec<T, 3>* s = side == 0 ? u : v;
        const Vec<T, 3>* t = side == 0 ? v : u;
        if ((side == 0 ? av : au) == 3) continue;
        const Vec3x t0(t[0]), n = cross(Vec3x(t[1]) - t0, Vec3x(t[2]) - t0);
        for (int i = 0; i < 3; ++i) {
            const Vec<T, 3>&p = s[i], &q = s[(i + 1) % 3];
            const int op = orient3d_sign(t[0], t[1], t[2], p),
                      oq = orient3d_sign(t[0], t[1], t[2], q);
            if (op * oq < 0 && segment_meets_triangle(p, q, t, side == 0 ? av : au))
                return plane_cut_point(Vec3x(p), Vec3x(q), dot(n, Vec3x(p) - t0),
                                       dot(n, Vec3x(q) - t0));
        }
    }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const Vec<T, 3>&a = u[i], &b = u[(i + 1) % 3], &c = v[j], &d = v[(j + 1) % 3];
            if (segments_meet_3d(a, b, c, d))
                return segment_line_point(Vec3x(a), Vec3x(b), Vec3x(c), Vec3x(d));
        }
    return Vec3x(u[0]);  // not reached when the triangles meet
}

/// For the segment of a double pair whose extent (largest coordinate difference) lies outside
/// [2^-300, 2^300], where the constructions' products of differences overflow or sink: a k that
/// brings the extent near 1, limited so that no coordinate passes 2^1000 (a pair more than 2^1000
/// times smaller than its distance from the origin gets a rough point, never a non-finite one).
inline bool segment_shift(const Vec3x* u, const Vec3x* v, int& k) {
    double lo[3], hi[3], largest = 0;
    for (std::size_t j = 0; j < 3; ++j) {
        lo[j] = hi[j] = u[0][j];
        for (int i = 0; i < 3; ++i) {
            lo[j] = std::min({lo[j], u[i][j], v[i][j]});
            hi[j] = std::max({hi[j], u[i][j], v[i][j]});
        }
        largest = std::max({largest, std::fabs(lo[j]), std::fabs(hi[j])});
    }
    double extent = 0;  // halved, so that the differences of any doubles stay finite
    for (std::size_t j = 0; j < 3; ++j) extent = std::max(extent, hi[j] * 0.5 - lo[j] * 0.5);
    if (!(extent > 0) || (extent >= 0x1p-301 && extent <= 0x1p299)) return false;
    k = std::min(-std::ilogb(extent), 1000 - std::ilogb(largest));
    return true;
}

inline Vec3x scaled(const Vec3x& p, int k) {
    return {std::ldexp(p[0], k), std::ldexp(p[1], k), std::ldexp(p[2], k)};
}

/// The segment of triangles u and v known to meet (`m` from decide(), ra and rb its reordering),
/// from their double corners.
template <class P>
TriangleIntersection<double> contact_segment(Meet m, const Vec3x* u, const Vec3x* v,
                                             const Vec3x* ra, const Vec3x* rb, const P* eu,
                                             const P* ev) {
    if (m == Meet::Crossing) return crossing_segment(ra, rb);
    const std::size_t au = projection_axis(eu), av = projection_axis(ev);
    if (au != 3 && av != 3) return coplanar_segment(u, v, au);
    const Vec3x p = degenerate_contact(u, v);
    return {true, false, p, p};
}

/// contact_segment on the corners scaled by 2^k where segment_shift() asks for it (the decision
/// m was taken on the exact corners eu, ev; the constructions only place the points).
template <class P>
TriangleIntersection<double> contact_segment_scaled(Meet m, const Vec3x* u, const Vec3x* v,
                                                    const Vec3x* ra, const Vec3x* rb, const P* eu,
                                                    const P* ev) {
    int k = 0;
    if (!segment_shift(u, v, k)) return contact_segment(m, u, v, ra, rb, eu, ev);
    Vec3x w[12];
    for (int i = 0; i < 3; ++i) {
        w[i] = scaled(u[i], k);
        w[3 + i] = scaled(v[i], k);
        w[6 + i] = scaled(ra[i], k);
        w[9 + i] = scaled(rb[i], k);
    }
    TriangleIntersection<double> x = contact_segment(m, w, w + 3, w + 6, w + 9, eu, ev);
    x.p = scaled(x.p, -k);
    x.q = scaled(x.q, -k);
    return x;
}

}  // namespace detail

/// Whether the closed triangles meet, and where (triangle_triangle.hpp's rules).
template <class T>
TriangleIntersection<T> intersect_triangles(const Triangle<T>& a, const Triangle<T>& b) {
    const Vec<T, 3> u[3] = {a.p0, a.p1, a.p2}, v[3] = {b.p0, b.p1, b.p2};
    if constexpr (!std::is_same_v<T, float>) {  // segments at any scale
        using detail::Vec3x;
        const Vec3x du[3] = {Vec3x(u[0]), Vec3x(u[1]), Vec3x(u[2])},
                    dv[3] = {Vec3x(v[0]), Vec3x(v[1]), Vec3x(v[2])};
        Vec3x ra[3], rb[3];
        const detail::Meet m = detail::decide(du, dv, ra, rb);
        if (m == detail::Meet::None) return {};
        if (m == detail::Meet::General && !detail::edges_meet(du, dv)) return {};
        const TriangleIntersection<double> x =
            detail::contact_segment_scaled(m, du, dv, ra, rb, du, dv);
        return {true, x.coplanar, Vec<T, 3>(x.p), Vec<T, 3>(x.q)};
    }
    Vec<T, 3> ra[3], rb[3];
    switch (detail::decide(u, v, ra, rb)) {
        case detail::Meet::None:
            return {};
        case detail::Meet::Crossing:
            return detail::crossing_segment(ra, rb);
        case detail::Meet::General:
            break;
    }
    if (!detail::edges_meet(u, v)) return {};
    const std::size_t au = detail::projection_axis(u), av = detail::projection_axis(v);
    if (au != 3 && av != 3) return detail::coplanar_segment(u, v, au);
    const Vec<T, 3> p(detail::degenerate_contact(u, v));
    return {true, false, p, p};
}

}  // namespace bvhkit

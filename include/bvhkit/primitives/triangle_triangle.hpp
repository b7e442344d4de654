#pragma once
// Triangle-triangle intersection with the intersection segment, after Moller 1997 ("A fast
// triangle-triangle intersection test"): reject when one triangle lies strictly on one side of the
// other's plane; otherwise each triangle meets the other's plane in a segment, both segments lie on
// the planes' common line, and the triangles meet where those segments overlap.
//
// Rules for the special cases (closed triangles: touching counts):
// - Plane sides are orientation determinants orient(a, b, c, p) = (a - p) . ((b - p) x (c - p)),
//   which are exactly zero when p is one of a, b, c: a vertex shared by two triangles (or an
//   identical triangle) is always found "on the plane", so neighbours in a mesh and a model
//   against its copy at the identity pose touch, with no epsilon to tune.
// - Touching at a single vertex or along an edge is an intersection; the segment degenerates to
//   the touching point, or is the shared piece of the edge.
// - Coplanar triangles (every orientation zero) are tested in 2D, in the coordinate plane where
//   the normal is largest: they intersect when an edge of one crosses or touches an edge of the
//   other, or a vertex of one lies in or on the other. Their overlap is an area, not a segment:
//   the segment reported runs between two points of the overlap region (vertices inside the other
//   triangle, edge crossings) that are farthest apart, with `coplanar` set.
// - A zero-area triangle (its edge cross product is exactly zero) is not a surface and intersects
//   nothing, as it is never hit by a ray (primitives/triangle.hpp). The distance query ignores it
//   likewise.
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit {

template <class T>
struct TriangleIntersection {
    bool hit = false;
    bool coplanar = false;
    Vec<T, 3> p{}, q{};  // the intersection segment (p == q for a single touching point)
};

template <class T>
T orient3d(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, const Vec<T, 3>& p) {
    return dot(a - p, cross(b - p, c - p));
}

template <class T>
bool is_degenerate(const Triangle<T>& t) {
    const Vec<T, 3> n = cross(t.p1 - t.p0, t.p2 - t.p0);
    return n[0] == T(0) && n[1] == T(0) && n[2] == T(0);
}

namespace detail {

template <class T>
int sign_of(T x) {
    return (x > T(0)) - (x < T(0));
}

/// Where triangle (v0, v1, v2), with signed plane distances d, meets the plane: 1 or 2 points.
template <class T>
int plane_cut(const Vec<T, 3>* v, const T* d, Vec<T, 3>* out) {
    int n = 0;
    for (int i = 0; i < 3; ++i)
        if (d[i] == T(0)) out[n++] = v[i];
    for (int i = 0; i < 3 && n < 2; ++i) {
        const int j = (i + 1) % 3;
        if ((d[i] < T(0) && d[j] > T(0)) || (d[i] > T(0) && d[j] < T(0)))
            out[n++] = v[i] + (v[j] - v[i]) * (d[i] / (d[i] - d[j]));
    }
    return n;
}

template <class T>
T orient2d(T ax, T ay, T bx, T by, T cx, T cy) {
    return (ax - cx) * (by - cy) - (ay - cy) * (bx - cx);
}

/// Coplanar triangles, compared in the coordinate plane that drops axis `drop`.
template <class T, bool WantSegment>
bool coplanar_intersect(const Vec<T, 3>* u, const Vec<T, 3>* v, std::size_t drop,
                        TriangleIntersection<T>* out) {
    const std::size_t x = drop == 0 ? 1 : 0, y = drop == 2 ? 1 : 2;
    Vec<T, 3> pts[16];
    int npts = 0;
    const auto add = [&](const Vec<T, 3>& p) {
        if (npts < 16) pts[npts++] = p;
    };
    const auto inside = [&](const Vec<T, 3>* t, const Vec<T, 3>& p) {
        const T a = orient2d(t[0][x], t[0][y], t[1][x], t[1][y], p[x], p[y]);
        const T b = orient2d(t[1][x], t[1][y], t[2][x], t[2][y], p[x], p[y]);
        const T c = orient2d(t[2][x], t[2][y], t[0][x], t[0][y], p[x], p[y]);
        return (a >= T(0) && b >= T(0) && c >= T(0)) || (a <= T(0) && b <= T(0) && c <= T(0));
    };
    bool hit = false;
    for (int i = 0; i < 3; ++i) {
        if (inside(v, u[i])) {
            hit = true;
            if constexpr (!WantSegment) return true;
            add(u[i]);
        }
        if (inside(u, v[i])) {
            hit = true;
            if constexpr (!WantSegment) return true;
            add(v[i]);
        }
    }
    for (int i = 0; i < 3; ++i) {
        const Vec<T, 3>&a = u[i], &b = u[(i + 1) % 3];
        for (int j = 0; j < 3; ++j) {
            const Vec<T, 3>&c = v[j], &d = v[(j + 1) % 3];
            const T o1 = orient2d(a[x], a[y], b[x], b[y], c[x], c[y]);
            const T o2 = orient2d(a[x], a[y], b[x], b[y], d[x], d[y]);
            const T o3 = orient2d(c[x], c[y], d[x], d[y], a[x], a[y]);
            const T o4 = orient2d(c[x], c[y], d[x], d[y], b[x], b[y]);
            if (o1 == T(0) && o2 == T(0)) continue;  // collinear: endpoints were tested above
            if (sign_of(o1) * sign_of(o2) > 0 || sign_of(o3) * sign_of(o4) > 0) continue;
            hit = true;
            if constexpr (!WantSegment) return true;
            add(c + (d - c) * (o1 / (o1 - o2)));
        }
    }
    if constexpr (WantSegment) {
        if (hit) {
            int far = 0;
            T best = -1;
            for (int k = 0; k < npts; ++k) {
                const T d2 = length_squared(pts[k] - pts[0]);
                if (d2 > best) best = d2, far = k;
            }
            *out = {true, true, pts[0], pts[far]};
        }
    }
    return hit;
}

template <class T, bool WantSegment>
bool intersect_impl(const Triangle<T>& a, const Triangle<T>& b, TriangleIntersection<T>* out) {
    const Vec<T, 3> u[3] = {a.p0, a.p1, a.p2}, v[3] = {b.p0, b.p1, b.p2};
    const Vec<T, 3> nu = cross(u[1] - u[0], u[2] - u[0]), nv = cross(v[1] - v[0], v[2] - v[0]);
    if ((nu[0] == T(0) && nu[1] == T(0) && nu[2] == T(0)) ||
        (nv[0] == T(0) && nv[1] == T(0) && nv[2] == T(0)))
        return false;
    // Sides of b's corners against a's plane; a quick plane-equation pre-test first would be
    // cheaper, but its rounding could disagree with the exact-zero rule above.
    T dv[3];
    for (int i = 0; i < 3; ++i) dv[i] = orient3d(u[0], u[1], u[2], v[i]);
    if ((dv[0] > T(0) && dv[1] > T(0) && dv[2] > T(0)) ||
        (dv[0] < T(0) && dv[1] < T(0) && dv[2] < T(0)))
        return false;
    T du[3];
    for (int i = 0; i < 3; ++i) du[i] = orient3d(v[0], v[1], v[2], u[i]);
    if ((du[0] > T(0) && du[1] > T(0) && du[2] > T(0)) ||
        (du[0] < T(0) && du[1] < T(0) && du[2] < T(0)))
        return false;
    if ((dv[0] == T(0) && dv[1] == T(0) && dv[2] == T(0)) ||
        (du[0] == T(0) && du[1] == T(0) && du[2] == T(0)))
        return coplanar_intersect<T, WantSegment>(u, v, largest_axis(max(nu, -nu)), out);

    Vec<T, 3> su[2], sv[2];
    const int nsu = plane_cut(u, du, su), nsv = plane_cut(v, dv, sv);
    if (nsu == 1) su[1] = su[0];
    if (nsv == 1) sv[1] = sv[0];
    // Both cuts lie on the planes' common line: compare them along its largest coordinate.
    const Vec<T, 3> line = cross(nu, nv);
    const std::size_t k = largest_axis(max(line, -line));
    if (su[0][k] > su[1][k]) std::swap(su[0], su[1]);
    if (sv[0][k] > sv[1][k]) std::swap(sv[0], sv[1]);
    const Vec<T, 3>& lo = su[0][k] >= sv[0][k] ? su[0] : sv[0];
    const Vec<T, 3>& hi = su[1][k] <= sv[1][k] ? su[1] : sv[1];
    if (lo[k] > hi[k]) return false;
    if constexpr (WantSegment) *out = {true, false, lo, hi};
    return true;
}

}  // namespace detail

/// Whether the closed triangles meet (the rules above).
template <class T>
bool triangles_intersect(const Triangle<T>& a, const Triangle<T>& b) {
    return detail::intersect_impl<T, false>(a, b, nullptr);
}

/// Whether the closed triangles meet, and where (the rules above).
template <class T>
TriangleIntersection<T> intersect_triangles(const Triangle<T>& a, const Triangle<T>& b) {
    TriangleIntersection<T> r;
    detail::intersect_impl<T, true>(a, b, &r);
    return r;
}

}  // namespace bvhkit

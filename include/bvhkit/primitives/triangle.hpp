#pragma once
// Triangle<T>: three corners, its bounds and centroid, and two ray tests:
// - Moller and Trumbore 1997, "Fast, minimum storage ray/triangle intersection" (fast, not
// watertight:
//   a ray through a shared edge may slip between its two triangles);
// - Woop, Benthin and Wald 2013, "Watertight ray/triangle intersection" (no ray slips through a
// shared
//   edge or vertex; a little slower).
// PrecomputedTriangle keeps the edges and normal so the hot loop does one cross product per test.
#include <optional>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/hit.hpp"

namespace bvhkit {

template <class T>
struct TriangleHit {
    T t, u, v;
};

template <class T>
struct Triangle {
    using Scalar = T;
    Vec<T, 3> p0, p1, p2;

    Aabb<T, 3> bounds() const { return Aabb<T, 3>::of_points(p0, p1, p2); }
    Vec<T, 3> centroid() const { return (p0 + p1 + p2) * (T(1) / T(3)); }
    Vec<T, 3> normal() const { return cross(p1 - p0, p2 - p0); }  // not normalized
    T area() const { return T(0.5) * length(normal()); }

    /// Moller-Trumbore. Hits with t in [ray.tmin, ray.tmax]; degenerate and parallel cases miss.
    std::optional<TriangleHit<T>> intersect(const Ray<T, 3>& ray) const {
        const Vec<T, 3> e1 = p1 - p0, e2 = p2 - p0;
        const Vec<T, 3> p = cross(ray.direction, e2);
        const T det = dot(e1, p);
        if (det == T(0) || !std::isfinite(det)) return std::nullopt;
        const T inv_det = T(1) / det;
        const Vec<T, 3> s = ray.origin - p0;
        const T u = dot(s, p) * inv_det;
        if (!(u >= T(0) && u <= T(1))) return std::nullopt;
        const Vec<T, 3> q = cross(s, e1);
        const T v = dot(ray.direction, q) * inv_det;
        if (!(v >= T(0) && u + v <= T(1))) return std::nullopt;
        const T t = dot(e2, q) * inv_det;
        if (!(t >= ray.tmin && t <= ray.tmax)) return std::nullopt;
        return TriangleHit<T>{t, u, v};
    }

    /// Woop, Benthin, Wald 2013. Edge functions are evaluated in a ray-aligned frame; a zero edge
    /// function in float is re-evaluated in double, as the paper prescribes, so shared edges are
    /// never missed.
    std::optional<TriangleHit<T>> intersect_watertight(const Ray<T, 3>& ray) const {
        const Vec<T, 3>& d = ray.direction;
        // kz: the axis where the direction is largest; kx, ky follow it cyclically (swapped if
        // d[kz] < 0 so the winding is preserved).
        std::size_t kz = 0;
        for (std::size_t i = 1; i < 3; ++i)
            if (std::fabs(d[i]) > std::fabs(d[kz])) kz = i;
        std::size_t kx = (kz + 1) % 3, ky = (kx + 1) % 3;
        if (d[kz] < T(0)) std::swap(kx, ky);
        if (d[kz] == T(0)) return std::nullopt;  // zero direction
        const T sx = d[kx] / d[kz], sy = d[ky] / d[kz], sz = T(1) / d[kz];

        const Vec<T, 3> a = p0 - ray.origin, b = p1 - ray.origin, c = p2 - ray.origin;
        const T ax = a[kx] - sx * a[kz], ay = a[ky] - sy * a[kz];
        const T bx = b[kx] - sx * b[kz], by = b[ky] - sy * b[kz];
        const T cx = c[kx] - sx * c[kz], cy = c[ky] - sy * c[kz];
        T eu = cx * by - cy * bx;  // edge b-c: weight of p0
        T ev = ax * cy - ay * cx;  // edge c-a: weight of p1
        T ew = bx * ay - by * ax;  // edge a-b: weight of p2
        if constexpr (std::is_same_v<T, float>) {
            if (eu == 0.0f || ev == 0.0f || ew == 0.0f) {
                eu = static_cast<float>(double(cx) * double(by) - double(cy) * double(bx));
                ev = static_cast<float>(double(ax) * double(cy) - double(ay) * double(cx));
                ew = static_cast<float>(double(bx) * double(ay) - double(by) * double(ax));
            }
        }
        if ((eu < 0 || ev < 0 || ew < 0) && (eu > 0 || ev > 0 || ew > 0)) return std::nullopt;
        const T det = eu + ev + ew;
        if (det == T(0) || !std::isfinite(det)) return std::nullopt;
        const T az = sz * a[kz], bz = sz * b[kz], cz = sz * c[kz];
        const T t_scaled = eu * az + ev * bz + ew * cz;
        const T inv_det = T(1) / det;
        const T t = t_scaled * inv_det;
        if (!(t >= ray.tmin && t <= ray.tmax)) return std::nullopt;
        return TriangleHit<T>{t, ev * inv_det, ew * inv_det};
    }
};

/// A triangle stored for fast ray tests: p0, e1 = p0 - p1, e2 = p2 - p0 and n = e1 x e2.
/// Solving o + t d = p0 + u (p1 - p0) + v (p2 - p0) by Cramer's rule with c = p0 - o and r = d x c
/// gives det = d.n, u = r.e2 / det, v = r.e1 / det, t = c.n / det (the Moller-Trumbore solution
/// with the triple products regrouped so that only r is computed per ray).
template <class T>
struct PrecomputedTriangle {
    Vec<T, 3> p0, e1, e2, n;

    PrecomputedTriangle() = default;
    explicit PrecomputedTriangle(const Triangle<T>& tri)
        : p0(tri.p0), e1(tri.p0 - tri.p1), e2(tri.p2 - tri.p0), n(cross(e1, e2)) {}

    /// Hits with t in [ray.tmin, tmax]. A degenerate triangle or a parallel ray makes det 0, and
    /// the resulting inf/NaN fails the comparisons, so it misses without a branch of its own.
    bool intersect(const Ray<T, 3>& ray, T tmax, TriangleHit<T>& hit) const {
        const Vec<T, 3> c = p0 - ray.origin;
        const Vec<T, 3> r = cross(ray.direction, c);
        const T inv_det = T(1) / dot(n, ray.direction);
        const T u = dot(r, e2) * inv_det;
        const T v = dot(r, e1) * inv_det;
        const T w = T(1) - u - v;
        if (!(u >= T(0) && v >= T(0) && w >= T(0))) return false;
        const T t = dot(n, c) * inv_det;
        if (!(t >= ray.tmin && t <= tmax)) return false;
        hit = {t, u, v};
        return true;
    }
};

using Trianglef = Triangle<float>;
using Triangled = Triangle<double>;

}  // namespace bvhkit

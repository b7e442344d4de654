#pragma once
// Sphere<T>: centre and radius. Fitted around the centre of the triangles' box (not the minimal
// sphere, but cheap and within a factor sqrt(3) of it). Under a pose the test is exact (the centre
// moves, the radius does not); the distance lower bound is |ca - cb| - ra - rb.
#include "bvhkit/volumes/bounding_volume.hpp"

namespace bvhkit {

template <class T>
struct Sphere {
    using Scalar = T;
    Vec<T, 3> center{};
    T radius = -1;  // negative: empty
};

template <class T>
struct VolumeTraits<Sphere<T>> {
    using V = Sphere<T>;
    using Prepared = PreparedPose<T>;
    static constexpr bool merge_is_tight = false;

    static V fit(std::span<const Triangle<T>> tris) {
        if (tris.empty()) return {};
        Aabb<T, 3> box;
        for (const auto& t : tris) box.grow(t.p0).grow(t.p1).grow(t.p2);
        const Vec<T, 3> c = box.centroid();
        T r2 = 0;
        for (const auto& t : tris)
            r2 = std::max(
                {r2, length_squared(t.p0 - c), length_squared(t.p1 - c), length_squared(t.p2 - c)});
        const T r = std::sqrt(r2);
        return {c, r + (r + max_component(bvhkit::max(c, -c))) * detail::fit_pad<T>};
    }
    static V merge(const V& a, const V& b) {
        if (a.radius < 0) return b;
        if (b.radius < 0) return a;
        const Vec<T, 3> d = b.center - a.center;
        const T dist = length(d);
        if (dist + b.radius <= a.radius) return a;
        if (dist + a.radius <= b.radius) return b;
        const T r = (dist + a.radius + b.radius) * T(0.5);
        const Vec<T, 3> c = dist > T(0) ? a.center + d * ((r - a.radius) / dist) : a.center;
        return {c, r * (T(1) + detail::fit_pad<T>)};
    }
    static bool overlaps(const V& a, const V& b) {
        if (a.radius < T(0) || b.radius < T(0)) return false;  // an empty sphere meets nothing
        const T r = a.radius + b.radius;
        return length_squared(a.center - b.center) <= r * r;
    }
    static Prepared prepare(const Transform<T>& pose, T slack) { return {pose, slack}; }
    static bool overlaps(const V& a, const V& b, const Prepared& p) {
        if (a.radius < T(0) || b.radius < T(0)) return false;
        const T r = a.radius + b.radius + p.slack;
        return length_squared(a.center - (p.r * b.center + p.t)) <= r * r;
    }
    static T size(const V& v) { return v.radius * v.radius; }
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p) {
        const T d = length(a.center - (p.r * b.center + p.t)) - a.radius - b.radius - p.slack;
        return d > T(0) ? d : T(0);
    }
};

}  // namespace bvhkit

#pragma once
// Sphere<T>: centre and radius. Fitted around the centre of the triangles' box (not the minimal
// sphere, but cheap and within a factor sqrt(3) of it). Under a pose the test is exact (the centre
// moves, the radius does not); the distance lower bound is |ca - cb| - ra - rb.
#include "bvhkit/math/wide_length.hpp"
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

    /// The radius in double without squaring (wide_length), rounded up: squares in T overflow
    /// for a float model at 1e19 (an infinite radius) and sink at 1e-20 (a radius too small to
    /// hold the triangles); the centre is a midpoint that cannot overflow.
    static V fit(std::span<const Triangle<T>> tris) {
        if (tris.empty()) return {};
        Aabb<T, 3> box;
        for (const auto& t : tris) box.grow(t.p0).grow(t.p1).grow(t.p2);
        Vec<T, 3> c;
        for (std::size_t a = 0; a < 3; ++a) c[a] = midpoint_of(box.min[a], box.max[a]);
        const Vec3d cd(c);
        double r = 0;
        for (const auto& t : tris)
            for (const Vec<T, 3>& p : {t.p0, t.p1, t.p2})
                r = std::max(r, wide_length(Vec3d(p) - cd));
        const double pad = (r + max_component(bvhkit::max(cd, -cd))) * double(detail::fit_pad<T>);
        return {c, round_up_to<T>(r + pad)};
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

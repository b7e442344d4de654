#pragma once
// Generators of hard triangle pairs for the exact tests: needles crossing at about 70 degrees
// with shallow crossings and near misses of ~1e-4, touching at a corner or along an edge,
// coplanar overlapping, zero-area (segments, points), far from the origin and at scales from
// 1e-6 to 1e6. Built in double, then rounded to T: what is tested is the rounded pair.
#include <utility>

#include "bvhkit/math/random.hpp"
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit::test {

inline Vec3d any_perpendicular(const Vec3d& d) {
    const Vec3d a = std::fabs(d[0]) < 0.6 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    return normalize(cross(d, a));
}

/// A needle: length up to 4.2, width 0.002-0.017, from `start` along unit `dir`.
inline Triangle<double> needle(SplitMix64& rng, const Vec3d& start, const Vec3d& dir,
                               const Vec3d& side) {
    const double len = rng.uniform(0.5, 4.2), width = rng.uniform(0.002, 0.017);
    return {start, start + dir * len, start + dir * (len * rng.uniform(0.2, 0.8)) + side * width};
}

/// Two needles crossing at ~70 degrees; the second's edge passes within ~1e-4 of the first.
inline std::pair<Triangle<double>, Triangle<double>> crossing_needles(SplitMix64& rng) {
    const Vec3d d1 = rng.unit_vector();
    const Vec3d n = any_perpendicular(d1);  // the first needle's rough plane normal
    const Vec3d s1 = normalize(cross(n, d1));
    const Triangle<double> a = needle(rng, Vec3d(0.0), d1, s1);
    // A point on the first needle, then the second needle through it (plus a tiny offset).
    const Vec3d hit =
        a.p0 + (a.p1 - a.p0) * rng.uniform(0.05, 0.95) + (a.p2 - a.p0) * rng.uniform(0.0, 0.05);
    const double angle = rng.uniform(1.1, 1.35);  // ~63-77 degrees
    const Vec3d d2 = normalize(d1 * std::cos(angle) + n * std::sin(angle));
    const Vec3d off = rng.unit_vector() * rng.uniform(-2e-4, 2e-4);
    const double back = rng.uniform(0.2, 2.0);
    const Vec3d s2 = normalize(cross(d2, rng.unit_vector()));
    return {a, needle(rng, hit + off - d2 * back, d2, s2)};
}

/// A triangle touching `a` at a corner, along (part of) an edge, or at a point of an edge.
inline Triangle<double> touching(SplitMix64& rng, const Triangle<double>& a) {
    const Vec3d c[3] = {a.p0, a.p1, a.p2};
    const int i = int(rng.below(3)), j = (i + 1) % 3;
    const Vec3d far1 = c[i] + rng.unit_vector() * rng.uniform(0.1, 2.0);
    const Vec3d far2 = c[i] + rng.unit_vector() * rng.uniform(0.1, 2.0);
    switch (rng.below(3)) {
        case 0:
            return {c[i], far1, far2};  // shares a corner
        case 1:
            return {c[j], c[i], far1};  // shares an edge
        default:
            return {c[i] + (c[j] - c[i]) * rng.uniform(), far1, far2};  // a point of an edge
    }
}

/// Coplanar triangles in the plane z = const (exactly coplanar after rounding), overlapping or
/// close.
inline std::pair<Triangle<double>, Triangle<double>> coplanar(SplitMix64& rng) {
    const double z = rng.uniform(-1, 1);
    const auto corner = [&] { return Vec3d{rng.uniform(-1, 1), rng.uniform(-1, 1), z}; };
    return {{corner(), corner(), corner()}, {corner(), corner(), corner()}};
}

/// A zero-area triangle: a segment (a repeated corner or three collinear points) or a point,
/// placed through or near `a`.
inline Triangle<double> zero_area(SplitMix64& rng, const Triangle<double>& a) {
    const Vec3d on =
        a.p0 + (a.p1 - a.p0) * rng.uniform(0, 0.6) + (a.p2 - a.p0) * rng.uniform(0, 0.4);
    const Vec3d d = rng.unit_vector() * rng.uniform(0.01, 1.0);
    const Vec3d s = on - d * rng.uniform(-0.2, 1.2);
    switch (rng.below(3)) {
        case 0:
            return {s, s + d * 2.0, s};
        case 1:
            return {s, s + d, s + d * 2.0};  // collinear in double, maybe not after rounding
        default:
            return {on, on, on};
    }
}

/// One hard pair of kind `kind` (0..4), scaled by 10^[-6, 6] and moved up to 1e6 from the
/// origin, rounded to T.
template <class T>
std::pair<Triangle<T>, Triangle<T>> hard_pair(SplitMix64& rng, int kind) {
    std::pair<Triangle<double>, Triangle<double>> p;
    switch (kind) {
        case 0:
            p = crossing_needles(rng);
            break;
        case 1: {
            const Triangle<double> a = crossing_needles(rng).first;
            p = {a, touching(rng, a)};
            break;
        }
        case 2:
            p = coplanar(rng);
            break;
        case 3: {
            const Triangle<double> a = crossing_needles(rng).first;
            p = {a, zero_area(rng, a)};
            break;
        }
        default: {  // random pairs of small triangles near each other
            const Vec3d c = rng.unit_vector() * 0.3;
            const auto corner = [&] { return c + rng.unit_vector() * rng.uniform(0, 1); };
            p = {{corner(), corner(), corner()}, {corner(), corner(), corner()}};
        }
    }
    const double scale = std::pow(10.0, rng.uniform(-6, 6));
    const double far = rng.below(2) == 0 ? 0.0 : std::pow(10.0, rng.uniform(4, 6));
    const Vec3d offset = rng.unit_vector() * far;
    const auto place = [&](const Triangle<double>& t) {
        // Far pairs keep their size: a needle 1e6 from the origin at scale 1e-6 would be a point.
        const double s = far > 0 ? 1.0 : scale;
        return Triangle<T>{Vec<T, 3>(t.p0 * s + offset), Vec<T, 3>(t.p1 * s + offset),
                           Vec<T, 3>(t.p2 * s + offset)};
    };
    if (rng.below(2) == 0) std::swap(p.first, p.second);
    return {place(p.first), place(p.second)};
}

}  // namespace bvhkit::test

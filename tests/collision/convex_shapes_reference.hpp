#pragma once
// What the convex shape tests judge against: long double geometry written apart from convex/'s
// (points in a pose's frame, a box's signed distance, segment distances by a one-dimensional
// search), random poses, and the invariants every ConvexSignedDistance must satisfy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "bvhkit/convex/penetration.hpp"

namespace convex_shapes_test {

using bvhkit::BoxShape;
using bvhkit::CapsuleShape;
using bvhkit::ConeShape;
using bvhkit::ConvexPolytope;
using bvhkit::ConvexShape;
using bvhkit::CylinderShape;
using bvhkit::SphereShape;
using bvhkit::Transformd;
using bvhkit::Vec3d;
using LD = long double;

struct V3L {
    LD x, y, z;
};
inline V3L to_ld(const Vec3d& v) {
    return {v[0], v[1], v[2]};
}
inline LD dot_ld(const V3L& a, const V3L& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline V3L sub_ld(const V3L& a, const V3L& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline LD len_ld(const V3L& a) {
    return std::sqrt(dot_ld(a, a));
}
/// R^T (p - t) in long double: a world point in the pose's local frame.
inline V3L to_local_ld(const Transformd& pose, const Vec3d& p) {
    const V3L d = sub_ld(to_ld(p), to_ld(pose.translation));
    V3L r{};
    LD* out[3] = {&r.x, &r.y, &r.z};
    for (int j = 0; j < 3; ++j)
        *out[j] = LD(pose.rotation[0][j]) * d.x + LD(pose.rotation[1][j]) * d.y +
                  LD(pose.rotation[2][j]) * d.z;
    return r;
}
/// R p + t in long double.
inline V3L to_world_ld(const Transformd& pose, const Vec3d& p) {
    V3L r{};
    LD* out[3] = {&r.x, &r.y, &r.z};
    for (int i = 0; i < 3; ++i)
        *out[i] = LD(pose.rotation[i][0]) * p[0] + LD(pose.rotation[i][1]) * p[1] +
                  LD(pose.rotation[i][2]) * p[2] + LD(pose.translation[i]);
    return r;
}

inline Transformd random_pose(std::mt19937_64& rng, double spread) {
    std::normal_distribution<double> g(0, 1);
    std::uniform_real_distribution<double> u(-spread, spread);
    double q[4];
    double n = 0;
    do {
        for (double& c : q) c = g(rng);
        n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    } while (n < 1e-3);
    Transformd t;
    t.rotation = bvhkit::rotation_from_quaternion(q[0] / n, q[1] / n, q[2] / n, q[3] / n);
    t.translation = {u(rng), u(rng), u(rng)};
    return t;
}

/// Signed distance from a local point to the box [-h, h]: outside, the Euclidean distance; inside,
/// minus the distance to the nearest face.
inline LD box_point_signed(const V3L& p, const Vec3d& h) {
    const LD c[3] = {std::fabs(p.x) - h[0], std::fabs(p.y) - h[1], std::fabs(p.z) - h[2]};
    LD outside = 0;
    for (LD v : c) outside += v > 0 ? v * v : 0;
    if (outside > 0) return std::sqrt(outside);
    return std::max({c[0], c[1], c[2]});
}

/// Distance from 2D point q to segment ab.
inline LD segment_distance_2d(LD qx, LD qy, LD ax, LD ay, LD bx, LD by) {
    const LD dx = bx - ax, dy = by - ay;
    LD t = ((qx - ax) * dx + (qy - ay) * dy) / (dx * dx + dy * dy);
    t = std::clamp<LD>(t, 0, 1);
    return std::hypot(qx - ax - t * dx, qy - ay - t * dy);
}

/// The distance between segments p0p1 and q0q1: min over s of the distance from P(s) to the
/// segment Q (closed form per s), a convex function of s, minimised by golden-section search.
inline LD segment_segment_distance(const V3L& p0, const V3L& p1, const V3L& q0, const V3L& q1) {
    const V3L dq = sub_ld(q1, q0), dp = sub_ld(p1, p0);
    const auto at = [&](LD s) {
        const V3L p{p0.x + s * dp.x, p0.y + s * dp.y, p0.z + s * dp.z};
        const LD len2 = dot_ld(dq, dq);
        LD t = len2 > 0 ? dot_ld(sub_ld(p, q0), dq) / len2 : 0;
        t = std::clamp<LD>(t, 0, 1);
        return len_ld(sub_ld(p, {q0.x + t * dq.x, q0.y + t * dq.y, q0.z + t * dq.z}));
    };
    LD lo = 0, hi = 1;
    const LD phi = (std::sqrt(LD(5)) - 1) / 2;
    for (int i = 0; i < 200; ++i) {
        const LD m1 = hi - phi * (hi - lo), m2 = lo + phi * (hi - lo);
        if (at(m1) < at(m2))
            hi = m2;
        else
            lo = m1;
    }
    return std::min({at((lo + hi) / 2), at(0), at(1)});
}

template <class T>
inline bvhkit::Transform<T> translated(bvhkit::Transform<T> pose, const bvhkit::Vec<T, 3>& by) {
    pose.translation += by;
    return pose;
}

/// The invariants every answer must satisfy: a unit normal, point_b - point_a = signed * normal.
inline void expect_consistent(const bvhkit::ConvexSignedDistance<double>& r, double tol) {
    EXPECT_NEAR(bvhkit::length(r.normal), 1.0, 1e-9);
    const Vec3d gap = r.point_b - r.point_a - r.normal * r.signed_distance;
    EXPECT_LE(bvhkit::length(gap), tol);
}

}  // namespace convex_shapes_test

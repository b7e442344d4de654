// EPA's penetration depth between random convex polytopes against an independent reference: the
// separating-axis minimum in long double. For two convex polytopes the shortest separating
// translation is along a face normal of A, a face normal of B or the cross product of an edge of A
// and an edge of B, and its length is the least overlap of the projections over those axes. The
// faces and edges come from the vertex lists by brute force (a triple is a face when every other
// point is on one side), without the library's hull. Every answer is also checked to separate: B
// moved by (1 + 1e-6) depth along the normal is apart, by (1 - 1e-3) depth it still overlaps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "bvhkit/convex/penetration.hpp"
#include "convex_shapes_reference.hpp"
#include "test_support.hpp"

namespace convex_penetration_test {

using bvhkit::ConvexPolytope;
using bvhkit::ConvexShape;
using bvhkit::Transformd;
using bvhkit::Vec3d;
using LD = long double;
using convex_shapes_test::random_pose;

struct PointL {
    LD v[3];
};
PointL minus(const PointL& a, const PointL& b) {
    return {{a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2]}};
}
PointL crossed(const PointL& a, const PointL& b) {
    return {{a.v[1] * b.v[2] - a.v[2] * b.v[1], a.v[2] * b.v[0] - a.v[0] * b.v[2],
             a.v[0] * b.v[1] - a.v[1] * b.v[0]}};
}
LD dotted(const PointL& a, const PointL& b) {
    return a.v[0] * b.v[0] + a.v[1] * b.v[1] + a.v[2] * b.v[2];
}

/// The polytope's vertices in the world frame (long double), its face normals and edges found by
/// brute force.
struct ReferencePolytope {
    std::vector<PointL> points;
    std::vector<PointL> normals;  // outward, unit
    std::vector<LD> offsets;      // normal . x <= offset on the polytope
    std::vector<PointL> edges;
};

ReferencePolytope reference(const std::vector<Vec3d>& local, const Transformd& pose) {
    ReferencePolytope r;
    for (const Vec3d& p : local) {
        PointL w{};
        for (int i = 0; i < 3; ++i)
            w.v[i] = LD(pose.rotation[i][0]) * p[0] + LD(pose.rotation[i][1]) * p[1] +
                     LD(pose.rotation[i][2]) * p[2] + LD(pose.translation[i]);
        r.points.push_back(w);
    }
    const std::size_t n = r.points.size();
    std::set<std::pair<std::size_t, std::size_t>> edges;
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
            for (std::size_t k = j + 1; k < n; ++k) {
                const PointL normal =
                    crossed(minus(r.points[j], r.points[i]), minus(r.points[k], r.points[i]));
                bool above = false, below = false;
                for (std::size_t m = 0; m < n && !(above && below); ++m) {
                    // The triple's own points would give rounding noise, not a side.
                    if (m == i || m == j || m == k) continue;
                    const LD side = dotted(normal, minus(r.points[m], r.points[i]));
                    above |= side > 0;
                    below |= side < 0;
                }
                if (above && below) continue;
                const LD len = std::sqrt(dotted(normal, normal));
                const LD sign = above ? -1 : 1;
                const PointL unit{
                    {normal.v[0] * sign / len, normal.v[1] * sign / len, normal.v[2] * sign / len}};
                r.normals.push_back(unit);
                r.offsets.push_back(dotted(unit, r.points[i]));
                edges.insert({i, j});
                edges.insert({j, k});
                edges.insert({i, k});
            }
    for (const auto& [i, j] : edges) r.edges.push_back(minus(r.points[j], r.points[i]));
    return r;
}

/// The signed distance of p to the polytope's boundary when p is near it: max over the face
/// planes of normal . p - offset (0 on the boundary).
LD boundary_gap(const ReferencePolytope& poly, const Vec3d& p) {
    const PointL q{{p[0], p[1], p[2]}};
    LD worst = -std::numeric_limits<LD>::infinity();
    for (std::size_t f = 0; f < poly.normals.size(); ++f)
        worst = std::max(worst, dotted(poly.normals[f], q) - poly.offsets[f]);
    return worst;
}

/// min over the candidate axes of the projections' overlap: the penetration depth when positive;
/// negative when some axis separates (then it is minus that axis's gap, a lower bound of the
/// distance).
LD separating_axis_depth(const ReferencePolytope& a, const ReferencePolytope& b) {
    LD best = std::numeric_limits<LD>::infinity();
    const auto try_axis = [&](const PointL& axis) {
        const LD len = std::sqrt(dotted(axis, axis));
        if (!(len > 1e-12L)) return;
        LD a_lo = std::numeric_limits<LD>::infinity(), a_hi = -a_lo, b_lo = a_lo, b_hi = -a_lo;
        for (const PointL& p : a.points) {
            const LD s = dotted(axis, p) / len;
            a_lo = std::min(a_lo, s);
            a_hi = std::max(a_hi, s);
        }
        for (const PointL& p : b.points) {
            const LD s = dotted(axis, p) / len;
            b_lo = std::min(b_lo, s);
            b_hi = std::max(b_hi, s);
        }
        best = std::min(best, std::min(a_hi - b_lo, b_hi - a_lo));
    };
    for (const PointL& n : a.normals) try_axis(n);
    for (const PointL& n : b.normals) try_axis(n);
    for (const PointL& ea : a.edges)
        for (const PointL& eb : b.edges) try_axis(crossed(ea, eb));
    return best;
}

/// n points on an ellipsoid with random semi-axes (all of them hull vertices, in general position).
std::vector<Vec3d> ellipsoid_points(std::mt19937_64& rng, std::size_t n) {
    std::normal_distribution<double> g(0, 1);
    std::uniform_real_distribution<double> axis(0.3, 1.5);
    const Vec3d semi{axis(rng), axis(rng), axis(rng)};
    std::vector<Vec3d> pts;
    while (pts.size() < n) {
        Vec3d d{g(rng), g(rng), g(rng)};
        const double len = bvhkit::length(d);
        if (len < 1e-6) continue;
        d = d * (1 / len);
        pts.push_back({d[0] * semi[0], d[1] * semi[1], d[2] * semi[2]});
    }
    return pts;
}

/// The separation property of a penetration answer: B moved along the normal by a little more
/// than the depth is apart, by a little less still overlaps.
template <class T>
void expect_separating(const ConvexShape<T>& a, const bvhkit::Transform<T>& pa,
                       const ConvexShape<T>& b, bvhkit::Transform<T> pb,
                       const bvhkit::ConvexSignedDistance<T>& r, int id) {
    const T depth = -r.signed_distance;
    const bvhkit::Vec<T, 3> start = pb.translation;
    // In float the touching tolerance (64 epsilon times the shapes' size, ~2e-5 here) is above
    // 1e-6 of a depth: float moves 1e-4 beyond it.
    const bool is_double = sizeof(T) > sizeof(float);
    const T beyond = is_double ? depth * T(1e-6) : T(1e-4) * (depth + T(1));
    pb.translation = start + r.normal * (depth + beyond);
    EXPECT_FALSE(bvhkit::convex_distance(a, pa, b, pb).overlap)
        << id << " depth " << depth << " converged " << r.converged;
    pb.translation = start + r.normal * (depth * T(1 - 1e-3));
    EXPECT_TRUE(bvhkit::convex_distance(a, pa, b, pb).overlap) << id << " depth " << depth;
}

TEST(ConvexPenetration, RandomHullPairsMatchSeparatingAxes) {
    std::mt19937_64 rng(41);
    std::uniform_int_distribution<std::size_t> count(8, 50);
    // The reference costs O(edges_a * edges_b * points) a pair: 2000 pairs with
    // BVHKIT_TEST_SCALE=full, 400 in the Release run, 20 under the sanitizers.
    const std::size_t pairs = bvhkit::test::full_scale() ? 2000 : bvhkit::test::scaled(400);
    std::size_t overlapping = 0, apart = 0, unconverged = 0;
    double worst_relative = 0;
    for (std::size_t i = 0; i < pairs; ++i) {
        const std::vector<Vec3d> la = ellipsoid_points(rng, count(rng));
        const std::vector<Vec3d> lb = ellipsoid_points(rng, count(rng));
        const Transformd pa = random_pose(rng, 0), pb = random_pose(rng, 1.6);
        const ConvexShape<double> a(ConvexPolytope<double>{std::span<const Vec3d>(la)});
        const ConvexShape<double> b(ConvexPolytope<double>{std::span<const Vec3d>(lb)});
        const ReferencePolytope ra = reference(la, pa), rb = reference(lb, pb);
        const LD reference_depth = separating_axis_depth(ra, rb);
        const auto r = bvhkit::convex_signed_distance(a, pa, b, pb);
        // The witnesses lie on the boundaries (closest or deepest points alike).
        EXPECT_NEAR(double(boundary_gap(ra, r.point_a)), 0.0, 1e-9) << i;
        EXPECT_NEAR(double(boundary_gap(rb, r.point_b)), 0.0, 1e-9) << i;
        const int id = int(i);
        if (reference_depth > 1e-6L) {
            ++overlapping;
            unconverged += !r.converged;
            const double relative =
                double(std::fabs(-r.signed_distance - reference_depth) / reference_depth);
            worst_relative = std::max(worst_relative, relative);
            EXPECT_LE(relative, 1e-5)
                << id << " depth " << double(reference_depth) << " epa " << -r.signed_distance;
            expect_separating(a, pa, b, pb, r, id);
        } else if (reference_depth < -1e-6L) {
            ++apart;
            // A separating axis with gap g: the distance is at least g.
            EXPECT_GE(r.signed_distance, double(-reference_depth) * (1 - 1e-9)) << id;
        }
        const Vec3d gap = r.point_b - r.point_a - r.normal * r.signed_distance;
        EXPECT_LE(bvhkit::length(gap), 1e-9) << id;
    }
    EXPECT_GT(overlapping, pairs / 4);
    EXPECT_GT(apart, pairs / 4);
    EXPECT_EQ(unconverged, 0u);
    char worst[32];
    std::snprintf(worst, sizeof worst, "%.3g", worst_relative);
    RecordProperty("worst_relative_depth_error", worst);
}

TEST(ConvexPenetration, MixedShapesSeparate) {
    // Every pair of shape kinds, overlapping at random poses: the answer separates (curved shapes
    // included, where EPA approximates the boundary and stops at its tolerance).
    const std::vector<Vec3d> hull_points{{-1, -0.5, -0.7}, {1.1, -0.6, -0.4}, {0.2, 1.2, -0.8},
                                         {0.1, 0.1, 1.3},  {0.8, 0.7, 0.6},   {-0.9, 0.6, 0.5}};
    const std::vector<ConvexShape<double>> shapes{
        ConvexShape<double>(bvhkit::SphereShape<double>(0.7)),
        ConvexShape<double>(bvhkit::BoxShape<double>(Vec3d{0.5, 0.8, 0.3})),
        ConvexShape<double>(bvhkit::CapsuleShape<double>(0.4, 0.7)),
        ConvexShape<double>(bvhkit::CylinderShape<double>(0.6, 0.5)),
        ConvexShape<double>(bvhkit::ConeShape<double>(0.7, 1.4)),
        ConvexShape<double>(ConvexPolytope<double>{std::span<const Vec3d>(hull_points)})};
    std::mt19937_64 rng(43);
    const int poses = int(bvhkit::test::scaled(60, 6));
    for (std::size_t i = 0; i < shapes.size(); ++i)
        for (std::size_t j = 0; j < shapes.size(); ++j)
            for (int k = 0; k < poses; ++k) {
                const Transformd pa = random_pose(rng, 0);
                const Transformd pb = random_pose(rng, 0.6);
                const auto r = bvhkit::convex_signed_distance(shapes[i], pa, shapes[j], pb);
                if (-r.signed_distance > 1e-6)
                    expect_separating(shapes[i], pa, shapes[j], pb, r, int(1000 * i + 100 * j + k));
            }
}

TEST(ConvexPenetration, FloatHullsSeparate) {
    std::mt19937_64 rng(47);
    for (int i = 0; i < 200; ++i) {
        const std::vector<Vec3d> la = ellipsoid_points(rng, 20), lb = ellipsoid_points(rng, 20);
        std::vector<bvhkit::Vec3f> fa, fb;
        for (const Vec3d& p : la) fa.push_back(bvhkit::Vec3f(p));
        for (const Vec3d& p : lb) fb.push_back(bvhkit::Vec3f(p));
        const ConvexShape<float> a(ConvexPolytope<float>{std::span<const bvhkit::Vec3f>(fa)});
        const ConvexShape<float> b(ConvexPolytope<float>{std::span<const bvhkit::Vec3f>(fb)});
        const auto pa = bvhkit::Transformf(random_pose(rng, 0));
        const auto pb = bvhkit::Transformf(random_pose(rng, 0.8));
        const auto r = bvhkit::convex_signed_distance(a, pa, b, pb);
        if (-r.signed_distance > 1e-3f) expect_separating(a, pa, b, pb, r, i);
    }
}

}  // namespace convex_penetration_test

// Convex shapes, GJK distance and EPA penetration (convex/) against analytic answers computed in
// long double from the shapes' parameters (convex_shapes_reference.hpp): spheres, boxes, capsules,
// cylinders and cones, and a hull equal to a box; bad input. Scales, far poses and continuity are
// in convex_shapes_scale_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "bvhkit/convex/penetration.hpp"
#include "convex_shapes_reference.hpp"
#include "test_support.hpp"

namespace convex_shapes_test {

TEST(ConvexShapes, BadParametersThrowNamingThem) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const auto expect_error = [](auto make, const std::string& name) {
        try {
            make();
            ADD_FAILURE() << "no error for " << name;
        } catch (const bvhkit::Error& e) {
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        }
    };
    for (double bad : {-1.0, nan, inf, -1e-30}) {
        expect_error([&] { SphereShape<double>{bad}; }, "radius");
        expect_error([&] { BoxShape<double>(Vec3d{1, bad, 1}); }, "half_extents.y");
        expect_error([&] { CapsuleShape<double>(bad, 1); }, "radius");
        expect_error([&] { CapsuleShape<double>(1, bad); }, "half_length");
        expect_error([&] { CylinderShape<double>(bad, 1); }, "radius");
        expect_error([&] { CylinderShape<double>(1, bad); }, "half_height");
        expect_error([&] { ConeShape<double>(bad, 1); }, "radius");
        expect_error([&] { ConeShape<double>(1, bad); }, "height");
        expect_error([&] { SphereShape<float>{float(bad)}; }, "radius");
    }
    expect_error([] { ConvexPolytope<double>(std::span<const Vec3d>{}); }, "empty");
    const std::vector<Vec3d> with_nan{{0, 0, 0}, {1, 0, 0}, {0, nan, 0}};
    expect_error([&] { ConvexPolytope<double>{std::span<const Vec3d>(with_nan)}; }, "points[2]");
    // Zero sizes are shapes too: a point, a flat box.
    EXPECT_NO_THROW(SphereShape<double>(0));
    EXPECT_NO_THROW(BoxShape<double>(Vec3d{1, 0, 1}));

    // Poses: NaN or non-rigid throws Error (no answer is made up).
    const ConvexShape<double> s(SphereShape<double>(1));
    Transformd bad_pose;
    bad_pose.translation = {nan, 0, 0};
    EXPECT_THROW(bvhkit::convex_distance(s, Transformd{}, s, bad_pose), bvhkit::Error);
    EXPECT_THROW(bvhkit::convex_signed_distance(s, bad_pose, s, Transformd{}), bvhkit::Error);
    Transformd scaled;
    scaled.rotation.row[0] = {2, 0, 0};
    EXPECT_THROW(bvhkit::convex_signed_distance(s, Transformd{}, s, scaled), bvhkit::Error);
    Transformd nan_rotation;
    nan_rotation.rotation.row[1] = {0, nan, 0};
    EXPECT_THROW(bvhkit::convex_distance(s, nan_rotation, s, Transformd{}), bvhkit::Error);
}

TEST(ConvexShapes, DegenerateHullsAreValidSets) {
    // One point, a segment, a flat square: GJK measures them; a flat set has no depth of its own.
    const std::vector<Vec3d> point{{0, 0, 0}},
        segment{{-1, 0, 0}, {1, 0, 0}, {0.5, 0, 0}, {-0.25, 0, 0}},
        square{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 0}};
    const ConvexShape<double> p(ConvexPolytope<double>{std::span<const Vec3d>(point)});
    const ConvexShape<double> s(ConvexPolytope<double>{std::span<const Vec3d>(segment)});
    const ConvexShape<double> q(ConvexPolytope<double>{std::span<const Vec3d>(square)});
    EXPECT_EQ(std::get<ConvexPolytope<double>>(s.variant()).vertices().size(), 2u);
    EXPECT_EQ(std::get<ConvexPolytope<double>>(q.variant()).vertices().size(), 4u);
    Transformd up;
    up.translation = {0, 0, 2};
    EXPECT_NEAR(bvhkit::convex_distance(p, Transformd{}, q, up).distance, 2.0, 1e-14);
    EXPECT_NEAR(bvhkit::convex_distance(s, Transformd{}, q, up).distance, 2.0, 1e-14);
    // A unit sphere through the square, its centre 0.25 above: B leaves upwards, by 0.75.
    const ConvexShape<double> ball(SphereShape<double>(1));
    Transformd slightly_up;
    slightly_up.translation = {0.1, 0.2, 0.25};
    const auto r = bvhkit::convex_signed_distance(q, Transformd{}, ball, slightly_up);
    EXPECT_NEAR(r.signed_distance, -0.75, 1e-12);
    EXPECT_NEAR(r.normal[2], 1.0, 1e-12);
    // Two crossing segments (capsules of radius 0): touching, depth 0, normal across both.
    const ConvexShape<double> c1(CapsuleShape<double>(0, 1));
    Transformd across;
    across.rotation = bvhkit::rotation_about(Vec3d{1, 0, 0}, std::acos(-1.0) / 2);
    const auto crossing = bvhkit::convex_signed_distance(c1, Transformd{}, c1, across);
    EXPECT_NEAR(crossing.signed_distance, 0.0, 1e-15);
    EXPECT_NEAR(std::fabs(crossing.normal[0]), 1.0, 1e-12);
    // Coincident shapes: two equal boxes at one pose leave by their smallest full extent; two
    // points at one place touch (0); every answer has a unit normal.
    std::mt19937_64 rng(3);
    for (int i = 0; i < 20; ++i) {
        const Transformd pose = random_pose(rng, 2);
        const ConvexShape<double> box{BoxShape<double>(Vec3d{0.3, 0.7, 0.5})};
        const auto same = bvhkit::convex_signed_distance(box, pose, box, pose);
        EXPECT_NEAR(same.signed_distance, -0.6, 1e-12);
        expect_consistent(same, 1e-12);
        const ConvexShape<double> dot{SphereShape<double>(0)},
            flat{BoxShape<double>(Vec3d{0, 0, 0})};
        const auto points = bvhkit::convex_signed_distance(dot, pose, flat, pose);
        EXPECT_EQ(points.signed_distance, 0.0);
        expect_consistent(points, 1e-12);
        EXPECT_TRUE(bvhkit::convex_distance(dot, pose, flat, pose).overlap);
    }
}

TEST(ConvexShapes, SphereSphereExact) {
    const ConvexShape<double> a(SphereShape<double>(1.25)), b(SphereShape<double>(0.5));
    std::mt19937_64 rng(7);
    for (int i = 0; i < 200; ++i) {
        const Transformd pa = random_pose(rng, 3), pb = random_pose(rng, 3);
        const LD centres = len_ld(sub_ld(to_ld(pb.translation), to_ld(pa.translation)));
        const double expected = double(centres - LD(1.75));
        const auto r = bvhkit::convex_signed_distance(a, pa, b, pb);
        EXPECT_NEAR(r.signed_distance, expected, 4e-15 * 8);
        expect_consistent(r, 1e-14);
        const auto d = bvhkit::convex_distance(a, pa, b, pb);
        EXPECT_EQ(d.overlap, expected <= 0);
        if (!d.overlap) {
            EXPECT_NEAR(d.distance, expected, 4e-15 * 8);
        }
    }
    // Touching exactly (centres 1.75 apart along x): 0, and it counts as overlap.
    Transformd touch;
    touch.translation = {1.75, 0, 0};
    const auto t = bvhkit::convex_signed_distance(a, Transformd{}, b, touch);
    EXPECT_EQ(t.signed_distance, 0.0);
    EXPECT_EQ(t.normal, (Vec3d{1, 0, 0}));
    EXPECT_TRUE(bvhkit::convex_distance(a, Transformd{}, b, touch).overlap);
    // Concentric: depth = the radii's sum, along the documented fallback (+z).
    const auto c = bvhkit::convex_signed_distance(a, touch, b, touch);
    EXPECT_EQ(c.signed_distance, -1.75);
    EXPECT_EQ(c.normal, (Vec3d{0, 0, 1}));
    expect_consistent(c, 1e-15);
}

TEST(ConvexShapes, SphereBoxFaceEdgeCornerAndInside) {
    std::mt19937_64 rng(11);
    const Vec3d h{1.0, 0.5, 2.0};
    const ConvexShape<double> box{BoxShape<double>(h)}, ball{SphereShape<double>(0.3)};
    std::uniform_real_distribution<double> u(-2.8, 2.8);
    int regions[4] = {0, 0, 0, 0};  // inside, face, edge, corner
    for (int i = 0; i < 3000; ++i) {
        const Transformd pose = random_pose(rng, 5);
        const Vec3d local{u(rng), u(rng) * 0.5, u(rng) * 1.5};
        Transformd at;
        at.translation = pose.apply(local);
        const V3L p = to_local_ld(pose, at.translation);
        const LD signed_point = box_point_signed(p, h);
        int outside_axes =
            (std::fabs(p.x) > h[0]) + (std::fabs(p.y) > h[1]) + (std::fabs(p.z) > h[2]);
        ++regions[outside_axes];
        const double expected = double(signed_point - LD(0.3));
        const auto r = bvhkit::convex_signed_distance(box, pose, ball, at);
        // Outside the box the answer is GJK on a polytope and a point: exact to rounding. Inside,
        // EPA on a box and a point: exact to rounding as well (the polytope is the box).
        EXPECT_NEAR(r.signed_distance, expected, 1e-13) << i << " region " << outside_axes;
        expect_consistent(r, 1e-12);
        // The witnesses lie on the boundaries: point_a on the box, point_b on the ball.
        EXPECT_NEAR(double(box_point_signed(to_local_ld(pose, r.point_a), h)), 0.0, 1e-13) << i;
        EXPECT_NEAR(double(len_ld(sub_ld(to_ld(r.point_b), to_ld(at.translation)))), 0.3, 1e-13)
            << i;
    }
    for (int k = 0; k < 4; ++k) EXPECT_GT(regions[k], 50) << "region " << k;
}

TEST(ConvexShapes, AxisAlignedBoxBox) {
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> size(0.1, 2), u(-3, 3);
    int overlapping = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3d ha{size(rng), size(rng), size(rng)}, hb{size(rng), size(rng), size(rng)};
        Transformd pa, pb;
        pa.translation = {u(rng), u(rng), u(rng)};
        pb.translation = {u(rng), u(rng), u(rng)};
        const ConvexShape<double> a(BoxShape<double>{ha}), b(BoxShape<double>{hb});
        LD gap2 = 0, least_overlap = std::numeric_limits<LD>::infinity();
        for (int k = 0; k < 3; ++k) {
            const LD gap = std::fabs(LD(pb.translation[k]) - LD(pa.translation[k])) - ha[k] - hb[k];
            if (gap > 0) gap2 += gap * gap;
            least_overlap = std::min(least_overlap, -gap);
        }
        const double expected = gap2 > 0 ? double(std::sqrt(gap2)) : double(-least_overlap);
        overlapping += expected < 0;
        const auto r = bvhkit::convex_signed_distance(a, pa, b, pb);
        EXPECT_NEAR(r.signed_distance, expected, 1e-13) << i;
        expect_consistent(r, 1e-12);
        const auto d = bvhkit::convex_distance(a, pa, b, pb);
        EXPECT_NEAR(d.distance, std::max(expected, 0.0), 1e-13);
        if (std::fabs(expected) > 1e-9) {
            EXPECT_EQ(d.overlap, expected < 0);
        }
        if (d.overlap) {
            // The point reported for meeting shapes lies in both boxes.
            for (int k = 0; k < 3; ++k) {
                EXPECT_LE(std::fabs(d.point_a[k] - pa.translation[k]), ha[k] + 1e-12) << i;
                EXPECT_LE(std::fabs(d.point_a[k] - pb.translation[k]), hb[k] + 1e-12) << i;
            }
        }
    }
    EXPECT_GT(overlapping, 200);
    EXPECT_LT(overlapping, 1800);
}

TEST(ConvexShapes, CapsuleCapsuleAgainstSegmentSearch) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> size(0.05, 1.0);
    int overlapping = 0;
    for (int i = 0; i < 1000; ++i) {
        const double ra = size(rng), la = size(rng) * 2, rb = size(rng), lb = size(rng) * 2;
        const ConvexShape<double> a(CapsuleShape<double>(ra, la)), b(CapsuleShape<double>(rb, lb));
        const Transformd pa = random_pose(rng, 2), pb = random_pose(rng, 2);
        const LD core =
            segment_segment_distance(to_world_ld(pa, {0, 0, -la}), to_world_ld(pa, {0, 0, la}),
                                     to_world_ld(pb, {0, 0, -lb}), to_world_ld(pb, {0, 0, lb}));
        const LD expected = core - ra - rb;
        const auto r = bvhkit::convex_signed_distance(a, pa, b, pb);
        // The margin split makes capsules exact to rounding as long as the segments do not cross.
        if (core > 1e-9) {
            EXPECT_NEAR(r.signed_distance, double(expected), 1e-13) << i;
            overlapping += expected < 0;
            // The witnesses lie on the capsules' boundaries: at their radius from the segments.
            const V3L wa = to_ld(r.point_a), wb = to_ld(r.point_b);
            EXPECT_NEAR(double(segment_segment_distance(wa, wa, to_world_ld(pa, {0, 0, -la}),
                                                        to_world_ld(pa, {0, 0, la}))),
                        ra, 1e-12)
                << i;
            EXPECT_NEAR(double(segment_segment_distance(wb, wb, to_world_ld(pb, {0, 0, -lb}),
                                                        to_world_ld(pb, {0, 0, lb}))),
                        rb, 1e-12)
                << i;
        }
        expect_consistent(r, 1e-12);
    }
    EXPECT_GT(overlapping, 100);
}

/// Signed distance from local point p to a cylinder (radius r, half height h); inside: minus the
/// distance to its boundary.
LD cylinder_point_signed(const V3L& p, LD r, LD h) {
    const LD rho = std::hypot(p.x, p.y), dr = rho - r, dz = std::fabs(p.z) - h;
    if (dr > 0 || dz > 0) return std::hypot(std::max<LD>(dr, 0), std::max<LD>(dz, 0));
    return std::max(dr, dz);
}

/// Distance from local point p to a cone (base radius r at z = -H / 2, apex at z = H / 2), outside
/// points only: the distance in the (rho, z) half-plane to the cross-section triangle.
LD cone_point_distance(const V3L& p, LD r, LD height) {
    const LD rho = std::hypot(p.x, p.y), half = height / 2;
    // Inside: below the apex line and above the base.
    const bool inside = p.z >= -half && rho * height <= r * (half - p.z);
    if (inside) return 0;
    return std::min({segment_distance_2d(rho, p.z, 0, -half, r, -half),
                     segment_distance_2d(rho, p.z, r, -half, 0, half)});
}

TEST(ConvexShapes, CylinderAndConeAgainstSphere) {
    std::mt19937_64 rng(19);
    const double r = 0.8, h = 1.1, height = 2.0, rs = 0.25;
    const ConvexShape<double> cylinder(CylinderShape<double>(r, h)),
        cone(ConeShape<double>(r, height));
    const ConvexShape<double> ball{SphereShape<double>(rs)};
    std::uniform_real_distribution<double> u(-3, 3);
    for (int i = 0; i < 1500; ++i) {
        const Transformd pose = random_pose(rng, 4);
        // A fifth of the centres on the axis, the rest anywhere.
        Vec3d local{u(rng), u(rng), u(rng)};
        if (i % 5 == 0) local = {0, 0, u(rng)};
        Transformd at;
        at.translation = pose.apply(local);
        const V3L p = to_local_ld(pose, at.translation);
        const LD cyl = cylinder_point_signed(p, r, h);
        const auto rc = bvhkit::convex_signed_distance(cylinder, pose, ball, at);
        if (cyl > 0) {
            // Apart or overlapping by less than the ball: GJK on a curved set and a point.
            EXPECT_NEAR(rc.signed_distance, double(cyl - rs), 1e-9) << i;
        } else {
            // The centre inside: EPA on a curved set approximates its boundary by a polytope.
            EXPECT_NEAR(rc.signed_distance, double(cyl - rs), 1e-5 * double(rs - cyl)) << i;
            EXPECT_LE(rc.signed_distance, double(cyl - rs) + 1e-9) << i;  // an upper bound of depth
        }
        expect_consistent(rc, 1e-9);
        // The witnesses on the boundaries: point_a on the cylinder, point_b on the ball.
        const double on_boundary = cyl > 0 ? 1e-9 : 1e-5;
        EXPECT_NEAR(double(cylinder_point_signed(to_local_ld(pose, rc.point_a), r, h)), 0.0,
                    on_boundary)
            << i;
        EXPECT_NEAR(double(len_ld(sub_ld(to_ld(rc.point_b), to_ld(at.translation)))), rs,
                    on_boundary)
            << i;
        const LD co = cone_point_distance(p, r, height);
        if (co > 0) {
            const auto d = bvhkit::convex_distance(cone, pose, ball, at);
            EXPECT_NEAR(std::max(0.0, double(co - rs)), d.distance, 1e-9) << i;
        }
    }
    // On the axis above the cap: distance is exact along the axis.
    Transformd above;
    above.translation = {0, 0, 3};
    EXPECT_NEAR(bvhkit::convex_distance(cylinder, Transformd{}, ball, above).distance, 3 - h - rs,
                1e-14);
    EXPECT_NEAR(bvhkit::convex_distance(cone, Transformd{}, ball, above).distance,
                3 - height / 2 - rs, 1e-14);
}

TEST(ConvexShapes, CubeHullEqualsBox) {
    const std::vector<Vec3d> corners{{-1, -2, -3}, {1, -2, -3}, {-1, 2, -3}, {1, 2, -3},
                                     {-1, -2, 3},  {1, -2, 3},  {-1, 2, 3},  {1, 2, 3}};
    const ConvexShape<double> hull(ConvexPolytope<double>{std::span<const Vec3d>(corners)});
    const ConvexShape<double> box(BoxShape<double>(Vec3d{1, 2, 3}));
    const ConvexShape<double> other(CapsuleShape<double>(0.4, 1.5));
    std::mt19937_64 rng(23);
    for (int i = 0; i < 500; ++i) {
        const Transformd pa = random_pose(rng, 3), pb = random_pose(rng, 3);
        const auto h = bvhkit::convex_signed_distance(hull, pa, other, pb);
        const auto b = bvhkit::convex_signed_distance(box, pa, other, pb);
        EXPECT_NEAR(h.signed_distance, b.signed_distance, 1e-9 * (1 + std::fabs(b.signed_distance)))
            << i;
    }
}

}  // namespace convex_shapes_test

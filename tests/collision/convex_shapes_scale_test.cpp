// Convex shapes (convex/) far from the origin, at tiny and huge scales (a power of two apart from
// the unit answer), with offsets beyond the range and subnormal pairs, continuous through contact,
// and in float: against the long double references of convex_shapes_reference.hpp.
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

namespace convex_shapes_scale_test {
using namespace convex_shapes_test;

TEST(ConvexShapes, FarFromTheOriginAndScales) {
    // A box and a capsule near each other at a 1e6 offset: the answer is computed relative to A's
    // position, so only the poses' own rounding at 1e6 (ulp 1.2e-10) is lost; the tolerance is a
    // few such ulps.
    const double ulp = std::nextafter(1e6, 2e6) - 1e6;
    std::mt19937_64 rng(29);
    for (double offset : {1e6, -3e6}) {
        for (int i = 0; i < 300; ++i) {
            const Transformd pa = random_pose(rng, 2), pb = random_pose(rng, 2);
            const Vec3d shift{offset, -offset / 2, offset / 3};
            const ConvexShape<double> a(BoxShape<double>(Vec3d{0.7, 0.4, 1.0}));
            const ConvexShape<double> b(CapsuleShape<double>(0.3, 0.6));
            const auto near = bvhkit::convex_signed_distance(a, pa, b, pb);
            const auto far =
                bvhkit::convex_signed_distance(a, translated(pa, shift), b, translated(pb, shift));
            EXPECT_NEAR(far.signed_distance, near.signed_distance,
                        8 * ulp * std::fabs(offset) / 1e6)
                << i;
            // Witness points need not be unique (faces in contact): check their relation instead.
            const Vec3d gap = far.point_b - far.point_a - far.normal * far.signed_distance;
            EXPECT_LE(bvhkit::length(gap), 8 * ulp * std::fabs(offset) / 1e6);
            EXPECT_NEAR(bvhkit::length(far.point_a - shift - pa.translation),
                        bvhkit::length(near.point_a - pa.translation), 3.0);
        }
    }
    // Scales: boxes and capsules of size s at distances of size s give s times the unit answer.
    for (double s : {1e-6, 1e6}) {
        std::mt19937_64 same(31);
        for (int i = 0; i < 200; ++i) {
            Transformd pa = random_pose(same, 1.5), pb = random_pose(same, 1.5);
            const ConvexShape<double> a1(BoxShape<double>(Vec3d{0.7, 0.4, 1.0}));
            const ConvexShape<double> b1(CapsuleShape<double>(0.3, 0.6));
            const ConvexShape<double> as(BoxShape<double>(Vec3d{0.7, 0.4, 1.0} * s));
            const ConvexShape<double> bs(CapsuleShape<double>(0.3 * s, 0.6 * s));
            const auto unit = bvhkit::convex_signed_distance(a1, pa, b1, pb);
            pa.translation *= s;
            pb.translation *= s;
            const auto scaled = bvhkit::convex_signed_distance(as, pa, bs, pb);
            EXPECT_NEAR(scaled.signed_distance / s, unit.signed_distance,
                        unit.converged ? 1e-8 : 1e-3)
                << "scale " << s << " pair " << i;
        }
    }
}

TEST(ConvexShapes, ExtremeScalesArePowersOfTwoOfTheUnitAnswer) {
    // Every coordinate scaled by 2^k is exact, so the exact answers scale by 2^k too. GJK's and
    // EPA's determinants multiply four coordinates: at 2^+-600 (1e+-180) they leave double's
    // range unless the pair is brought to unit size first. Hulls, boxes, capsules and spheres,
    // apart and overlapping.
    const std::vector<Vec3d> hull_points{{-1, -0.5, -0.7}, {1.1, -0.6, -0.4}, {0.2, 1.2, -0.8},
                                         {0.1, 0.1, 1.3},  {0.8, 0.7, 0.6},   {-0.9, 0.6, 0.5}};
    const auto shapes = [&](double s) {
        std::vector<Vec3d> scaled_points;
        for (const Vec3d& p : hull_points) scaled_points.push_back(p * s);
        return std::vector<ConvexShape<double>>{
            ConvexShape<double>(BoxShape<double>(Vec3d{0.7, 0.4, 1.0} * s)),
            ConvexShape<double>(CapsuleShape<double>(0.3 * s, 0.6 * s)),
            ConvexShape<double>(bvhkit::SphereShape<double>(0.5 * s)),
            ConvexShape<double>(
                bvhkit::ConvexPolytope<double>{std::span<const Vec3d>(scaled_points)})};
    };
    const auto unit_shapes = shapes(1);
    int overlapping = 0;
    for (const int k : {-1000, -600, -300, 300, 600, 1000}) {
        const double s = std::ldexp(1.0, k);
        const auto scaled_shapes = shapes(s);
        std::mt19937_64 same(37);
        for (int i = 0; i < 120; ++i) {
            const std::size_t x = std::size_t(i) % 4, y = std::size_t(i / 4) % 4;
            Transformd pa = random_pose(same, 1.5), pb = random_pose(same, 1.5);
            const auto unit =
                bvhkit::convex_signed_distance(unit_shapes[x], pa, unit_shapes[y], pb);
            const auto apart = bvhkit::convex_distance(unit_shapes[x], pa, unit_shapes[y], pb);
            pa.translation *= s;
            pb.translation *= s;
            const auto scaled =
                bvhkit::convex_signed_distance(scaled_shapes[x], pa, scaled_shapes[y], pb);
            const auto scaled_apart =
                bvhkit::convex_distance(scaled_shapes[x], pa, scaled_shapes[y], pb);
            const double tol = unit.converged ? 1e-8 : 1e-3;
            EXPECT_NEAR(scaled.signed_distance / s, unit.signed_distance, tol)
                << "2^" << k << " pair " << i;
            EXPECT_NEAR(scaled_apart.distance / s, apart.distance, 1e-8)
                << "2^" << k << " pair " << i;
            EXPECT_EQ(scaled_apart.overlap, apart.overlap) << "2^" << k << " pair " << i;
            EXPECT_NEAR(bvhkit::length(scaled.normal - unit.normal), 0.0, 1e-6)
                << "2^" << k << " pair " << i;
            for (std::size_t a = 0; a < 3; ++a) {
                EXPECT_NEAR(scaled.point_a[a] / s, unit.point_a[a], 1e-6) << "2^" << k << " " << i;
                EXPECT_NEAR(scaled_apart.point_b[a] / s, apart.point_b[a], 1e-6)
                    << "2^" << k << " " << i;
            }
            overlapping += unit.signed_distance < 0;
        }
    }
    EXPECT_GT(overlapping, 60);
    EXPECT_LT(overlapping, 6 * 120 - 60);
}

TEST(ConvexShapes, OffsetsBeyondTheRangeAndSubnormalPairs) {
    // Poses at -1e308 and 1e308: the offset overflows a double, the distance is beyond its range
    // (+inf, or the largest finite values near it), never "overlapping".
    const ConvexShape<double> ball{SphereShape<double>(1)};
    Transformd left, right;
    left.translation = Vec3d{-1e308, 0, 0};
    right.translation = Vec3d{1e308, 0, 0};
    const auto far = bvhkit::convex_distance(ball, left, ball, right);
    EXPECT_FALSE(far.overlap);
    EXPECT_GT(far.distance, 1.7e308);
    const auto far_signed = bvhkit::convex_signed_distance(ball, left, ball, right);
    EXPECT_GT(far_signed.signed_distance, 1.7e308);
    EXPECT_NEAR(far_signed.normal[0], 1.0, 1e-12);
    // Two points 3e-310 apart (a subnormal distance): found apart, by that distance.
    const ConvexShape<double> point{SphereShape<double>(0)};
    Transformd here, there;
    there.translation = Vec3d{3e-310, 0, 0};
    const auto tiny = bvhkit::convex_distance(point, here, point, there);
    EXPECT_FALSE(tiny.overlap);
    EXPECT_EQ(tiny.distance, 3e-310);
    EXPECT_FALSE(std::isnan(tiny.point_b[0]));
    const auto tiny_f = bvhkit::convex_distance(
        ConvexShape<float>{SphereShape<float>(0)}, bvhkit::Transformf{},
        ConvexShape<float>{SphereShape<float>(0)},
        bvhkit::Transformf{bvhkit::Mat3<float>::identity(), bvhkit::Vec3f{1e-40f, 0, 0}});
    EXPECT_FALSE(tiny_f.overlap);
    EXPECT_EQ(tiny_f.distance, 1e-40f);
}

TEST(ConvexShapes, ContinuousThroughContact) {
    // B moves along a fixed direction through A in small steps: the signed distance changes by at
    // most the step (it is 1-Lipschitz in a translation), and the normal never flips.
    const std::vector<Vec3d> pts{{-1, -1, -1}, {1.2, -0.8, -1}, {0.1, 1.3, -0.9},
                                 {0, 0, 1.4},  {0.9, 0.9, 0.8}, {-0.9, 0.7, 0.9}};
    const std::vector<ConvexShape<double>> shapes{
        ConvexShape<double>(SphereShape<double>(0.6)),
        ConvexShape<double>(BoxShape<double>(Vec3d{0.5, 0.8, 0.3})),
        ConvexShape<double>(CapsuleShape<double>(0.4, 0.7)),
        ConvexShape<double>(ConvexPolytope<double>{std::span<const Vec3d>(pts)})};
    std::mt19937_64 rng(37);
    for (const auto& a : shapes)
        for (const auto& b : shapes) {
            const Transformd pa = random_pose(rng, 0);
            Transformd pb = random_pose(rng, 0);
            const Vec3d dir = bvhkit::normalize(Vec3d{0.3, -0.5, 0.8});
            const double step = 1e-3;
            pb.translation = dir * 4.0;
            double previous = 0;
            Vec3d previous_normal{};
            bool touched = false;
            for (int i = 0; i < 3600; ++i) {
                pb.translation -= dir * step;
                const auto r = bvhkit::convex_signed_distance(a, pa, b, pb);
                if (i > 0) {
                    EXPECT_LE(std::fabs(r.signed_distance - previous), step * (1 + 1e-6) + 1e-4)
                        << i;
                    // Near the deepest point the normal may turn fast, but never reverses.
                    if (previous > -0.3) {
                        EXPECT_GT(bvhkit::dot(r.normal, previous_normal), 0.0) << i;
                    }
                }
                touched |= r.signed_distance < 0;
                previous = r.signed_distance;
                previous_normal = r.normal;
                if (r.signed_distance < -0.3) break;
            }
            EXPECT_TRUE(touched);
        }
}

TEST(ConvexShapes, FloatAnswers) {
    using bvhkit::Transformf;
    using bvhkit::Vec3f;
    const ConvexShape<float> box(BoxShape<float>(Vec3f{1, 0.5f, 2}));
    const ConvexShape<float> ball(SphereShape<float>(0.25f));
    Transformf at;
    at.translation = {1.75f, 0.25f, 0.5f};
    const auto r = bvhkit::convex_signed_distance(box, Transformf{}, ball, at);
    EXPECT_NEAR(r.signed_distance, 0.5f, 1e-6f);
    at.translation = {0.9f, 0.1f, 0.5f};
    const auto inside = bvhkit::convex_signed_distance(box, Transformf{}, ball, at);
    EXPECT_NEAR(inside.signed_distance, -0.35f, 1e-6f);
    EXPECT_NEAR(inside.normal[0], 1.0f, 1e-6f);
    const auto d = bvhkit::convex_distance(box, Transformf{}, ball, at);
    EXPECT_TRUE(d.overlap);
}

}  // namespace convex_shapes_scale_test

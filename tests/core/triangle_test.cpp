#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "bvhkit/primitives/segment.hpp"
#include "bvhkit/primitives/triangle.hpp"
#include "random_geometry.hpp"

using namespace bvhkit;

template <class T>
class TriangleTests : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(TriangleTests, Scalars);

TYPED_TEST(TriangleTests, ThreeTestsAgreeAndHitPointsLieOnTheTriangle) {
    using T = TypeParam;
    test::Random rng(3);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const Triangle<T> tri{rng.point_in(Aabb<T, 3>({-1, -1, -1}, {1, 1, 1})),
                              rng.point_in(Aabb<T, 3>({-1, -1, -1}, {1, 1, 1})),
                              rng.point_in(Aabb<T, 3>({-1, -1, -1}, {1, 1, 1}))};
        // Aim at a random barycentric point (sometimes outside) from a random origin.
        const T a = T(rng.uniform(-0.2, 1.2)), b = T(rng.uniform(-0.2, 1.2));
        const Vec<T, 3> target = tri.p0 + (tri.p1 - tri.p0) * a + (tri.p2 - tri.p0) * b;
        const Vec<T, 3> origin = rng.point_in(Aabb<T, 3>({-3, -3, -3}, {3, 3, 3}));
        const Ray<T, 3> ray(origin, target - origin);
        const auto mt = tri.intersect(ray);
        const auto wt = tri.intersect_watertight(ray);
        TriangleHit<T> pre;
        const bool pre_hit = PrecomputedTriangle<T>(tri).intersect(ray, ray.tmax, pre);
        const bool inside = a >= 0 && b >= 0 && a + b <= 1;
        // Away from the edges all three must agree with where we aimed.
        const T margin = T(1e-3);
        const bool clear =
            std::min({a, b, T(1) - a - b}) > margin || std::min({a, b, T(1) - a - b}) < -margin;
        if (tri.area() < T(1e-2) || !clear) continue;
        ASSERT_EQ(mt.has_value(), inside) << i;
        ASSERT_EQ(wt.has_value(), inside) << i;
        ASSERT_EQ(pre_hit, inside) << i;
        if (!inside) continue;
        ++hits;
        const T tol = std::is_same_v<T, float> ? T(2e-3) : T(1e-9);
        EXPECT_NEAR(mt->t, T(1), tol);
        EXPECT_NEAR(wt->t, T(1), tol);
        EXPECT_NEAR(pre.t, T(1), tol);
        for (const auto& h : {*mt, *wt, pre}) {
            const Vec<T, 3> p = tri.p0 * (T(1) - h.u - h.v) + tri.p1 * h.u + tri.p2 * h.v;
            EXPECT_NEAR(length(p - ray.at(h.t)), T(0), tol * 10);
            EXPECT_NEAR(h.u, a, tol * 10);
            EXPECT_NEAR(h.v, b, tol * 10);
        }
    }
    EXPECT_GT(hits, 1000);
}

TYPED_TEST(TriangleTests, RespectsTminTmaxAndMissesDegenerateOnes) {
    using T = TypeParam;
    const Triangle<T> tri{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const Ray<T, 3> ray({T(0.25), T(0.25), 1}, {0, 0, -1});
    ASSERT_TRUE(tri.intersect(ray));
    Ray<T, 3> short_ray = ray;
    short_ray.tmax = T(0.5);
    EXPECT_FALSE(tri.intersect(short_ray));
    EXPECT_FALSE(tri.intersect_watertight(short_ray));
    TriangleHit<T> h;
    EXPECT_FALSE(PrecomputedTriangle<T>(tri).intersect(short_ray, short_ray.tmax, h));
    Ray<T, 3> late = ray;
    late.tmin = T(1.5);
    EXPECT_FALSE(tri.intersect(late));
    // Zero-area triangles (a point, a segment) are never hit, even when the ray passes through
    // them.
    for (const Triangle<T>& flat : {Triangle<T>{{0.25, 0.25, 0}, {0.25, 0.25, 0}, {0.25, 0.25, 0}},
                                    Triangle<T>{{0, 0.25, 0}, {1, 0.25, 0}, {0.5, 0.25, 0}}}) {
        EXPECT_FALSE(flat.intersect(ray));
        EXPECT_FALSE(flat.intersect_watertight(ray));
        EXPECT_FALSE(PrecomputedTriangle<T>(flat).intersect(ray, ray.tmax, h));
    }
    // A ray lying in the triangle's plane misses (it never crosses it).
    EXPECT_FALSE(tri.intersect(Ray<T, 3>({-1, T(0.1), 0}, {1, 0, 0})));
}

TEST(Watertight, RaysThroughASharedEdgeNeverSlipBetween) {
    // A quad split along its diagonal; rays aimed exactly at points of the diagonal must hit one of
    // the two triangles (the property Moller-Trumbore does not guarantee).
    test::Random rng(17);
    int fast_misses = 0;
    for (int i = 0; i < 100000; ++i) {
        const Vec3f a = rng.point_in(Aabb3f({-1, -1, -1}, {1, 1, 1}));
        const Vec3f c = rng.point_in(Aabb3f({-1, -1, -1}, {1, 1, 1}));
        const Vec3f b = rng.point_in(Aabb3f({-1, -1, -1}, {1, 1, 1}));
        const Vec3f d = a + c - b;  // the fourth corner of a parallelogram
        const Trianglef t1{a, b, c}, t2{a, c, d};
        const float s = float(rng.uniform(0.05, 0.95));
        const Vec3f on_edge = a + (c - a) * s;
        const Vec3f origin = rng.point_in(Aabb3f({-4, -4, -4}, {4, 4, 4}));
        const Ray3f ray(origin, on_edge - origin);
        ASSERT_TRUE(t1.intersect_watertight(ray) || t2.intersect_watertight(ray)) << i;
        fast_misses += !(t1.intersect(ray) || t2.intersect(ray));
    }
    std::printf("Moller-Trumbore slipped through a shared edge on %d of 100000 rays\n",
                fast_misses);
}

TEST(Watertight, DoubleHitsAtEveryScale) {
    // The triangle (0, 0, z), (L, 0, z), (0, L, z) and a ray from (L/4, L/4, 0) along (0, 0, m),
    // with L, z and m powers of two across double's range: t = z / m and u = v = 1/4 exactly.
    // Without the scaled path the edge functions (L^2) and t's numerator (L^2 z) leave the range.
    int tested = 0;
    for (int a = -1000; a <= 1000; a += 50)
        for (int b = -1000; b <= 1000; b += 50)
            for (int c = -1000; c <= 1000; c += 50) {
                if (std::abs(b - c) > 1000) continue;  // t itself must be a normal double
                const double L = std::ldexp(1.0, a), z = std::ldexp(1.0, b), m = std::ldexp(1.0, c);
                const Triangled tri{{0, 0, z}, {L, 0, z}, {0, L, z}};
                const Ray<double, 3> ray({L / 4, L / 4, 0}, {0, 0, m});
                const auto h = tri.intersect_watertight(ray);
                ASSERT_TRUE(h) << "L 2^" << a << " z 2^" << b << " m 2^" << c;
                ASSERT_EQ(h->t, std::ldexp(1.0, b - c)) << a << " " << b << " " << c;
                ASSERT_NEAR(h->u, 0.25, 1e-15);
                ASSERT_NEAR(h->v, 0.25, 1e-15);
                ++tested;
            }
    EXPECT_GT(tested, 40000);
}

TEST(Watertight, DoubleSharedCornerScaledAlikeByBothTriangles) {
    // A corner C near the ray (2^-801) shared by two triangles whose other corners are 2^249 and
    // 2^261 out: scaled by each triangle's own power of two, C's coordinates sank into denormals
    // differently in the two, and both missed a ray that hits T2 (its third edge function is
    // +1.4e-170 exactly). Each corner is now scaled by its own power of two.
    const Vec3d a{-0x1.97bdbe66b87e7p+248, 0x1.d5a9084a6ea9ep+249, 1};
    const Vec3d b{0x1.d5a9084a6ea9ep+249, 0x1.97bdbe66b87e7p+248, 1};
    const Vec3d c{-0x1.e2370fa70f8d5p-801, -0x1.a2959d4526a98p-802, 1};
    const Vec3d d{0x1.97bdbe66b87e7p+260, -0x1.d5a9084a6ea9ep+261, 1};
    const Triangled t1{a, b, c}, t2{c, b, d};
    const Ray<double, 3> ray({0, 0, 0}, {0, 0, 1});
    EXPECT_TRUE(t1.intersect_watertight(ray) || t2.intersect_watertight(ray));
}

TEST(Watertight, DoubleRaysThroughASharedEdgeAtEveryScale) {
    // As above in double, the quad scaled by 2^k across double's range, and one triangle's third
    // corner sometimes 2^f farther out, so that the two triangles of the shared edge take
    // different scales (or one the scaled path and the other the direct one).
    test::Random rng(29);
    for (int i = 0; i < 100000; ++i) {
        const int f = i % 3 == 0 ? int(rng.below(600)) : 0;
        const int k = int(rng.below(std::uint32_t(1900 - f))) - 950;  // 2^(k + f + 3) stays finite
        const double far = std::ldexp(1.0, f);
        const auto point = [&](double reach) {
            const Vec3d p = rng.point_in(Aabb3d({-1, -1, -1}, {1, 1, 1}));
            return Vec3d(std::ldexp(p[0] * reach, k), std::ldexp(p[1] * reach, k),
                         std::ldexp(p[2] * reach, k));
        };
        const Vec3d a = point(1), c = point(1), b0 = point(1);
        const Vec3d b = a + (b0 - a) * far;  // on b0's side of the edge a-c
        const Vec3d d = a + c - b0;          // on the other side
        const Triangled t1{a, b, c}, t2{a, c, d};
        const double s = rng.uniform(0.05, 0.95);
        const Vec3d on_edge = a + (c - a) * s;
        const Vec3d origin = point(4);
        const Ray<double, 3> ray(origin, on_edge - origin);
        ASSERT_TRUE(t1.intersect_watertight(ray) || t2.intersect_watertight(ray))
            << i << " at 2^" << k;
    }
}

TEST(Segment, RayHitsAgreeWithParametricSolve) {
    test::Random rng(9);
    int hits = 0;
    for (int i = 0; i < 10000; ++i) {
        const Segment<double> seg{{rng.uniform(-1, 1), rng.uniform(-1, 1)},
                                  {rng.uniform(-1, 1), rng.uniform(-1, 1)}};
        const double s = rng.uniform(-0.3, 1.3);
        const Vec2d target = seg.p0 + (seg.p1 - seg.p0) * s;
        const Vec2d origin{rng.uniform(-3, 3), rng.uniform(-3, 3)};
        const auto h = seg.intersect(Ray2d(origin, target - origin));
        if (std::fabs(s) < 1e-6 || std::fabs(s - 1) < 1e-6) continue;
        ASSERT_EQ(h.has_value(), s >= 0 && s <= 1) << i;
        if (h) {
            ++hits;
            EXPECT_NEAR(h->t, 1.0, 1e-9);
            EXPECT_NEAR(h->u, s, 1e-9);
        }
    }
    EXPECT_GT(hits, 3000);
}

TYPED_TEST(TriangleTests, InfiniteDirectionsMissAndSubnormalOnesGiveTheTrueT) {
    using T = TypeParam;
    constexpr T inf = std::numeric_limits<T>::infinity();
    constexpr T tiny = std::numeric_limits<T>::denorm_min();
    // A subnormal plane z0, so that a subnormal direction reaches it at a finite t.
    const T z0 = tiny * T(4096);
    const Triangle<T> far{{-1, -1, 1}, {1, -1, 1}, {0, 1, 1}};
    const Triangle<T> near{{-1, -1, z0}, {1, -1, z0}, {0, 1, z0}};
    // An infinite component is invalid: a miss, never t = 0 or t = inf.
    for (const Vec<T, 3> d : {Vec<T, 3>{0, 0, inf}, Vec<T, 3>{inf, 0, 1}, Vec<T, 3>{0, 0, -inf}}) {
        EXPECT_FALSE(far.intersect_watertight(Ray<T, 3>({0, 0, 0}, d)));
        EXPECT_FALSE(far.intersect(Ray<T, 3>({0, 0, 0}, d)));
    }
    // d = (0, 0, denorm_min): the plane z = 1 lies at t = 1 / denorm_min, beyond the largest T:
    // a miss. The plane z = z0 lies at t = 4096 exactly.
    const Ray<T, 3> slow({0, 0, 0}, {0, 0, tiny});
    EXPECT_FALSE(far.intersect_watertight(slow));
    const auto h = near.intersect_watertight(slow);
    ASSERT_TRUE(h);
    EXPECT_EQ(h->t, T(4096));
    // Tilted, on a triangle of the same subnormal size: the hit is at t = 1024, x = 1024 tiny. For
    // float the edge functions are evaluated in double and find it; in double they underflow to
    // zero (det = 0), which gives a miss: also a defined answer.
    const Triangle<T> small{{-z0, -z0, z0}, {z0, -z0, z0}, {0, z0, z0}};
    const auto tilted = small.intersect_watertight(Ray<T, 3>({0, 0, 0}, {tiny, 0, 4 * tiny}));
    if (std::is_same_v<T, float>) {
        ASSERT_TRUE(tilted);
    }
    if (tilted) {
        EXPECT_EQ(tilted->t, T(1024));
    }
}

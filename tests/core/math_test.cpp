#include <gtest/gtest.h>

#include "bvhkit/math/ray.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;

TEST(Aabb, EmptyBoxHasNoMeasureAndGrowsToWhatItIsGiven) {
    Aabb3f b;
    EXPECT_TRUE(b.is_empty());
    EXPECT_EQ(b.area(), 0.0f);
    EXPECT_EQ(b.extent(), Vec3f(0.0f));
    b.grow(Vec3f(1, 2, 3));
    EXPECT_FALSE(b.is_empty());
    EXPECT_EQ(b.min, Vec3f(1, 2, 3));
    EXPECT_EQ(b.max, Vec3f(1, 2, 3));
    EXPECT_EQ(b.area(), 0.0f);
}

TEST(Aabb, AreaIsSurfaceIn3dAndPerimeterIn2d) {
    EXPECT_DOUBLE_EQ(Aabb3d({0, 0, 0}, {1, 2, 3}).area(), 2.0 * (2 + 6 + 3));
    EXPECT_DOUBLE_EQ(Aabb2d({0, 0}, {1, 2}).area(), 6.0);
    EXPECT_DOUBLE_EQ(Aabb3d({-1, -1, -1}, {1, 1, 1}).area(), 24.0);
}

TEST(Aabb, UnionCentroidExtentAxis) {
    const Aabb3f a({0, 0, 0}, {1, 1, 1}), b({2, -1, 0}, {3, 0, 5});
    const Aabb3f u = unite(a, b);
    EXPECT_EQ(u.min, Vec3f(0, -1, 0));
    EXPECT_EQ(u.max, Vec3f(3, 1, 5));
    EXPECT_EQ(u.centroid(), Vec3f(1.5f, 0, 2.5f));
    EXPECT_EQ(u.extent(), Vec3f(3, 2, 5));
    EXPECT_EQ(u.largest_axis(), 2u);
    EXPECT_TRUE(u.contains(a));
    EXPECT_TRUE(u.contains(b));
    EXPECT_FALSE(a.contains(u));
    EXPECT_TRUE(intersect(a, b).is_empty());
}

TEST(Aabb, OverlapIsClosedAndContainmentOfPoints) {
    const Aabb2f a({0, 0}, {1, 1});
    EXPECT_TRUE(a.overlaps(Aabb2f({1, 1}, {2, 2})));  // touching corners overlap
    EXPECT_FALSE(a.overlaps(Aabb2f({1.0001f, 0}, {2, 1})));
    EXPECT_TRUE(a.contains(Vec2f(1, 0)));
    EXPECT_FALSE(a.contains(Vec2f(1, 1.5f)));
    EXPECT_FALSE(a.contains(Vec2f(std::nanf(""), 0.5f)));
}

TEST(Aabb, SquaredDistanceMatchesClosestPointByHand) {
    const Aabb3d box({0, 0, 0}, {1, 2, 3});
    test::Random rng(5);
    for (int i = 0; i < 1000; ++i) {
        const Vec3d p = rng.point_in(Aabb3d({-3, -3, -3}, {5, 5, 5}));
        Vec3d q;  // clamp by hand
        for (int k = 0; k < 3; ++k) q[k] = std::clamp(p[k], box.min[k], box.max[k]);
        EXPECT_NEAR(box.distance_squared(p), length_squared(p - q), 1e-12);
    }
}

// Reference slab test in long double with the zero-direction cases spelled out: along an axis the
// ray does not move, it is inside the closed slab for all t or for none.
template <class T>
bool reference_ray_box(const Ray<T, 3>& r, const Aabb<T, 3>& b) {
    long double lo = r.tmin, hi = r.tmax;
    for (int k = 0; k < 3; ++k) {
        const long double o = r.origin[k], d = r.direction[k];
        if (d == 0) {
            if (o < b.min[k] || o > b.max[k]) return false;
            continue;
        }
        long double t0 = (b.min[k] - o) / d, t1 = (b.max[k] - o) / d;
        if (t0 > t1) std::swap(t0, t1);
        lo = std::max(lo, t0);
        hi = std::min(hi, t1);
    }
    return lo <= hi;
}

TEST(RaySlab, ZeroDirectionComponentsOfBothSignsOnAndOffTheBoxPlanes) {
    const Aabb3f box({-1, 0, 2}, {1, 3, 4});
    const float coords[] = {-2, -1, 0, 0.5f, 1, 2, 3, 4, 5};
    const float dirs[] = {-1.0f, -0.0f, 0.0f, 1.0f, 0.5f};
    int checked = 0, hits = 0;
    for (float ox : coords)
        for (float oy : coords)
            for (float oz : coords)
                for (float dx : dirs)
                    for (float dy : dirs)
                        for (float dz : dirs) {
                            if (dx == 0 && dy == 0 && dz == 0) continue;
                            const Ray3f ray({ox, oy, oz}, {dx, dy, dz}, 0.0f, 100.0f);
                            float t0, t1;
                            const bool got = intersect(ray, box, t0, t1);
                            const bool want = reference_ray_box(ray, box);
                            ASSERT_EQ(got, want) << "origin " << ox << "," << oy << "," << oz
                                                 << " dir " << dx << "," << dy << "," << dz;
                            if (got) {
                                ASSERT_FALSE(std::isnan(t0) || std::isnan(t1));
                                ++hits;
                            }
                            ++checked;
                        }
    EXPECT_GT(hits, checked / 20);  // the grid must exercise both answers
}

TEST(RaySlab, ConservativeForRaysThroughBoxCorners) {
    // Rays aimed exactly at box corners and edge points must not miss through rounding.
    test::Random rng(11);
    for (int i = 0; i < 20000; ++i) {
        const Aabb3f box(rng.point_in(Aabb3f({-10, -10, -10}, {0, 0, 0})),
                         rng.point_in(Aabb3f({0, 0, 0}, {10, 10, 10})));
        Vec3f target{box.min[0], box.max[1], rng.uniform() < 0.5 ? box.min[2] : box.max[2]};
        const Vec3f origin = rng.point_in(Aabb3f({-50, -50, -50}, {50, 50, 50}));
        const Ray3f ray(origin, target - origin, 0.0f, 2.0f);
        float t0, t1;
        ASSERT_TRUE(intersect(ray, box, t0, t1)) << i;
    }
}

#include "bvhkit/query/ray_pair_test.hpp"

TEST(RayPairTest, MatchesTheScalarSlabTestIncludingZeroDirectionsOnPlanes) {
    // Boxes with faces on the grid, rays from grid points with +-0 components: the plane cases.
    BvhNode<Aabb3f> pair[2];
    pair[0].bounds = Aabb3f({-1, 0, 2}, {1, 3, 4});
    pair[1].bounds = Aabb3f({0, -1, 0}, {2, 2, 3});
    pair[0].first = 0x7F800000u;  // bits of +inf in the padding lanes must not matter
    pair[1].first = 0x7FC00000u;  // nor those of a NaN
    const float coords[] = {-2, -1, 0, 0.5f, 1, 2, 3, 4};
    const float dirs[] = {-1.0f, -0.0f, 0.0f, 1.0f, 0.25f};
    int both = 0;
    for (float ox : coords)
        for (float oy : coords)
            for (float oz : coords)
                for (float dx : dirs)
                    for (float dy : dirs)
                        for (float dz : dirs) {
                            if (dx == 0 && dy == 0 && dz == 0) continue;
                            const Ray3f ray({ox, oy, oz}, {dx, dy, dz}, 0.5f, 50.0f);
                            const RaySlabData<float, 3> slab(ray);
                            float entry[2];
                            const unsigned got = slab.with_octant([&](auto o) {
                                const RayPairTest<float, 3> test(slab, o);
                                return test.template test<decltype(o)::value>(
                                    pair, test.interval(ray.tmin, ray.tmax), entry);
                            });
                            for (int k = 0; k < 2; ++k) {
                                float t0, t1;
                                const bool want = intersect(ray, pair[k].bounds, t0, t1);
                                ASSERT_EQ(bool(got >> k & 1u), want)
                                    << "box " << k << " origin " << ox << "," << oy << "," << oz
                                    << " dir " << dx << "," << dy << "," << dz;
                                if (want) {
                                    ASSERT_EQ(entry[k], t0);
                                }
                            }
                            both += got == 3u;
                        }
    EXPECT_GT(both, 100);
}

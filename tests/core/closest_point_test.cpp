#include <gtest/gtest.h>

#include "bvhkit/primitives/closest_point.hpp"
#include "random_geometry.hpp"

using namespace bvhkit;

// Reference: minimize the distance over a fine barycentric grid, then compare distances (the grid
// bounds the reference's error), and check the returned point lies on the triangle.
TEST(ClosestPoint, MatchesADenseSearchAndLiesOnTheTriangle) {
    test::Random rng(1);
    for (int i = 0; i < 300; ++i) {
        Triangle<double> tri{rng.point_in(Aabb3d({-1, -1, -1}, {1, 1, 1})),
                             rng.point_in(Aabb3d({-1, -1, -1}, {1, 1, 1})),
                             rng.point_in(Aabb3d({-1, -1, -1}, {1, 1, 1}))};
        if (i % 10 == 0) tri.p2 = tri.p0 + (tri.p1 - tri.p0) * 0.5;  // degenerate: a segment
        if (i % 25 == 0) tri.p1 = tri.p2 = tri.p0;                   // degenerate: a point
        const Vec3d p = rng.point_in(Aabb3d({-2, -2, -2}, {2, 2, 2}));
        const ClosestPoint<double> c = closest_point(tri, p);
        EXPECT_GE(c.u, -1e-12);
        EXPECT_GE(c.v, -1e-12);
        EXPECT_LE(c.u + c.v, 1 + 1e-12);
        const Vec3d from_uv = tri.p0 * (1 - c.u - c.v) + tri.p1 * c.u + tri.p2 * c.v;
        EXPECT_NEAR(length(from_uv - c.point), 0.0, 1e-9);
        double best = std::numeric_limits<double>::infinity();
        const int n = 300;
        for (int a = 0; a <= n; ++a)
            for (int b = 0; a + b <= n; ++b) {
                const Vec3d q = tri.p0 * (double(n - a - b) / n) + tri.p1 * (double(a) / n) +
                                tri.p2 * (double(b) / n);
                best = std::min(best, length(q - p));
            }
        const double got = length(c.point - p);
        EXPECT_LE(got, best + 1e-12);  // never worse than any grid point
        EXPECT_GE(got, best - 0.02);   // and within the grid's resolution of the optimum
    }
}

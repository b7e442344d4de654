// Closest point and signed distance (pseudonormal sign) on a sphere scaled by 10^k across the
// type's range (float 1e-30..1e30, double 1e-300..1e300), at the origin and moved 1e3 (float) or
// 1e6 (double) times its size from it, for points inside, near and up to 1e6 sizes away. The
// reference is exact rational arithmetic (tests/support/exact_point_triangle.hpp) over every
// triangle, and the sign is the analytic one: the mesh lies between its inradius and radius 1.
//
// What must hold (docs/accuracy.md): a closest triangle whose exact distance is within
// B = 128 eps_W (d + E + L) of the exact least (E the mesh's diagonal, L its longest edge), a
// distance within 2 eps_T d + 96 eps_W (d + L) + B of it, finite and non-zero; a point on that
// triangle (within the rounding of its coordinates and B) at that distance; the right sign.
#include <gtest/gtest.h>

#include <cmath>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/signed_distance.hpp"
#include "exact_point_triangle.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

using LD = long double;

template <class T>
void check_scale(const TriangleMesh& unit, double scale, double offset, std::size_t points,
                 std::uint64_t seed) {
    BasicTriangleMesh<T> mesh;
    mesh.triangles = unit.triangles;
    for (const auto& v : unit.vertices) {
        Vec<T, 3> w;
        for (int k = 0; k < 3; ++k) w[k] = T(double(v[k]) * scale + offset);
        mesh.vertices.push_back(w);
    }
    std::vector<Triangle<T>> tris;
    for (const auto& t : mesh.triangles)
        tris.push_back({mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]});
    const SignedDistanceMesh<T> sdf(mesh);
    const LD eps_t = std::numeric_limits<T>::epsilon();
    const LD eps_w = std::numeric_limits<AccurateScalar<T>>::epsilon();
    LD longest = 0;
    for (const auto& t : tris)
        for (const auto& [a, b] : {std::pair{t.p0, t.p1}, {t.p1, t.p2}, {t.p2, t.p0}}) {
            LD e2 = 0;
            for (int k = 0; k < 3; ++k) e2 += (LD(a[k]) - LD(b[k])) * (LD(a[k]) - LD(b[k]));
            longest = std::max(longest, std::sqrt(e2));
        }
    const LD diagonal = 2 * std::sqrt(LD(3)) * LD(scale);
    // Inside below the inradius of the 80-triangle sphere (above 0.79), outside above 1.
    const double radii[] = {0.3, 0.7, 1.05, 1.5, 3, 30, 1e3, 1e6};
    test::Random rng(seed);
    for (std::size_t i = 0; i < points; ++i) {
        const double r = radii[i % std::size(radii)];
        const Vec<double, 3> u = rng.unit_vector<double>();
        Vec<T, 3> p;
        for (int k = 0; k < 3; ++k) p[k] = T(u[k] * r * scale + offset);
        SCOPED_TRACE("point " + std::to_string(i) + " radius " + std::to_string(r));
        LD best = std::numeric_limits<LD>::infinity();
        std::vector<LD> exact(tris.size());
        for (std::size_t f = 0; f < tris.size(); ++f)
            best = std::min(best, exact[f] = std::sqrt(
                                      test::pt_exact::exact_distance_squared(tris[f], p).value()));
        const SignedDistance<T> got = sdf.signed_distance(p);
        ASSERT_TRUE(got.closest);
        const LD bound = 128 * eps_w * (best + diagonal + longest);
        EXPECT_LE(exact[got.closest.triangle], best + bound) << "not the closest triangle";
        const LD tol = 2 * eps_t * best + 96 * eps_w * (best + longest) + bound;
        ASSERT_TRUE(std::isfinite(got.distance));
        EXPECT_GT(std::fabs(got.distance), T(0));
        EXPECT_NEAR(std::fabs(LD(got.distance)), best, tol);
        EXPECT_NEAR(LD(got.closest.distance), best, tol);
        EXPECT_EQ(got.distance < 0, r < 1) << "wrong sign";
        // The point: on the triangle within its coordinates' rounding, at the distance.
        const Vec<T, 3>& x = got.closest.point;
        LD xmax = 0, dx = 0;
        for (int k = 0; k < 3; ++k) {
            xmax = std::max(xmax, std::fabs(LD(x[k])));
            dx += (LD(x[k]) - LD(p[k])) * (LD(x[k]) - LD(p[k]));
        }
        const LD off = std::sqrt(
            test::pt_exact::exact_distance_squared(tris[got.closest.triangle], x).value());
        EXPECT_LE(off, 4 * eps_t * xmax + 2 * bound) << "the point is off its triangle";
        EXPECT_NEAR(std::sqrt(dx), best, tol + 4 * eps_t * xmax);
    }
}

template <class T>
void across_the_range(int lowest, int highest, int step, double offset_sizes) {
    const TriangleMesh unit = make_sphere(1);  // 80 triangles
    const std::size_t points = test::scaled(16, 4);
    std::uint64_t seed = 1;
    test::for_each_scale(lowest, highest, step, offset_sizes, [&](double scale, double offset) {
        check_scale<T>(unit, scale, offset, points, seed++);
    });
}

TEST(ExtremeScale, FloatClosestPointAndSign) {
    across_the_range<float>(-30, 30, 5, 1e3);
}
TEST(ExtremeScale, DoubleClosestPointAndSign) {
    across_the_range<double>(-300, 300, 50, 1e6);
}

}  // namespace
}  // namespace bvhkit

// Closest point and signed distance for points far from the mesh and for meshes at the ends of
// the type's range (issue 38, defects 1 and 9).
//
// The reference for a far point p, |p| = D, on a mesh within radius R of the origin: for every x
// of the mesh |p - x| = D - p^.x + e with 0 <= e <= R^2 / (D - R) (p^ = p / D), so a triangle's
// distance is D - h_f + e_f, h_f its largest p^.x, reached at a corner. The closest triangle's
// h_f is the largest h within R^2 / (D - R); computed in long double from p and the corners, each
// h is within a few ulps (of long double) of R. This is an analytic answer: it shares nothing with
// the library's measure.
#include <gtest/gtest.h>

#include <cmath>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/signed_distance.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

using LD = long double;

template <class T>
BasicTriangleMesh<T> scaled_sphere(std::uint32_t subdivisions, double scale) {
    const TriangleMesh s = make_sphere(subdivisions);
    BasicTriangleMesh<T> m;
    m.triangles = s.triangles;
    for (const auto& v : s.vertices)
        m.vertices.push_back(
            {T(double(v[0]) * scale), T(double(v[1]) * scale), T(double(v[2]) * scale)});
    return m;
}

/// Checks the answer for a point far from a mesh around the origin (see the file's comment).
template <class T>
void check_far_point(const BasicTriangleMesh<T>& mesh, const SignedDistanceMesh<T>& sdf,
                     const Vec<T, 3>& p) {
    LD D = 0, R = 0;
    for (int k = 0; k < 3; ++k) D += LD(p[k]) * LD(p[k]);
    D = std::sqrt(D);
    for (const auto& v : mesh.vertices)
        R = std::max(R, std::sqrt(LD(v[0]) * LD(v[0]) + LD(v[1]) * LD(v[1]) + LD(v[2]) * LD(v[2])));
    ASSERT_GT(D, 4 * R);
    const auto support = [&](std::uint32_t f) {
        LD h = -std::numeric_limits<LD>::infinity();
        for (int c = 0; c < 3; ++c) {
            const auto& v = mesh.vertices[mesh.triangles[f][c]];
            h = std::max(h, (LD(p[0]) * LD(v[0]) + LD(p[1]) * LD(v[1]) + LD(p[2]) * LD(v[2])) / D);
        }
        return h;
    };
    LD best = -std::numeric_limits<LD>::infinity();
    for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f) best = std::max(best, support(f));
    const LD tol = R * R / (D - R) + 64 * std::numeric_limits<LD>::epsilon() * R;
    const SignedDistance<T> got = sdf.signed_distance(p);
    ASSERT_TRUE(got.closest);
    EXPECT_GE(support(got.closest.triangle), best - tol) << "not the closest triangle";
    // The distance: D - best within the reference's e and T's rounding (the answer is in T).
    const LD want = D - best;
    EXPECT_TRUE(std::isfinite(got.distance));
    EXPECT_GT(got.distance, T(0)) << "a far point is outside";
    EXPECT_NEAR(LD(got.distance), want, 4 * LD(std::numeric_limits<T>::epsilon()) * want + 2 * tol);
    EXPECT_NEAR(LD(got.closest.distance), want,
                4 * LD(std::numeric_limits<T>::epsilon()) * want + 2 * tol);
}

template <class T>
void far_points_on_the_sphere(std::initializer_list<double> distances) {
    const BasicTriangleMesh<T> mesh = scaled_sphere<T>(3, 1.0);
    const SignedDistanceMesh<T> sdf(mesh);
    test::Random rng(38);
    for (const double d : distances) {
        SCOPED_TRACE("distance " + std::to_string(d));
        std::vector<Vec<double, 3>> dirs = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                            {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
        for (int i = 0; i < 20; ++i) dirs.push_back(rng.unit_vector<double>());
        for (const auto& u : dirs) {
            SCOPED_TRACE("direction " + std::to_string(u[0]) + " " + std::to_string(u[1]) + " " +
                         std::to_string(u[2]));
            check_far_point(mesh, sdf, Vec<T, 3>(u * d));
        }
    }
}

// Defect 1: (1e16, 0, 0) from a float unit sphere got the far side and "inside"; double from
// about 1e18.
TEST(FarPoints, FloatSphereFromAfar) {
    far_points_on_the_sphere<float>({1e4, 1e8, 1e12, 1e16, 1e20, 1e25, 1e30, 1e35, 3e38});
}
TEST(FarPoints, DoubleSphereFromAfar) {
    far_points_on_the_sphere<double>({1e8, 1e16, 1e18, 1e25, 1e50, 1e100, 1e200, 1e300, 1e307});
}

// Defect 9: a float mesh 1e-25 across had distance 0 everywhere (the squared distance sank below
// float's least denormal), and a point 1e30 away distance inf. The reference is analytic: from
// the centre of a sphere of circumradius s the distance lies between the inradius (above 0.79 s
// for the 80-triangle sphere) and s; from p, |p| - s to |p| - 0.79 s.
TEST(FarPoints, DistancesWhoseSquaresLeaveFloatsRange) {
    for (const double s : {1e-25, 1e-30, 1e-35}) {
        const SignedDistanceMesh<float> sdf(scaled_sphere<float>(1, s));
        const SignedDistance<float> in = sdf.signed_distance({0.0f, 0.0f, 0.0f});
        EXPECT_LT(in.distance, -0.79 * s);
        EXPECT_GT(in.distance, -1.0001 * s);
        EXPECT_GT(in.closest.distance, 0.79 * s);
        const SignedDistance<float> out = sdf.signed_distance({0.0f, float(3 * s), 0.0f});
        EXPECT_GT(out.distance, 1.9999 * s);
        EXPECT_LT(out.distance, 2.21 * s);
    }
    const SignedDistanceMesh<float> unit(scaled_sphere<float>(1, 1.0));
    for (const float d : {1e20f, 1e30f, 3e38f}) {
        const SignedDistance<float> far = unit.signed_distance({0.0f, 0.0f, -d});
        ASSERT_TRUE(far.closest);
        EXPECT_EQ(far.distance, d);  // d - 1 rounds to d
        EXPECT_EQ(far.closest.distance, d);
    }
}

}  // namespace
}  // namespace bvhkit

// The winding number (exact and fast), contains (inside()) and the winding-number sign of the
// signed distance on closed meshes scaled by 10^k across float's range (1e-30 to 1e30) and
// double's (1e-300 to 1e300), moved off the origin. The references share none of the code's
// arithmetic: the sphere's inside is analytic (nearer the centre than every face's plane, or
// farther than its vertices), and spot's winding number is summed in long double on the unscaled
// mesh, on normalized directions.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/query/signed_distance.hpp"
#include "bvhkit/query/winding_number.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

using LVec = Vec<long double, 3>;

/// A point of the unit frame (the mesh as loaded) and whether it is inside.
struct Probe {
    LVec p;
    bool inside;
};

/// The solid angle in long double on normalized directions (Van Oosterom and Strackee 1983).
long double reference_solid_angle(const LVec& a, const LVec& b, const LVec& c, const LVec& q) {
    LVec u[3] = {a - q, b - q, c - q};
    for (LVec& v : u) v = v / std::sqrt(length_squared(v));
    const long double num = dot(u[0], cross(u[1], u[2]));
    const long double den = 1 + dot(u[0], u[1]) + dot(u[1], u[2]) + dot(u[2], u[0]);
    return 2 * std::atan2(num, den);
}

long double reference_winding(const TriangleMesh& mesh, const LVec& q) {
    long double sum = 0;
    for (const auto& t : mesh.triangles)
        sum += reference_solid_angle(LVec(mesh.vertices[t[0]]), LVec(mesh.vertices[t[1]]),
                                     LVec(mesh.vertices[t[2]]), q);
    return sum / (4 * std::numbers::pi_v<long double>);
}

/// The mesh's vertices as T at (v + offset) * scale, rounded once from long double.
template <class T>
std::vector<T> placed(const TriangleMesh& mesh, long double scale, const LVec& offset) {
    std::vector<T> xyz;
    for (const Vec3f& v : mesh.vertices)
        for (int a = 0; a < 3; ++a) xyz.push_back(T((v[a] + offset[a]) * scale));
    return xyz;
}

/// Every query on `mesh` placed at scale 10^k for each k in `exponents`, against the probes.
template <class T>
void check_scales(const TriangleMesh& mesh, const std::vector<Probe>& probes,
                  const std::vector<int>& exponents, const LVec& offset, double fast_bound) {
    std::vector<std::uint32_t> ids;
    for (const auto& t : mesh.triangles) ids.insert(ids.end(), t.begin(), t.end());
    for (const int k : exponents) {
        const long double scale = std::pow(10.0L, k);
        const std::vector<T> xyz = placed<T>(mesh, scale, offset);
        const TriangleMeshView<T, std::uint32_t> view(xyz.data(), mesh.vertices.size(), ids.data(),
                                                      mesh.triangles.size());
        const WindingNumberMesh<T> wn(view);
        const SignedDistanceMesh<T> sdf(view);
        for (std::size_t i = 0; i < probes.size(); ++i) {
            const Probe& pr = probes[i];
            Vec<T, 3> q;
            for (int a = 0; a < 3; ++a) q[a] = T((pr.p[a] + offset[a]) * scale);
            const double want = pr.inside ? 1.0 : 0.0;
            const double exact = double(wn.exact(q)), fast = double(wn.fast(q));
            ASSERT_TRUE(std::isfinite(exact) && std::isfinite(fast))
                << "1e" << k << " point " << i << ": exact " << exact << " fast " << fast;
            ASSERT_NEAR(exact, want, 1e-4) << "1e" << k << " point " << i;
            ASSERT_NEAR(fast, want, fast_bound) << "1e" << k << " point " << i;
            ASSERT_EQ(wn.inside(q), pr.inside) << "1e" << k << " point " << i;
            // The signed distance with the winding-number sign, as the Python binding forms it
            // (with the exact winding number too); signbit, since the distance may be 0 or inf
            // where it underflows or overflows.
            const MeshPoint<T> c = sdf.closest_point_mesh().closest_point(q);
            ASSERT_TRUE(bool(c)) << "1e" << k << " point " << i;
            const T d = std::sqrt(c.distance_squared);
            ASSERT_FALSE(std::isnan(d)) << "1e" << k << " point " << i;
            const T by_fast = wn.inside(q) ? -d : d, by_exact = wn.exact(q) > T(0.5) ? -d : d;
            ASSERT_EQ(std::signbit(by_fast), pr.inside) << "1e" << k << " point " << i;
            ASSERT_EQ(std::signbit(by_exact), pr.inside) << "1e" << k << " point " << i;
        }
    }
}

std::vector<int> exponents(int lo, int hi, int step) {
    std::vector<int> ks;
    for (int k = lo; k <= hi; k += step) ks.push_back(k);
    return ks;
}

/// Points at known radii about the sphere's centre: inside below every face's plane, outside
/// beyond the unit sphere that holds every vertex.
std::vector<Probe> sphere_probes(const TriangleMesh& sphere, std::size_t per_radius) {
    long double plane = 1;  // the nearest face plane's distance from the centre
    for (const auto& t : sphere.triangles) {
        const LVec a(sphere.vertices[t[0]]), b(sphere.vertices[t[1]]), c(sphere.vertices[t[2]]);
        const LVec n = cross(b - a, c - a);
        plane = std::min(plane, std::fabs(dot(n, a)) / std::sqrt(length_squared(n)));
    }
    EXPECT_GT(plane, 0.95L);
    std::vector<Probe> probes{{LVec(0.0L), true}};
    test::Random rng(38);
    for (const long double r : {0.3L, 0.6L, 0.9L * plane, 1.05L, 1.5L, 3.0L, 100.0L, 1e4L})
        for (std::size_t i = 0; i < per_radius; ++i)
            probes.push_back({LVec(rng.unit_vector<double>()) * r, r < 1});
    return probes;
}

TEST(WindingScale, SphereFloat) {
    const TriangleMesh sphere = make_sphere(3);
    const auto probes = sphere_probes(sphere, test::scaled(12, 4));
    const auto ks = test::small_scale() ? exponents(-30, 30, 15) : exponents(-30, 30, 3);
    check_scales<float>(sphere, probes, ks, LVec(2.5L, -1.5L, 4.0L), 0.01);
    check_scales<float>(sphere, probes, exponents(-30, 30, 30), LVec(300.0L, -200.0L, 500.0L),
                        0.01);
}

TEST(WindingScale, SphereDouble) {
    const TriangleMesh sphere = make_sphere(3);
    const auto probes = sphere_probes(sphere, test::scaled(12, 4));
    const auto ks = test::small_scale() ? exponents(-300, 300, 150) : exponents(-300, 300, 25);
    check_scales<double>(sphere, probes, ks, LVec(2.5L, -1.5L, 4.0L), 0.01);
    check_scales<double>(sphere, probes, exponents(-300, 300, 300), LVec(300.0L, -200.0L, 500.0L),
                         0.01);
}

/// Points about spot's surface (a random vertex moved by 1% to 6% of the diagonal in a random
/// direction), kept where they are at least 1% of the diagonal from the surface, with the
/// long-double winding number rounded (a closed mesh: 0 or 1).
std::vector<Probe> spot_probes(const TriangleMesh& mesh, std::size_t count) {
    const double diag = length(Vec3d(mesh.bounds().extent()));
    std::vector<Probe> probes;
    test::Random rng(3838);
    while (probes.size() < count) {
        const Vec3f v = mesh.vertices[rng.below(std::uint32_t(mesh.vertices.size()))];
        const Vec3d q = Vec3d(v) + rng.unit_vector<double>() * (diag * rng.uniform(0.01, 0.06));
        double d2 = std::numeric_limits<double>::infinity();
        for (const auto& t : mesh.triangles) {
            const Triangled tri{Vec3d(mesh.vertices[t[0]]), Vec3d(mesh.vertices[t[1]]),
                                Vec3d(mesh.vertices[t[2]])};
            d2 = std::min(d2, length_squared(closest_point(tri, q).point - q));
        }
        if (d2 < (0.01 * diag) * (0.01 * diag)) continue;
        const long double w = reference_winding(mesh, LVec(q));
        EXPECT_LT(std::fabs(w - std::round(w)), 1e-6L);
        probes.push_back({LVec(q), w > 0.5L});
    }
    return probes;
}

TEST(WindingScale, SpotFloatAndDouble) {
    BVHKIT_REQUIRE_MESH(path, "spot.obj");
    const TriangleMesh mesh = read_mesh(path);
    const auto probes = spot_probes(mesh, test::scaled(40, 4));
    std::size_t inside = 0;
    for (const Probe& p : probes) inside += p.inside;
    EXPECT_GT(inside, probes.size() / 10);
    EXPECT_LT(inside, probes.size() - probes.size() / 10);
    const LVec offset(-3.0L, 2.0L, 1.5L);
    check_scales<float>(mesh, probes, exponents(-30, 30, test::small_scale() ? 30 : 10), offset,
                        0.01);
    check_scales<double>(mesh, probes, exponents(-300, 300, test::small_scale() ? 300 : 100),
                         offset, 0.01);
}

// The case of the report: a float sphere at 1e10 gave -inf or NaN and half its contains wrong.
TEST(WindingScale, FloatSphereAt1e10) {
    const TriangleMesh sphere = make_sphere(3);
    std::vector<float> xyz = placed<float>(sphere, 1e10L, LVec(0.0L));
    std::vector<std::uint32_t> ids;
    for (const auto& t : sphere.triangles) ids.insert(ids.end(), t.begin(), t.end());
    const WindingNumberMesh<float> wn(TriangleMeshView<float, std::uint32_t>(
        xyz.data(), sphere.vertices.size(), ids.data(), sphere.triangles.size()));
    EXPECT_NEAR(wn.fast(Vec3f(0.0f)), 1.0f, 1e-2f);
    EXPECT_NEAR(wn.fast(Vec3f(2e10f, 0.0f, 0.0f)), 0.0f, 1e-2f);
    EXPECT_NEAR(wn.exact(Vec3f(0.0f)), 1.0f, 1e-4f);
    EXPECT_TRUE(wn.inside(Vec3f(5e9f, 0.0f, 0.0f)));
    EXPECT_FALSE(wn.inside(Vec3f(0.0f, -1.5e10f, 0.0f)));
}

// A non-finite point is inside nothing and has no winding number.
TEST(WindingScale, NonFinitePoint) {
    const WindingNumberMesh<float> wn(make_sphere(2));
    for (const float x :
         {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        EXPECT_TRUE(std::isnan(wn.fast(Vec3f(x, 0.0f, 0.0f))));
        EXPECT_TRUE(std::isnan(wn.exact(Vec3f(0.0f, x, 0.0f))));
        EXPECT_FALSE(wn.inside(Vec3f(0.0f, 0.0f, x)));
    }
}

}  // namespace
}  // namespace bvhkit

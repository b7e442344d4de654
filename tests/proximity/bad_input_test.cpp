// Extreme and invalid arguments of the proximity queries: a point too far for float squares, a
// negative radius, a winding-number beta out of range.
#include <gtest/gtest.h>

#include <string>

#include "bvhkit/error.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "bvhkit/query/winding_number.hpp"

namespace bvhkit {
namespace {

// A point 2e19 from a float mesh: its squared distance is past float's range, yet the mesh has a
// closest triangle (k_nearest found it; closest_point answered "none", the empty mesh's answer).
TEST(ProximityBadInput, FarPointStillHasAClosestTriangle) {
    const TriangleMesh sphere = make_sphere(2);
    const ClosestPointMesh<float> mesh(sphere);
    const ClosestPointMesh<double> meshd(sphere);
    for (const Vec3f p :
         {Vec3f(2e19f, 0.0f, 0.0f), Vec3f(-3e30f, 1e30f, 5e29f), Vec3f(0.0f, 0.0f, 3.4e38f)}) {
        const MeshPoint<float> got = mesh.closest_point(p);
        ASSERT_TRUE(got) << p[0];
        std::vector<MeshPoint<float>> knn;
        NearestScratch<float> scratch;
        mesh.k_nearest(p, 1, knn, scratch);
        ASSERT_EQ(knn.size(), 1u);
        // The same triangle, or one at the same distance, to double's precision: the squared
        // distances of the triangles (~d^2) round by an ulp or two of it, and the closest is
        // ranked without that rounding (ClosestPointMesh::far_key), so the one found may measure
        // a few ulps above the least here.
        const Vec3d pd(p);
        const double d_got =
            double(distance_squared_accurate(triangle_at<float>(sphere, got.triangle), p));
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < sphere.triangles.size(); ++i)
            best =
                std::min(best, double(distance_squared_accurate(triangle_at<float>(sphere, i), p)));
        EXPECT_LE(d_got, best * (1 + 0x1p-49));
        // The point itself is finite and on the sphere.
        EXPECT_TRUE(is_finite(got.point));
        EXPECT_LT(length(Vec3d(got.point)), 1.01);
        // In double, the squares fit: the distance is finite.
        const MeshPoint<double> gd = meshd.closest_point(pd);
        ASSERT_TRUE(gd);
        EXPECT_NEAR(std::sqrt(gd.distance_squared), length(pd), 1.01);
    }
    // Beyond double's squares too.
    const MeshPoint<double> huge = meshd.closest_point(Vec3d(1e200, -1e200, 0.0));
    ASSERT_TRUE(huge);
}

// A negative (or NaN) radius holds nothing: no triangle (it gave those within |radius|).
TEST(ProximityBadInput, NegativeRadiusFindsNothing) {
    const ClosestPointMesh<float> mesh(make_sphere(2));
    std::vector<MeshPoint<float>> out;
    mesh.within_radius(Vec3f(0.0f), 2.0f, out);
    EXPECT_EQ(out.size(), mesh.triangle_count());  // the premise: +2 holds every triangle
    for (float r : {-1.0f, -2.0f, -0.0f, std::numeric_limits<float>::quiet_NaN(),
                    -std::numeric_limits<float>::infinity()}) {
        mesh.within_radius(Vec3f(0.0f), r, out);
        EXPECT_TRUE(out.empty()) << r;
    }
}

// beta is the ratio of distance to node radius beyond which a node counts as its expansion: at or
// below 1 the point may be inside the node's ball, where the series does not converge (beta <= 0
// gave -1.4e10).
TEST(ProximityBadInput, WindingNumberBetaOutOfRange) {
    const WindingNumberMesh<float> wn(make_sphere(2));
    for (float beta : {0.0f, -1.0f, 0.5f, std::numeric_limits<float>::quiet_NaN()}) {
        try {
            (void)wn.fast(Vec3f(0.1f), beta);
            ADD_FAILURE() << "no error for beta " << beta;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("beta"), std::string::npos) << e.what();
        }
        std::vector<Vec3f> points(3, Vec3f(0.1f));
        std::vector<float> out(3);
        EXPECT_THROW(wn.fast(points, out, beta), Error);
    }
    EXPECT_NEAR(wn.fast(Vec3f(0.1f), 1.0f), 1.0f, 0.5f);  // allowed, if crude
    EXPECT_NEAR(wn.fast(Vec3f(0.1f), std::numeric_limits<float>::infinity()), 1.0f, 1e-4f);
}

}  // namespace
}  // namespace bvhkit

// closest_point through the wide tree and the triangle packs (query/nearest_wide.hpp,
// primitives/triangle_pack.hpp) against brute force: far from the origin, slivers, extreme scales,
// double, stats, packs that do not scale back exactly, radii equal to the distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "closest_point_reference.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

TEST(NearestWide, FarFromTheOriginEqualsBruteForce) {
    // The unit sphere moved by 1e4 on every axis: in float its corners are rounded to ~1e-3, so
    // the triangles are skewed and some degenerate, and every pack and box sits at 1e4.
    const TriangleMesh sphere = make_sphere(test::small_scale() ? 2 : 4);
    test::check_against_brute_force(test::moved<float>(sphere, 1e4f), test::scaled(300, 10), 31);
    test::check_against_brute_force(test::moved<double>(sphere, 1e4), test::scaled(300, 10), 32);
    // Also at -1e4 and scaled up to radius 100 (no rounding to speak of, still far out).
    test::check_against_brute_force(test::moved<float>(sphere, -1e4f, 100.0f),
                                    test::scaled(300, 10), 33);
}

TEST(NearestWide, SharedMeshesFarFromTheOrigin) {
    BVHKIT_REQUIRE_MESH(fandisk, "fandisk.obj");
    BVHKIT_REQUIRE_MESH(bunny, "stanford-bunny.obj");
    const TriangleMesh f = read_mesh(fandisk), b = read_mesh(bunny);
    test::check_against_brute_force(test::moved<float>(f, 1e4f), test::scaled(150, 10), 34);
    test::check_against_brute_force(test::moved<double>(f, 1e4), test::scaled(150, 10), 35);
    test::check_against_brute_force(test::moved<double>(b, 1e4), test::scaled(100, 10), 36);
}

// The bunny (0.25 across) moved by 1e4 in float: its corners round to ~1e-3, and 603 of its
// triangles end up with p0 == p1. closest_point() (primitives/closest_point.hpp) must not take
// the "edge p0-p1" branch for them (d1 = d3 = 0 there, so s = d1 / (d1 - d3) would be 0 / 0 and
// the point NaN, which ClosestPointMesh would never report and k_nearest would return). See
// TriangleWithFirstTwoCornersEqual.
TEST(NearestWide, SharedBunnyFloatFarFromTheOrigin) {
    BVHKIT_REQUIRE_MESH(path, "stanford-bunny.obj");
    test::check_against_brute_force(test::moved<float>(read_mesh(path), 1e4f),
                                    test::scaled(100, 10), 37);
}

// A triangle whose first two corners are equal is the segment from p1 to p2: closest_point()
// gives its closest point (not NaN) for a point with dot(p2 - p0, p - p0) > 0, and ClosestPointMesh
// reports it, alone and beside a farther triangle.
TEST(NearestWide, TriangleWithFirstTwoCornersEqual) {
    const Trianglef segment{{0, 0, 0}, {0, 0, 0}, {1, 0, 0}};
    const Vec3f p(0.5f, 1.0f, 0.0f);
    const auto c = closest_point(segment, p);
    EXPECT_EQ(c.point, Vec3f(0.5f, 0.0f, 0.0f));
    EXPECT_FLOAT_EQ(length_squared(c.point - p), 1.0f);
    // Alone, and beside a farther ordinary triangle.
    const ClosestPointMesh<float> alone(std::vector<Trianglef>{segment});
    const auto got = alone.closest_point(p);
    ASSERT_TRUE(got);
    EXPECT_EQ(got.triangle, 0u);
    EXPECT_FLOAT_EQ(got.distance_squared, 1.0f);
    const ClosestPointMesh<float> two(
        std::vector<Trianglef>{{{0, 3, 0}, {1, 3, 0}, {0, 3, 1}}, segment});
    const auto got2 = two.closest_point(p);
    ASSERT_TRUE(got2);
    EXPECT_EQ(got2.triangle, 1u);
    EXPECT_FLOAT_EQ(got2.distance_squared, 1.0f);
}

TEST(NearestWide, SliverSoupEqualsBruteForce) {
    const auto tris = test::sliver_soup<float>(test::scaled(3000, 5), 36);
    test::check_against_brute_force(tris, test::scaled(300, 5), 37);
    BuildOptions lbvh;  // another tree shape over the same slivers
    lbvh.builder = Builder::Lbvh;
    test::check_against_brute_force(tris, test::scaled(100, 5), 38, lbvh);
    // The slivers far from the origin.
    auto far = tris;
    for (auto& t : far)
        for (Vec3f* v : {&t.p0, &t.p1, &t.p2}) *v = *v + Vec3f(1e4f);
    test::check_against_brute_force(test::no_equal_first_corners(far), test::scaled(200, 5), 39);
}

TEST(NearestWide, DoubleSliversTorusAndSoup) {
    test::check_against_brute_force(test::sliver_soup<double>(test::scaled(3000, 5), 40),
                                    test::scaled(300, 5), 41);
    test::check_against_brute_force(mesh_triangles<double>(make_torus(48, 24)),
                                    test::scaled(300, 5), 42);
    test::check_against_brute_force(test::random_soup<double>(test::scaled(2000, 5), 43),
                                    test::scaled(200, 5), 44);
}

// Meshes whose coordinates are far from 1 in float: spheres of radius 1e7 (Earth-sized in metres),
// 1e8, 1e-7 and 1e-8. Ericson's closest point in float is accurate at both; the packs must
// not make closest_point miss the nearest triangle there. (The packs' first version, formed
// from the coordinates as given, missed it for ~3% of the points at 1e7 and ~1% at 1e-7.)
TEST(NearestWide, ExtremeScalesEqualBruteForce) {
    for (float scale : {1e7f, 1e-7f, 1e8f, 1e-8f}) {
        SCOPED_TRACE(::testing::Message() << "scale " << scale);
        test::check_against_brute_force(test::moved<float>(make_sphere(1), 0.0f, scale),
                                        test::scaled(500, 10), 45);
        test::check_against_brute_force(test::moved<float>(make_sphere(3), 0.0f, scale),
                                        test::scaled(300, 10), 46);
    }
    // Points in a shell around a coarse sphere of radius 1e-7 (where the first packs went wrong
    // most often: the triangles' plane distances sank into denormals).
    for (float scale : {1e-7f, 2e-7f}) {
        const auto tris = test::moved<float>(make_sphere(1), 0.0f, scale);
        const ClosestPointMesh<float> mesh(tris);
        test::Random rng(48);
        for (std::size_t i = 0; i < test::scaled(2000, 10); ++i) {
            const Vec3f p = rng.unit_vector<float>() * float(scale * rng.uniform(0.7, 1.3));
            float want = std::numeric_limits<float>::infinity();
            for (const auto& t : tris) want = std::min(want, test::distance2(t, p));
            const auto got = mesh.closest_point(p);
            ASSERT_TRUE(got);
            ASSERT_NEAR(got.distance_squared, want, 1e-6f * want)
                << "scale " << scale << " point " << i;
        }
    }
    // Both scales in one mesh: a sphere of radius 1e4 around one of radius 1e-3.
    auto both = test::moved<float>(make_sphere(3), 0.0f, 1e4f);
    const auto small = test::moved<float>(make_sphere(3), 0.0f, 1e-3f);
    both.insert(both.end(), small.begin(), small.end());
    const ClosestPointMesh<float> mesh(both);
    test::Random rng(47);
    for (std::size_t i = 0; i < test::scaled(300, 10); ++i) {
        const Vec3f p = rng.unit_vector<float>() * float(1e-3 * rng.uniform(0.5, 1.5));
        float want = std::numeric_limits<float>::infinity();
        for (const auto& t : both) want = std::min(want, test::distance2(t, p));
        const auto got = mesh.closest_point(p);
        ASSERT_TRUE(got);
        ASSERT_EQ(got.distance_squared, want) << "point " << i;
    }
}

TEST(NearestWide, StatsCountTheWork) {
    const auto tris = test::random_soup<float>(test::scaled(5000, 5), 48);
    const ClosestPointMesh<float> mesh(tris);
    NearestScratch<float> scratch;
    std::uint64_t total = 0;
    for (const Vec3f& p : test::query_points(tris, test::scaled(200, 5), 49)) {
        TraversalStats stats;
        const auto got =
            mesh.closest_point(p, scratch, std::numeric_limits<float>::infinity(), stats);
        ASSERT_TRUE(got);
        EXPECT_GT(stats.nodes_visited, 0u);
        EXPECT_GT(stats.primitives_tested, 0u);
        // Each leaf group is opened at most once, so no triangle is counted twice.
        EXPECT_LE(stats.primitives_tested, tris.size());
        total += stats.primitives_tested;
        // The answer is the same with and without stats.
        const auto plain = mesh.closest_point(p, scratch);
        EXPECT_EQ(plain.triangle, got.triangle);
        EXPECT_EQ(plain.distance_squared, got.distance_squared);
    }
    // A best-first walk tests a small part of the mesh per point on average.
    EXPECT_LT(total, std::uint64_t(tris.size()) * test::scaled(200, 5) / 10);

    // Nothing within the radius: no triangle tested, no answer.
    TraversalStats none;
    EXPECT_FALSE(mesh.closest_point(Vec3f(50.0f), scratch, 1.0f, none));
    EXPECT_EQ(none.primitives_tested, 0u);
}

TEST(NearestWide, NonFinitePointHasNoClosestPoint) {
    const ClosestPointMesh<float> mesh(test::random_soup<float>(500, 50));
    const ClosestPointMesh<double> meshd(test::random_soup<double>(500, 51));
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    for (const Vec3f& p :
         {Vec3f(nan), Vec3f(0.5f, nan, 0.5f), Vec3f(0.5f, 0.5f, inf), Vec3f(-inf, 0.5f, 0.5f)}) {
        EXPECT_FALSE(mesh.closest_point(p));
        EXPECT_FALSE(meshd.closest_point(Vec3d(p)));
    }
}

TEST(NearestWide, PacksThatDoNotScaleBackExactly) {
    // One triangle near 1e30 sets the packs' scale to about 2^-100; the small triangles near the
    // origin (coordinates ~1e-12) then scale into float's denormals and do not come back bit for
    // bit, so the walk must measure candidates from the triangle array. Every answer must still
    // equal brute force, to the bit, in the same triangle or an exact tie.
    auto tris = test::random_soup<float>(test::scaled(400, 5), 53);
    for (auto& t : tris)
        for (Vec3f* v : {&t.p0, &t.p1, &t.p2}) *v = *v * 1e-12f;
    tris.push_back({{1e30f, 0.0f, 0.0f}, {1e30f, 1e29f, 0.0f}, {1e30f, 0.0f, 1e29f}});
    const ClosestPointMesh<float> mesh(tris);
    test::Random rng(54);
    for (std::size_t i = 0; i < test::scaled(500, 5); ++i) {
        const Vec3f p = rng.unit_vector<float>() * float(1e-12 * rng.uniform(0.0, 2.0));
        std::uint32_t want_triangle = 0;
        float want = std::numeric_limits<float>::infinity();
        for (std::uint32_t k = 0; k < tris.size(); ++k)
            if (const float d = test::distance2(tris[k], p); d < want) want = d, want_triangle = k;
        const auto got = mesh.closest_point(p);
        ASSERT_TRUE(got) << "point " << i;
        ASSERT_EQ(got.distance_squared, want) << "point " << i;
        if (got.triangle != want_triangle) {
            ASSERT_EQ(test::distance2(tris[got.triangle], p), want) << "point " << i;
        }
    }
}

// A review's case: Ericson's rounded closest point lies an ulp outside the triangle's box, so its
// distance (2^-50) is below the box's (2^-48). Pruning boxes against the plain radius lost it;
// they are pruned against the widened one, in closest_point, k_nearest and within_radius alike.
TEST(NearestWide, EricsonsPointOutsideTheBox) {
    const Trianglef t{{-0x1.3cb95ap+0f, -0x1.8b6328p+0f, -0x1.e2826cp-2f},
                      {-0x1.82e3eap-1f, -0x1.7ebba4p+0f, -0x1.8047d8p+0f},
                      {-0x1.eeb6c8p-1f, 0x1.ecd2f8p-3f, 0x1.11ef44p-2f}};
    const Vec3f p{-0x1.eeb6c8p-1f, 0x1.ecd3p-3f, 0x1.11ef3ep-2f};
    const float ericson = length_squared(closest_point(t, p).point - p);
    ASSERT_LT(ericson, t.bounds().distance_squared(p));  // the premise
    const float want = test::distance2(t, p);
    const ClosestPointMesh<float> one(std::vector<Trianglef>{t});
    NearestScratch<float> scratch;
    const auto got = one.closest_point(p, scratch, want);
    ASSERT_TRUE(got);
    EXPECT_EQ(got.distance_squared, want);
    std::vector<MeshPoint<float>> out;
    one.k_nearest(p, 1, out, scratch);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].distance_squared, want);
    one.within_radius(p, std::sqrt(want) * 1.0001f, out);
    EXPECT_EQ(out.size(), 1u);
}

// Points on the mesh (its corners, and points on faces and edges), searched with a radius equal
// to the brute-force distance, often exactly 0: the answer must be found. The pack's rounded
// distance there may be above Ericson's, so the widening must not skip a zero radius.
TEST(NearestWide, RadiusEqualToTheDistanceFindsIt) {
    for (const float offset : {0.0f, 1000.0f}) {
        auto tris = test::random_soup<float>(test::scaled(300, 3), 55);
        for (auto& t : tris)
            for (Vec3f* v : {&t.p0, &t.p1, &t.p2}) *v = *v + Vec3f(offset);
        const ClosestPointMesh<float> mesh(tris);
        NearestScratch<float> scratch;
        std::vector<MeshPoint<float>> out;
        test::Random rng(56);
        std::size_t zeros = 0;
        for (std::size_t i = 0; i < tris.size(); ++i) {
            const Trianglef& t = tris[i];
            const float a = float(rng.uniform()), b = float(rng.uniform()) * (1 - a);
            const Vec3f on_edge = t.p0 + (t.p1 - t.p0) * a;
            for (const Vec3f& p : {t.p0, t.p1 + Vec3f(0.0f), on_edge,
                                   t.p0 + (t.p1 - t.p0) * a + (t.p2 - t.p0) * b}) {
                float want = std::numeric_limits<float>::infinity();
                for (const auto& u : tris) want = std::min(want, test::distance2(u, p));
                zeros += want == 0.0f;
                const auto got = mesh.closest_point(p, scratch, want);
                ASSERT_TRUE(got) << "triangle " << i << " offset " << offset << " d2 " << want;
                EXPECT_EQ(got.distance_squared, want);
                // within_radius compares the squared distance in double with r^2 taken there
                // (exactly): a radius whose square is below it holds no triangle, rightly.
                const float r = std::sqrt(want);
                double exact = std::numeric_limits<double>::infinity();
                for (const auto& u : tris) exact = std::min(exact, distance_squared_accurate(u, p));
                if (!(double(r) * double(r) >= exact)) continue;
                mesh.within_radius(p, r, out);
                EXPECT_FALSE(out.empty()) << "triangle " << i << " offset " << offset;
            }
        }
        EXPECT_GT(zeros, tris.size());  // the premise: many searches with a radius of 0
    }
}

}  // namespace
}  // namespace bvhkit

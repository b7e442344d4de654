// closest_point against brute force on adversarial inputs: small fuzzed meshes at scales from
// 1e-10 to 1e9, walks from any starting triangle, meshes whose squared distances underflow, and
// points beyond the packs' scale.
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

// Small adversarial meshes against brute force (after the fuzz a review ran): sizes from 1e-10 to
// 1e9 and offsets up to 1e6; degenerate, duplicate, NaN, nearly flat triangles and shared edges;
// points far, on corners, on edges, on faces and a hair off them; search radii of infinity, 0,
// -1, NaN, exactly the brute-force distance and a little above. closest_point must agree with
// Ericson's closest point on every triangle, bit for bit, on whether there is an answer and on
// its squared distance.
template <class T>
void fuzz_closest_point(std::uint64_t seed) {
    using V = Vec<T, 3>;
    test::Random rng(seed);
    const T inf = std::numeric_limits<T>::infinity();
    const auto random_vec = [&] {
        return V(T(rng.uniform(-1, 1)), T(rng.uniform(-1, 1)), T(rng.uniform(-1, 1)));
    };
    for (std::size_t trial = 0; trial < test::scaled(60, 3); ++trial) {
        const std::uint32_t n = 1 + rng.below(200);
        const T offset = rng.below(3) == 0 ? T(0) : T(std::pow(10.0, int(rng.below(9)) - 2));
        const T scale = rng.below(4) == 0 ? T(1) : T(std::pow(10.0, int(rng.below(20)) - 10));
        std::vector<Triangle<T>> tris;
        for (std::uint32_t i = 0; i < n; ++i) {
            V a = random_vec() * scale + V(offset);
            const T size = scale * T(std::pow(10.0, -4 * rng.uniform()));
            V b = a + random_vec() * size, c = a + random_vec() * size;
            switch (rng.below(12)) {
                case 0:
                    c = a + (b - a) * T(rng.uniform());
                    break;  // collinear
                case 1:
                    b = a;
                    break;
                case 2:
                    b = c = a;
                    break;
                case 3:
                    if (!tris.empty()) {
                        tris.push_back(tris[rng.below(std::uint32_t(tris.size()))]);
                        continue;
                    }
                    break;
                case 4:
                    a[0] = std::numeric_limits<T>::quiet_NaN();
                    break;
                case 5:
                    c = a + (b - a) * T(0.5) + random_vec() * (size * T(1e-3));
                    break;
                case 6:
                    if (!tris.empty()) {
                        const auto& q = tris[rng.below(std::uint32_t(tris.size()))];
                        a = q.p1, b = q.p0;  // a shared edge
                    }
                    break;
                default:
                    break;
            }
            tris.push_back({a, b, c});
        }
        const ClosestPointMesh<T> mesh(tris);
        NearestScratch<T> scratch;
        for (int k = 0; k < 120; ++k) {
            const auto& q = tris[rng.below(std::uint32_t(tris.size()))];
            V p;
            switch (k % 6) {
                case 0:
                    p = random_vec() * (scale * T(1.5)) + V(offset);
                    break;
                case 1:
                    p = q.p0;
                    break;
                case 2:
                    p = q.p0 + (q.p1 - q.p0) * T(rng.uniform());
                    break;
                default: {
                    T u = T(rng.uniform()), v = T(rng.uniform());
                    if (u + v > 1) u = 1 - u, v = 1 - v;
                    p = q.p0 * (1 - u - v) + q.p1 * u + q.p2 * v +
                        random_vec() * (scale * T(std::pow(10.0, -8 * rng.uniform())));
                }
            }
            if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) continue;
            T want = inf;
            for (const auto& t : tris) want = std::min(want, test::distance2(t, p));
            T limit = inf;
            switch (rng.below(6)) {
                case 1:
                    limit = 0;
                    break;
                case 2:
                    limit = -1;
                    break;
                case 3:
                    limit = std::numeric_limits<T>::quiet_NaN();
                    break;
                case 4:
                    limit = want;
                    break;
                case 5:
                    limit = want * T(1.0001);
                    break;
                default:
                    break;
            }
            const bool expected = want <= limit && want < inf;
            const auto got = mesh.closest_point(p, scratch, limit);
            ASSERT_EQ(bool(got), expected)
                << "trial " << trial << " point " << k << " want " << want << " limit " << limit;
            if (got) {
                ASSERT_EQ(got.distance_squared, want) << "trial " << trial << " point " << k;
            }
        }
    }
}

// closest_point(p, near, ...) gives closest_point(p)'s answer bit for bit whatever `near` is: the
// previous point's answer (as the batches use it), a far point's, none, an index out of range, a
// triangle left out for a NaN corner; on slivers, far from the origin, at tiny and huge scales, in
// float and double, with and without a radius limit. The walk from the root is itself judged
// against an exact reference in the tests above, so equality here carries that over.
template <class T>
void check_walks_from_a_start(const std::vector<Triangle<T>>& tris, std::uint64_t seed) {
    const ClosestPointMesh<T> mesh(tris);
    const auto points = test::query_points(tris, test::scaled(3000, 10), seed);
    NearestScratch<T> scratch;
    test::Random rng(seed);
    MeshPoint<T> previous;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Vec<T, 3>& p = points[i];
        const T limit = i % 5 == 0 ? T(rng.uniform(0, 0.1)) : std::numeric_limits<T>::infinity();
        const MeshPoint<T> want = mesh.closest_point(p, scratch, limit);
        MeshPoint<T> far_answer = mesh.closest_point(points[(i * 7919) % points.size()]);
        MeshPoint<T> out_of_range;
        out_of_range.triangle = std::uint32_t(tris.size() + 5);
        MeshPoint<T> skipped;
        skipped.triangle = 0;  // left out of the tree: its corner is NaN
        for (const MeshPoint<T>& near :
             {previous, far_answer, MeshPoint<T>{}, out_of_range, skipped}) {
            const MeshPoint<T> got = mesh.closest_point(p, near, scratch, limit);
            ASSERT_EQ(got.triangle, want.triangle) << i;
            ASSERT_EQ(got.distance_squared, want.distance_squared) << i;
            ASSERT_EQ(got.point, want.point) << i;
            ASSERT_EQ(got.u, want.u) << i;
            ASSERT_EQ(got.v, want.v) << i;
        }
        previous = want;
    }
}

TEST(NearestWide, WalksFromAStartingTriangleGiveTheSameAnswers) {
    const auto with_a_nan = [](auto tris) {
        tris[0].p1[2] =
            std::numeric_limits<typename decltype(tris)::value_type::Scalar>::quiet_NaN();
        return tris;
    };
    const TriangleMesh torus = make_torus(48, 24);
    check_walks_from_a_start(with_a_nan(test::sliver_soup<float>(test::scaled(2000, 10), 3)), 31);
    check_walks_from_a_start(with_a_nan(test::sliver_soup<double>(test::scaled(2000, 10), 4)), 32);
    check_walks_from_a_start(with_a_nan(test::moved<float>(torus, 1e6f)), 33);
    check_walks_from_a_start(with_a_nan(test::moved<float>(torus, 0, 1e-6f)), 34);
    check_walks_from_a_start(with_a_nan(test::moved<double>(torus, 1e9, 1e12)), 35);
    // Squared distances below T's least normal: the walk's radius is kept in the packs' units.
    check_walks_from_a_start(with_a_nan(test::moved<float>(torus, 0, 1e-36f)), 36);
    check_walks_from_a_start(with_a_nan(test::moved<double>(torus, 0, 1e-300)), 37);
}

// The answer is the triangle nearest by the accurate distance (in a wider type than T), also when
// the walk starts from the previous point's answer. What is judged here is the walk's pruning at
// extreme scales, so the reference measures every triangle with the same accurate function the
// mesh uses; that function itself is judged against exact rationals in
// closest_point_accuracy_test.cpp.
template <class T>
void check_accurately_nearest(const std::vector<Triangle<T>>& tris,
                              const std::vector<Vec<T, 3>>& points) {
    const ClosestPointMesh<T> mesh(tris);
    NearestScratch<T> scratch;
    MeshPoint<T> previous;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Vec<T, 3>& p = points[i];
        AccurateScalar<T> want = std::numeric_limits<AccurateScalar<T>>::infinity();
        for (const auto& t : tris) want = std::min(want, distance_squared_accurate(t, p));
        const MeshPoint<T> got = mesh.closest_point(p);
        ASSERT_TRUE(got) << i;
        ASSERT_EQ(distance_squared_accurate(tris[got.triangle], p), want) << i;
        const MeshPoint<T> from = mesh.closest_point(p, previous, scratch);
        ASSERT_EQ(from.triangle, got.triangle) << i;
        previous = got;
    }
}

// A mesh so small that its squared distances underflow T (float 1e-36, double 1e-300).
template <class T>
void check_tiny_mesh(T scale, std::uint64_t seed) {
    const auto tris = test::moved<T>(make_torus(24, 12), T(0), scale);
    check_accurately_nearest(tris, test::query_points(tris, test::scaled(400, 10), seed));
}

TEST(NearestWide, TinyMeshesEqualBruteForce) {
    check_tiny_mesh<float>(1e-36f, 38);
    check_tiny_mesh<double>(1e-300, 39);
}

// A unit torus and one point triangle 1e25 away (double: 1e160): the packs' scale follows the
// far corner, and the torus's squared distances in the packs' units sink below T's least normal.
template <class T>
void check_far_point_triangle(T far, std::uint64_t seed) {
    const auto torus = mesh_triangles<T>(make_torus(24, 12));
    auto tris = torus;
    const Vec<T, 3> corner(far, T(0), T(0));
    tris.push_back({corner, corner, corner});
    check_accurately_nearest(tris, test::query_points(torus, test::scaled(400, 10), seed));
}

TEST(NearestWide, MeshFarLargerThanItsNearestTriangles) {
    check_far_point_triangle<float>(1e25f, 40);
    check_far_point_triangle<double>(1e160, 41);
}

TEST(NearestWide, FuzzAgainstBruteForce) {
    for (std::uint64_t seed : {1, 2, 3}) {
        SCOPED_TRACE(::testing::Message() << "seed " << seed);
        fuzz_closest_point<float>(seed);
        fuzz_closest_point<double>(seed + 100);
    }
}

TEST(NearestWide, PointBeyondThePackScale) {
    // A mesh of magnitude 1e-25 and a point at 1e15: the point scaled as the packs are (by about
    // 1e25) is not finite in float, so every triangle is measured exactly. Still the brute-force
    // answer (all triangles are nearly equally far: the distance only).
    auto tris = test::random_soup<float>(300, 52);
    for (auto& t : tris)
        for (Vec3f* v : {&t.p0, &t.p1, &t.p2}) *v = *v * 1e-25f;
    const ClosestPointMesh<float> mesh(tris);
    for (const Vec3f& p : {Vec3f(1e15f, 0.0f, 0.0f), Vec3f(-3e14f, 1e15f, 2e13f)}) {
        float want = std::numeric_limits<float>::infinity();
        for (const auto& t : tris) want = std::min(want, test::distance2(t, p));
        const auto got = mesh.closest_point(p);
        ASSERT_TRUE(got);
        EXPECT_EQ(got.distance_squared, want);
    }
}

}  // namespace
}  // namespace bvhkit

// Signed distance sign and winding numbers against dense references, and overlap queries against
// brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numbers>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/overlap.hpp"
#include "bvhkit/query/signed_distance.hpp"
#include "bvhkit/query/winding_number.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

/// The dense reference: sum of every triangle's solid angle (no tree), in double.
double brute_winding(const TriangleMesh& mesh, const Vec3d& q) {
    double sum = 0;
    for (const auto& t : mesh.triangles)
        sum += solid_angle(Vec3d(mesh.vertices[t[0]]), Vec3d(mesh.vertices[t[1]]),
                           Vec3d(mesh.vertices[t[2]]), q);
    return sum / (4 * std::numbers::pi);
}

double brute_distance(const TriangleMesh& mesh, const Vec3d& q) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : mesh.triangles) {
        const Triangled tri{Vec3d(mesh.vertices[t[0]]), Vec3d(mesh.vertices[t[1]]),
                            Vec3d(mesh.vertices[t[2]])};
        best = std::min(best, length_squared(closest_point(tri, q).point - q));
    }
    return std::sqrt(best);
}

template <class T>
void check_signs(const TriangleMesh& mesh, std::size_t count, std::uint64_t seed) {
    const SignedDistanceMesh<T> sdf(mesh);
    const WindingNumberMesh<T> wn(mesh);
    const Aabb3f box = mesh.bounds();
    const double diag = length(Vec3d(box.extent()));
    const Vec3f e = box.extent();
    const Aabb3f around(box.min - e * 0.2f, box.max + e * 0.2f);
    test::Random rng(seed);
    std::size_t tested = 0, inside = 0;
    for (std::size_t i = 0; i < count; ++i) {
        Vec3d q = Vec3d(rng.point_in(around));
        if (i % 2) {  // half the points near the surface: a vertex pushed in or out a little
            const Vec3f v = mesh.vertices[rng.below(std::uint32_t(mesh.vertices.size()))];
            q = Vec3d(v) + Vec3d(rng.unit_vector<float>()) * (diag * 0.01 * rng.uniform());
        }
        const double d = brute_distance(mesh, q);
        if (d < 1e-3 * diag) continue;
        const bool want_inside = brute_winding(mesh, q) > 0.5;
        const auto got = sdf.signed_distance(Vec<T, 3>(q));
        ++tested;
        inside += want_inside;
        ASSERT_EQ(got.distance < 0, want_inside) << "point " << i;
        ASSERT_NEAR(std::fabs(double(got.distance)), d, 1e-5 * diag) << "point " << i;
        ASSERT_EQ(wn.inside(Vec<T, 3>(q)), want_inside) << "point " << i;
        ASSERT_NEAR(double(wn.exact(Vec<T, 3>(q))), want_inside ? 1.0 : 0.0, 1e-3) << i;
    }
    EXPECT_GT(inside, tested / 10);
    EXPECT_LT(inside, tested - tested / 10);
}

TEST(Inside, ReferenceIsRightOnASphere) {
    const TriangleMesh sphere = make_sphere(3);
    EXPECT_NEAR(brute_winding(sphere, {0, 0, 0}), 1.0, 1e-9);
    EXPECT_NEAR(brute_winding(sphere, {0.3, -0.2, 0.5}), 1.0, 1e-9);
    EXPECT_NEAR(brute_winding(sphere, {2, 0, 0}), 0.0, 1e-9);
}

TEST(Inside, SignsOnClosedMeshes) {
    const std::size_t n = test::scaled(1500, 10);
    check_signs<float>(make_sphere(4), n, 1);
    check_signs<double>(make_sphere(4), n, 2);
    check_signs<float>(make_torus(64, 32), n, 3);
    check_signs<double>(make_torus(64, 32), n, 4);
    const TriangleMesh blob = make_sphere(4, 0.4f, 7);  // closed, noisy
    check_signs<float>(blob, n, 5);
    check_signs<double>(blob, n, 6);
}

TEST(Inside, FastWindingNumberAgreesOnTheOpenBunny) {
    BVHKIT_REQUIRE_MESH(path, "stanford-bunny.obj");
    const TriangleMesh bunny = read_mesh(path);
    // Boundary edges (one triangle only): the holes.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edge_count;
    for (const auto& t : bunny.triangles)
        for (int k = 0; k < 3; ++k) ++edge_count[std::minmax(t[k], t[(k + 1) % 3])];
    std::vector<Triangled> boundary;  // each boundary edge as a degenerate triangle
    for (const auto& [e, c] : edge_count)
        if (c == 1)
            boundary.push_back({Vec3d(bunny.vertices[e.first]), Vec3d(bunny.vertices[e.second]),
                                Vec3d(bunny.vertices[e.second])});
    ASSERT_GT(boundary.size(), 0u) << "the bunny has holes";
    const WindingNumberMesh<float> wn(bunny);
    const Aabb3f box = bunny.bounds();
    const double diag = length(Vec3d(box.extent()));
    test::Random rng(11);
    std::size_t tested = 0, inside = 0;
    double worst = 0;
    for (std::size_t i = 0; i < test::scaled(400, 10); ++i) {
        const Vec3d q(rng.point_in(box));
        double hole = std::numeric_limits<double>::infinity();
        for (const auto& b : boundary) hole = std::min(hole, length(closest_point(b, q).point - q));
        if (hole < 0.1 * diag || brute_distance(bunny, q) < 1e-3 * diag) continue;
        const double want = brute_winding(bunny, q);
        const double got = wn.fast(Vec3f(q));
        worst = std::max(worst, std::fabs(got - want));
        ++tested;
        inside += want > 0.5;
        ASSERT_EQ(got > 0.5, want > 0.5) << "point " << i << ": " << got << " vs " << want;
        ASSERT_NEAR(double(wn.exact(Vec3f(q))), want, 1e-4);
    }
    std::printf("bunny: %zu points away from the holes, %zu inside, max |fast - exact| = %.2e\n",
                tested, inside, worst);
    EXPECT_GT(tested, test::scaled(400, 10) / 4);
    EXPECT_GT(inside, 0u);
    std::vector<Vec3f> points;
    for (std::size_t i = 0; i < spatial_order_from + 1000; ++i) points.push_back(rng.point_in(box));
    std::vector<float> a(points.size()), b(points.size());
    wn.fast(points, a, 2.0f, 1);
    wn.fast(points, b, 2.0f, 0);
    EXPECT_EQ(a, b);
    for (std::size_t i = 0; i < points.size(); i += 97) ASSERT_EQ(a[i], wn.fast(points[i])) << i;
}

TEST(Overlap, BoxSphereAndPointEqualBruteForce) {
    const auto tris = test::random_soup<float>(test::scaled(5000, 10), 21);
    std::vector<Aabb3f> boxes;
    for (const auto& t : tris) boxes.push_back(t.bounds());
    const std::span<const Aabb3f> pb(boxes);
    for (const auto& [name, options] : all_builder_configurations()) {
        if (options.optimize && options.builder != Builder::Lbvh) continue;
        SCOPED_TRACE(name);
        std::vector<Vec3f> centroids;
        for (const auto& b : boxes) centroids.push_back(b.centroid());
        const auto bvh = build_bvh<float, 3>(boxes, centroids, options);
        test::Random rng(22);
        std::vector<Aabb3f> qboxes;
        std::vector<Vec3f> centers;
        std::vector<float> radii;
        for (int q = 0; q < 200; ++q) {
            const Vec3f c = rng.point_in(Aabb3f({-0.1f, -0.1f, -0.1f}, {1.1f, 1.1f, 1.1f}));
            const float r = float(0.1 * rng.uniform());
            qboxes.push_back(Aabb3f(c - Vec3f(r), c + Vec3f(r * 0.5f)));
            centers.push_back(c);
            radii.push_back(r);
        }
        const BatchHits by_box = query_boxes(bvh, pb, std::span<const Aabb3f>(qboxes));
        const BatchHits by_sphere =
            query_spheres(bvh, pb, std::span<const Vec3f>(centers), std::span<const float>(radii));
        const BatchHits by_point = query_points(bvh, pb, std::span<const Vec3f>(centers), 1);
        for (int q = 0; q < 200; ++q) {
            std::vector<std::uint32_t> want_box, want_sphere, want_point;
            for (std::uint32_t i = 0; i < boxes.size(); ++i) {
                if (boxes[i].overlaps(qboxes[q])) want_box.push_back(i);
                if (boxes[i].distance_squared(centers[q]) <= radii[q] * radii[q])
                    want_sphere.push_back(i);
                if (boxes[i].contains(centers[q])) want_point.push_back(i);
            }
            const auto sorted = [](std::span<const std::uint32_t> s) {
                std::vector<std::uint32_t> v(s.begin(), s.end());
                std::sort(v.begin(), v.end());
                return v;
            };
            ASSERT_EQ(sorted(by_box.of(q)), want_box) << q;
            ASSERT_EQ(sorted(by_sphere.of(q)), want_sphere) << q;
            ASSERT_EQ(sorted(by_point.of(q)), want_point) << q;
            // Early stop: asking to stop at the first hit gives exactly one.
            int seen = 0;
            const bool finished = query_box(bvh, pb, qboxes[q], [&](std::uint32_t) {
                ++seen;
                return false;
            });
            EXPECT_EQ(seen, want_box.empty() ? 0 : 1);
            EXPECT_EQ(finished, want_box.empty());
        }
        // Batch results do not depend on the threads.
        const BatchHits serial = query_boxes(bvh, pb, std::span<const Aabb3f>(qboxes), 1);
        EXPECT_EQ(serial.hits, by_box.hits);
        EXPECT_EQ(serial.offsets, by_box.offsets);
    }
}

// The batch signed distance: the same answers as one at a time, on 1 thread and on all, in float
// and double; an output too small is an error.
template <class T>
void check_signed_distance_batch(const TriangleMesh& mesh, std::uint64_t seed) {
    const SignedDistanceMesh<T> sdf(mesh);
    test::Random rng(seed);
    std::vector<Vec<T, 3>> points(spatial_order_from + 1000);  // answered in spatial order
    for (auto& p : points) p = rng.point_in(Aabb<T, 3>(Vec<T, 3>(T(-1.3)), Vec<T, 3>(T(1.3))));
    std::vector<SignedDistance<T>> one(points.size()), all(points.size());
    sdf.signed_distances(points, one, 1);
    sdf.signed_distances(points, all, 0);
    std::size_t inside = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const SignedDistance<T> single = sdf.signed_distance(points[i]);
        ASSERT_EQ(one[i].distance, single.distance) << i;
        ASSERT_EQ(one[i].closest.triangle, single.closest.triangle) << i;
        ASSERT_EQ(all[i].distance, single.distance) << i;
        ASSERT_EQ(all[i].closest.point, single.closest.point) << i;
        inside += single.distance < 0;
    }
    EXPECT_GT(inside, points.size() / 20);  // the premise: both signs occur
    std::vector<SignedDistance<T>> small(points.size() - 1);
    EXPECT_THROW(sdf.signed_distances(points, small), Error);
}

TEST(SignedDistanceBatch, EqualsOneAtATimeOnAnyThreads) {
    check_signed_distance_batch<float>(make_sphere(4), 1);
    check_signed_distance_batch<double>(make_torus(48, 24), 2);
}

}  // namespace
}  // namespace bvhkit

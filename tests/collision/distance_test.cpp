// Distance between models against brute force (every triangle pair), refit against rebuild, and the
// volumes' own promises (they contain what they were fitted to; their distance lower bounds never
// exceed the true distance).
#include <gtest/gtest.h>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/convex_hull.hpp"
#include "bvhkit/volumes/kdop.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "bvhkit/volumes/sphere.hpp"
#include "collision_support.hpp"
#include "random_rigid_poses.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

/// Separated poses per case: the acceptance figure (100) in the Release run, a few under the
/// sanitizers (BVHKIT_TEST_SCALE=small).
std::size_t separated_count(std::size_t small) {
    return small_scale() ? small : 100;
}

/// The first `count` poses (from a C1 stream) at which brute force finds no intersection.
template <class T>
std::vector<Transform<T>> separated_poses(const std::vector<Triangle<T>>& ta,
                                          const std::vector<Triangle<T>>& tb,
                                          const Aabb<T, 3>& bounds, std::size_t count,
                                          std::uint64_t seed) {
    std::vector<Transform<T>> out;
    const T pad = T(1e-5) * length(bounds.max - bounds.min);
    for (const auto& p : random_rigid_poses(bounds, 20 * count + 50, seed)) {
        if (out.size() == count) break;
        if (brute_force_pairs(ta, tb, p, pad).empty()) out.push_back(p);
    }
    EXPECT_EQ(out.size(), count);
    return out;
}

template <class V>
void check_distance(const BasicTriangleMesh<double>& ma, const BasicTriangleMesh<double>& mb,
                    const std::vector<Transform<double>>& poses, const std::vector<double>& truth) {
    const CollisionModel<V> a(ma), b(mb);
    const auto ta = mesh_triangles(ma), tb = mesh_triangles(mb);
    for (std::size_t k = 0; k < poses.size(); ++k) {
        for (DescentRule rule : {DescentRule::Larger, DescentRule::A, DescentRule::Simultaneous}) {
            DistanceOptions<double> o;
            o.rule = rule;
            const auto d = distance(a, b, poses[k], o);
            ASSERT_NEAR(d.distance, truth[k], 1e-5 * truth[k]) << "pose " << k;
            // The reported points are that far apart and lie on the reported triangles.
            EXPECT_NEAR(length(d.point_a - d.point_b), d.distance, 1e-9 + 1e-7 * d.distance);
            const auto& tri_a = ta[d.triangle_a];
            const Triangle<double> tri_b = transformed(tb[d.triangle_b], poses[k]);
            EXPECT_LT(length(closest_point(tri_a, d.point_a).point - d.point_a), 1e-9);
            EXPECT_LT(length(closest_point(tri_b, d.point_b).point - d.point_b), 1e-9);
        }
        // An upper bound above the distance changes nothing; one below it cuts the walk, and what
        // comes back (a measured pair, or +inf) is never below the true distance; at zero no
        // volume bound can be below it, so nothing is measured.
        const auto plain = distance(a, b, poses[k]);
        DistanceOptions<double> above, below, zero;
        above.upper_bound = truth[k] * 1.001;
        below.upper_bound = truth[k] * 0.999;
        zero.upper_bound = 0;
        EXPECT_EQ(distance(a, b, poses[k], above).distance, plain.distance) << "pose " << k;
        EXPECT_GE(distance(a, b, poses[k], below).distance, truth[k] * (1 - 1e-9)) << "pose " << k;
        const auto none = distance(a, b, poses[k], zero);
        EXPECT_EQ(none.distance, std::numeric_limits<double>::infinity()) << "pose " << k;
        EXPECT_EQ(none.stats.primitive_tests, 0u) << "pose " << k;
        if (k == 0) {
            DistanceOptions<double> nan;
            nan.upper_bound = std::numeric_limits<double>::quiet_NaN();
            EXPECT_THROW((void)distance(a, b, poses[k], nan), Error);
        }
        // A tolerance may stop early but never undershoots, nor overshoots by more than allowed.
        DistanceOptions<double> loose;
        loose.relative_tolerance = 0.1;
        const auto d = distance(a, b, poses[k], loose);
        EXPECT_GE(d.distance, truth[k] * (1 - 1e-9));
        EXPECT_LE(d.distance, truth[k] * 1.1 + 1e-12);
    }
}

void check_all(const TriangleMesh& fa, const TriangleMesh& fb, std::size_t count,
               std::uint64_t seed) {
    const auto ma = converted<double>(fa), mb = converted<double>(fb);
    const auto ta = mesh_triangles(ma), tb = mesh_triangles(mb);
    const auto poses = separated_poses(ta, tb, mb.bounds(), count, seed);
    std::vector<double> truth;
    for (const auto& p : poses) {
        truth.push_back(brute_force_distance(ta, tb, p));
        ASSERT_GT(truth.back(), 0.0);
    }
    check_distance<Aabb3d>(ma, mb, poses, truth);
    check_distance<Sphere<double>>(ma, mb, poses, truth);
    check_distance<Obb<double>>(ma, mb, poses, truth);
    check_distance<Rss<double>>(ma, mb, poses, truth);
    check_distance<Kdop<double, 18>>(ma, mb, poses, truth);
    check_distance<ConvexHull<double>>(ma, mb, poses, truth);
    std::printf("[ distance ] %zu separated poses\n", poses.size());
}

TEST(Distance, SuzanneMatchesBruteForce) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    const auto m = read_mesh(path);
    check_all(m, m, separated_count(10), 21);
}

TEST(Distance, RandomSoupsMatchBruteForce) {
    for (std::uint64_t s = 0; s < 2; ++s) {
        const auto a = random_soup<float>(200, 0.1, 700 + s),
                   b = random_soup<float>(150, 0.1, 800 + s);
        check_all(a, b, separated_count(10), 900 + s);
    }
}

TEST(Distance, FloatModelsAgreeWithDoubleBruteForce) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    const auto m = read_mesh(path);
    const auto md = converted<double>(m);
    const auto td = mesh_triangles(md);
    const CollisionModel<Obb<float>> model(m);
    const auto poses = separated_poses(td, td, md.bounds(), separated_count(5), 31);
    for (const auto& p : poses) {
        const double truth = brute_force_distance(td, td, p);
        const auto d = distance(model, model, Transform<float>(p));
        EXPECT_NEAR(d.distance, truth, 1e-4 * length(md.bounds().extent()));
    }
}

TEST(Distance, IntersectingModelsAreAtZero) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    const auto m = read_mesh(path);
    const CollisionModel<Aabb3f> model(m);
    EXPECT_EQ(distance(model, model, Transform<float>::identity()).distance, 0.0f);
    const Transform<float> shifted{Mat3<float>{}, Vec3f(0.3f, 0, 0)};
    EXPECT_EQ(distance(model, model, shifted).distance, 0.0f);
}

// Refit after deformation answers exactly what a tree rebuilt over the deformed mesh answers
// (and what brute force answers).
template <class V>
void check_refit(const TriangleMesh& m) {
    TriangleMesh moved = m;
    const Aabb3f box = m.bounds();
    const float size = length(box.max - box.min);
    CollisionModel<V> refitted(m);
    for (int step = 1; step <= 2; ++step) {
        for (auto& v : moved.vertices)
            v = v + Vec3f(std::sin(4 * v[1] / size * 6.28f), std::cos(3 * v[2] / size * 6.28f),
                          std::sin(5 * v[0] / size * 6.28f)) *
                        (0.05f * size);
        refitted.refit(moved);
        const CollisionModel<V> rebuilt(moved);
        const auto tris = mesh_triangles(moved);
        const auto poses = random_rigid_poses(moved.bounds(), scaled(20, 4), 40 + step);
        CollideResult<float> r1, r2;
        for (const auto& p : poses) {
            collide(refitted, refitted, p, {}, r1);
            collide(rebuilt, rebuilt, p, {}, r2);
            PairSet s1, s2;
            for (const auto& c : r1.contacts) s1.insert({c.triangle_a, c.triangle_b});
            for (const auto& c : r2.contacts) s2.insert({c.triangle_a, c.triangle_b});
            ASSERT_EQ(s1, s2);
            ASSERT_EQ(s1, brute_force_pairs(tris, tris, p, 1e-5f * size));
            if (!r1.colliding) {
                const float d1 = distance(refitted, refitted, p).distance;
                const float d2 = distance(rebuilt, rebuilt, p).distance;
                EXPECT_NEAR(d1, d2, 1e-5f * size);
            }
        }
    }
}

TEST(Refit, EveryVolumeMatchesRebuild) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    const auto m = read_mesh(path);
    check_refit<Aabb3f>(m);
    check_refit<Sphere<float>>(m);
    check_refit<Obb<float>>(m);
    check_refit<Rss<float>>(m);
    check_refit<Kdop<float, 14>>(m);
    check_refit<Kdop<float, 18>>(m);
    check_refit<Kdop<float, 26>>(m);
    check_refit<ConvexHull<float>>(m);
}

TEST(Refit, RejectsAnotherMesh) {
    const auto m = random_soup<float>(10, 0.1, 1);
    CollisionModel<Obb<float>> model(m);
    const auto other = random_soup<float>(11, 0.1, 1);
    EXPECT_THROW(model.refit(other), Error);
}

// Each volume contains its triangles, and its lower bound under a pose never exceeds the true
// distance between two sets of triangles.
template <class V>
void check_volume_promises() {
    SplitMix64 rng(77);
    using Traits = VolumeTraits<V>;
    for (int trial = 0; trial < int(scaled(300, 10)); ++trial) {
        const auto a = random_soup<double>(1 + rng.below(6), 0.2, rng.next());
        const auto b = random_soup<double>(1 + rng.below(6), 0.2, rng.next());
        const auto ta = mesh_triangles(a), tb = mesh_triangles(b);
        const V va = Traits::fit(ta), vb = Traits::fit(tb);
        const V one = Traits::fit(std::span<const Triangle<double>>(ta).first(1));
        ASSERT_TRUE(Traits::overlaps(va, one));
        const auto pose = random_rigid_poses(Aabb3d(Vec3d(0.0), Vec3d(1.0)), 1, rng.next())[0];
        const auto prepared = Traits::prepare(pose, 0.0);
        const double truth = brute_force_distance(ta, tb, pose);
        const double lb = Traits::distance_lower_bound(va, vb, prepared);
        ASSERT_LE(lb, truth + 1e-12) << "trial " << trial;
        // Intersecting triangles imply overlapping volumes.
        if (!brute_force_pairs(ta, tb, pose, 0.0).empty()) {
            ASSERT_TRUE(Traits::overlaps(va, vb, prepared));
        }
        // Merging keeps both.
        const V m = Traits::merge(va, vb);
        ASSERT_TRUE(Traits::overlaps(m, va) && Traits::overlaps(m, vb));
        ASSERT_GE(Traits::size(m), std::max(Traits::size(va), Traits::size(vb)) * (1 - 1e-12));
    }
}

TEST(Volumes, PromisesHold) {
    check_volume_promises<Aabb3d>();
    check_volume_promises<Sphere<double>>();
    check_volume_promises<Obb<double>>();
    check_volume_promises<Rss<double>>();
    check_volume_promises<Kdop<double, 14>>();
    check_volume_promises<Kdop<double, 18>>();
    check_volume_promises<Kdop<double, 26>>();
    check_volume_promises<ConvexHull<double>>();
    check_volume_promises<ConvexHull<double, 4>>();  // capped: the swept margin at work
}

// Rss: every vertex lies within the radius of the rectangle, and the rectangle distance (the
// bound's core) equals a dense sampling of both rectangles, never more.
TEST(Volumes, RssContainsItsTrianglesAndMeasuresRectanglesExactly) {
    SplitMix64 rng(91);
    using Traits = VolumeTraits<Rss<double>>;
    const auto rect_point = [](const Rss<double>& v, double s, double t) {
        return v.center + v.axes[0] * (s * v.half[0]) + v.axes[1] * (t * v.half[1]);
    };
    for (int trial = 0; trial < int(scaled(200, 10)); ++trial) {
        const auto soup = random_soup<double>(1 + rng.below(8), 0.3, rng.next());
        const auto tris = mesh_triangles(soup);
        const Rss<double> v = Traits::fit(tris);
        ASSERT_GE(v.half[0], 0.0);
        ASSERT_GE(v.half[1], 0.0);
        for (const auto& t : tris)
            for (const Vec3d& p : {t.p0, t.p1, t.p2}) {
                const Vec3d q = p - v.center;
                const double x = std::clamp(dot(q, v.axes[0]), -v.half[0], v.half[0]);
                const double y = std::clamp(dot(q, v.axes[1]), -v.half[1], v.half[1]);
                ASSERT_LE(length(p - rect_point(v, x / std::max(v.half[0], 1e-300),
                                                y / std::max(v.half[1], 1e-300))),
                          v.radius * (1 + 1e-12) + 1e-15)
                    << "trial " << trial;
            }
        // Against a second volume under a pose: the bound against sampled points of each edge
        // (a closest pair always has a point on an edge) and a grid over the other rectangle.
        const auto other = random_soup<double>(1 + rng.below(8), 0.3, rng.next());
        const Rss<double> w = Traits::fit(mesh_triangles(other));
        const auto pose = random_rigid_poses(Aabb3d(Vec3d(0.0), Vec3d(1.0)), 1, rng.next())[0];
        Rss<double> wp = w;  // w carried into v's frame
        wp.center = pose.apply(w.center);
        for (int i = 0; i < 3; ++i) wp.axes[i] = pose.rotation * w.axes[i];
        const auto prepared = Traits::prepare(pose, 0.0);
        const double bound = Traits::distance_lower_bound(v, w, prepared);
        double sampled = std::numeric_limits<double>::infinity();
        constexpr int n = 40;
        for (int e = 0; e < 8; ++e)
            for (int i = 0; i <= n; ++i) {
                const double s = -1 + 2.0 * i / n;
                const bool first = e < 4;
                const Rss<double>& edge_of = first ? v : wp;
                const Rss<double>& grid_of = first ? wp : v;
                const double es = (e & 1) ? 1.0 : -1.0;
                const Vec3d p = (e & 2) ? rect_point(edge_of, es, s) : rect_point(edge_of, s, es);
                for (int j = 0; j <= n; ++j)
                    for (int k = 0; k <= n; ++k)
                        sampled = std::min(sampled, length(p - rect_point(grid_of, -1 + 2.0 * j / n,
                                                                          -1 + 2.0 * k / n)));
            }
        sampled -= v.radius + wp.radius;
        const double step = 2.0 * (v.half[0] + v.half[1] + w.half[0] + w.half[1]) / n;
        ASSERT_LE(bound, std::max(0.0, sampled) + 1e-12) << "trial " << trial;
        ASSERT_GE(bound, sampled - step) << "trial " << trial;
    }
}

// The segment-rectangle distance inside the Rss bound: against a ternary search of the exact
// point-rectangle distance along the segment (convex in s), including segments parallel to an
// axis of the rectangle or to its plane, points, and segments through the rectangle.
TEST(Volumes, SegmentRectangleDistanceMatchesSearch) {
    SplitMix64 rng(17);
    const auto point_d2 = [](const Vec3d& q, double h0, double h1) {
        const double ex = q[0] - std::clamp(q[0], -h0, h0), ey = q[1] - std::clamp(q[1], -h1, h1);
        return ex * ex + ey * ey + q[2] * q[2];
    };
    for (int trial = 0; trial < int(scaled(20000, 2000)); ++trial) {
        const double h0 = rng.uniform(0, 2), h1 = rng.uniform(0, 2);
        Vec3d p, d;
        for (int a = 0; a < 3; ++a) {
            p[a] = rng.uniform(-4, 4);
            d[a] = rng.uniform(-6, 6);
            if (rng.below(5) == 0) d[a] = 0;  // parallel to an axis or to the plane
        }
        if (rng.below(7) == 0) p[2] = 0;  // in the plane
        const double got = detail::segment_rectangle_distance_squared(p, d, h0, h1);
        double lo = 0, hi = 1;
        for (int i = 0; i < 200; ++i) {
            const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
            if (point_d2(p + d * m1, h0, h1) <= point_d2(p + d * m2, h0, h1))
                hi = m2;
            else
                lo = m1;
        }
        const double want =
            std::min({point_d2(p + d * lo, h0, h1), point_d2(p, h0, h1), point_d2(p + d, h0, h1)});
        ASSERT_NEAR(got, want, 1e-9 * (1 + want)) << "trial " << trial;
    }
}

TEST(Volumes, ObbFollowsTheShape) {
    // A long thin slab along (1, 1, 0): the covariance fit finds that axis, so the box is far
    // smaller than the AABB.
    BasicTriangleMesh<double> m;
    for (int i = 0; i < 20; ++i) {
        const double s = i * 0.5;
        const auto n = std::uint32_t(m.vertices.size());
        m.vertices.push_back({s, s, 0.0});
        m.vertices.push_back({s + 0.1, s, 0.0});
        m.vertices.push_back({s, s + 0.1, 0.05});
        m.triangles.push_back({n, n + 1, n + 2});
    }
    const auto tris = mesh_triangles(m);
    const Obb<double> o = VolumeTraits<Obb<double>>::fit(tris);
    const Aabb3d b = VolumeTraits<Aabb3d>::fit(tris);
    const Vec3d e = b.extent() * 0.5;
    EXPECT_LT(o.extents[0] * o.extents[1] * o.extents[2], 0.2 * e[0] * e[1] * e[2]);
    for (const auto& t : tris)
        for (const Vec3d& p : {t.p0, t.p1, t.p2}) {
            const Vec3d q = o.axes * (p - o.center);
            for (int k = 0; k < 3; ++k) EXPECT_LE(std::fabs(q[k]), o.extents[k]);
        }
}

TEST(Volumes, Kdop2D) {
    Kdop<float, 8> a, b, c;
    a.grow(Vec2f(0, 0)).grow(Vec2f(1, 0)).grow(Vec2f(0, 1));
    b.grow(Vec2f(0.9f, 0.9f)).grow(Vec2f(2, 2));  // inside a's box, outside the diagonal slab
    c.grow(Vec2f(0.4f, 0.4f)).grow(Vec2f(2, 2));
    EXPECT_FALSE(a.overlaps(b));
    EXPECT_TRUE(a.overlaps(c));
}

}  // namespace
}  // namespace bvhkit::test

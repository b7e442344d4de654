// Scene: the API (ids, generations, errors, validate, world boxes) and the queries over random
// scenes against brute force over the concatenated world-space mesh built by the test
// (scene_support.hpp): rays (closest, any, all) and closest points, near and far from the origin,
// at tiny and huge scales, before and after pose changes and removals.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <thread>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/scene/closest_point.hpp"
#include "bvhkit/scene/ray_batches.hpp"
#include "bvhkit/scene/rays.hpp"
#include "scene_support.hpp"

namespace bvhkit {
namespace {

using scene_test::LD;

template <class T>
BasicTriangleMesh<T> scaled_mesh(const TriangleMesh& m, double scale) {
    BasicTriangleMesh<T> out;
    for (const auto& v : m.vertices)
        out.vertices.push_back(Vec<T, 3>(T(v[0] * scale), T(v[1] * scale), T(v[2] * scale)));
    out.triangles = m.triangles;
    return out;
}

TriangleMesh tetrahedron() {
    TriangleMesh m;
    m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    return m;
}

template <class T>
Transform<T> translation(T x, T y, T z) {
    Transform<T> p;
    p.translation = {x, y, z};
    return p;
}

TEST(Scene, IdsGenerationsAndErrors) {
    Scene<float> scene;
    const GeometryId g = scene.add_mesh(tetrahedron());
    EXPECT_THROW(scene.add_instance(GeometryId(5), translation(0.f, 0.f, 0.f)), Error);
    EXPECT_THROW(scene.add_instance(GeometryId(), translation(0.f, 0.f, 0.f)), Error);
    Transform<float> sheared;
    sheared.rotation[0][1] = 0.5f;
    EXPECT_THROW(scene.add_instance(g, sheared), Error);
    Transform<float> nan_pose = translation(std::nanf(""), 0.f, 0.f);
    EXPECT_THROW(scene.add_instance(g, nan_pose), Error);
    EXPECT_THROW(scene.add_instance(g, {}, {.margin = -1.f}), Error);
    EXPECT_THROW(scene.add_instance(g, {}, {.margin = INFINITY}), Error);
    EXPECT_EQ(scene.instance_count(), 0u);

    const InstanceId a = scene.add_instance(g, translation(1.f, 2.f, 3.f), {.user_data = 42});
    const InstanceId b = scene.add_instance(g, translation(5.f, 0.f, 0.f), {.group = 2});
    EXPECT_TRUE(scene.contains(a));
    EXPECT_EQ(scene.user_data(a), 42u);
    EXPECT_EQ(scene.options(b).group, 2u);
    EXPECT_EQ(scene.geometry_of(a), g);
    EXPECT_EQ(scene.pose(a).translation, Vec3f(1, 2, 3));
    scene.validate();

    scene.remove(a);
    EXPECT_FALSE(scene.contains(a));
    EXPECT_THROW(scene.set_pose(a, {}), Error);
    EXPECT_THROW(scene.remove(a), Error);
    EXPECT_THROW((void)scene.pose(a), Error);
    EXPECT_THROW((void)scene.world_box(a), Error);
    EXPECT_THROW(scene.set_options(a, {}), Error);
    const InstanceId c = scene.add_instance(g, {});  // reuses a's slot with the next generation
    EXPECT_EQ(c.index(), a.index());
    EXPECT_NE(c.generation(), a.generation());
    EXPECT_FALSE(scene.contains(a));
    EXPECT_THROW(scene.set_pose(a, {}), Error);
    EXPECT_THROW(scene.set_pose(InstanceId::from_bits(0x123456789ull), {}), Error);
    EXPECT_THROW(scene.set_pose(InstanceId(), {}), Error);

    // A batch with one bad id or pose changes nothing.
    const std::array<InstanceId, 2> ids{b, a};
    const std::array<Transform<float>, 2> poses{translation(9.f, 9.f, 9.f), Transform<float>{}};
    EXPECT_THROW(scene.set_poses(ids, poses), Error);
    EXPECT_EQ(scene.pose(b).translation, Vec3f(5, 0, 0));
    const std::array<InstanceId, 2> good{b, c};
    const std::array<Transform<float>, 2> bad_pose{translation(9.f, 9.f, 9.f), sheared};
    EXPECT_THROW(scene.set_poses(good, bad_pose), Error);
    EXPECT_EQ(scene.pose(b).translation, Vec3f(5, 0, 0));
    EXPECT_THROW(scene.set_poses(good, std::span<const Transform<float>>(poses.data(), 1)), Error);
    scene.set_poses(good, poses);
    EXPECT_EQ(scene.pose(b).translation, Vec3f(9, 9, 9));
    scene.validate();

    // Bad mesh indices.
    TriangleMesh broken = tetrahedron();
    broken.triangles[1][2] = 9;
    EXPECT_THROW(scene.add_mesh(broken), Error);
    EXPECT_EQ(scene.geometry_count(), 1u);
}

TEST(Scene, EmptyScenesAndEmptyGeometry) {
    Scene<double> scene;
    const Ray<double, 3> ray({0, 0, -5}, {0, 0, 1});
    EXPECT_FALSE(closest_hit(scene, ray));
    EXPECT_FALSE(any_hit(scene, ray));
    EXPECT_FALSE(closest_point(scene, Vec3d(0, 0, 0)));
    EXPECT_TRUE(scene.bounds().is_empty());
    scene.validate();
    // A mesh without triangles: its instances are kept but never hit or found.
    const GeometryId none = scene.add_mesh(BasicTriangleMesh<double>{});
    const InstanceId e = scene.add_instance(none, translation(0.0, 0.0, 1.0));
    EXPECT_TRUE(scene.contains(e));
    EXPECT_FALSE(closest_hit(scene, ray));
    EXPECT_FALSE(closest_point(scene, Vec3d(0, 0, 0)));
    std::vector<SceneHit<double>> all;
    all_hits(scene, ray, all);
    EXPECT_TRUE(all.empty());
    scene.validate();
    // Rays that cannot be traced miss; a negative tmin is an Error.
    EXPECT_FALSE(closest_hit(scene, Ray<double, 3>({0, 0, 0}, {0, 0, 0})));
    EXPECT_FALSE(closest_hit(scene, Ray<double, 3>({NAN, 0, 0}, {0, 0, 1})));
    EXPECT_THROW(closest_hit(scene, Ray<double, 3>({0, 0, 0}, {0, 0, 1}, -1.0)), Error);
    EXPECT_FALSE(closest_point(scene, Vec3d(NAN, 0, 0)));
}

// The world box is the hull's extent under the pose: it holds every world vertex and each side is
// within the pad of the exact extreme, which for a rotated long thin mesh is far tighter than the
// box of the rotated local box.
TEST(Scene, WorldBoxesAreTheHullsExtent) {
    SplitMix64 rng(7);
    TriangleMesh rod = make_torus(24, 8, 1.0f, 0.05f);
    for (auto& v : rod.vertices) v[0] *= 20;  // a long flat ring
    Scene<float> scene;
    const GeometryId g = scene.add_mesh(rod);
    for (int trial = 0; trial < 20; ++trial) {
        Transform<float> pose;
        pose.rotation = scene_test::random_rotation<float>(rng);
        pose.translation = Vec3f(float(rng.uniform(-1e3, 1e3)), 2.f, -7.f);
        const InstanceId id = scene.add_instance(g, pose);
        pose = scene.pose(id);  // as stored: the nearest rotation
        const Aabb<float, 3>& box = scene.world_box(id);
        LD lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (const auto& v : rod.vertices)
            for (std::size_t i = 0; i < 3; ++i) {
                const LD w = LD(pose.rotation[i][0]) * v[0] + LD(pose.rotation[i][1]) * v[1] +
                             LD(pose.rotation[i][2]) * v[2] + LD(pose.translation[i]);
                lo[i] = std::min(lo[i], w), hi[i] = std::max(hi[i], w);
            }
        // pad: (8 eps + deviation) * (|t| + 2 extent), extent 21: well under 1e-3 here.
        for (std::size_t i = 0; i < 3; ++i) {
            EXPECT_LE(LD(box.min[i]), lo[i]);
            EXPECT_GE(LD(box.max[i]), hi[i]);
            EXPECT_LT(lo[i] - LD(box.min[i]), 1e-3L);
            EXPECT_LT(LD(box.max[i]) - hi[i], 1e-3L);
        }
        scene.set_pose(id, translation(0.f, 0.f, 0.f));
        EXPECT_NEAR(scene.world_box(id).max[0], 21.f, 1e-3f);
        EXPECT_NEAR(scene.world_box(id).max[2], 0.05f, 1e-3f);
    }
    scene.validate();
    EXPECT_LE(scene.bounds().max[0], 21.001f);
}

// The top level's best-first walk: boxes in increasing distance, a shrinking bound ends it, and a
// walk started inside another's callback is independent of it.
TEST(Scene, DynamicTreeQueryNearestIsBestFirst) {
    SplitMix64 rng(3);
    DynamicTree<float, 3> tree;
    for (int i = 0; i < 200; ++i) {
        const Vec3f c(float(rng.uniform(-50, 50)), float(rng.uniform(-50, 50)),
                      float(rng.uniform(-50, 50)));
        tree.create(Aabb<float, 3>(c - Vec3f(0.5f), c + Vec3f(0.5f)));
    }
    const Vec3f p(1, 2, 3);
    std::vector<double> keys;
    int nested_count = 0;
    tree.query_nearest(p, [&](ProxyId id, double key) {
        const Aabb<float, 3>& b = tree.box(id);
        double expect = 0;
        for (std::size_t a = 0; a < 3; ++a) {
            const double g = std::max({double(b.min[a]) - p[a], double(p[a]) - b.max[a], 0.0});
            expect += g * g;
        }
        EXPECT_DOUBLE_EQ(key, expect);
        keys.push_back(key);
        if (keys.size() == 3) {
            tree.query_nearest(Vec3f(-40, 0, 0), [&](ProxyId, double) {
                ++nested_count;
                return INFINITY;
            });
        }
        return INFINITY;
    });
    EXPECT_EQ(keys.size(), 200u);
    EXPECT_EQ(nested_count, 200);
    EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
    // A bound of the first box's distance squared plus 100 stops at the boxes within it.
    std::size_t reported = 0;
    tree.query_nearest(p, [&](ProxyId, double key) {
        ++reported;
        return keys[0] + 100.0 + 0 * key;
    });
    EXPECT_EQ(reported, std::size_t(std::upper_bound(keys.begin(), keys.end(), keys[0] + 100.0) -
                                    keys.begin()));
    EXPECT_THROW(tree.query_nearest(Vec3f(NAN, 0, 0), [](ProxyId, double) { return 0.0; }), Error);
}

/// A random scene: `count` instances of a few meshes scaled by `scale`, rotated at random and
/// placed in a cube of side 6 * scale around `offset` (so many overlap), some touching.
template <class T>
struct RandomScene {
    Scene<T> scene;
    std::vector<InstanceId> ids;
    std::vector<GeometryId> geometry;
    double scale, offset;

    RandomScene(double scale_, double offset_, int count, std::uint64_t seed)
        : scale(scale_), offset(offset_) {
        SplitMix64 rng(seed);
        geometry.push_back(scene.add_mesh(scaled_mesh<T>(make_sphere(1), scale)));
        geometry.push_back(scene.add_mesh(scaled_mesh<T>(make_torus(12, 6), scale)));
        geometry.push_back(scene.add_mesh(scaled_mesh<T>(make_soup(40, seed), scale)));
        geometry.push_back(scene.add_mesh(scaled_mesh<T>(tetrahedron(), scale)));
        geometry.push_back(scene.add_mesh(BasicTriangleMesh<T>{}));
        for (int i = 0; i < count; ++i) add(rng);
        // Two touching copies: the tetrahedron's face x = 0 against a mirror image's.
        Transform<T> left = pose_near(rng, Vec<T, 3>{});
        left.rotation = Mat3<T>{};
        Transform<T> right = left;
        right.rotation = Mat3<T>{};
        right.rotation[0][0] = T(-1), right.rotation[1][1] = T(-1);  // a half turn about z
        ids.push_back(scene.add_instance(geometry[3], left));
        ids.push_back(scene.add_instance(geometry[3], right));
    }
    Transform<T> pose_near(SplitMix64& rng, const Vec<T, 3>&) {
        Transform<T> p;
        p.rotation = scene_test::random_rotation<T>(rng);
        for (std::size_t a = 0; a < 3; ++a)
            p.translation[a] = T(offset + scale * rng.uniform(-3.0, 3.0));
        return p;
    }
    void add(SplitMix64& rng) {
        const GeometryId g = geometry[rng.next() % geometry.size()];
        ids.push_back(scene.add_instance(g, pose_near(rng, {})));
    }
};

template <class T>
struct QueryChecker {
    const Scene<T>& scene;
    scene_test::WorldMesh<T> world;
    LD wobble_scale;  // the largest |coordinate| among the world mesh and the queries
    int checked_ids = 0, ties = 0, hits = 0;

    explicit QueryChecker(const Scene<T>& s) : scene(s), world(s) {}

    // What the scene and the test's world mesh may differ by, as a length: each rounds the
    // geometry's world or local coordinates once (eps/2 of |x| per coordinate, from both sides:
    // eps |x| per point), the rotation rounded to T is up to a few eps from orthogonal (R^T is
    // the scene's inverse), and the library's own ray and point tests err by a few eps of the
    // local coordinates. Sixteen eps of the largest coordinate bound them all.
    LD wobble(const Vec<T, 3>& query) const {
        LD m = world.largest;
        for (std::size_t a = 0; a < 3; ++a) m = std::max(m, std::fabs(LD(query[a])));
        return 16 * LD(std::numeric_limits<T>::epsilon()) * m;
    }

    void check_ray(const Ray<T, 3>& ray) {
        const LD wob = wobble(ray.origin) * 2;  // the ray's far end: at most twice as far out
        LD best_hit = INFINITY, best_tol = 0, earliest = INFINITY;
        bool any_sure = false, any_unsure = false;
        for (const auto& tri : world.triangles) {
            const scene_test::RayCrossing c = scene_test::cross(ray, tri, wob);
            if (c.kind == scene_test::Crossing::Miss) continue;
            earliest = std::min(earliest, c.t - c.t_tolerance);
            if (c.kind == scene_test::Crossing::Hit) {
                any_sure = true;
                if (c.t < best_hit) best_hit = c.t, best_tol = c.t_tolerance;
            } else {
                any_unsure = true;
            }
        }
        const SceneHit<T> h = closest_hit(scene, ray);
        if (any_sure) {
            ASSERT_TRUE(h) << "the scene missed a sure hit at t = " << double(best_hit);
        }
        if (!any_sure && !any_unsure) {
            ASSERT_FALSE(h) << "a hit at t = " << h.t << " where none is";
        }
        EXPECT_EQ(any_hit(scene, ray), bool(h));
        if (!h) return;
        ++hits;
        // The triangle reported is crossed there, no hit is surely nearer, and none is earlier.
        const auto* tri = world.find(h.instance, h.face);
        ASSERT_NE(tri, nullptr);
        EXPECT_EQ(scene.geometry_of(h.instance), h.geometry);
        const scene_test::RayCrossing c = scene_test::cross(ray, *tri, wob);
        ASSERT_NE(c.kind, scene_test::Crossing::Miss)
            << "instance " << h.instance.text() << " face " << h.face;
        EXPECT_LE(std::fabs(LD(h.t) - c.t),
                  c.t_tolerance + 4 * std::numeric_limits<T>::epsilon() * c.t);
        if (any_sure) {
            EXPECT_LE(LD(h.t),
                      best_hit + best_tol + 4 * std::numeric_limits<T>::epsilon() * best_hit);
        }
        EXPECT_GE(LD(h.t), earliest - 4 * std::numeric_limits<T>::epsilon() * std::fabs(earliest));
        // The world normal is the world triangle's, when the triangle is large next to the wobble.
        const scene_test::V3 e1 = scene_test::wide(tri->p[1]) - scene_test::wide(tri->p[0]);
        const scene_test::V3 e2 = scene_test::wide(tri->p[2]) - scene_test::wide(tri->p[0]);
        const scene_test::V3 n = scene_test::cross3(e1, e2);
        const LD longest = std::max({scene_test::norm3(e1), scene_test::norm3(e2)});
        if (wob * longest < 1e-3L * scene_test::norm3(n)) {
            const scene_test::V3 hn = scene_test::wide(h.normal);
            EXPECT_GT(scene_test::dot3(hn, n),
                      0.99L * scene_test::norm3(hn) * scene_test::norm3(n));
        }
        if (c.kind != scene_test::Crossing::Hit || std::fabs(c.t - best_hit) > 0) ++ties;
        ++checked_ids;
    }

    void check_all_hits(const Ray<T, 3>& ray) {
        const LD wob = wobble(ray.origin) * 2;
        std::vector<SceneHit<T>> all;
        all_hits(scene, ray, all);
        for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LE(all[i - 1].t, all[i].t);
        std::size_t sure = 0;
        for (const auto& tri : world.triangles) {
            const scene_test::RayCrossing c = scene_test::cross(ray, tri, wob);
            if (c.kind != scene_test::Crossing::Hit) continue;
            ++sure;
            bool found = false;
            for (const auto& h : all)
                found = found || (h.instance == tri.instance && h.face == tri.face);
            EXPECT_TRUE(found) << "all_hits left out instance " << tri.instance.text() << " face "
                               << tri.face;
        }
        for (const auto& h : all) {
            const auto* tri = world.find(h.instance, h.face);
            ASSERT_NE(tri, nullptr);
            EXPECT_NE(scene_test::cross(ray, *tri, wob).kind, scene_test::Crossing::Miss);
        }
        EXPECT_GE(all.size(), sure);
    }

    void check_point(const Vec<T, 3>& p) {
        const LD tol = wobble(p);
        const scene_test::V3 q = scene_test::wide(p);
        LD best = INFINITY;
        for (const auto& tri : world.triangles)
            best = std::min(best, scene_test::point_triangle_distance(q, tri));
        const ScenePoint<T> s = closest_point(scene, p);
        if (world.triangles.empty()) {
            EXPECT_FALSE(s);
            return;
        }
        ASSERT_TRUE(s);
        EXPECT_LE(std::fabs(LD(s.distance) - best),
                  tol + 4 * std::numeric_limits<T>::epsilon() * best)
            << "at " << p[0] << " " << p[1] << " " << p[2];
        // The point lies on the triangle reported (within the wobble), at the distance reported;
        // that triangle is among the nearest (ties: any of them).
        const auto* tri = world.find(s.instance, s.face);
        ASSERT_NE(tri, nullptr);
        EXPECT_EQ(scene.geometry_of(s.instance), s.geometry);
        EXPECT_LE(scene_test::point_triangle_distance(scene_test::wide(s.point), *tri), 2 * tol);
        EXPECT_LE(std::fabs(scene_test::norm3(scene_test::wide(s.point) - q) - LD(s.distance)),
                  2 * tol + 4 * std::numeric_limits<T>::epsilon() * best);
        EXPECT_LE(scene_test::point_triangle_distance(q, *tri), best + 2 * tol);
    }
};

template <class T>
void check_queries(RandomScene<T>& rs, int rays, int points, std::uint64_t seed) {
    rs.scene.validate();
    QueryChecker<T> check(rs.scene);
    SplitMix64 rng(seed);
    const double s = rs.scale, o = rs.offset;
    const auto random_point = [&](double reach) {
        return Vec<T, 3>(T(o + s * rng.uniform(-reach, reach)),
                         T(o + s * rng.uniform(-reach, reach)),
                         T(o + s * rng.uniform(-reach, reach)));
    };
    for (int i = 0; i < rays; ++i) {
        const Vec<T, 3> origin = random_point(6);
        Vec<T, 3> dir;
        if (i % 2 == 0 && !check.world.triangles.empty()) {  // aimed at a point inside a triangle
            const auto& tri = check.world.triangles[rng.next() % check.world.triangles.size()];
            const LD u = rng.uniform(0.1, 0.8), v = rng.uniform(0.1, 0.9 - double(u));
            for (std::size_t a = 0; a < 3; ++a)
                dir[a] = T((1 - u - v) * tri.p[0][a] + u * tri.p[1][a] + v * tri.p[2][a] -
                           LD(origin[a]));
        } else {
            const Vec<double, 3> d = rng.unit_vector();
            dir = Vec<T, 3>(T(d[0]), T(d[1]), T(d[2]));
        }
        Ray<T, 3> ray(origin, dir);
        if (i % 5 == 1) ray.tmax = T(0.5);  // a segment: half way to the target
        if (i % 7 == 2) ray.tmin = T(0.25);
        check.check_ray(ray);
        if (i % 4 == 0) check.check_all_hits(ray);
    }
    for (int i = 0; i < points; ++i) check.check_point(random_point(i % 3 == 0 ? 40 : 5));
    EXPECT_GT(check.hits, rays / 4);
}

struct Placement {
    double scale, offset;
};

class SceneQueries : public ::testing::TestWithParam<Placement> {};

TEST_P(SceneQueries, FloatAgreesWithTheWorldMesh) {
    RandomScene<float> rs(GetParam().scale, GetParam().offset, 24, 11);
    check_queries(rs, 240, 160, 3);
    // Poses change (one by one and in a batch), instances go and come: the answers follow.
    SplitMix64 rng(5);
    std::vector<InstanceId> moved;
    std::vector<Transform<float>> poses;
    for (std::size_t i = 0; i < rs.ids.size(); i += 2) {
        moved.push_back(rs.ids[i]);
        poses.push_back(rs.pose_near(rng, {}));
    }
    rs.scene.set_poses(moved, poses);
    rs.scene.set_pose(rs.ids[1], rs.pose_near(rng, {}));
    rs.scene.remove(rs.ids[3]);
    rs.scene.remove(rs.ids[5]);
    rs.add(rng);
    check_queries(rs, 120, 80, 4);
}

INSTANTIATE_TEST_SUITE_P(Placements, SceneQueries,
                         ::testing::Values(Placement{1, 0}, Placement{1e-6, 0}, Placement{1e6, 0},
                                           Placement{10, 1e5}, Placement{1e3, 1e6}));

TEST(SceneQueries, DoubleFarFromTheOrigin) {
    for (const Placement p : {Placement{1, 1e6}, Placement{1e-6, 1e5}, Placement{1e6, 1e6}}) {
        RandomScene<double> rs(p.scale, p.offset, 20, 21);
        check_queries(rs, 160, 100, 8);
    }
}

// Const queries on many threads at once, on a scene whose bottom-level trees are not built yet
// (the first queries build them, once): the answers are the serial ones.
TEST(SceneQueries, ManyThreadsBuildTheTreesOnceAndAgree) {
    RandomScene<float> rs(1, 0, 16, 31);
    std::vector<Ray<float, 3>> rays;
    std::vector<Vec3f> points;
    SplitMix64 rng(2);
    for (int i = 0; i < 200; ++i) {
        const Vec3f o(float(rng.uniform(-6, 6)), float(rng.uniform(-6, 6)),
                      float(rng.uniform(-6, 6)));
        const Vec3d d = rng.unit_vector();
        rays.push_back(Ray<float, 3>(o, Vec3f(float(d[0]), float(d[1]), float(d[2]))));
        points.push_back(o);
    }
    std::vector<std::vector<SceneHit<float>>> hits(4, std::vector<SceneHit<float>>(rays.size()));
    std::vector<std::vector<float>> distances(4, std::vector<float>(points.size()));
    std::vector<std::thread> threads;
    for (int k = 0; k < 4; ++k)
        threads.emplace_back([&, k] {
            closest_hits(rs.scene, std::span<const Ray<float, 3>>(rays), std::span(hits[k]));
            for (std::size_t i = 0; i < points.size(); ++i)
                distances[k][i] = closest_point(rs.scene, points[i]).distance;
        });
    for (auto& t : threads) t.join();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const SceneHit<float> serial = closest_hit(rs.scene, rays[i]);
        for (int k = 0; k < 4; ++k) {
            EXPECT_EQ(hits[k][i].t, serial.t);
            EXPECT_EQ(hits[k][i].face, serial.face);
            EXPECT_EQ(distances[k][i], closest_point(rs.scene, points[i]).distance);
        }
    }
}

// The batch calls on every thread give each ray the one-by-one answer (a scene whose trees the
// batch itself builds), and lengths that differ are Errors.
TEST(SceneQueries, BatchesOnAllThreadsEqualOneByOne) {
    RandomScene<float> rs(1, 0, 16, 37);
    std::vector<Ray<float, 3>> rays;
    SplitMix64 rng(5);
    for (int i = 0; i < 3000; ++i) {
        const Vec3f o(float(rng.uniform(-6, 6)), float(rng.uniform(-6, 6)),
                      float(rng.uniform(-6, 6)));
        const Vec3d d = rng.unit_vector();
        rays.push_back(Ray<float, 3>(o, Vec3f(float(d[0]), float(d[1]), float(d[2]))));
    }
    const std::span<const Ray<float, 3>> all(rays);
    std::vector<SceneHit<float>> hits(rays.size()), serial(rays.size());
    std::vector<std::uint8_t> occluded(rays.size(), 7), occluded_serial(rays.size(), 7);
    closest_hits(rs.scene, all, std::span(hits));  // every core
    any_hits(rs.scene, all, std::span(occluded), 0u);
    closest_hits(rs.scene, all, std::span(serial), 1u);
    any_hits(rs.scene, all, std::span(occluded_serial), 1u);
    int hit = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const SceneHit<float> one = closest_hit(rs.scene, rays[i]);
        EXPECT_EQ(hits[i].t, one.t);
        EXPECT_EQ(hits[i].face, one.face);
        EXPECT_EQ(hits[i].instance, one.instance);
        EXPECT_EQ(serial[i].t, one.t);
        EXPECT_EQ(occluded[i], std::uint8_t(any_hit(rs.scene, rays[i])));
        EXPECT_EQ(occluded_serial[i], occluded[i]);
        EXPECT_EQ(bool(occluded[i]), bool(one));  // any hit exactly when a closest hit
        hit += bool(one);
    }
    EXPECT_GT(hit, 150);  // the rays meet the scene: the comparison is not of misses only
    EXPECT_GT(int(rays.size()) - hit, 150);
    EXPECT_THROW(closest_hits(rs.scene, all, std::span(hits).first(5)), Error);
    EXPECT_THROW(any_hits(rs.scene, all, std::span(occluded).first(5)), Error);
}

}  // namespace
}  // namespace bvhkit

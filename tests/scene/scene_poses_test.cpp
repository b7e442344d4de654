// Scene poses and boxes: a pose within rigid_tolerance of a rotation is stored as the nearest
// rotation (so the collision queries' relative poses are rigid, and a closest point's distance is
// the distance to the reported point), the InstanceId / InstancePair order and the collision
// output's order after slots are reused, margins that stay local to their instance, set_poses'
// all-or-nothing batch, and the hull of the finite triangles only.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "bvhkit/scene/closest_point.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/rays.hpp"
#include "scene_support.hpp"

namespace bvhkit {
namespace {

using scene_test::LD;

template <class T>
BasicTriangleMesh<T> cube(T h) {
    BasicTriangleMesh<T> m;
    for (int i = 0; i < 8; ++i)
        m.vertices.push_back({(i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h});
    const std::uint32_t f[12][3] = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5},
                                    {0, 4, 5}, {0, 5, 1}, {2, 3, 7}, {2, 7, 6},
                                    {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
    for (const auto& t : f) m.triangles.push_back({t[0], t[1], t[2]});
    return m;
}

/// A pose whose rotation is the identity scaled by k: within rigid_tolerance for |k - 1| < 5e-5.
template <class T>
Transform<T> scaled(T k, Vec<T, 3> t) {
    Transform<T> p;
    for (std::size_t i = 0; i < 3; ++i) p.rotation[i][i] = k;
    p.translation = t;
    return p;
}

template <class T>
Transform<T> translation_pose(T x) {
    Transform<T> p;
    p.translation = {x, 0, 0};
    return p;
}

template <class T>
void near_rigid_poses_collide() {
    Scene<T> scene;
    const GeometryId g = scene.add_mesh(cube<T>(1));
    // Each pose is accepted (deviation ~6.6e-5), but R_a^T R_b would be ~1.3e-4 off a rotation.
    const T k = T(1) + T(3.3e-5);
    const Transform<T> pa = scaled<T>(k, {0, 0, 0}), pb = scaled<T>(k, {T(0.5), 0, 0});
    ASSERT_LE(rigid_deviation(pa.rotation), rigid_tolerance<T>());
    const InstanceId a = scene.add_instance(g, pa);
    const InstanceId b = scene.add_instance(g, pb);
    // Stored as the nearest rotation (here exactly the identity), the translation as given.
    EXPECT_LE(rigid_deviation(scene.pose(a).rotation),
              8 * double(std::numeric_limits<T>::epsilon()));
    EXPECT_EQ(scene.pose(b).translation, pb.translation);
    std::vector<InstancePair> pairs;
    ASSERT_NO_THROW(colliding_pairs(scene, pairs));
    ASSERT_EQ(pairs.size(), 1u);
    EXPECT_EQ(pairs[0], (InstancePair{a, b}));
    EXPECT_TRUE(any_collision(scene));
    InstanceOptions<T> o;
    o.margin = T(0.1);
    EXPECT_TRUE(collides_with(scene, g, pb, o));  // the caller's near-rigid pose, too
    std::vector<InstanceId> hit;
    colliding_instances(scene, g, scaled<T>(k, {T(5), 0, 0}), o, hit);
    EXPECT_TRUE(hit.empty());
    // set_pose and set_poses store the nearest rotation as well.
    scene.set_pose(a, scaled<T>(T(1) - T(3.3e-5), {T(0.25), 0, 0}));
    EXPECT_LE(rigid_deviation(scene.pose(a).rotation),
              8 * double(std::numeric_limits<T>::epsilon()));
    ASSERT_NO_THROW(colliding_pairs(scene, pairs));
    EXPECT_EQ(pairs.size(), 1u);
    scene.validate();
}

TEST(ScenePoses, NearRigidPosesCollideWithoutThrowing) {
    near_rigid_poses_collide<float>();
    near_rigid_poses_collide<double>();
}

// The stored rotation is the nearest one: a rotation rounded from an exact one stays within a
// few epsilons of it, and a near-rigid one comes back orthonormal.
TEST(ScenePoses, StoredRotationIsTheNearest) {
    SplitMix64 rng(11);
    Scene<double> scene;
    const GeometryId g = scene.add_mesh(cube<double>(1));
    for (int i = 0; i < 50; ++i) {
        Transform<double> p;
        p.rotation = scene_test::random_rotation<double>(rng);
        const Mat3<double> exact = p.rotation;
        // Off a rotation by up to ~5e-5 in each entry (within the tolerance).
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 3; ++c) p.rotation[r][c] += rng.uniform(-1.5e-5, 1.5e-5);
        if (rigid_deviation(p.rotation) > rigid_tolerance<double>()) continue;
        const InstanceId id = scene.add_instance(g, p);
        const Mat3<double>& s = scene.pose(id).rotation;
        EXPECT_LE(rigid_deviation(s), 1e-15);
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 3; ++c) EXPECT_NEAR(s[r][c], exact[r][c], 1e-4);
        Transform<double> q;
        q.rotation = exact;
        scene.set_pose(id, q);
        // Orthonormal to a few units of double's rounding already: stored as given, bit for bit.
        if (rigid_deviation(exact) <= 8 * std::numeric_limits<double>::epsilon()) {
            for (std::size_t r = 0; r < 3; ++r)
                EXPECT_EQ(scene.pose(id).rotation.row[r], exact.row[r]);
        }
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 3; ++c)
                EXPECT_NEAR(scene.pose(id).rotation[r][c], exact[r][c], 4e-16);
        // Just beyond that: the nearest rotation replaces it, closer to orthonormal than given.
        Transform<double> off = q;
        for (std::size_t c = 0; c < 3; ++c) off.rotation[0][c] *= 1 + 1e-13;
        scene.set_pose(id, off);
        EXPECT_NE(scene.pose(id).rotation.row[0], off.rotation.row[0]);
        EXPECT_LE(rigid_deviation(scene.pose(id).rotation), 1e-15);
    }
    scene.validate();
}

// With a near-rigid pose, R^T is not R's inverse: the point was measured at R^T (p - t) and the
// nearer instance could lose. Stored orthonormal, the distance is the distance to the point found.
TEST(ScenePoses, NearRigidClosestPointMatchesItsDistance) {
    Scene<double> scene;
    const GeometryId g = scene.add_mesh(cube<double>(1));
    const double k = 1 - 3.3e-5;
    const InstanceId a = scene.add_instance(g, scaled<double>(k, {1000, 0, 0}));
    const InstanceId b = scene.add_instance(g, scaled<double>(1, {0, 999.99, 0}));
    (void)a;
    const ScenePoint<double> q = closest_point(scene, Vec3d(0, 0, 0));
    ASSERT_TRUE(q);
    EXPECT_EQ(q.instance, b);  // 998.99 away; a is 999 away
    EXPECT_NEAR(q.distance, 998.99, 1e-9);
    EXPECT_NEAR(std::sqrt(dot(q.point, q.point)), q.distance, 1e-9);
}

// InstanceId orders by slot, then generation; colliding_pairs' output is sorted by that order
// after slots are reused (the raw bits put the generation first).
TEST(ScenePoses, PairsAreSortedAfterSlotsAreReused) {
    Scene<float> scene;
    const GeometryId g = scene.add_mesh(cube<float>(1));
    InstanceId a = scene.add_instance(g, {});
    scene.remove(a);
    a = scene.add_instance(g, {});  // slot 0, generation 1
    const InstanceId b = scene.add_instance(g, {});
    const InstanceId c = scene.add_instance(g, {});
    ASSERT_EQ(a.index(), 0);
    ASSERT_GT(a.generation(), b.generation());
    EXPECT_LT(a, b);
    EXPECT_LT(b, c);
    EXPECT_LT(InstanceId(), a);
    std::vector<InstancePair> out;
    colliding_pairs(scene, out);
    ASSERT_EQ(out.size(), 3u);
    EXPECT_TRUE(std::is_sorted(out.begin(), out.end()));
    EXPECT_TRUE(std::binary_search(out.begin(), out.end(), InstancePair{a, b}));
    EXPECT_TRUE(std::binary_search(out.begin(), out.end(), InstancePair{a, c}));
    EXPECT_TRUE(std::binary_search(out.begin(), out.end(), InstancePair{b, c}));
    std::vector<InstanceId> hit;
    colliding_instances(scene, g, Transform<float>{}, {}, hit);
    EXPECT_TRUE(std::is_sorted(hit.begin(), hit.end()));
    EXPECT_EQ(hit.size(), 3u);
}

// One instance with a large margin: the top-level boxes are each instance's world box grown by
// its own margin (so the others' queries stay small), and the pairs are those of brute force over
// every pair with the single-pair tests.
TEST(ScenePoses, LargeMarginStaysWithItsInstance) {
    Scene<float> scene;
    const GeometryId g = scene.add_mesh(cube<float>(0.4f));
    std::vector<InstanceId> ids;
    for (int i = 0; i < 1000; ++i) {
        Transform<float> p;
        p.translation = {float(i % 10), float((i / 10) % 10), float(i / 100)};
        ids.push_back(scene.add_instance(g, p));
    }
    scene.set_options(ids[0], {.margin = 2.5f});
    scene.set_options(ids[555], {.margin = 0.1f});
    scene.validate();
    for (const InstanceId id : ids) {
        const Aabb<float, 3> top = scene.top_level().box(id.proxy());
        const Aabb<float, 3> want =
            scene_detail::grown(scene.world_box(id), scene.options(id).margin);
        EXPECT_EQ(top.min, want.min);
        EXPECT_EQ(top.max, want.max);
    }
    std::vector<InstancePair> pairs;
    colliding_pairs(scene, pairs);
    std::set<std::pair<std::int32_t, std::int32_t>> found, expected;
    for (const auto& p : pairs) found.insert({p.a.index(), p.b.index()});
    const auto& model = scene.geometry(g).collision_model();
    for (std::size_t i = 0; i < ids.size(); ++i)
        for (std::size_t j = i + 1; j < ids.size(); ++j) {
            const Transform<float>& pa = scene.pose(ids[i]);
            const Transform<float>& pb = scene.pose(ids[j]);
            const float m = scene.options(ids[i]).margin + scene.options(ids[j]).margin;
            Transform<float> rel;
            rel.translation = pb.translation - pa.translation;  // identity rotations
            if (std::fabs(rel.translation[0]) > 4 || std::fabs(rel.translation[1]) > 4 ||
                std::fabs(rel.translation[2]) > 4)
                continue;  // 3.2 apart at the least: beyond every margin sum here
            const bool hit =
                m == 0.f ? collides(model, model, rel) : distance(model, model, rel).distance <= m;
            if (hit) expected.insert({ids[i].index(), ids[j].index()});
        }
    EXPECT_EQ(found, expected);
    EXPECT_GT(expected.size(), 20u);
    // A margin change regrows only that instance's top-level box; back to 0, the box is tight.
    scene.set_options(ids[0], {});
    EXPECT_EQ(scene.top_level().box(ids[0].proxy()).max, scene.world_box(ids[0]).max);
    scene.validate();
}

// Far from the origin the pad no longer grows with |t|: each side of a world box is within T's
// spacing there (plus a few epsilons of the mesh's size) of the exact extent, and the walks still
// find what a loop over every instance finds with the same transforms into the instances' frames.
template <class T>
void far_boxes_are_tight(double offset, std::uint64_t seed) {
    using W = AccurateScalar<T>;
    SplitMix64 rng(seed);
    Scene<T> scene;
    const GeometryId g[2] = {scene.add_mesh(cube<T>(T(0.05))), scene.add_mesh(cube<T>(T(0.5)))};
    std::vector<InstanceId> ids;
    for (int i = 0; i < 300; ++i) {
        Transform<T> p;
        p.rotation = scene_test::random_rotation<T>(rng);
        for (std::size_t a = 0; a < 3; ++a) p.translation[a] = T(offset + rng.uniform(-4.0, 4.0));
        ids.push_back(scene.add_instance(g[i % 2], p));
    }
    scene.validate();
    for (const InstanceId id : ids) {
        const SceneInstance<T>& r = scene.instance(id);
        const Aabb<T, 3>& box = scene.world_box(id);
        for (std::size_t a = 0; a < 3; ++a) {
            LD lo = INFINITY, hi = -INFINITY;
            for (const auto& v : scene.geometry(r.geometry).mesh().vertices) {
                const LD w = LD(r.pose.rotation[a][0]) * v[0] + LD(r.pose.rotation[a][1]) * v[1] +
                             LD(r.pose.rotation[a][2]) * v[2] + LD(r.pose.translation[a]);
                lo = std::min(lo, w), hi = std::max(hi, w);
            }
            const LD spacing =
                LD(std::nextafter(T(hi), std::numeric_limits<T>::infinity())) - LD(T(hi));
            // One spacing for the outward rounding, one more where the pad crosses a boundary,
            // and the bound the box adds for its extremes taken in double (4 eps_d of
            // 3.01 E + |t|: a few double spacings far out, below a float's).
            const LD slack = 2 * spacing + 64 * LD(std::numeric_limits<T>::epsilon()) +
                             8 * LD(std::numeric_limits<double>::epsilon()) *
                                 (std::fabs(LD(r.pose.translation[a])) + 4);
            EXPECT_LE(LD(box.min[a]), lo);
            EXPECT_GE(LD(box.max[a]), hi);
            EXPECT_LE(lo - LD(box.min[a]), slack) << "offset " << offset;
            EXPECT_LE(LD(box.max[a]) - hi, slack) << "offset " << offset;
        }
    }
    for (int k = 0; k < 600; ++k) {
        Vec<T, 3> o;
        for (std::size_t a = 0; a < 3; ++a) o[a] = T(offset + rng.uniform(-6.0, 6.0));
        const Vec<double, 3> d = rng.unit_vector();
        const Ray<T, 3> ray(o, Vec<T, 3>(T(d[0]), T(d[1]), T(d[2])));
        T best_t = std::numeric_limits<T>::infinity(), best_d = best_t;
        for (const InstanceId id : ids) {
            const SceneInstance<T>& r = scene.instance(id);
            const SceneGeometry<T>& geo = scene.geometry(r.geometry);
            const Hit<T> h =
                geo.ray_tree().closest_hit(scene_detail::local_ray(r.pose, ray, ray.tmax));
            if (h) best_t = std::min(best_t, h.t);
            const MeshPoint<T> m =
                geo.closest_point_tree().closest_point(scene_detail::to_local_point<W>(r.pose, o));
            if (m) best_d = std::min(best_d, m.distance);
        }
        EXPECT_EQ(closest_hit(scene, ray).t, best_t) << "ray " << k << " offset " << offset;
        EXPECT_EQ(closest_point(scene, o).distance, best_d)
            << "point " << k << " offset " << offset;
    }
}

TEST(ScenePoses, BoxesFarOutAreTightAndTheWalksAgree) {
    far_boxes_are_tight<float>(0, 1);
    far_boxes_are_tight<float>(1e5, 2);
    far_boxes_are_tight<float>(1e6, 3);
    far_boxes_are_tight<double>(1e6, 4);
    far_boxes_are_tight<double>(1e12, 5);
}

// Conversions from the wider type to T beyond T's range are checked, not undefined: the rounding
// helpers saturate to the infinity (or the largest value) on the value's side, and a ray or point
// that leaves T's range in an instance's frame misses (or skips) that instance.
TEST(ScenePoses, OutOfRangeLocalCoordinates) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    constexpr float big = std::numeric_limits<float>::max();
    EXPECT_EQ(scene_detail::round_up<float>(1e39), inf);
    EXPECT_EQ(scene_detail::round_down<float>(1e39), big);
    EXPECT_EQ(scene_detail::round_down<float>(-1e39), -inf);
    EXPECT_EQ(scene_detail::round_up<float>(-1e39), -big);
    EXPECT_EQ(scene_detail::narrow<float>(1e39), inf);
    EXPECT_EQ(scene_detail::narrow<float>(-1e39), -inf);
    EXPECT_EQ(scene_detail::narrow<float>(0.5), 0.5f);

    Scene<float> scene;
    const GeometryId g = scene.add_mesh(cube<float>(1));
    Transform<float> turned;
    turned.rotation = rotation_about(Vec3f(0, 0, 1), 0.78539816f);
    const InstanceId a = scene.add_instance(g, turned);
    // R^T d of (3e38, 3e38, 0) is 4.2e38 along x: beyond float, so a miss of that instance.
    const Ray3f huge({-10, -10, 0}, {3e38f, 3e38f, 0});
    EXPECT_FALSE(closest_hit(scene, huge));
    EXPECT_FALSE(any_hit(scene, huge));
    std::vector<SceneHit<float>> hits;
    all_hits(scene, huge, hits);
    EXPECT_TRUE(hits.empty());
    EXPECT_TRUE(closest_hit(scene, Ray3f({-10, -10, 0}, {1, 1, 0})));
    // p - t is 6e38 for the instance at -3e38: skipped; the one at the origin is found.
    scene.add_instance(g, translation_pose(-3e38f));
    const ScenePoint<float> q = closest_point(scene, Vec3f(3e38f, 0, 0));
    ASSERT_TRUE(q);
    EXPECT_EQ(q.instance, a);
    EXPECT_EQ(q.distance, 3e38f);  // 3e38 - 1 in float
}

// A batch whose later pose puts a box beyond float's range changes nothing; a displacement that
// overflows (a jump across the whole range) is only the fat box's prediction, and is accepted.
TEST(ScenePoses, SetPosesIsAllOrNothing) {
    Scene<float> scene;
    const GeometryId g = scene.add_mesh(cube<float>(1));
    const GeometryId huge = scene.add_mesh(cube<float>(1e37f));
    const InstanceId a = scene.add_instance(g, {});
    const InstanceId b = scene.add_instance(huge, {});
    std::array<InstanceId, 2> ids{a, b};
    std::array<Transform<float>, 2> poses;
    poses[0].translation = {5, 0, 0};
    poses[1].translation = {3.4e38f, 0, 0};  // b's box would reach past FLT_MAX
    EXPECT_THROW(scene.set_poses(ids, poses), Error);
    EXPECT_EQ(scene.pose(a).translation, Vec3f(0, 0, 0));
    EXPECT_EQ(scene.pose(b).translation, Vec3f(0, 0, 0));
    scene.validate();

    const InstanceId c = scene.add_instance(g, translation_pose(-3e38f));
    ids = {a, c};
    poses[1].translation = {3e38f, 0, 0};
    EXPECT_NO_THROW(scene.set_poses(ids, poses));
    EXPECT_EQ(scene.pose(a).translation, Vec3f(5, 0, 0));
    EXPECT_EQ(scene.pose(c).translation, Vec3f(3e38f, 0, 0));
    scene.validate();
    EXPECT_THROW(scene.add_instance(huge, translation_pose(3.4e38f)), Error);
    EXPECT_EQ(scene.instance_count(), 3u);
    scene.validate();
}

// A triangle with a NaN corner is never hit, found or collided with, so its finite corners do not
// widen the instance's box.
TEST(ScenePoses, HullOfTheFiniteTrianglesOnly) {
    BasicTriangleMesh<float> m = cube<float>(1);
    m.vertices.push_back({std::numeric_limits<float>::quiet_NaN(), 0, 0});
    m.vertices.push_back({100, 100, 100});
    m.triangles.push_back({8, 9, 0});
    Scene<float> scene;
    const GeometryId g = scene.add_mesh(m);
    const InstanceId a = scene.add_instance(g, {});
    EXPECT_EQ(scene.geometry(g).hull_vertices().size(), 8u);
    EXPECT_LT(scene.world_box(a).max[0], 1.001f);
    EXPECT_LT(scene.world_box(a).max[1], 1.001f);
    const ScenePoint<float> q = closest_point(scene, Vec3f(50, 50, 50));
    ASSERT_TRUE(q);
    EXPECT_NEAR(q.distance, std::sqrt(3.f) * 49, 1e-3f);
    scene.validate();
}

}  // namespace
}  // namespace bvhkit

// Scene collision: the colliding pairs, any_collision and a posed mesh against the scene, judged
// against analytic answers (rotated spheres: polyhedra between an inner and an outer ball), the
// single-pair collide/distance (the scene's culling must lose none), and a brute
// force triangle-triangle loop over the world-space triangles on small meshes; group/mask
// filters, margins, the ignore list, touching instances, pose changes and stale ids. The
// single-pair reference runs on every pair whose centres are not surely too far apart.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/primitives/triangle_triangle.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/face_contacts.hpp"
#include "scene_support.hpp"

namespace bvhkit {
namespace {

using scene_test::LD;
using scene_test::sphere_mesh;

/// The radii of the balls a convex polyhedron around the origin lies between: the least distance
/// of a face's plane, the largest of a vertex (long double).
template <class T>
void ball_radii(const BasicTriangleMesh<T>& m, LD& inner, LD& outer) {
    inner = INFINITY, outer = 0;
    for (const auto& v : m.vertices)
        outer = std::max(outer, scene_test::norm3(scene_test::wide(v)));
    for (const auto& t : m.triangles) {
        const scene_test::V3 a = scene_test::wide(m.vertices[t[0]]),
                             b = scene_test::wide(m.vertices[t[1]]),
                             c = scene_test::wide(m.vertices[t[2]]);
        const scene_test::V3 n = scene_test::cross3(b - a, c - a);
        inner = std::min(inner, std::fabs(scene_test::dot3(n, a)) / scene_test::norm3(n));
    }
}

template <class T>
Transform<T> relative_pose_ld(const Transform<T>& a, const Transform<T>& b) {
    Transform<T> r;
    for (std::size_t i = 0; i < 3; ++i) {
        for (std::size_t j = 0; j < 3; ++j) {
            LD s = 0;
            for (std::size_t k = 0; k < 3; ++k) s += LD(a.rotation[k][i]) * LD(b.rotation[k][j]);
            r.rotation[i][j] = T(s);
        }
        LD s = 0;
        for (std::size_t k = 0; k < 3; ++k)
            s += LD(a.rotation[k][i]) * (LD(b.translation[k]) - LD(a.translation[k]));
        r.translation[i] = T(s);
    }
    return r;
}

/// Spheres at random: every pair's answer is known from the centres' distance d alone, unless d
/// falls in the band between the inner and outer balls (then the pair is skipped by the analytic
/// check, and judged by the single-pair reference only).
template <class T>
void check_spheres(double scale, double offset, std::uint64_t seed) {
    SplitMix64 rng(seed);
    Scene<T> scene;
    const BasicTriangleMesh<T> mesh = sphere_mesh<T>(1, scale);
    const GeometryId g = scene.add_mesh(mesh);
    LD inner, outer;
    ball_radii(mesh, inner, outer);
    ASSERT_GT(inner, 0.85L * scale);
    std::vector<InstanceId> ids;
    for (int i = 0; i < 40; ++i) {
        Transform<T> pose;
        pose.rotation = scene_test::random_rotation<T>(rng);
        for (std::size_t a = 0; a < 3; ++a)
            pose.translation[a] = T(offset + scale * rng.uniform(-5.0, 5.0));
        InstanceOptions<T> o;
        o.margin = T(scale * std::array<double, 3>{0, 0.05, 0.3}[rng.next() % 3]);
        o.group = 1u << (rng.next() % 3);
        o.mask = rng.next() % 4 == 0 ? ~o.group : 0xFFFFFFFFu;  // some never meet their own group
        o.user_data = std::uint64_t(i);
        ids.push_back(scene.add_instance(g, pose, o));
    }
    std::vector<InstancePair> ignore;
    for (int k = 0; k < 30; ++k) {
        const InstanceId a = ids[rng.next() % ids.size()], b = ids[rng.next() % ids.size()];
        if (a != b) ignore.push_back({b, a});  // either order
    }
    const auto is_ignored = [&](InstanceId a, InstanceId b) {
        for (const auto& p : ignore)
            if ((p.a == a && p.b == b) || (p.a == b && p.b == a)) return true;
        return false;
    };
    for (int round = 0; round < 2; ++round) {
        scene.validate();
        std::vector<InstancePair> pairs;
        colliding_pairs(scene, pairs, ignore);
        EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
        std::set<std::pair<std::int32_t, std::int32_t>> found;
        for (const auto& p : pairs) {
            EXPECT_LT(p.a.index(), p.b.index());
            found.insert({p.a.index(), p.b.index()});
        }
        EXPECT_EQ(found.size(), pairs.size());
        const LD tol = 1e-4L * scale;  // the float rotation's deviation and the vertices' rounding
        int sure = 0, expected_count = 0;
        for (std::size_t i = 0; i < ids.size(); ++i)
            for (std::size_t j = i + 1; j < ids.size(); ++j) {
                const InstanceId a = ids[i], b = ids[j];
                const bool reported = found.count({a.index(), b.index()}) > 0;
                const auto& oa = scene.options(a);
                const auto& ob = scene.options(b);
                const bool filtered = !((oa.group & ob.mask) && (ob.group & oa.mask));
                if (filtered || is_ignored(a, b)) {
                    EXPECT_FALSE(reported);
                    continue;
                }
                const T m = oa.margin + ob.margin;
                // The analytic answer where the centres settle it: apart by more than the outer
                // balls (no single-pair call needed), or closer than the inner ones.
                const LD d = scene_test::norm3(scene_test::wide(scene.pose(a).translation) -
                                               scene_test::wide(scene.pose(b).translation));
                if (d - 2 * outer > LD(m) + tol) {
                    EXPECT_FALSE(reported) << "d " << double(d);
                    ++sure;
                    continue;
                }
                if (d > 0 && d - 2 * inner <= LD(m) - tol) {
                    EXPECT_TRUE(reported) << "d " << double(d);
                    ++sure;
                }
                // The single-pair reference on every pair near enough to matter.
                const SceneGeometry<T>& geo = scene.geometry(g);
                const Transform<T> rel = relative_pose_ld(scene.pose(a), scene.pose(b));
                const bool single =
                    m == T(0)
                        ? collides(geo.collision_model(), geo.collision_model(), rel)
                        : distance(geo.collision_model(), geo.collision_model(), rel).distance <= m;
                EXPECT_EQ(reported, single) << "pair " << a.text() << " " << b.text();
                expected_count += single;
            }
        EXPECT_GT(sure, 400);
        EXPECT_GT(expected_count, 3);
        EXPECT_EQ(any_collision(scene, ignore), !pairs.empty());
        std::vector<InstancePair> none;
        std::vector<InstancePair> all_ignored = ignore;
        all_ignored.insert(all_ignored.end(), pairs.begin(), pairs.end());
        colliding_pairs(scene, none, all_ignored);
        EXPECT_TRUE(none.empty());
        EXPECT_FALSE(any_collision(scene, all_ignored));

        // The same sphere posed apart from the scene: the instances it meets, by the centres.
        for (int k = 0; k < 20; ++k) {
            Transform<T> pose;
            pose.rotation = scene_test::random_rotation<T>(rng);
            for (std::size_t a = 0; a < 3; ++a)
                pose.translation[a] = T(offset + scale * rng.uniform(-5.0, 5.0));
            InstanceOptions<T> o;
            o.margin = T(scale * 0.1);
            std::vector<InstanceId> hit;
            colliding_instances(scene, g, pose, o, hit);
            EXPECT_EQ(collides_with(scene, g, pose, o), !hit.empty());
            for (const InstanceId b : ids) {
                const bool reported = std::find(hit.begin(), hit.end(), b) != hit.end();
                const T m = o.margin + scene.options(b).margin;
                const bool filtered =
                    !((o.group & scene.options(b).mask) && (scene.options(b).group & o.mask));
                const LD d = scene_test::norm3(scene_test::wide(pose.translation) -
                                               scene_test::wide(scene.pose(b).translation));
                if (filtered) {
                    EXPECT_FALSE(reported);
                } else if (d - 2 * inner <= LD(m) - tol) {
                    EXPECT_TRUE(reported);
                } else if (d - 2 * outer > LD(m) + tol) {
                    EXPECT_FALSE(reported);
                }
            }
        }
        // Half the instances move (a batch), one is removed and its id goes stale.
        std::vector<InstanceId> moved;
        std::vector<Transform<T>> poses;
        for (std::size_t i = 0; i < ids.size(); i += 2) {
            Transform<T> pose = scene.pose(ids[i]);
            for (std::size_t a = 0; a < 3; ++a)
                pose.translation[a] = T(offset + scale * rng.uniform(-5.0, 5.0));
            moved.push_back(ids[i]);
            poses.push_back(pose);
        }
        scene.set_poses(moved, poses);
        const InstanceId gone = ids.back();
        scene.remove(gone);
        ids.pop_back();
        EXPECT_THROW(scene.set_pose(gone, {}), Error);
    }
}

TEST(SceneCollision, SpheresAgreeWithCentresAndSinglePairs) {
    check_spheres<float>(1, 0, 1);
    check_spheres<float>(1e-6, 0, 2);
    check_spheres<float>(1e6, 0, 3);
    check_spheres<float>(100, 1e6, 4);
    check_spheres<double>(1, 1e6, 5);
}

// Brute force: every pair of world-space triangles (moved by the test in long double) of every
// pair of instances, small meshes placed at random (a pair touching by chance would be a tie
// between the two roundings; at random it does not happen).
TEST(SceneCollision, PairsAgreeWithATriangleLoop) {
    SplitMix64 rng(9);
    Scene<double> scene;
    BasicTriangleMesh<double> tetra;
    tetra.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    tetra.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    const GeometryId geometry[3] = {scene.add_mesh(sphere_mesh<double>(0, 0.7)),
                                    scene.add_mesh(tetra), scene.add_mesh(make_soup(15, 3))};
    for (int i = 0; i < 30; ++i) {
        Transform<double> pose;
        pose.rotation = scene_test::random_rotation<double>(rng);
        for (std::size_t a = 0; a < 3; ++a) pose.translation[a] = 1e5 + rng.uniform(-2.5, 2.5);
        scene.add_instance(geometry[rng.next() % 3], pose);
    }
    const scene_test::WorldMesh<double> world(scene);
    std::set<std::pair<std::int32_t, std::int32_t>> expected;
    std::set<std::array<std::int64_t, 4>> expected_faces;
    for (const auto& x : world.triangles)
        for (const auto& y : world.triangles)
            if (x.instance.index() < y.instance.index() &&
                triangles_intersect(Triangle<double>{x.p[0], x.p[1], x.p[2]},
                                    Triangle<double>{y.p[0], y.p[1], y.p[2]})) {
                expected.insert({x.instance.index(), y.instance.index()});
                expected_faces.insert({x.instance.index(), y.instance.index(), x.face, y.face});
            }
    std::vector<InstancePair> pairs;
    colliding_pairs(scene, pairs);
    std::set<std::pair<std::int32_t, std::int32_t>> found;
    for (const auto& p : pairs) found.insert({p.a.index(), p.b.index()});
    EXPECT_EQ(found, expected);
    EXPECT_GT(expected.size(), 5u);
    EXPECT_EQ(any_collision(scene), !expected.empty());
    // The face contacts: the same triangle pairs as the loop, each segment on both triangles.
    std::vector<SceneFaceContact<double>> contacts;
    colliding_faces(scene, contacts);
    std::set<std::array<std::int64_t, 4>> found_faces;
    for (const auto& c : contacts) {
        EXPECT_FALSE(c.separated);
        found_faces.insert({c.a.index(), c.b.index(), c.face_a, c.face_b});
        for (const auto& end : {c.p, c.q}) {
            EXPECT_LT(scene_test::point_triangle_distance(scene_test::wide(end),
                                                          *world.find(c.a, c.face_a)),
                      1e-8);
            EXPECT_LT(scene_test::point_triangle_distance(scene_test::wide(end),
                                                          *world.find(c.b, c.face_b)),
                      1e-8);
        }
    }
    EXPECT_EQ(found_faces, expected_faces);
    EXPECT_EQ(found_faces.size(), contacts.size());  // each triangle pair once
}

// Touching counts as colliding; a gap does not, unless the margins cover it.
TEST(SceneCollision, TouchingGapsAndMargins) {
    Scene<double> scene;
    BasicTriangleMesh<double> tetra;
    tetra.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    tetra.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    const GeometryId g = scene.add_mesh(tetra);
    Transform<double> left, right;
    right.rotation[0][0] = -1, right.rotation[1][1] = -1;  // half turn about z: touches along z
    for (const double far : {0.0, 1e6}) {
        left.translation = right.translation = {far, far, far};
        const InstanceId a = scene.add_instance(g, left);
        const InstanceId b = scene.add_instance(g, right);
        std::vector<InstancePair> pairs;
        colliding_pairs(scene, pairs);
        ASSERT_EQ(pairs.size(), 1u);
        // Slots are reused in the other order on the second pass: a pair runs by slot.
        EXPECT_EQ(pairs[0], a.index() < b.index() ? (InstancePair{a, b}) : (InstancePair{b, a}));
        // Apart by 1e-3 along x: no contact, until the margins add up to the gap.
        right.translation[0] = far - 1e-3;
        scene.set_pose(b, right);
        EXPECT_FALSE(any_collision(scene));
        scene.set_options(b, {.margin = 4e-4});
        EXPECT_FALSE(any_collision(scene));
        scene.set_options(a, {.margin = 6.5e-4});
        EXPECT_TRUE(any_collision(scene));
        // Colliding through the margins only: one separated entry, the closest points 1e-3 apart.
        std::vector<SceneFaceContact<double>> contacts;
        colliding_faces(scene, contacts);
        ASSERT_EQ(contacts.size(), 1u);
        EXPECT_TRUE(contacts[0].separated);
        EXPECT_NEAR(double(scene_test::norm3(scene_test::wide(contacts[0].p) -
                                             scene_test::wide(contacts[0].q))),
                    1e-3, 1e-9);
        // The left tetrahedron's point on its face x = far, the right one's at far - 1e-3.
        const bool left_first = contacts[0].a == a;
        EXPECT_NEAR((left_first ? contacts[0].p : contacts[0].q)[0], far, 1e-9);
        EXPECT_NEAR((left_first ? contacts[0].q : contacts[0].p)[0], far - 1e-3, 1e-9);
        // Groups that exclude each other never collide.
        scene.set_options(a, {.group = 1, .mask = 1, .margin = 1});
        scene.set_options(b, {.group = 2, .mask = 3, .margin = 1});
        EXPECT_FALSE(any_collision(scene));
        scene.remove(a);
        scene.remove(b);
        EXPECT_FALSE(any_collision(scene));
        right.translation[0] = far;
    }
    std::vector<InstanceId> out;
    EXPECT_THROW(colliding_instances(scene, GeometryId(3), left, {}, out), Error);
    EXPECT_THROW(colliding_instances(scene, g, left, {.margin = -1}, out), Error);
}

}  // namespace
}  // namespace bvhkit

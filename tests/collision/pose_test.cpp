// Collision under a pose: the pair sets on the shared meshes over the C1 poses equal an exact
// reference that carries B's corners into A's frame exactly (R x + t as real numbers, as collide()
// decides); poses that are not finite and rigid are rejected;
// far-apart models get a finite distance.
#include <gtest/gtest.h>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/kdop.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "bvhkit/volumes/sphere.hpp"
#include "collision_support.hpp"
#include "exact_reference.hpp"
#include "posed_reference.hpp"
#include "random_rigid_poses.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

/// Every pair (i in a, j in b) that meets with B's corners carried into A's frame exactly
/// (posed_reference.hpp), as collide() decides.
PairSet exact_pairs(const std::vector<Triangle<float>>& a, const std::vector<Triangle<float>>& b,
                    const Transform<float>& pose) {
    return exact_posed_pairs(a, b, pose);
}

template <class V>
PairSet collide_pairs(const CollisionModel<V>& m, const Transform<float>& pose) {
    CollideResult<float> r;
    CollideOptions o;
    o.segments = false;
    collide(m, m, pose, o, r);
    PairSet got;
    for (const auto& c : r.contacts) got.insert({c.triangle_a, c.triangle_b});
    EXPECT_EQ(got.size(), r.contacts.size());
    return got;
}

void check_c1_poses(const char* name) {
    const auto path = shared_mesh(name);
    if (path.empty()) GTEST_SKIP() << name << " not found in " << data_dirs_text();
    const TriangleMesh mesh = read_mesh(path);
    const auto tris = mesh_triangles(mesh);
    // C1's poses (bench/workloads/collide_bench.cpp): the same generator and seed; all 1,000
    // under BVHKIT_TEST_SCALE=full.
    const auto poses =
        random_rigid_poses(mesh.bounds(), full_scale() ? 1000 : scaled(60, 10), 2026);
    const CollisionModel<Aabb3f> aabb(mesh);
    const CollisionModel<Obb<float>> obb(mesh);
    const CollisionModel<Rss<float>> rss(mesh);
    const CollisionModel<Kdop<float, 18>> kdop(mesh);
    std::size_t colliding = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
        const PairSet want = exact_pairs(tris, tris, poses[i]);
        colliding += !want.empty();
        ASSERT_EQ(collide_pairs(aabb, poses[i]), want) << name << " pose " << i;
        ASSERT_EQ(collide_pairs(obb, poses[i]), want) << name << " pose " << i;
        ASSERT_EQ(collide_pairs(rss, poses[i]), want) << name << " pose " << i;
        ASSERT_EQ(collide_pairs(kdop, poses[i]), want) << name << " pose " << i;
        ASSERT_EQ(collides(obb, obb, poses[i]), !want.empty()) << name << " pose " << i;
    }
    EXPECT_GT(colliding, poses.size() / 4);
    EXPECT_LT(colliding, poses.size());
}

TEST(PosedPairs, SuzanneC1PosesMatchExactReference) {
    check_c1_poses("suzanne.obj");
}

TEST(PosedPairs, TeapotC1PosesMatchExactReference) {
    check_c1_poses("teapot.obj");
}

TriangleMesh unit_triangle_mesh() {
    TriangleMesh m;
    m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    m.triangles = {{0, 1, 2}, {0, 1, 3}};
    return m;
}

template <class V>
void expect_rejected(const Transform<float>& pose, const char* what) {
    const CollisionModel<V> m(unit_triangle_mesh());
    CollideResult<float> r;
    for (int call = 0; call < 3; ++call) {
        try {
            if (call == 0) collide(m, m, pose, {}, r);
            if (call == 1) (void)collides(m, m, pose);
            if (call == 2) (void)distance(m, m, pose);
            ADD_FAILURE() << what << ": call " << call << " accepted the pose";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("pose_of_b_in_a"), std::string::npos) << e.what();
        }
    }
}

TEST(PoseValidation, NonFiniteAndNonRigidPosesAreRejected) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    Transform<float> p;
    p.translation = {nan, 0, 0};
    expect_rejected<Obb<float>>(p, "NaN translation");
    expect_rejected<Aabb3f>(p, "NaN translation");
    p = {};
    p.rotation[1][2] = nan;
    expect_rejected<Rss<float>>(p, "NaN rotation");
    p = {};
    p.translation = {0, inf, 0};
    expect_rejected<Sphere<float>>(p, "infinite translation");
    p = {};
    p.rotation[0][0] = 1.01f;  // a scale
    expect_rejected<Obb<float>>(p, "scale");
    p = {};
    p.rotation[0][1] = 0.01f;  // a shear
    expect_rejected<Kdop<float, 18>>(p, "shear");
    p = {};
    p.rotation[2][2] = -1;  // a mirror: orthogonal, det -1
    expect_rejected<Obb<float>>(p, "mirror");
    p = {};
    p.rotation[0][0] = p.rotation[1][1] = p.rotation[2][2] = 0;  // all zero
    expect_rejected<Aabb3f>(p, "zero");
}

TEST(PoseValidation, RotationsRoundedToFloatAreAccepted) {
    const CollisionModel<Obb<float>> m(unit_triangle_mesh());
    for (const auto& pose : random_rigid_poses(Aabb<float, 3>{{0, 0, 0}, {1, 1, 1}}, 200, 7)) {
        EXPECT_NO_THROW((void)collides(m, m, pose));
        EXPECT_NO_THROW((void)distance(m, m, pose));
    }
    // Double: the same tolerance, so that a rotation read from float data (or rounded a little)
    // is taken as given; a scale of 1e-3 is still refused.
    const BasicTriangleMesh<double> md = converted<double>(unit_triangle_mesh());
    const CollisionModel<Obb<double>> m2(md);
    Transform<double> q{rotation_about(normalize(Vec3d{1, 2, 3}), 0.7), {1, 2, 3}};
    EXPECT_NO_THROW((void)collides(m2, m2, q));
    q.rotation[0][0] *= 1 + 1e-7;
    EXPECT_NO_THROW((void)collides(m2, m2, q));
    q.rotation[0][0] *= 1 + 1e-3;
    EXPECT_THROW((void)collides(m2, m2, q), Error);
}

template <class V>
void check_far_apart(double gap) {
    const CollisionModel<V> m(unit_triangle_mesh());
    const Transform<float> far{Mat3<float>{}, Vec3f(float(gap), 0, 0)};
    const auto d = distance(m, m, far);
    // The nearest pair: corner (0, y, z) of the moved copy against x = 1 of the original.
    EXPECT_TRUE(std::isfinite(d.distance)) << gap;
    EXPECT_NEAR(d.distance / (float(gap) - 1.0f), 1.0f, 1e-6f) << gap;
}

TEST(Distance, FarApartModelsGetAFiniteDistance) {
    for (const double gap : {1e10, 1e20, 1e30, 1e37}) {
        check_far_apart<Aabb3f>(gap);
        check_far_apart<Obb<float>>(gap);
        check_far_apart<Rss<float>>(gap);
        check_far_apart<Sphere<float>>(gap);
        check_far_apart<Kdop<float, 18>>(gap);
    }
}

template <class V>
void check_far_mesh(const TriangleMesh& mesh, float gap) {
    const CollisionModel<V> m(mesh);
    const auto tris = mesh_triangles(mesh);
    const Transform<float> far{rotation_about(normalize(Vec3f{1, 2, 3}), 0.5f), Vec3f(gap, 0, 0)};
    const float got = distance(m, m, far).distance;
    const float want = brute_force_distance(tris, tris, far);
    EXPECT_TRUE(std::isfinite(got));
    EXPECT_NEAR(got / want, 1.0f, 1e-6f) << gap;
}

TEST(Distance, FarApartMeshesMatchBruteForce) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    const TriangleMesh mesh = read_mesh(path);
    for (const float gap : {1e20f, 1e30f}) {
        check_far_mesh<Aabb3f>(mesh, gap);
        check_far_mesh<Obb<float>>(mesh, gap);
        check_far_mesh<Rss<float>>(mesh, gap);
        check_far_mesh<Sphere<float>>(mesh, gap);
        check_far_mesh<Kdop<float, 18>>(mesh, gap);
    }
}

}  // namespace
}  // namespace bvhkit::test

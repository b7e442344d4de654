// Tree-vs-tree collision against brute force: for every volume type and descent rule, the set of
// intersecting triangle pairs equals the all-pairs reference on shared meshes and random soups
// under random C1 poses; first-contact and yes/no answers agree with the all-pairs answer.
#include <gtest/gtest.h>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/query/self_collision.hpp"
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

constexpr DescentRule kRules[] = {DescentRule::Larger, DescentRule::A, DescentRule::B,
                                  DescentRule::Simultaneous, DescentRule::ByOverlap};

/// Poses per mesh: the acceptance figure (200) in the Release run (about 12 s in all), a few under
/// the sanitizers (BVHKIT_TEST_SCALE=small).
std::size_t pose_count(std::size_t small) {
    return small_scale() ? small : 200;
}

template <class V>
void check_volume(const TriangleMesh& ma, const TriangleMesh& mb,
                  const std::vector<Transform<float>>& poses, const std::vector<PairSet>& truth,
                  std::size_t& colliding) {
    const CollisionModel<V> a(ma), b(mb);
    CollideResult<float> result;
    for (std::size_t k = 0; k < poses.size(); ++k) {
        for (DescentRule rule : kRules) {
            CollideOptions o;
            o.rule = rule;
            collide(a, b, poses[k], o, result);
            PairSet got;
            for (const auto& c : result.contacts) got.insert({c.triangle_a, c.triangle_b});
            ASSERT_EQ(got.size(), result.contacts.size()) << "a pair reported twice";
            ASSERT_EQ(got, truth[k]) << "pose " << k << " rule " << to_string(rule);
            EXPECT_EQ(result.colliding, !truth[k].empty());

            o.mode = CollideMode::FirstContact;
            collide(a, b, poses[k], o, result);
            ASSERT_EQ(result.colliding, !truth[k].empty()) << "pose " << k;
            ASSERT_LE(result.contacts.size(), 1u);
            if (result.colliding) {
                EXPECT_TRUE(
                    truth[k].count({result.contacts[0].triangle_a, result.contacts[0].triangle_b}));
            }
            ASSERT_EQ(collides(a, b, poses[k], rule), !truth[k].empty()) << "pose " << k;
        }
        colliding += !truth[k].empty();
    }
}

void check_meshes(const TriangleMesh& ma, const TriangleMesh& mb, std::size_t count,
                  std::uint64_t seed) {
    const auto poses = random_rigid_poses(mb.bounds(), count, seed);
    const auto ta = mesh_triangles(ma), tb = mesh_triangles(mb);
    const Aabb3f box = unite(ma.bounds(), mb.bounds());
    const float pad = 1e-5f * length(box.max - box.min);
    std::vector<PairSet> truth;
    for (const auto& p : poses) truth.push_back(brute_force_pairs(ta, tb, p, pad));
    std::size_t colliding = 0;
    check_volume<Aabb3f>(ma, mb, poses, truth, colliding);
    check_volume<Sphere<float>>(ma, mb, poses, truth, colliding);
    check_volume<Obb<float>>(ma, mb, poses, truth, colliding);
    check_volume<Rss<float>>(ma, mb, poses, truth, colliding);
    check_volume<Kdop<float, 14>>(ma, mb, poses, truth, colliding);
    check_volume<Kdop<float, 18>>(ma, mb, poses, truth, colliding);
    check_volume<Kdop<float, 26>>(ma, mb, poses, truth, colliding);
    check_volume<ConvexHull<float>>(ma, mb, poses, truth, colliding);
    // Both outcomes must be exercised for the comparison to mean anything.
    EXPECT_GT(colliding, 0u);
    EXPECT_LT(colliding, 8 * poses.size());
    std::printf("[ collision ] %zu poses, %zu colliding\n", poses.size(), colliding / 8);
}

TEST(Pairs, SuzanneMatchesBruteForce) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    const auto m = read_mesh(path);
    check_meshes(m, m, pose_count(20), 11);
}

TEST(Pairs, TeapotMatchesBruteForce) {
    BVHKIT_REQUIRE_MESH(path, "teapot.obj");
    const auto m = read_mesh(path);
    check_meshes(m, m, pose_count(20), 12);
}

TEST(Pairs, RandomSoupsMatchBruteForce) {
    const std::size_t count = pose_count(20);
    for (std::uint64_t s = 0; s < 3; ++s) {
        const auto a = random_soup<float>(300, 0.15, 100 + s);
        const auto b = random_soup<float>(200, 0.2, 200 + s);
        check_meshes(a, b, count, 300 + s);
    }
}

TEST(Pairs, DifferentMeshesMatchBruteForce) {
    BVHKIT_REQUIRE_MESH(a, "suzanne.obj");
    BVHKIT_REQUIRE_MESH(b, "teapot.obj");
    auto ma = read_mesh(a), mb = read_mesh(b);
    // Scale and move the teapot onto suzanne so that poses around it overlap suzanne about half the
    // time.
    const float s = length(ma.bounds().extent()) / length(mb.bounds().extent());
    const Vec3f ca = ma.bounds().centroid(), cb = mb.bounds().centroid();
    for (auto& v : mb.vertices) v = (v - cb) * s + ca;
    check_meshes(ma, mb, pose_count(20), 13);
}

template <class V>
void check_self(const TriangleMesh& m, const PairSet& truth) {
    const CollisionModel<V> model(m);
    std::vector<Contact<float>> contacts;
    PairStats stats;
    self_collide(model, contacts, stats);
    PairSet got;
    for (const auto& c : contacts) got.insert({c.triangle_a, c.triangle_b});
    EXPECT_EQ(got.size(), contacts.size());
    EXPECT_EQ(got, truth);
}

void check_self_all(const TriangleMesh& m, bool expect_some) {
    const Aabb3f box = m.bounds();
    const PairSet truth = brute_force_self(m, 1e-5f * length(box.max - box.min));
    if (expect_some) {
        EXPECT_FALSE(truth.empty());
    }
    check_self<Aabb3f>(m, truth);
    check_self<Sphere<float>>(m, truth);
    check_self<Obb<float>>(m, truth);
    check_self<Rss<float>>(m, truth);
    check_self<Kdop<float, 18>>(m, truth);
    std::printf("[ self ] %zu triangles, %zu intersecting pairs\n", m.triangles.size(),
                truth.size());
}

TEST(SelfCollision, SoupsMatchBruteForce) {
    for (std::uint64_t s = 0; s < 3; ++s)
        check_self_all(random_soup<float>(600, 0.1, 500 + s), true);
}

TEST(SelfCollision, SharedMeshesMatchBruteForce) {
    for (const char* name : {"suzanne.obj", "teapot.obj", "spot.obj"}) {
        const auto p = shared_mesh(name);
        if (p.empty()) continue;
        check_self_all(read_mesh(p), false);
    }
}

TEST(SelfCollision, TwoInterpenetratingCopiesInOneMesh) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    const auto m = read_mesh(path);
    // One mesh holding suzanne and a shifted, rotated copy: many intersections between the two.
    TriangleMesh both = m;
    const Transform<float> pose{rotation_about(Vec3f(0, 0, 1), 0.3f), Vec3f(0.2f, 0.1f, 0)};
    const auto n = std::uint32_t(m.vertices.size());
    for (const auto& v : m.vertices) both.vertices.push_back(pose.apply(v));
    for (auto t : m.triangles) both.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
    check_self_all(both, true);
}

}  // namespace
}  // namespace bvhkit::test

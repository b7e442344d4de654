// ObbRss: one model for collision and distance. Its answers must be those of the box model for
// collision and of the swept-sphere model for distance (each volume is only a filter: the pairs
// and distances come from the triangles), and the distance must equal the brute-force minimum over
// every triangle pair of the two meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/primitives/triangle_distance.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "bvhkit/volumes/obb_rss.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

Transform<float> random_pose(SplitMix64& rng, float reach) {
    Transform<float> pose;
    pose.rotation =
        rotation_about(normalize(Vec3f(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)),
                                       float(rng.uniform(-1, 1)) + 2.0f)),
                       float(rng.uniform(0, 6.283)));
    for (int k = 0; k < 3; ++k) pose.translation[k] = float(rng.uniform(-reach, reach));
    return pose;
}

std::set<std::pair<std::uint32_t, std::uint32_t>> pair_set(const CollideResult<float>& r) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> s;
    for (const auto& c : r.contacts) s.insert({c.triangle_a, c.triangle_b});
    return s;
}

TEST(ObbRss, CollisionEqualsTheBoxModelAndDistanceTheBruteForce) {
    const TriangleMesh mesh = make_procedural("sphere:subdiv=2,displacement=0.3");
    const CollisionModel<ObbRss<float>> both(mesh);
    const CollisionModel<Obb<float>> box(mesh);
    const CollisionModel<Rss<float>> swept(mesh);
    const auto tris = mesh_triangles(mesh);
    SplitMix64 rng(7);
    const std::size_t poses = test::scaled(60, 6);
    std::size_t colliding = 0;
    for (std::size_t i = 0; i < poses; ++i) {
        const Transform<float> pose = random_pose(rng, 3.0f);
        CollideResult<float> r_both, r_box;
        collide(both, both, pose, CollideOptions{}, r_both);
        collide(box, box, pose, CollideOptions{}, r_box);
        ASSERT_EQ(r_both.colliding, r_box.colliding) << "pose " << i;
        ASSERT_EQ(pair_set(r_both), pair_set(r_box)) << "pose " << i;
        EXPECT_EQ(collides(both, both, pose), r_box.colliding);
        colliding += r_box.colliding;
        if (r_box.colliding) continue;
        // Distance: the minimum over every pair of triangles, B's carried into A's frame.
        double brute = std::numeric_limits<double>::infinity();
        for (const auto& a : tris)
            for (const auto& b : tris)
                brute = std::min(
                    brute,
                    double(std::sqrt(triangle_distance(a, transformed(b, pose)).distance_squared)));
        const float d_both = distance(both, both, pose).distance;
        EXPECT_EQ(d_both, distance(swept, swept, pose).distance) << "pose " << i;
        EXPECT_NEAR(d_both, brute, 1e-5 * (1 + brute)) << "pose " << i;
    }
    EXPECT_GT(colliding, 0u);
    EXPECT_LT(colliding, poses);
}

TEST(ObbRss, EveryNodeEnclosesItsTriangles) {
    const TriangleMesh mesh = make_procedural("torus:u=24,v=12");
    const CollisionModel<ObbRss<float>> model(mesh);
    const auto& bvh = model.bvh();
    const auto slots = model.slot_triangles();
    // Each leaf's box and swept sphere hold its triangles' corners (a hair of rounding allowed).
    for (const auto& node : bvh.nodes) {
        if (node.count == 0) continue;
        const ObbRss<float>& v = node.bounds;
        for (std::uint32_t s = node.first; s < node.first + node.count; ++s)
            for (const Vec3f& p : {slots[s].p0, slots[s].p1, slots[s].p2}) {
                const Vec3f d = p - v.obb.center;
                for (int k = 0; k < 3; ++k)
                    EXPECT_LE(std::fabs(dot(d, v.obb.axes[k])), v.obb.extents[k] * 1.0001f + 1e-6f);
                const Vec3f e = p - v.rss.center;
                const float x = std::clamp(dot(e, v.rss.axes[0]), -v.rss.half[0], v.rss.half[0]);
                const float y = std::clamp(dot(e, v.rss.axes[1]), -v.rss.half[1], v.rss.half[1]);
                const Vec3f q = v.rss.center + v.rss.axes[0] * x + v.rss.axes[1] * y;
                EXPECT_LE(length(p - q), v.rss.radius * 1.0001f + 1e-6f);
            }
    }
}

}  // namespace
}  // namespace bvhkit

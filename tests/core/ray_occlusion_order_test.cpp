// The wide layouts' lane order for occlusion rays (query/ray_wide_occlusion_order.hpp): an any-hit
// walk takes first the children most likely to end it soon. A cloud of small triangles between a
// ground and a ceiling of two large triangles each: a ray up or down through the cloud's box,
// between its triangles, must find the ceiling or the ground at once, opening the root and no
// other node. Without the order, whichever of the two the collapse puts after the cloud
// comes after it, and the walk opens the cloud's nodes first. The answers are the other tests';
// only the work shows here.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"

using namespace bvhkit;

namespace {

/// The ceiling (y = 3, [-50, 50] in x and z, triangles 0 and 1), the ground (the same at y = 0,
/// triangles 2 and 3) and `count` small triangles in [-1, 1] x [1, 2] x [-1, 1], none within 0.1
/// of the line x = z = 0.
TriangleMesh cloud_between_floors(std::uint32_t count) {
    TriangleMesh mesh;
    mesh.vertices = {{-50, 3, -50}, {50, 3, -50}, {50, 3, 50}, {-50, 3, 50},
                     {-50, 0, -50}, {50, 0, -50}, {50, 0, 50}, {-50, 0, 50}};
    mesh.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 6, 5}, {4, 7, 6}};
    test::Random rng(11);
    while (mesh.triangles.size() < count + 4) {
        const float x = float(rng.uniform(-1, 1)), y = float(rng.uniform(1, 2)),
                    z = float(rng.uniform(-1, 1));
        if (std::fabs(x) < 0.12f && std::fabs(z) < 0.12f) continue;  // keep the line clear
        const std::uint32_t v = std::uint32_t(mesh.vertices.size());
        mesh.vertices.push_back({x, y, z});
        mesh.vertices.push_back({x + 0.01f, y, z});
        mesh.vertices.push_back({x, y + 0.01f, z + 0.01f});
        mesh.triangles.push_back({v, v + 1, v + 2});
    }
    return mesh;
}

void expect_floors_first(RayLayout layout, int lanes) {
    const TriangleMesh mesh = cloud_between_floors(4000);
    TriangleBvhOptions options;
    options.ray_layout = layout;
    const TriangleBvh<float> tree(mesh, options);
    if (tree.ray_width() != lanes) GTEST_SKIP() << "this CPU walks " << tree.ray_width() << " wide";
    for (const float x : {0.0f, 0.05f, -0.07f})
        for (const float dy : {1.0f, -1.0f}) {
            const Ray3f ray{{x, 1.5f, 0.03f}, {0.0f, dy, 0.0f}, 0.0f, 100.0f};
            // The ceiling (up) or the ground: of each, the triangle with z > x is the second.
            const std::uint32_t first = dy > 0 ? 0u : 2u;
            ASSERT_EQ(tree.closest_hit(ray).primitive, first + (x > 0.03f ? 0u : 1u));
            TraversalStats stats;
            ASSERT_TRUE(tree.any_hit(ray, stats));
            // The root's boxes and no more: the floors' leaf hangs from the root (its box is the
            // scene's), and it ends the walk before any of the cloud's nodes is opened.
            EXPECT_LE(stats.nodes_visited, std::uint64_t(lanes))
                << "x " << x << ", direction y " << dy;
        }
}

}  // namespace

TEST(OcclusionOrder, AnyHitTestsTheFloorsFirstEightWide) {
    expect_floors_first(RayLayout::Auto, 8);
}

TEST(OcclusionOrder, AnyHitTestsTheFloorsFirstFourWide) {
    expect_floors_first(RayLayout::Wide4, 4);
}

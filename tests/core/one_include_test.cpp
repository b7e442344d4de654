// bvhkit.hpp promises everything in one include: this file includes nothing else of bvhkit and
// uses one entry point of each module (it fails to compile when one is missing).
#include <gtest/gtest.h>
#include <bvhkit/bvhkit.hpp>

#include <vector>

namespace {

TEST(OneInclude, EveryModuleIsReachable) {
    const bvhkit::TriangleMesh mesh = bvhkit::load_mesh("sphere:subdiv=2");
    ASSERT_EQ(mesh.triangle_count(), 320u);

    const bvhkit::TriangleBvh<float> bvh(mesh);
    EXPECT_TRUE(bvh.closest_hit(bvhkit::Ray3f({0, 0, -5}, {0, 0, 1})));

    const bvhkit::ClosestPointMesh<float> surface(mesh);
    EXPECT_TRUE(surface.closest_point(bvhkit::Vec3f(0, 0, 3)));
    const bvhkit::SignedDistanceMesh<float> sdf(mesh);
    EXPECT_TRUE(sdf.inside(bvhkit::Vec3f(0, 0, 0)));
    EXPECT_FALSE(sdf.inside(bvhkit::Vec3f(0, 0, 3)));

    const bvhkit::CollisionModel<bvhkit::Obb<float>> model(mesh);
    EXPECT_TRUE(bvhkit::collides(model, model, bvhkit::Transform<float>::identity()));
    bvhkit::Transform<float> apart = bvhkit::Transform<float>::identity();
    apart.translation = bvhkit::Vec3f(10, 0, 0);
    EXPECT_FALSE(bvhkit::collides(model, model, apart));
    const bvhkit::CollisionModel<bvhkit::Rss<float>> rss(mesh);
    EXPECT_GT(bvhkit::distance(rss, rss, apart).distance, 7.9f);

    bvhkit::DynamicTree<float, 2> tree;
    tree.create(bvhkit::Aabb<float, 2>(bvhkit::Vec<float, 2>(0, 0), bvhkit::Vec<float, 2>(1, 1)));
    tree.create(
        bvhkit::Aabb<float, 2>(bvhkit::Vec<float, 2>(0.5f, 0.5f), bvhkit::Vec<float, 2>(2, 2)));
    std::vector<bvhkit::ProxyPair> pairs;
    tree.find_pairs(pairs);
    EXPECT_EQ(pairs.size(), 1u);
}

}  // namespace

// TriangleMeshView: every structure builds from the caller's own buffers (float or double xyz,
// 32- or 64-bit, signed or unsigned indices) and answers exactly as when built from the owning
// TriangleMesh with the same triangles; bad indices are an Error naming the triangle.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "bvhkit/bvhkit.hpp"

namespace bvhkit {
namespace {

template <class Index>
std::vector<Index> flat_ids(const TriangleMesh& mesh) {
    std::vector<Index> ids;
    for (const auto& t : mesh.triangles)
        for (std::uint32_t k : t) ids.push_back(Index(k));
    return ids;
}

std::vector<float> flat_xyz(const TriangleMesh& mesh) {
    std::vector<float> xyz;
    for (const auto& v : mesh.vertices)
        for (int k = 0; k < 3; ++k) xyz.push_back(v[k]);
    return xyz;
}

TEST(MeshView, EveryStructureAnswersAsFromTheOwningMesh) {
    const TriangleMesh mesh = load_mesh("sphere:subdiv=3,displacement=0.3");
    const std::vector<float> xyz = flat_xyz(mesh);
    const std::vector<std::int64_t> ids = flat_ids<std::int64_t>(mesh);
    const TriangleMeshView<float, std::int64_t> view(xyz.data(), mesh.vertices.size(), ids.data(),
                                                     mesh.triangles.size());
    ASSERT_EQ(view.triangle_count(), mesh.triangle_count());

    const TriangleBvh<float> rays_owned(mesh), rays_viewed(view);
    const ClosestPointMesh<float> near_owned(mesh), near_viewed(view);
    const SignedDistanceMesh<float> sdf_owned(mesh), sdf_viewed(view);
    const WindingNumberMesh<float> wn_owned(mesh), wn_viewed(view);
    const CollisionModel<Obb<float>> obb_owned(mesh), obb_viewed(view);
    SplitMix64 rng(3);
    for (int i = 0; i < 500; ++i) {
        const Vec3f p(float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)),
                      float(rng.uniform(-2, 2)));
        const Ray3f ray(p, -p);
        const Hit<float> a = rays_owned.closest_hit(ray), b = rays_viewed.closest_hit(ray);
        ASSERT_EQ(a.primitive, b.primitive);
        ASSERT_EQ(a.t, b.t);
        ASSERT_EQ(near_owned.closest_point(p).distance_squared,
                  near_viewed.closest_point(p).distance_squared);
        ASSERT_EQ(sdf_owned.signed_distance(p).distance, sdf_viewed.signed_distance(p).distance);
        ASSERT_EQ(wn_owned.fast(p), wn_viewed.fast(p));
        Transform<float> pose = Transform<float>::identity();
        pose.translation = p;
        ASSERT_EQ(collides(obb_owned, obb_owned, pose), collides(obb_viewed, obb_viewed, pose));
    }
}

TEST(MeshView, OfAnOwningMeshAndOtherIndexTypes) {
    const TriangleMesh mesh = load_mesh("torus:u=12,v=8");
    const TriangleMeshView<float> of_mesh(mesh);
    EXPECT_EQ(of_mesh.vertex_count(), mesh.vertices.size());
    EXPECT_EQ(of_mesh.triangle(5), mesh.triangles[5]);
    const std::vector<std::int32_t> ids32 = flat_ids<std::int32_t>(mesh);
    std::vector<double> xyz64;
    for (const auto& v : mesh.vertices)
        for (int k = 0; k < 3; ++k) xyz64.push_back(v[k]);
    const TriangleMeshView<double, std::int32_t> view(xyz64.data(), mesh.vertices.size(),
                                                      ids32.data(), mesh.triangles.size());
    const TriangleBvh<double> bvh(view);
    EXPECT_EQ(bvh.triangle_count(), mesh.triangle_count());
}

TEST(MeshView, BadIndicesAreErrorsNamingTheTriangle) {
    const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::vector<std::int64_t> negative = {0, 1, 2, 0, -1, 2};
    const std::vector<std::int64_t> too_large = {0, 1, 2, 0, 1, 3};
    const std::vector<std::uint64_t> huge = {0, 1, 2, 0, 1, (std::uint64_t(1) << 63) + 1};
    const TriangleMeshView<float, std::int64_t> a(xyz.data(), 3, negative.data(), 2);
    const TriangleMeshView<float, std::int64_t> b(xyz.data(), 3, too_large.data(), 2);
    const TriangleMeshView<float, std::uint64_t> c(xyz.data(), 3, huge.data(), 2);
    try {
        TriangleBvh<float> bvh(a);
        FAIL() << "negative index accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("triangle 1"), std::string::npos) << e.what();
    }
    EXPECT_THROW(TriangleBvh<float>{b}, Error);
    EXPECT_THROW(CollisionModel<Obb<float>>{b}, Error);
    EXPECT_THROW(ClosestPointMesh<float>{c}, Error);
    EXPECT_THROW(TriangleMeshView<float>(nullptr, 3, nullptr, 0), Error);
}

// A NaN vertex must not make the signed-distance welding sort undefined; the triangles that use
// it are left out, the others answer.
TEST(MeshView, NanVertexIsLeftOutBySignedDistance) {
    TriangleMesh mesh = load_mesh("sphere:subdiv=2");
    mesh.vertices.push_back(Vec3f(std::numeric_limits<float>::quiet_NaN(), 0, 0));
    mesh.triangles.push_back({0, 1, std::uint32_t(mesh.vertices.size() - 1)});
    const SignedDistanceMesh<float> sdf(mesh);
    EXPECT_LT(sdf.signed_distance(Vec3f(0, 0, 0)).distance, 0.0f);
    EXPECT_GT(sdf.signed_distance(Vec3f(0, 0, 3)).distance, 0.0f);
}

}  // namespace
}  // namespace bvhkit

// The real test meshes (data/ and BVHKIT_DATA_DIR): triangle counts as listed in data/README.md and
// docs/workloads.md (an independent source), plausible vertex counts, every index in range and
// finite bounds.
#include <gtest/gtest.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "bvhkit/io/read_mesh.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

struct SharedMesh {
    const char* file;
    std::size_t triangles;
};

class SharedMeshTest : public ::testing::TestWithParam<SharedMesh> {};

TEST_P(SharedMeshTest, ReadsTheDocumentedTriangleCount) {
    const SharedMesh m = GetParam();
    BVHKIT_REQUIRE_MESH(path, m.file);
    const auto start = std::chrono::steady_clock::now();
    const TriangleMesh mesh = read_mesh(path);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::printf("  %s: %zu triangles, %zu vertices, read in %.1f ms\n", m.file,
                mesh.triangle_count(), mesh.vertices.size(), ms);
    EXPECT_EQ(mesh.triangle_count(), m.triangles);
    // A closed-ish manifold has about half as many vertices as triangles; allow wide slack for
    // seams and unreferenced vertices, but catch a reader that drops or duplicates vertices.
    EXPECT_GE(mesh.vertices.size(), m.triangles / 4);
    EXPECT_LE(mesh.vertices.size(), m.triangles * 3);
    for (const auto& t : mesh.triangles)
        for (const std::uint32_t i : t) ASSERT_LT(i, mesh.vertices.size());
    const auto b = mesh.bounds();
    EXPECT_TRUE(is_finite(b.min) && is_finite(b.max));
    EXPECT_FALSE(b.is_empty());
}

INSTANTIATE_TEST_SUITE_P(
    All, SharedMeshTest,
    ::testing::Values(SharedMesh{"suzanne.obj", 968}, SharedMesh{"teapot.obj", 6320},
                      SharedMesh{"spot.obj", 5856}, SharedMesh{"fandisk.obj", 12946},
                      SharedMesh{"dragon-lowres.ply", 22866},
                      SharedMesh{"stanford-bunny.obj", 69451}, SharedMesh{"igea.ply", 268686}),
    [](const ::testing::TestParamInfo<SharedMesh>& param_info) {
        std::string n = param_info.param.file;
        for (char& c : n)
            if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
        return n;
    });

TEST(SharedMeshes, ExtensionDispatchIsCaseInsensitiveForInMemoryBytes) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    const TriangleMesh from_file = read_mesh(path);
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const TriangleMesh from_bytes = read_mesh(bytes, "models/SUZANNE.OBJ");
    EXPECT_EQ(from_bytes.triangles, from_file.triangles);
    EXPECT_EQ(from_bytes.vertices, from_file.vertices);
    EXPECT_THROW(read_mesh(bytes, "suzanne.off"), Error);
    EXPECT_TRUE(is_mesh_file_extension(".OBJ"));
    EXPECT_TRUE(is_mesh_file_extension(".Ply"));
    EXPECT_FALSE(is_mesh_file_extension(".off"));
}

}  // namespace

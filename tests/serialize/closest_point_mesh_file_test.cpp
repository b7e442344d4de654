// ClosestPointMesh files: a saved mesh loads to the same tree and triangles and answers 10^4
// closest-point queries (and k-nearest and radius queries) bit for bit; malformed files are Errors.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "bvhkit/io/closest_point_mesh_file.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "byte_flips.hpp"
#include "random_geometry.hpp"
#include "test_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

template <class T>
bool same_point(const MeshPoint<T>& a, const MeshPoint<T>& b) {
    return a.triangle == b.triangle && std::memcmp(&a.point, &b.point, sizeof(a.point)) == 0 &&
           std::memcmp(&a.distance_squared, &b.distance_squared, sizeof(T)) == 0 &&
           std::memcmp(&a.u, &b.u, sizeof(T)) == 0 && std::memcmp(&a.v, &b.v, sizeof(T)) == 0;
}

template <class T>
void expect_same_answers(const ClosestPointMesh<T>& got, const ClosestPointMesh<T>& want,
                         const Aabb<T, 3>& bounds, std::size_t count) {
    const Vec<T, 3> margin = bounds.extent() * T(0.5);
    const Aabb<T, 3> box(bounds.min - margin, bounds.max + margin);
    Random rng(5);
    NearestScratch<T> s1, s2;
    std::vector<MeshPoint<T>> k1, k2;
    for (std::size_t i = 0; i < count; ++i) {
        const Vec<T, 3> p = rng.point_in(box);
        ASSERT_TRUE(same_point(got.closest_point(p, s1), want.closest_point(p, s2))) << i;
        if (i % 50 == 0) {
            got.k_nearest(p, 4, k1, s1);
            want.k_nearest(p, 4, k2, s2);
            ASSERT_EQ(k1.size(), k2.size());
            for (std::size_t j = 0; j < k1.size(); ++j) ASSERT_TRUE(same_point(k1[j], k2[j]));
            const T r = std::sqrt(want.closest_point(p, s2).distance_squared) * T(1.5);
            got.within_radius(p, r, k1);
            want.within_radius(p, r, k2);
            ASSERT_EQ(k1.size(), k2.size());
        }
    }
}

template <class T>
void round_trip(const ClosestPointMesh<T>& mesh, const Aabb<T, 3>& bounds,
                const std::string& what) {
    SCOPED_TRACE(what);
    const std::vector<std::uint8_t> bytes = to_bytes(mesh);
    for (const bool validate : {true, false}) {
        const ClosestPointMesh<T> loaded = closest_point_mesh_from_bytes<T>(bytes, {validate});
        const auto &g = loaded.bvh(), &w = mesh.bvh();
        ASSERT_EQ(g.nodes.size(), w.nodes.size());
        if (!w.nodes.empty()) {
            EXPECT_EQ(0, std::memcmp(g.nodes.data(), w.nodes.data(),
                                     w.nodes.size() * sizeof(w.nodes.front())));
        }
        EXPECT_EQ(g.primitive_indices, w.primitive_indices);
        EXPECT_EQ(loaded.triangle_count(), mesh.triangle_count());
        for (std::uint32_t s = 0; s < w.primitive_indices.size(); ++s)
            ASSERT_EQ(0, std::memcmp(&loaded.triangle_in_slot(s), &mesh.triangle_in_slot(s),
                                     sizeof(Triangle<T>)));
        EXPECT_EQ(to_bytes(loaded), bytes);
        expect_same_answers(loaded, mesh, bounds, validate ? scaled(10000, 10) : 500);
    }
}

TEST(ClosestPointMeshFile, RoundTrips) {
    BVHKIT_REQUIRE_MESH(path, "spot.obj");
    const TriangleMesh spot = read_mesh(path);
    round_trip(ClosestPointMesh<float>(spot), bounds_as<float>(spot), "spot float");
    round_trip(ClosestPointMesh<double>(spot), bounds_as<double>(spot), "spot double");
    for (const char* spec : {"sphere:subdiv=3,displacement=0.3", "terrain:n=20", "soup:n=2000"}) {
        const TriangleMesh m = make_procedural(spec);
        round_trip(ClosestPointMesh<float>(m), bounds_as<float>(m), spec);
        round_trip(ClosestPointMesh<double>(m), bounds_as<double>(m), spec);
    }
    // Triangles left out of the tree, one with a finite edge that counts in the longest edge.
    std::vector<Triangle<float>> soup = random_soup<float>(300, 9);
    soup[3].p2[1] = std::numeric_limits<float>::quiet_NaN();
    soup[4] = {{0, 0, 0}, {5, 0, 0}, {std::numeric_limits<float>::infinity(), 0, 0}};
    round_trip(ClosestPointMesh<float>(soup), Aabb3f({0, 0, 0}, {1, 1, 1}), "soup with holes");
    round_trip(ClosestPointMesh<float>(std::vector<Triangle<float>>{}),
               Aabb3f({0, 0, 0}, {1, 1, 1}), "empty");
}

TEST(ClosestPointMeshFile, MalformedFilesAreErrors) {
    const std::vector<std::uint8_t> file = to_bytes(ClosestPointMesh<float>(make_sphere(1)));
    ASSERT_NO_THROW((void)closest_point_mesh_from_bytes<float>(file));
    for (std::size_t n = 0; n < file.size(); ++n)
        EXPECT_THROW((void)closest_point_mesh_from_bytes<float>(std::span(file).first(n)), Error);
    EXPECT_THROW((void)closest_point_mesh_from_bytes<double>(file), Error);
    // The other kind of file, and this kind loaded as the other.
    EXPECT_THROW((void)triangle_bvh_from_bytes<float>(file), Error);
    EXPECT_THROW(
        (void)closest_point_mesh_from_bytes<float>(to_bytes(TriangleBvh<float>(make_sphere(1)))),
        Error);
    SplitMix64 rng(4);
    const std::size_t rounds = full_scale() ? 100000 : scaled(10000, 10);
    std::size_t loaded = 0;
    for (std::size_t round = 0; round < rounds; ++round) {
        std::vector<std::uint8_t> bad = test::with_byte_flips(file, rng);
        if (bad == file) continue;
        ASSERT_THROW((void)closest_point_mesh_from_bytes<float>(bad), Error) << round;
        serial_detail::reseal_tree_file(bad);
        for (const bool validate : {true, false}) {
            try {
                const auto mesh = closest_point_mesh_from_bytes<float>(bad, {validate});
                ++loaded;
                NearestScratch<float> scratch;
                Random points(round);
                for (int i = 0; i < 8; ++i) {
                    const auto q = mesh.closest_point(
                        points.point_in(Aabb3f({-2, -2, -2}, {2, 2, 2})), scratch);
                    ASSERT_TRUE(!q || q.triangle < mesh.triangle_count());
                }
            } catch (const Error&) {
            }
        }
    }
    RecordProperty("resealed_loaded", std::to_string(loaded) + " of " + std::to_string(2 * rounds));
}

// The longest edge: the one value in the file the tree cannot vouch for.
TEST(ClosestPointMeshFile, LongestEdgeIsChecked) {
    const ClosestPointMesh<float> mesh(make_sphere(1));
    const std::vector<std::uint8_t> file = to_bytes(mesh);
    const std::size_t at =
        file.size() - 8;  // the last section: the scalar, then 4 bytes of padding
    const auto with = [&](float edge) {
        std::vector<std::uint8_t> f = file;
        std::memcpy(f.data() + at, &edge, 4);
        serial_detail::reseal_tree_file(f);
        return f;
    };
    float stored;
    std::memcpy(&stored, file.data() + at, 4);
    ASSERT_GT(stored, 0.1f);
    ASSERT_LT(stored, 1.0f);
    EXPECT_NO_THROW((void)closest_point_mesh_from_bytes<float>(with(stored * 2)));
    // inf is what a build stores for an edge past FLT_MAX: longer only costs time.
    EXPECT_NO_THROW(
        (void)closest_point_mesh_from_bytes<float>(with(std::numeric_limits<float>::infinity())));
    for (const float bad : {std::numeric_limits<float>::quiet_NaN(), -1.0f})
        for (const bool validate : {true, false})
            EXPECT_THROW((void)closest_point_mesh_from_bytes<float>(with(bad), {validate}), Error);
    EXPECT_THROW((void)closest_point_mesh_from_bytes<float>(with(stored / 2)), Error);
    EXPECT_NO_THROW((void)closest_point_mesh_from_bytes<float>(with(stored / 2), {false}));
}

}  // namespace

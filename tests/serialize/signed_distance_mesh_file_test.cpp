// SignedDistanceMesh files: a saved mesh loads to one that gives the same signed distances and
// closest points bit for bit on 10^4 points, and saves to the same bytes; malformed files,
// including forged sign data, are Errors.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/io/signed_distance_mesh_file.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "byte_flips.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

template <class T>
bool same_answer_bits(const SignedDistance<T>& a, const SignedDistance<T>& b) {
    const auto& p = a.closest;
    const auto& q = b.closest;
    return std::memcmp(&a.distance, &b.distance, sizeof(T)) == 0 && p.triangle == q.triangle &&
           std::memcmp(&p.point, &q.point, sizeof(p.point)) == 0 &&
           std::memcmp(&p.distance_squared, &q.distance_squared, sizeof(T)) == 0 &&
           std::memcmp(&p.u, &q.u, sizeof(T)) == 0 && std::memcmp(&p.v, &q.v, sizeof(T)) == 0;
}

template <class T>
void round_trip(const TriangleMesh& source, const std::string& what) {
    SCOPED_TRACE(what);
    const SignedDistanceMesh<T> mesh(source);
    const std::vector<std::uint8_t> bytes = to_bytes(mesh);
    const SignedDistanceMesh<T> loaded = signed_distance_mesh_from_bytes<T>(bytes);
    EXPECT_EQ(to_bytes(loaded), bytes);
    const Aabb3f b = source.bounds();
    const Vec<T, 3> margin = Vec<T, 3>(b.max - b.min) * T(0.5);
    const Aabb<T, 3> box(Vec<T, 3>(b.min) - margin, Vec<T, 3>(b.max) + margin);
    Random rng(8);
    NearestScratch<T> s1, s2;
    std::size_t inside = 0;
    const std::size_t count = scaled(10000, 10);
    for (std::size_t i = 0; i < count; ++i) {
        const Vec<T, 3> p = rng.point_in(box);
        const SignedDistance<T> a = loaded.signed_distance(p, s1), e = mesh.signed_distance(p, s2);
        ASSERT_TRUE(same_answer_bits(a, e)) << i;
        inside += e.distance < 0;
    }
    EXPECT_GT(inside, 0u);
}

TEST(SignedDistanceMeshFile, RoundTrips) {
    BVHKIT_REQUIRE_MESH(path, "spot.obj");
    const TriangleMesh spot = read_mesh(path);
    round_trip<float>(spot, "spot float");
    round_trip<double>(spot, "spot double");
    round_trip<float>(make_procedural("torus:u=24,v=12"), "torus");
    round_trip<double>(make_procedural("sphere:subdiv=3,displacement=0.3"), "bumpy sphere");
}

TEST(SignedDistanceMeshFile, MalformedFilesAreErrors) {
    const TriangleMesh sphere = make_sphere(1);  // 80 triangles, 42 vertices
    const SignedDistanceMesh<float> mesh(sphere);
    const std::vector<std::uint8_t> file = to_bytes(mesh);
    ASSERT_NO_THROW((void)signed_distance_mesh_from_bytes<float>(file));
    for (std::size_t n = 0; n < file.size(); ++n)
        EXPECT_THROW((void)signed_distance_mesh_from_bytes<float>(std::span(file).first(n)), Error);
    EXPECT_THROW((void)closest_point_mesh_from_bytes<float>(file), Error);  // another kind
    EXPECT_THROW((void)signed_distance_mesh_from_bytes<double>(file), Error);

    SplitMix64 rng(6);
    const std::size_t rounds = full_scale() ? 100000 : scaled(10000, 10);
    std::size_t loaded = 0;
    for (std::size_t round = 0; round < rounds; ++round) {
        std::vector<std::uint8_t> bad = test::with_byte_flips(file, rng);
        if (bad == file) continue;
        ASSERT_THROW((void)signed_distance_mesh_from_bytes<float>(bad), Error) << round;
        serial_detail::reseal_tree_file(bad);
        for (const bool validate : {true, false}) {
            try {
                const auto m = signed_distance_mesh_from_bytes<float>(bad, {validate});
                ++loaded;
                NearestScratch<float> scratch;
                Random points(round);
                for (int i = 0; i < 8; ++i)
                    (void)m.signed_distance(points.point_in(Aabb3f({-2, -2, -2}, {2, 2, 2})),
                                            scratch);
            } catch (const Error&) {
            }
        }
    }
    RecordProperty("resealed_loaded", std::to_string(loaded) + " of " + std::to_string(2 * rounds));

    // Forged sign data, checksum recomputed: the vertex count (just after the ClosestPointMesh
    // sections) and the corner ids (the last section: 80 x 12 bytes, no padding).
    const std::size_t count_at = to_bytes(mesh.closest_point_mesh()).size();
    const auto with_u64 = [&](std::size_t at, std::uint64_t v) {
        std::vector<std::uint8_t> f = file;
        for (int i = 0; i < 8; ++i) f[at + i] = std::uint8_t(v >> (8 * i));
        serial_detail::reseal_tree_file(f);
        return f;
    };
    std::uint64_t nv = 0;
    for (int i = 0; i < 8; ++i) nv |= std::uint64_t(file[count_at + i]) << (8 * i);
    ASSERT_EQ(nv, 42u);
    for (const std::uint64_t v : {std::uint64_t(0), nv - 1, nv + 1, std::uint64_t(1) << 40,
                                  std::numeric_limits<std::uint64_t>::max()})
        for (const bool validate : {true, false})
            EXPECT_THROW(
                (void)signed_distance_mesh_from_bytes<float>(with_u64(count_at, v), {validate}),
                Error)
                << v;
    std::vector<std::uint8_t> corner = file;
    const std::size_t last = corner.size() - 4;  // the last corner of the last triangle
    const std::uint32_t id = std::uint32_t(nv);
    std::memcpy(corner.data() + last, &id, 4);
    serial_detail::reseal_tree_file(corner);
    for (const bool validate : {true, false})
        EXPECT_THROW((void)signed_distance_mesh_from_bytes<float>(corner, {validate}), Error);
}

}  // namespace

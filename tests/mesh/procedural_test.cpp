// The procedural generators: sizes, closedness and outward orientation of the closed shapes (later
// code computes signed distance on them), determinism, and the spec parser's errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <unordered_map>

#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

// Closed and consistently oriented: every directed edge appears once and its reverse appears once,
// i.e. each edge is shared by exactly two triangles that traverse it in opposite directions.
::testing::AssertionResult is_closed_and_consistent(const TriangleMesh& mesh) {
    std::unordered_map<std::uint64_t, int> directed;
    directed.reserve(mesh.triangles.size() * 3);
    auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t(a) << 32) | b; };
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = t[k], b = t[(k + 1) % 3];
            if (a == b) return ::testing::AssertionFailure() << "degenerate triangle";
            if (++directed[key(a, b)] != 1)
                return ::testing::AssertionFailure() << "edge " << a << "->" << b << " used twice";
        }
    for (const auto& [k, count] : directed) {
        const auto a = static_cast<std::uint32_t>(k >> 32), b = static_cast<std::uint32_t>(k);
        if (!directed.contains(key(b, a)))
            return ::testing::AssertionFailure() << "edge " << a << "->" << b << " has no twin";
    }
    return ::testing::AssertionSuccess();
}

// Sum of the signed volumes of the tetrahedra (origin, a, b, c): the enclosed volume, positive when
// the triangles are counter-clockwise seen from outside.
double signed_volume(const TriangleMesh& mesh) {
    double v = 0;
    for (const auto& t : mesh.triangles) {
        const Vec3d a(mesh.vertices[t[0]]), b(mesh.vertices[t[1]]), c(mesh.vertices[t[2]]);
        v += dot(a, cross(b, c)) / 6.0;
    }
    return v;
}

// Shares vertices with equal positions (the room's boxes give each face its own vertices).
TriangleMesh welded(const TriangleMesh& mesh) {
    std::map<std::array<float, 3>, std::uint32_t> ids;
    std::vector<std::uint32_t> remap(mesh.vertices.size());
    TriangleMesh out;
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        const Vec3f& p = mesh.vertices[i];
        const auto [it, inserted] =
            ids.try_emplace({p[0], p[1], p[2]}, static_cast<std::uint32_t>(out.vertices.size()));
        if (inserted) out.vertices.push_back(p);
        remap[i] = it->second;
    }
    for (const auto& t : mesh.triangles)
        out.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
    return out;
}

TEST(Sphere, IsClosedOutwardAndHasTheExpectedSize) {
    for (std::uint32_t s = 0; s <= 5; ++s) {
        const TriangleMesh m = make_sphere(s);
        const std::size_t f = std::size_t(1) << s;
        EXPECT_EQ(m.triangle_count(), 20 * f * f);
        EXPECT_EQ(m.vertices.size(), 10 * f * f + 2);
        EXPECT_TRUE(is_closed_and_consistent(m)) << "subdivisions " << s;
        const double volume = signed_volume(m);
        EXPECT_GT(volume, 0.0);
        EXPECT_LE(volume, 4.0 / 3.0 * std::numbers::pi);
        for (const Vec3f& p : m.vertices) EXPECT_NEAR(length(p), 1.0f, 1e-5f);
    }
    // Fine subdivision approaches the ball's volume.
    EXPECT_NEAR(signed_volume(make_sphere(5)), 4.0 / 3.0 * std::numbers::pi, 0.01);
}

TEST(Sphere, AnyFrequencyIsClosedAndOutward) {
    for (std::uint32_t f : {1u, 3u, 5u, 7u, 12u}) {
        const TriangleMesh m = make_geodesic_sphere(f, 0.3f, 9);
        EXPECT_EQ(m.triangle_count(), 20u * f * f);
        EXPECT_TRUE(is_closed_and_consistent(m)) << "frequency " << f;
        EXPECT_GT(signed_volume(m), 0.0);
    }
}

TEST(Sphere, DisplacementStaysClosedOutwardAndWithinItsBound) {
    const TriangleMesh m = make_sphere(4, 0.4f, 3);
    EXPECT_TRUE(is_closed_and_consistent(m));
    EXPECT_GT(signed_volume(m), 0.0);
    float lo = 10, hi = 0;
    for (const Vec3f& p : m.vertices) {
        lo = std::min(lo, length(p));
        hi = std::max(hi, length(p));
    }
    EXPECT_GE(lo, 0.6f - 1e-5f);
    EXPECT_LE(hi, 1.4f + 1e-5f);
    EXPECT_GT(hi - lo, 0.1f) << "displacement should make visible bumps";
    // Every triangle faces away from the centre (the surface is star-shaped about it).
    for (const auto& t : m.triangles) {
        const Vec3f a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
        ASSERT_GT(dot(cross(b - a, c - a), a + b + c), 0.0f);
    }
}

TEST(Torus, IsClosedOutwardWithTheRightVolume) {
    const TriangleMesh m = make_torus(64, 32, 1.0f, 0.3f);
    EXPECT_EQ(m.triangle_count(), 2u * 64 * 32);
    EXPECT_EQ(m.vertices.size(), 64u * 32);
    EXPECT_TRUE(is_closed_and_consistent(m));
    const double exact = 2.0 * std::numbers::pi * std::numbers::pi * 1.0 * 0.3 * 0.3;
    EXPECT_NEAR(signed_volume(m), exact, 0.01 * exact);
    EXPECT_TRUE(is_closed_and_consistent(make_torus(3, 3, 2.0f, 0.5f)));
    EXPECT_GT(signed_volume(make_torus(3, 3, 2.0f, 0.5f)), 0.0);
}

TEST(Terrain, IsAGridFacingUp) {
    const TriangleMesh m = make_terrain(32, 5);
    EXPECT_EQ(m.triangle_count(), 2u * 32 * 32);
    EXPECT_EQ(m.vertices.size(), 33u * 33);
    for (const auto& t : m.triangles) {
        const Vec3f a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
        ASSERT_GT(cross(b - a, c - a)[1], 0.0f);
    }
    const auto box = m.bounds();
    EXPECT_FLOAT_EQ(box.min[0], 0.0f);
    EXPECT_FLOAT_EQ(box.max[2], 1.0f);
    EXPECT_GT(box.max[1] - box.min[1], 0.01f);
    EXPECT_LT(box.max[1], 0.3f);
}

TEST(Room, IsAClosedRoomHoldingClosedObjects) {
    const TriangleMesh m = make_room(40, 11);
    EXPECT_GT(m.triangle_count(), 768u + 40 * 12 - 1);
    EXPECT_TRUE(is_closed_and_consistent(welded(m)));
    const auto box = m.bounds();
    EXPECT_EQ(box.min, Vec3f(0, 0, 0));
    EXPECT_EQ(box.max, Vec3f(10, 4, 10));
    // The walls face inwards (volume -400); every object adds a positive volume.
    const TriangleMesh empty_room = make_room(0, 11);
    EXPECT_EQ(empty_room.triangle_count(), 768u);
    EXPECT_NEAR(signed_volume(empty_room), -400.0, 1e-6);
    EXPECT_GT(signed_volume(m), -400.0);
}

TEST(Soup, HasTheRequestedCountInsideTheUnitCube) {
    const TriangleMesh m = make_soup(5000, 7);
    EXPECT_EQ(m.triangle_count(), 5000u);
    EXPECT_EQ(m.vertices.size(), 15000u);
    for (const Vec3f& p : m.vertices)
        for (int k = 0; k < 3; ++k) {
            ASSERT_GE(p[k], 0.0f);
            ASSERT_LE(p[k], 1.0f);
        }
    float smallest = 1, largest = 0;
    for (const auto& t : m.triangles) {
        const float e = length(m.vertices[t[1]] - m.vertices[t[0]]);
        smallest = std::min(smallest, e);
        largest = std::max(largest, e);
    }
    EXPECT_LT(smallest, 0.003f);
    EXPECT_GT(largest, 0.05f);
}

TEST(Procedural, IsDeterministicAndSeedDependent) {
    for (const char* spec :
         {"sphere:subdiv=3,displacement=0.2,seed=3", "terrain:n=16,seed=4",
          "room:objects=10,seed=5", "soup:n=100,seed=6", "torus:u=8,v=5", "city:blocks=2,seed=7"}) {
        const TriangleMesh a = make_procedural(spec), b = make_procedural(spec);
        EXPECT_EQ(a.vertices, b.vertices) << spec;
        EXPECT_EQ(a.triangles, b.triangles) << spec;
    }
    EXPECT_NE(make_procedural("soup:n=100,seed=6").vertices,
              make_procedural("soup:n=100,seed=7").vertices);
    EXPECT_NE(make_procedural("city:blocks=2,seed=1").vertices,
              make_procedural("city:blocks=2,seed=2").vertices);
    EXPECT_NE(make_procedural("terrain:n=16,seed=1").vertices,
              make_procedural("terrain:n=16,seed=2").vertices);
    EXPECT_NE(make_procedural("sphere:subdiv=2,displacement=0.1,seed=1").vertices,
              make_procedural("sphere:subdiv=2,displacement=0.1,seed=2").vertices);
}

TEST(Procedural, SpecsSelectTheGeneratorAndItsParameters) {
    EXPECT_EQ(make_procedural("sphere").triangle_count(), 20u * 32 * 32);
    EXPECT_EQ(make_procedural("sphere:subdiv=6,seed=3").triangle_count(), 20u * 64 * 64);
    EXPECT_EQ(make_procedural("sphere:freq=10").triangle_count(), 2000u);
    EXPECT_EQ(make_procedural("terrain:n=20").triangle_count(), 800u);
    EXPECT_EQ(make_procedural("torus").triangle_count(), 2u * 96 * 48);
    EXPECT_EQ(make_procedural("soup:n=1234,seed=7").triangle_count(), 1234u);
    EXPECT_EQ(make_procedural("room:objects=0").triangle_count(), 768u);
    EXPECT_EQ(make_procedural("city").triangle_count(), make_city(8, 1).triangle_count());
    EXPECT_EQ(make_procedural("city:blocks=3,seed=4").vertices, make_city(3, 4).vertices);
    EXPECT_EQ(make_procedural("room:objects=200").triangle_count(),
              make_room(200, 1).triangle_count());
}

TEST(Procedural, BadSpecsAreErrorsListingWhatIsValid) {
    for (const char* spec : {"cube",
                             "",
                             ":n=3",
                             "sphere:",
                             "sphere:subdivs=3",
                             "sphere:subdiv=11",
                             "sphere:subdiv=x",
                             "sphere:subdiv=-1",
                             "sphere:subdiv=3,subdiv=4",
                             "sphere:subdiv=3,freq=4",
                             "sphere:displacement=1.5",
                             "sphere:displacement=nan",
                             "sphere:subdiv",
                             "terrain:n=",
                             "terrain:n=0",
                             "terrain:n=100000",
                             "torus:minor=2",
                             "torus:u=2",
                             "soup:n=0",
                             "soup:n=100000000",
                             "room:objects=1e3",
                             "room:seed=1,",
                             "city:blocks=0",
                             "city:blocks=41",
                             "city:n=3",
                             "torus:seed=1"}) {
        EXPECT_THROW(make_procedural(spec), Error) << spec;
    }
    try {
        make_procedural("cube:n=3");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("sphere, torus, terrain, room, soup, city"),
                  std::string::npos)
            << e.what();
    }
    try {
        make_procedural("terrain:size=3");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("unknown key 'size'"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("n=256, seed=1"), std::string::npos) << e.what();
    }
    EXPECT_THROW(make_sphere(11), Error);
    EXPECT_THROW(make_sphere(3, -0.1f), Error);
    EXPECT_THROW(make_torus(10, 10, 1.0f, 1.0f), Error);
    EXPECT_THROW(make_soup(0), Error);
}

TEST(LoadMesh, ReadsFilesGeneratesSpecsAndRejectsTheRest) {
    const auto dir = std::filesystem::temp_directory_path() / "bvhkit_load_mesh_test";
    std::filesystem::create_directories(dir);
    const auto file = dir / "quad.obj";
    std::ofstream(file) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    EXPECT_EQ(load_mesh(file.string()).triangle_count(), 2u);
    EXPECT_EQ(load_mesh("sphere:subdiv=2").triangle_count(), 320u);
    EXPECT_EQ(load_mesh("torus").triangle_count(), 2u * 96 * 48);
    try {
        load_mesh((dir / "missing.ply").string());
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
    }
    try {
        load_mesh("blob:n=3");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("neither"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("sphere"), std::string::npos) << e.what();
    }
    EXPECT_THROW(load_mesh("sphere:subdiv=99"), Error);
    std::filesystem::remove_all(dir);
}

// The generators must reach benchmark sizes (1M and 10M triangles) with memory close to the mesh
// itself: vectors exactly sized, no slack from growth.
TEST(Procedural, ReachesMillionsOfTrianglesWithTightMemory) {
    const TriangleMesh million = make_procedural("sphere:subdiv=8");
    EXPECT_EQ(million.triangle_count(), 1310720u);
    EXPECT_EQ(million.triangles.capacity(), million.triangles.size());
    EXPECT_EQ(million.vertices.capacity(), million.vertices.size());
    if (test::small_scale()) GTEST_SKIP() << "10M-triangle meshes only in the full-scale run";
    const TriangleMesh ten_million = make_procedural("sphere:freq=708");
    EXPECT_EQ(ten_million.triangle_count(), 20u * 708 * 708);
    EXPECT_EQ(ten_million.triangles.capacity(), ten_million.triangles.size());
    EXPECT_EQ(ten_million.vertices.capacity(), ten_million.vertices.size());
    const TriangleMesh soup = make_soup(10'000'000, 3);
    EXPECT_EQ(soup.triangle_count(), 10'000'000u);
    EXPECT_EQ(soup.vertices.capacity(), soup.vertices.size());
}

}  // namespace

TEST(Procedural, CityTrianglesSpanFourOrdersOfMagnitudeAndFaceOutwards) {
    const TriangleMesh city = make_city(3, 2);
    double smallest = 1e30, largest = 0;
    for (const auto& t : city.triangles) {
        const Vec3d a(city.vertices[t[0]]), b(city.vertices[t[1]]), c(city.vertices[t[2]]);
        const Vec3d n = cross(b - a, c - a);
        const double area = 0.5 * length(n);
        ASSERT_GT(area, 0.0);
        smallest = std::min(smallest, area);
        largest = std::max(largest, area);
        // Every face looks up or sideways, never down: the walls face away from their tower,
        // the roofs, plinths and ground up.
        ASSERT_GE(n[1], -1e-9 * length(n));
    }
    EXPECT_GT(largest / smallest, 1e4);
    // The ground is the lowest thing and covers the blocks with their streets.
    const Aabb3f box = city.bounds();
    EXPECT_EQ(box.min[1], 0.0f);
    EXPECT_EQ(box.min[0], -15.0f);
    EXPECT_EQ(box.max[2], 3 * 75.0f + 15.0f);
    // Rays from outside meet the front of whatever they hit first: from above, the roofs,
    // plinths and ground; from the sides at 10 m up, the walls.
    const TriangleBvh<float> tree(city);
    int hits = 0;
    for (int i = 0; i < 60; ++i)
        for (int j = 0; j < 60; ++j) {
            const float x = -10 + 235.0f * (i + 0.5f) / 60, z = -10 + 235.0f * (j + 0.5f) / 60;
            for (const Ray3f& ray : {Ray3f({x, 1000, z}, {0.01f, -1, 0.02f}),
                                     Ray3f({-100, 10, z}, {1, 0.001f, 0.0003f}),
                                     Ray3f({x, 10, 400}, {0.0002f, 0.001f, -1})}) {
                const Hit<float> h = tree.closest_hit(ray);
                if (!h) continue;
                ++hits;
                ASSERT_LT(dot(h.normal, ray.direction), 0.0f) << x << " " << z;
            }
        }
    EXPECT_GT(hits, 6000);  // every ray from above, most from the sides
}

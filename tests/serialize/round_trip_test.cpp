// TriangleBvh files: a saved tree loads to the same nodes, indices, triangles and skipped list,
// answers 10^4 rays bit for bit as the original, and saves again to the same bytes. Read in place
// (view_triangle_bvh, the loader of map_triangle_bvh), the file gives the same arrays and the
// answers of the same tree walked binary.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <ranges>

#include "bvhkit/io/mapped_triangle_bvh.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "random_geometry.hpp"
#include "test_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

template <class T>
bool same_hit(const Hit<T, 3>& a, const Hit<T, 3>& b) {
    return a.primitive == b.primitive && same_bits(a.t, b.t) && same_bits(a.u, b.u) &&
           same_bits(a.v, b.v) && std::memcmp(&a.normal, &b.normal, sizeof(a.normal)) == 0;
}

template <class T>
void expect_same_tree(const TriangleBvh<T>& got, const TriangleBvh<T>& want) {
    const auto &g = got.bvh(), &w = want.bvh();
    ASSERT_EQ(g.nodes.size(), w.nodes.size());
    if (!w.nodes.empty()) {  // memcmp of null pointers is undefined, even for 0 bytes
        EXPECT_EQ(0, std::memcmp(g.nodes.data(), w.nodes.data(),
                                 w.nodes.size() * sizeof(w.nodes.front())));
    }
    EXPECT_EQ(g.primitive_indices, w.primitive_indices);
    EXPECT_EQ(got.skipped(), want.skipped());
    EXPECT_EQ(got.triangle_count(), want.triangle_count());
    EXPECT_EQ(got.triangle_test(), want.triangle_test());
    // The wide ray layout is read from the file, or derived on load as on a build.
    EXPECT_EQ(got.ray_width(), want.ray_width());
}

template <class T>
void expect_same_arrays(const MappedTriangleBvh<T>& got, const TriangleBvh<T>& want) {
    const auto g = got.bvh();
    const auto& w = want.bvh();
    ASSERT_EQ(g.nodes.size(), w.nodes.size());
    if (!w.nodes.empty()) {
        EXPECT_EQ(0, std::memcmp(g.nodes.data(), w.nodes.data(),
                                 w.nodes.size() * sizeof(w.nodes.front())));
    }
    EXPECT_TRUE(std::ranges::equal(g.primitive_indices, w.primitive_indices));
    EXPECT_TRUE(std::ranges::equal(got.skipped(), want.skipped()));
    EXPECT_EQ(got.triangle_count(), want.triangle_count());
    EXPECT_EQ(got.triangle_test(), want.triangle_test());
    // Nothing was copied: the arrays lie in the bytes.
    const auto* first = got.bytes().data();
    if (!w.nodes.empty()) {
        EXPECT_GE(reinterpret_cast<const std::uint8_t*>(g.nodes.data()), first);
        EXPECT_LE(reinterpret_cast<const std::uint8_t*>(g.nodes.data() + g.nodes.size()),
                  first + got.bytes().size());
    }
}

// Rays from inside the mesh's box (enlarged) in every direction: most hit.
template <class Got, class T>
void expect_same_answers(const Got& got, const TriangleBvh<T>& want, const Aabb<T, 3>& bounds,
                         std::size_t count, std::uint64_t seed) {
    const Vec<T, 3> margin = bounds.extent() * T(0.25);
    const auto rays =
        random_rays<T>(count, Aabb<T, 3>(bounds.min - margin, bounds.max + margin), seed);
    std::size_t hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hit<T, 3> a = got.closest_hit(rays[i]), b = want.closest_hit(rays[i]);
        ASSERT_TRUE(same_hit(a, b)) << "ray " << i;
        ASSERT_EQ(got.any_hit(rays[i]), want.any_hit(rays[i])) << "ray " << i;
        hits += bool(b);
        if (i % 16 == 0) {
            std::size_t na = 0, nb = 0;
            got.all_hits(rays[i], [&](const Hit<T, 3>&) { return ++na, true; });
            want.all_hits(rays[i], [&](const Hit<T, 3>&) { return ++nb, true; });
            ASSERT_EQ(na, nb) << "ray " << i;
        }
    }
    if (want.bvh().primitive_indices.size() >= 50) {
        EXPECT_GT(hits, rays.size() / 10);
    }
}

template <class T>
void round_trip(const TriangleBvh<T>& tree, const Aabb<T, 3>& bounds, const std::string& what) {
    SCOPED_TRACE(what);
    const std::vector<std::uint8_t> bytes = to_bytes(tree);
    const TriangleBvh<T> loaded = triangle_bvh_from_bytes<T>(bytes);
    expect_same_tree(loaded, tree);
    EXPECT_EQ(to_bytes(loaded), bytes) << "saving a loaded tree gives other bytes";
    expect_same_answers(loaded, tree, bounds, scaled(10000, 10), 7);
    // Opting out of validate() loads the same tree.
    expect_same_tree(triangle_bvh_from_bytes<T>(bytes, LoadOptions{false}), tree);

    // In place: the same arrays, and the same wide layout walked by the same paths: the
    // original's answers bit for bit.
    const MappedTriangleBvh<T> mapped = view_triangle_bvh<T>(bytes);
    expect_same_arrays(mapped, tree);
    EXPECT_EQ(mapped.ray_width(), tree.ray_width());
    expect_same_answers(mapped, tree, bounds, scaled(10000, 10), 7);
}

TEST(TriangleBvhFile, SpotRoundTripsInBothScalarsAndTests) {
    BVHKIT_REQUIRE_MESH(path, "spot.obj");
    const TriangleMesh mesh = read_mesh(path);
    for (const TriangleTest test : {TriangleTest::Watertight, TriangleTest::Fast}) {
        TriangleBvhOptions options;
        options.triangle_test = test;
        const std::string name = test == TriangleTest::Fast ? "spot fast" : "spot watertight";
        round_trip(TriangleBvh<float>(mesh, options), bounds_as<float>(mesh), name + " float");
        round_trip(TriangleBvh<double>(mesh, options), bounds_as<double>(mesh), name + " double");
    }
}

TEST(TriangleBvhFile, ProceduralMeshesAndBuildersRoundTrip) {
    const char* specs[] = {"sphere:subdiv=3,displacement=0.3", "torus:u=24,v=12", "terrain:n=24",
                           "room:objects=8", "soup:n=3000"};
    const std::pair<const char*, Builder> builders[] = {
        {"binned", Builder::BinnedSah}, {"lbvh", Builder::Lbvh}, {"insertion", Builder::Insertion}};
    for (const char* spec : specs) {
        const TriangleMesh mesh = make_procedural(spec);
        for (const auto& [bname, builder] : builders)
            for (const TriangleTest test : {TriangleTest::Watertight, TriangleTest::Fast}) {
                TriangleBvhOptions options;
                options.builder = builder;
                options.max_leaf_size = builder == Builder::Lbvh ? 1 : 4;
                options.triangle_test = test;
                const std::string what = std::string(spec) + " " + bname +
                                         (test == TriangleTest::Fast ? " fast" : " watertight");
                round_trip(TriangleBvh<float>(mesh, options), bounds_as<float>(mesh), what);
                round_trip(TriangleBvh<double>(mesh, options), bounds_as<double>(mesh), what);
            }
    }
}

// The ray layout a tree was built with travels in the layout byte's high half: a tree built to walk
// the binary tree or four wide walks so after a load, and breaks ties on shared edges the same way
// (vertical rays through a terrain's grid lines hit two triangles at once).
TEST(TriangleBvhFile, RayLayoutsRoundTrip) {
    const TriangleMesh mesh = make_procedural("terrain:n=32");
    const Aabb3f box = mesh.bounds();
    // RayLayout(1) is the deprecated Wide8, which files written with it still carry.
    for (const RayLayout layout :
         {RayLayout::Auto, RayLayout(1), RayLayout::Wide4, RayLayout::Binary}) {
        TriangleBvhOptions options;
        options.ray_layout = layout;
        const TriangleBvh<float> tree(mesh, options);
        const std::string what = "ray layout " + std::to_string(int(layout));
        round_trip(tree, box, what);
        const std::vector<std::uint8_t> bytes = to_bytes(tree);
        EXPECT_EQ(bytes[18], 1 | int(layout) << 4) << what;
        const TriangleBvh<float> loaded = triangle_bvh_from_bytes<float>(bytes);
        EXPECT_EQ(loaded.ray_width(), tree.ray_width()) << what;
        SplitMix64 rng(3);
        for (std::size_t i = 0; i < scaled(20000, 10); ++i) {
            const float x = std::round(float(rng.uniform(box.min[0], box.max[0])) * 32) / 32;
            const float y = float(rng.uniform(box.min[1], box.max[1]));
            const Ray3f ray(Vec3f(x, y, box.max[2] + 1), Vec3f(0, 0, -1));
            ASSERT_TRUE(same_hit(loaded.closest_hit(ray), tree.closest_hit(ray))) << what << i;
        }
    }
}

TEST(TriangleBvhFile, SkippedTrianglesAndEmptyTreesRoundTrip) {
    std::vector<Triangle<float>> soup = random_soup<float>(500, 3);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t i = 0; i < soup.size(); i += 37) soup[i].p1[i % 3] = nan;
    soup[1].p2[0] = std::numeric_limits<float>::infinity();
    const TriangleBvh<float> tree(soup);
    ASSERT_FALSE(tree.skipped().empty());
    round_trip(tree, Aabb3f({0, 0, 0}, {1, 1, 1}), "soup with non-finite triangles");

    for (const TriangleTest test : {TriangleTest::Watertight, TriangleTest::Fast}) {
        TriangleBvhOptions options;
        options.triangle_test = test;
        round_trip(TriangleBvh<float>(std::vector<Triangle<float>>{}, options),
                   Aabb3f({0, 0, 0}, {1, 1, 1}), "empty");
        const std::vector<Triangle<float>> all_nan(3, Triangle<float>{{nan, 0, 0}, {}, {}});
        round_trip(TriangleBvh<float>(all_nan, options), Aabb3f({0, 0, 0}, {1, 1, 1}), "all NaN");
        round_trip(TriangleBvh<float>(std::vector<Triangle<float>>(1, soup[2]), options),
                   Aabb3f({0, 0, 0}, {1, 1, 1}), "one triangle");
    }
}

TEST(TriangleBvhFile, RefittedTreeRoundTrips) {
    TriangleMesh mesh = make_procedural("torus:u=16,v=8");
    TriangleBvh<float> tree(mesh);
    for (auto& v : mesh.vertices) v = v * 1.5f + Vec3f(0.25f, 0, 0);
    tree.refit(mesh);
    round_trip(tree, bounds_as<float>(mesh), "refitted torus");
}

TEST(TriangleBvhFile, SaveAndLoadThroughAFile) {
    const TriangleMesh mesh = make_sphere(2);
    const TriangleBvh<float> tree(mesh);
    const auto dir =
        std::filesystem::temp_directory_path() /
        ("bvhkit_serialize_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + std::to_string(reinterpret_cast<std::uintptr_t>(&tree)));
    std::filesystem::create_directories(dir);
    const auto path = dir / "sphere.bvh";
    save(tree, path);
    EXPECT_EQ(std::filesystem::file_size(path), to_bytes(tree).size());
    const TriangleBvh<float> loaded = load_triangle_bvh<float>(path);
    expect_same_tree(loaded, tree);
    expect_same_answers(loaded, tree, bounds_as<float>(mesh), 1000, 11);
    // A double load of a float file names both types; a missing file is an Error too.
    try {
        (void)load_triangle_bvh<double>(path);
        ADD_FAILURE() << "a float file loaded as double";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("float"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("sphere.bvh"), std::string::npos) << e.what();
    }
    EXPECT_THROW((void)load_triangle_bvh<float>(dir / "missing.bvh"), Error);

    // Mapped: the arrays in the mapping, the answers of the tree.
    const MappedTriangleBvh<float> mapped = map_triangle_bvh<float>(path);
    expect_same_arrays(mapped, tree);
    expect_same_answers(mapped, tree, bounds_as<float>(mesh), 1000, 11);
    try {
        (void)map_triangle_bvh<double>(path);
        ADD_FAILURE() << "a float file mapped as double";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("float"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("sphere.bvh"), std::string::npos) << e.what();
    }
    EXPECT_THROW((void)map_triangle_bvh<float>(dir / "missing.bvh"), Error);
    EXPECT_THROW((void)map_triangle_bvh<float>(dir), Error);  // a folder, not a file
    EXPECT_THROW(save(tree, dir / "no_such_dir" / "x.bvh"), Error);
    std::filesystem::remove_all(dir);
}

// The header's byte offsets as docs/serialization.md gives them, read by hand.
TEST(TriangleBvhFile, HeaderMatchesTheDocumentedLayout) {
    const TriangleMesh mesh = make_sphere(1);
    const TriangleBvh<double> tree(mesh);
    const std::vector<std::uint8_t> b = to_bytes(tree);
    const auto u32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        for (int i = 0; i < 4; ++i) v |= std::uint32_t(b[at + i]) << (8 * i);
        return v;
    };
    const auto u64 = [&](std::size_t at) {
        std::uint64_t v = 0;
        for (int i = 0; i < 8; ++i) v |= std::uint64_t(b[at + i]) << (8 * i);
        return v;
    };
    ASSERT_GE(b.size(), 72u);
    EXPECT_EQ(0, std::memcmp(b.data(), "BVHKIT\x1a\n", 8));
    EXPECT_EQ(u32(8), 2u);           // format version (of a TriangleBvh file)
    EXPECT_EQ(u32(12), 1u);          // kind: TriangleBvh
    EXPECT_EQ(b[16], 2);             // scalar: double
    EXPECT_EQ(b[17], 1);             // volume: Aabb3
    EXPECT_EQ(b[18], 1);             // layout: corners (watertight)
    EXPECT_EQ(b[19] | u32(20), 0u);  // reserved
    EXPECT_EQ(u64(24), tree.bvh().nodes.size());
    EXPECT_EQ(u64(32), tree.bvh().primitive_indices.size());
    EXPECT_EQ(u64(40), 0u);  // skipped
    EXPECT_EQ(u64(48), mesh.triangle_count());
    EXPECT_EQ(u64(56), b.size() - 72);          // payload bytes
    std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64 over all but the checksum
    for (std::size_t i = 0; i < b.size(); ++i)
        if (i < 64 || i >= 72) h = (h ^ b[i]) * 1099511628211ull;
    EXPECT_EQ(u64(64), h);
    // First node: the root's box min x as a little-endian double at the payload's start.
    EXPECT_EQ(std::bit_cast<double>(u64(72)), tree.bvh().nodes[0].bounds.min[0]);
    const std::size_t nodes_end = 72 + tree.bvh().nodes.size() * 56;
    EXPECT_EQ(u32(nodes_end), tree.bvh().primitive_indices[0]);
}

}  // namespace

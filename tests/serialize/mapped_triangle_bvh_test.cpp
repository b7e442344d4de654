// MappedTriangleBvh: what a mapping adds to a load (round_trip_test.cpp and malformed_test.cpp hold
// the answers and the hostile files): nothing is copied into this process's memory, batches answer
// as single rays, bytes that are not aligned are an Error, a moved-from tree is empty.
#include <gtest/gtest.h>

#if defined(__unix__)
#include <sys/stat.h>
#endif

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bvhkit/io/mapped_triangle_bvh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

// A field of /proc/self/status in bytes ("RssAnon", "RssFile"), or nothing off Linux.
std::optional<std::size_t> status_bytes(const std::string& field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(field + ":", 0) == 0)
            return std::stoull(line.substr(field.size() + 1)) * 1024;
    return std::nullopt;
}

struct TempFile {
    std::filesystem::path path;
    explicit TempFile(const std::string& name)
        : path(std::filesystem::temp_directory_path() /
               ("bvhkit_mapped_" +
                std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" + name)) {}
    ~TempFile() { std::filesystem::remove(path); }
};

// The acceptance check of a mapped load: the process's own (anonymous) memory does not grow by the
// tree's size, while the copying load's does (which shows the measure can see a copy). The pages
// read in place are file pages, shared with the page cache. Skipped under the sanitizers, whose
// allocators keep freed memory.
TEST(MappedTriangleBvh, ResidentMemoryDoesNotGrowByTheTreesSize) {
    if (small_scale()) GTEST_SKIP() << "sanitizer build: its allocator keeps freed memory";
    if (!status_bytes("RssAnon")) GTEST_SKIP() << "no /proc/self/status";
    TempFile file("rss.bvh");
    {
        const TriangleBvh<float> tree(make_procedural("sphere:subdiv=7"));  // 327,680 triangles
        save(tree, file.path);
    }
    const std::size_t size = std::filesystem::file_size(file.path);
    ASSERT_GT(size, std::size_t(12) << 20);  // large against the noise of the process's own memory
    const auto rays = random_rays<float>(2000, Aabb3f({-2, -2, -2}, {2, 2, 2}), 5);

    const std::size_t before = *status_bytes("RssAnon");
    const auto mapped = map_triangle_bvh<float>(file.path, LoadOptions{.validate = false});
    std::size_t hits = 0;
    for (const auto& ray : rays) hits += bool(mapped.closest_hit(ray));
    const std::size_t mapped_growth = *status_bytes("RssAnon") - before;
    EXPECT_GT(hits, rays.size() / 10);
    EXPECT_LT(mapped_growth, size / 8) << "mapped: " << mapped_growth << " of " << size << " bytes";

    const std::size_t before_copy = *status_bytes("RssAnon");
    const auto loaded = load_triangle_bvh<float>(file.path, LoadOptions{.validate = false});
    for (const auto& ray : rays) hits -= bool(loaded.closest_hit(ray));
    const std::size_t copy_growth = *status_bytes("RssAnon") - before_copy;
    EXPECT_EQ(hits, 0u);
    EXPECT_GT(copy_growth, size / 2) << "copied: " << copy_growth << " of " << size << " bytes";
    RecordProperty("file_bytes", std::to_string(size));
    RecordProperty("anon_growth_mapped", std::to_string(mapped_growth));
    RecordProperty("anon_growth_loaded", std::to_string(copy_growth));
}

TEST(MappedTriangleBvh, BatchesAnswerAsSingleRays) {
    const auto bytes = to_bytes(TriangleBvh<float>(make_procedural("torus:u=48,v=24")));
    const auto tree = view_triangle_bvh<float>(bytes);
    const auto rays = random_rays<float>(scaled(3000, 10), Aabb3f({-2, -2, -1}, {2, 2, 1}), 9);
    for (const unsigned threads : {1u, 0u}) {
        std::vector<Hit<float>> hits(rays.size());
        std::vector<std::uint8_t> occluded(rays.size());
        tree.trace(rays, hits, threads);
        tree.occluded(rays, occluded, threads);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Hit<float> h = tree.closest_hit(rays[i]);
            ASSERT_EQ(hits[i].primitive, h.primitive) << i;
            ASSERT_EQ(hits[i].t, h.t) << i;
            ASSERT_EQ(occluded[i], tree.any_hit(rays[i]) ? 1 : 0) << i;
        }
    }
    std::vector<Hit<float>> short_hits(rays.size() - 1);
    EXPECT_THROW(tree.trace(rays, short_hits), Error);
}

// save() writes a new file and renames it over the old one, so a tree mapped from the old file
// keeps its checked bytes (rewriting in place would show unchecked bytes to its walks).
TEST(MappedTriangleBvh, SavingOverAMappedFileLeavesTheMappedTreeWhole) {
    TempFile file("resaved.bvh");
    save(TriangleBvh<float>(make_sphere(1)), file.path);
    const auto mapped = map_triangle_bvh<float>(file.path);
    const auto rays = random_rays<float>(500, Aabb3f({-2, -2, -2}, {2, 2, 2}), 4);
    std::vector<Hit<float>> before(rays.size());
    mapped.trace(rays, before, 1);
    save(TriangleBvh<float>(make_procedural("torus:u=64,v=32")), file.path);  // larger, other
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hit<float> h = mapped.closest_hit(rays[i]);
        ASSERT_EQ(h.primitive, before[i].primitive) << i;
        ASSERT_EQ(h.t, before[i].t) << i;
    }
    EXPECT_NE(map_triangle_bvh<float>(file.path).triangle_count(), mapped.triangle_count());
    // No temporary file is left beside it.
    std::size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(file.path.parent_path()))
        files += e.path().filename().string().rfind(file.path.filename().string(), 0) == 0;
    EXPECT_EQ(files, 1u);
}

// A temporary buffer would be freed before the first query: view_triangle_bvh refuses it.
template <class Bytes>
concept ViewableFrom = requires(Bytes&& b) {
    view_triangle_bvh<float>(std::forward<Bytes>(b));
};
static_assert(ViewableFrom<std::vector<std::uint8_t>&>);
static_assert(ViewableFrom<const std::vector<std::uint8_t>&>);
static_assert(!ViewableFrom<std::vector<std::uint8_t>>);

TEST(MappedTriangleBvh, SpecialFilesAreErrorsNamingThem) {
    const auto dir = std::filesystem::temp_directory_path();
    for (const std::filesystem::path& p :
         {dir, std::filesystem::path("/dev/null"), std::filesystem::path("/proc/self/status"),
          dir / "bvhkit_no_such_file.bvh"}) {
        if (!std::filesystem::exists(p) && p.filename() != "bvhkit_no_such_file.bvh") continue;
        try {
            (void)map_triangle_bvh<float>(p);
            ADD_FAILURE() << p << " mapped";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
        }
    }
}

#if defined(__unix__)
// Opening a FIFO for reading waits for a writer; the map must not.
TEST(MappedTriangleBvh, AFifoIsAnErrorNotAHang) {
    TempFile fifo("fifo");
    ASSERT_EQ(::mkfifo(fifo.path.c_str(), 0600), 0);
    EXPECT_THROW((void)map_triangle_bvh<float>(fifo.path), Error);
}
#endif

TEST(MappedTriangleBvh, BytesNotAlignedAreAnError) {
    const auto bytes = to_bytes(TriangleBvh<double>(make_sphere(1)));
    std::vector<std::uint8_t> shifted(bytes.size() + 4);
    std::copy(bytes.begin(), bytes.end(), shifted.begin() + 4);
    try {
        (void)view_triangle_bvh<double>(std::span(shifted).subspan(4));
        ADD_FAILURE() << "misaligned bytes were read in place";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("aligned"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW((void)view_triangle_bvh<double>(bytes));
}

TEST(MappedTriangleBvh, EmptyAndMovedFromTreesMiss) {
    const Ray3f ray({0, 0, -5}, {0, 0, 1});
    EXPECT_FALSE(MappedTriangleBvh<float>().closest_hit(ray));
    EXPECT_FALSE(MappedTriangleBvh<float>().any_hit(ray));
    TempFile file("sphere.bvh");
    save(TriangleBvh<float>(make_sphere(2)), file.path);
    auto tree = map_triangle_bvh<float>(file.path);
    ASSERT_TRUE(tree.closest_hit(ray));
    const MappedTriangleBvh<float> moved = std::move(tree);
    EXPECT_TRUE(moved.closest_hit(ray));
    EXPECT_FALSE(tree.closest_hit(ray));  // NOLINT(bugprone-use-after-move): empty by contract
    EXPECT_TRUE(tree.bvh().empty());      // NOLINT(bugprone-use-after-move)
    // An empty file is an Error naming it, not a crash (mmap refuses length 0).
    TempFile empty("empty.bvh");
    std::ofstream(empty.path).close();
    try {
        (void)map_triangle_bvh<float>(empty.path);
        ADD_FAILURE() << "an empty file mapped";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("empty.bvh"), std::string::npos) << e.what();
    }
}

}  // namespace

// TriangleBvh files that lie: every truncation, random byte flips (caught by the checksum), flips
// with the checksum recomputed (caught by the structure checks, or loading a tree that validates
// and answers queries), and hand-made hostile headers and trees. Every failure must be a
// bvhkit::Error; the sanitizer build checks that nothing reads out of range meanwhile. Each file
// goes through both loaders, the copying one and the in-place one (view_triangle_bvh, what
// map_triangle_bvh runs), which must accept and refuse the same files.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "bvhkit/io/mapped_triangle_bvh.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "byte_flips.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

using Node = BvhNode<Aabb3f>;

std::size_t flip_count() {
    return full_scale() ? 100000 : scaled(10000, 10);
}

// Queries that touch every part of a loaded tree; ASan/UBSan judge them.
template <template <class> class Tree, class T>  // TriangleBvh or MappedTriangleBvh
std::size_t exercise(const Tree<T>& tree, std::uint64_t seed) {
    std::size_t n = 0;
    for (const auto& ray : random_rays<T>(8, Aabb<T, 3>({-1, -1, -1}, {1, 1, 1}), seed)) {
        n += bool(tree.closest_hit(ray));
        n += tree.any_hit(ray);
        tree.all_hits(ray, [&](const Hit<T>&) { return ++n, true; });
    }
    return n;
}

std::vector<std::uint8_t> small_file(TriangleTest test = TriangleTest::Watertight) {
    TriangleBvhOptions options;
    options.triangle_test = test;
    options.max_leaf_size = 2;
    return to_bytes(TriangleBvh<float>(make_sphere(1), options));  // 80 triangles, ~5 KB
}

void expect_error(std::span<const std::uint8_t> bytes, const std::string& what,
                  const std::string& message_part = "", bool validate = true) {
    try {
        (void)triangle_bvh_from_bytes<float>(bytes, LoadOptions{validate});
        ADD_FAILURE() << what << ": loaded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(message_part), std::string::npos)
            << what << ": " << e.what();
    }
    try {
        (void)view_triangle_bvh<float>(bytes, LoadOptions{validate});
        ADD_FAILURE() << what << ": viewed in place";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(message_part), std::string::npos)
            << what << " (in place): " << e.what();
    }
}

TEST(TriangleBvhFileMalformed, EveryTruncationAndAnExtraByteAreErrors) {
    for (const TriangleTest test : {TriangleTest::Watertight, TriangleTest::Fast}) {
        const std::vector<std::uint8_t> file = small_file(test);
        ASSERT_NO_THROW((void)triangle_bvh_from_bytes<float>(file));
        for (std::size_t n = 0; n < file.size(); ++n)
            expect_error(std::span(file).first(n), "truncated to " + std::to_string(n));
        std::vector<std::uint8_t> longer = file;
        longer.push_back(0);
        expect_error(longer, "one byte appended", "payload bytes");
    }
}

// FNV-1a changes with any one-byte change, so every flip is caught before the counts are used.
TEST(TriangleBvhFileMalformed, RandomByteFlipsAreCaughtByTheChecksum) {
    const std::vector<std::uint8_t> file = small_file();
    SplitMix64 rng(1);
    const std::size_t rounds = flip_count();
    for (std::size_t round = 0; round < rounds; ++round) {
        std::vector<std::uint8_t> bad = test::with_byte_flips(file, rng);
        if (bad == file) continue;
        ASSERT_THROW((void)triangle_bvh_from_bytes<float>(bad), Error) << "round " << round;
    }
}

// With the checksum recomputed, the flips reach the other checks: each load is an Error or a tree
// that validated (or, opted out, passed the structure checks) and answers queries in range.
TEST(TriangleBvhFileMalformed, ResealedByteFlipsGiveErrorsOrUsableTrees) {
    for (const TriangleTest test : {TriangleTest::Watertight, TriangleTest::Fast}) {
        const std::vector<std::uint8_t> file = small_file(test);
        SplitMix64 rng(test == TriangleTest::Fast ? 3 : 2);
        const std::size_t rounds = flip_count();
        std::size_t loaded[2] = {0, 0};
        for (std::size_t round = 0; round < rounds; ++round) {
            std::vector<std::uint8_t> bad = file;
            const std::uint32_t flips = 1 + rng.below(4);
            for (std::uint32_t f = 0; f < flips; ++f) {
                // Half the flips in the header, where the counts are.
                const std::uint32_t at =
                    rng.below(2) ? rng.below(72) : rng.below(std::uint32_t(bad.size()));
                bad[at] ^= std::uint8_t(1 + rng.below(255));
            }
            serial_detail::reseal_tree_file(bad);
            for (const bool validate : {true, false}) {
                bool copied = false, in_place = false;
                try {
                    const TriangleBvh<float> tree =
                        triangle_bvh_from_bytes<float>(bad, LoadOptions{validate});
                    ++loaded[validate];
                    copied = true;
                    (void)exercise(tree, round);
                } catch (const Error&) {
                }
                try {
                    const auto tree = view_triangle_bvh<float>(bad, LoadOptions{validate});
                    in_place = true;
                    (void)exercise(tree, round);
                } catch (const Error&) {
                }
                EXPECT_EQ(copied, in_place) << "round " << round << ", validate " << validate;
            }
        }
        // Flips in coordinates that stay inside their boxes load; most others must not.
        RecordProperty(test == TriangleTest::Fast ? "fast_loaded" : "watertight_loaded",
                       std::to_string(loaded[1]) + " of " + std::to_string(rounds));
        EXPECT_LT(loaded[1], rounds);
        EXPECT_LE(loaded[1], loaded[0]);
    }
}

// ---- Hand-made files, written from docs/serialization.md, not through the library's writer ----

struct RawTree {
    std::vector<Node> nodes;
    std::vector<std::uint32_t> prims;
    std::vector<Triangle<float>> tris;  // slot order, corners
    std::vector<std::uint32_t> skipped;
    std::uint64_t counts[4] = {};  // 0 means "the true count"
    std::uint32_t version = 1, kind = 1;
    std::uint8_t scalar = 1, volume = 1, layout = 1, reserved = 0;
    std::int64_t payload_adjust = 0;  // added to the payload size the header states
    bool nonzero_padding = false;

    std::vector<std::uint8_t> bytes() const {
        std::vector<std::uint8_t> p;
        const auto put = [&](std::uint64_t v, int n) {
            for (int i = 0; i < n; ++i) p.push_back(std::uint8_t(v >> (8 * i)));
        };
        const auto f32 = [&](float x) { put(std::bit_cast<std::uint32_t>(x), 4); };
        const auto pad = [&] {
            while (p.size() % 8) p.push_back(nonzero_padding ? 1 : 0);
        };
        for (const Node& n : nodes) {
            for (int a = 0; a < 3; ++a) f32(n.bounds.min[a]);
            for (int a = 0; a < 3; ++a) f32(n.bounds.max[a]);
            put(n.first, 4);
            put(n.count, 4);
        }
        pad();
        for (const std::uint32_t i : prims) put(i, 4);
        pad();
        for (const auto& t : tris)
            for (const auto& v : {t.p0, t.p1, t.p2})
                for (int a = 0; a < 3; ++a) f32(v[a]);
        pad();
        for (const std::uint32_t i : skipped) put(i, 4);
        pad();
        std::vector<std::uint8_t> h;
        const auto hput = [&](std::uint64_t v, int n) {
            for (int i = 0; i < n; ++i) h.push_back(std::uint8_t(v >> (8 * i)));
        };
        for (const char c : std::string("BVHKIT\x1a\n")) h.push_back(std::uint8_t(c));
        hput(version, 4);
        hput(kind, 4);
        h.insert(h.end(), {scalar, volume, layout, reserved});
        hput(0, 4);
        const std::uint64_t truth[4] = {nodes.size(), prims.size(), skipped.size(),
                                        prims.size() + skipped.size()};
        for (int i = 0; i < 4; ++i) hput(counts[i] ? counts[i] : truth[i], 8);
        hput(std::uint64_t(std::int64_t(p.size()) + payload_adjust), 8);
        std::uint64_t sum = 14695981039346656037ull;
        for (const std::uint8_t b : h) sum = (sum ^ b) * 1099511628211ull;
        for (const std::uint8_t b : p) sum = (sum ^ b) * 1099511628211ull;
        hput(sum, 8);
        h.insert(h.end(), p.begin(), p.end());
        return h;
    }
};

const Aabb3f unit({0, 0, 0}, {1, 1, 1});
const Triangle<float> tri{{0.1f, 0.1f, 0.5f}, {0.9f, 0.1f, 0.5f}, {0.1f, 0.9f, 0.5f}};
const Triangle<float> higher{{0.1f, 0.1f, 0.75f}, {0.9f, 0.1f, 0.75f}, {0.1f, 0.9f, 0.75f}};

Node internal(std::uint32_t first, Aabb3f box = unit) {
    return {box, first, 0};
}
Node leaf(std::uint32_t first, std::uint32_t count, Aabb3f box = unit) {
    return {box, first, count};
}

// Root and two one-triangle leaves: valid, and the base of the hostile variants.
RawTree two_leaves() {
    RawTree t;
    t.nodes = {internal(1), leaf(0, 1), leaf(1, 1)};
    t.prims = {1, 0};
    t.tris = {tri, higher};
    return t;
}

// A caterpillar: each internal node has a leaf on the left and the next internal on the right.
RawTree chain(std::uint32_t depth) {
    RawTree t;
    t.nodes.push_back(internal(1));
    for (std::uint32_t d = 0; d < depth; ++d) {
        const auto left = std::uint32_t(t.nodes.size());
        t.nodes.push_back(leaf(d, 1));
        t.nodes.push_back(d + 1 < depth ? internal(left + 2) : leaf(d + 1, 1));
    }
    for (std::uint32_t i = 0; i <= depth; ++i) t.prims.push_back(i), t.tris.push_back(tri);
    return t;
}

TEST(TriangleBvhFileHostile, HandMadeValidFilesLoad) {
    const auto tree = triangle_bvh_from_bytes<float>(two_leaves().bytes());
    EXPECT_EQ(tree.triangle_count(), 2u);
    const Hit<float> h = tree.closest_hit(Ray<float, 3>({0.2f, 0.2f, 0.0f}, {0, 0, 1}));
    EXPECT_EQ(h.primitive, 1u);  // slot 0 holds triangle 1
    EXPECT_EQ(h.t, 0.5f);
    // The deepest tree the traversals accept: depth max_bvh_depth.
    const auto deep_bytes = chain(max_bvh_depth).bytes();
    const auto deep = triangle_bvh_from_bytes<float>(deep_bytes);
    EXPECT_GT(exercise(deep, 1), 0u);
    EXPECT_EQ(exercise(view_triangle_bvh<float>(deep_bytes), 1), exercise(deep, 1));
    RawTree skipped = two_leaves();
    skipped.skipped = {0, 2};
    skipped.prims = {1, 3};
    EXPECT_EQ(triangle_bvh_from_bytes<float>(skipped.bytes()).skipped().size(), 2u);
}

TEST(TriangleBvhFileHostile, BadHeadersAreErrors) {
    const auto with = [](auto change) {
        RawTree t = two_leaves();
        change(t);
        return t.bytes();
    };
    std::vector<std::uint8_t> magic = two_leaves().bytes();
    magic[3] = 'X';
    expect_error(magic, "magic", "magic");
    expect_error(with([](RawTree& t) { t.version = 3; }), "version 3", "version 3");
    // Version 2 needs the wide sections' header after the skipped list.
    expect_error(with([](RawTree& t) { t.version = 2; }), "version 2 without wide sections",
                 "payload bytes");
    expect_error(with([](RawTree& t) { t.version = 0; }), "version 0", "version");
    expect_error(with([](RawTree& t) { t.kind = 2; }), "kind", "kind");
    expect_error(with([](RawTree& t) { t.scalar = 7; }), "scalar 7", "unknown");
    expect_error(with([](RawTree& t) { t.scalar = 2; }), "double as float", "double");
    expect_error(with([](RawTree& t) { t.volume = 2; }), "volume", "volume");
    expect_error(with([](RawTree& t) { t.layout = 0; }), "layout 0", "layout");
    expect_error(with([](RawTree& t) { t.layout = 3; }), "layout 3", "layout");
    expect_error(with([](RawTree& t) { t.layout = 0x41; }), "ray layout 4", "layout");
    expect_error(with([](RawTree& t) { t.reserved = 1; }), "reserved", "reserved");
    expect_error(with([](RawTree& t) { t.payload_adjust = 8; }), "payload too long", "truncated");
    expect_error(with([](RawTree& t) { t.payload_adjust = -8; }), "payload short", "payload");
    expect_error(with([](RawTree& t) {
                     // One slot: 4 bytes of padding after the indices and after the triangle.
                     t.nodes = {leaf(0, 1)};
                     t.prims = {0};
                     t.tris = {tri};
                     t.nonzero_padding = true;
                 }),
                 "padding", "padding");
}

// Counts that claim more than the file holds fail before any allocation (ASan would report an
// allocation of 2^60 records; the limit on allocations is the file's size).
TEST(TriangleBvhFileHostile, HugeOrInconsistentCountsAreErrors) {
    const std::uint64_t huge[] = {std::uint64_t(1) << 60, std::uint64_t(1) << 32, 0xffffffffu,
                                  std::numeric_limits<std::uint64_t>::max()};
    for (int field = 0; field < 4; ++field)
        for (const std::uint64_t count : huge) {
            RawTree t = two_leaves();
            t.counts[field] = count;
            expect_error(t.bytes(),
                         "count " + std::to_string(field) + " = " + std::to_string(count));
        }
    RawTree t = two_leaves();
    t.counts[3] = 3;  // triangles != slots + skipped
    expect_error(t.bytes(), "triangle count", "triangle count");
    // Sections consistent with the payload size but not with each other.
    RawTree more_nodes = two_leaves();
    more_nodes.counts[0] = 4;
    expect_error(more_nodes.bytes(), "one node too many", "payload bytes");
}

TEST(TriangleBvhFileHostile, BadTreesAreErrorsEvenWithoutValidation) {
    const auto check = [](RawTree t, const std::string& what, const std::string& part) {
        SCOPED_TRACE(what);
        expect_error(t.bytes(), what, part, true);
        expect_error(t.bytes(), what + " (validate off)", part, false);
    };
    RawTree t = two_leaves();
    t.nodes[0] = internal(0);
    check(t, "root is its own child", "out of order");
    t = two_leaves();
    t.nodes = {internal(1), internal(1), leaf(0, 1), leaf(1, 1)};
    check(t, "a child points back", "out of order");
    t = two_leaves();
    t.nodes = {internal(1), internal(3), internal(3), leaf(0, 1), leaf(1, 1)};
    check(t, "shared children", "two parents");
    t = two_leaves();
    t.nodes = {internal(2), leaf(0, 1), leaf(1, 1)};
    check(t, "children past the end", "range");
    t = two_leaves();
    t.nodes[0] = internal(0xffffffffu);
    check(t, "child index 2^32 - 1", "range");
    t = two_leaves();
    t.nodes[2] = leaf(1, 2);
    check(t, "leaf run past the slots", "leaf run");
    t = two_leaves();
    t.nodes[2] = leaf(0xffffffffu, 2);
    check(t, "leaf run wrapping around 2^32", "leaf run");
    t = two_leaves();
    t.nodes[2] = leaf(0, 1);
    check(t, "two leaves share a slot", "two leaves");
    t = two_leaves();
    t.nodes = {internal(1), leaf(0, 1), leaf(1, 1), leaf(0, 1), leaf(1, 1)};
    check(t, "unreachable nodes", "unreachable");
    t = two_leaves();
    t.nodes = {leaf(0, 1)};
    check(t, "a slot in no leaf", "no leaf");
    t = two_leaves();
    t.nodes.clear();
    check(t, "slots without nodes", "no nodes");
    t = two_leaves();
    t.prims = {0, 7};  // of 2 triangles
    check(t, "primitive index out of range", "names primitive");
    t = two_leaves();
    t.prims = {0, 1};
    t.skipped = {5};
    t.counts[3] = 3;
    check(t, "skipped out of range", "skipped");
    t = two_leaves();
    t.prims = {0, 3};
    t.skipped = {2, 1};
    check(t, "skipped not ascending", "skipped");
    check(chain(max_bvh_depth + 1), "one level too deep", "deeper");
}

// What only validate() catches: geometry. Opted out, such a tree loads and queries stay in range.
TEST(TriangleBvhFileHostile, BadGeometryIsCaughtByValidation) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<RawTree> cases;
    RawTree t = two_leaves();
    t.nodes[1].bounds = Aabb3f({0, 0, 0}, {0.5f, 0.5f, 0.5f});
    cases.push_back(t);  // a leaf does not enclose its triangle
    t = two_leaves();
    t.nodes[0].bounds = Aabb3f({0.5f, 0, 0}, {1, 1, 1});
    cases.push_back(t);  // the root does not enclose its children
    t = two_leaves();
    t.nodes[2].bounds.max[1] = nan;
    cases.push_back(t);
    t = two_leaves();
    t.tris[0].p1[2] = nan;
    cases.push_back(t);  // a non-finite triangle in the tree
    t = two_leaves();
    t.prims = {1, 1};
    t.skipped = {0};
    t.counts[3] = 3;
    cases.push_back(t);  // a triangle twice (and one listed as skipped)
    t = two_leaves();
    t.prims = {1, 0};
    t.skipped = {1};
    cases.push_back(t);  // a skipped triangle in the tree
    for (std::size_t i = 0; i < cases.size(); ++i) {
        SCOPED_TRACE("case " + std::to_string(i));
        const auto bytes = cases[i].bytes();
        expect_error(bytes, "validate on", "validate");
        const TriangleBvh<float> tree = triangle_bvh_from_bytes<float>(bytes, LoadOptions{false});
        (void)exercise(tree, i);
        (void)exercise(view_triangle_bvh<float>(bytes, LoadOptions{false}), i);
    }
}

}  // namespace

// The wide ray layout in TriangleBvh files (version 2, io/wide_ray_sections.hpp): a mapped file
// traces through it bit for bit as the tree in memory does, on every path; a version-1 file (one
// written before the layout was stored, kept here as bytes) still loads; a layout of another
// width than this CPU walks is derived again (copying load) or left for the binary walk (mapped);
// a layout written in the collapse's own lane order (before the order for occlusion rays) still
// loads; and wide sections that lie are Errors from both loaders, with validation on or off.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "bvhkit/io/mapped_triangle_bvh.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

// A TriangleBvh<float> of make_sphere(0) (20 triangles) as the library wrote it before version 2
// (format version 1: no wide sections), saved by the code of that time.
const std::uint8_t version1_sphere0[] = {
    0x42, 0x56, 0x48, 0x4b, 0x49, 0x54, 0x1a, 0x0a, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00,
    0x01, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x07, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x14, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x14, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0xda, 0xb6, 0x04, 0x74, 0x9f, 0x21, 0x53, 0xef, 0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f,
    0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x40, 0xc4, 0x59, 0xbf, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f,
    0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f,
    0x05, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x40, 0xc4, 0x59, 0xbf, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x50, 0x96, 0x06, 0x3f,
    0x00, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x50, 0x96, 0x06, 0xbf, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f,
    0x05, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x50, 0x96, 0x06, 0x3f,
    0x0a, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f,
    0x0f, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00,
    0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0x00, 0x09, 0x00, 0x00, 0x00,
    0x06, 0x00, 0x00, 0x00, 0x07, 0x00, 0x00, 0x00, 0x0e, 0x00, 0x00, 0x00, 0x0b, 0x00, 0x00, 0x00,
    0x10, 0x00, 0x00, 0x00, 0x0d, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00,
    0x11, 0x00, 0x00, 0x00, 0x12, 0x00, 0x00, 0x00, 0x0a, 0x00, 0x00, 0x00, 0x13, 0x00, 0x00, 0x00,
    0x0f, 0x00, 0x00, 0x00, 0x0c, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x00, 0x00, 0x00, 0x00, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f,
    0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0xbf,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f,
    0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x40, 0xc4, 0x59, 0xbf,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0xbf, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0xbf,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0x3f, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f,
    0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf,
    0x40, 0xc4, 0x59, 0x3f, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0xbf,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f,
    0x00, 0x00, 0x00, 0x00, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f,
    0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f,
    0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0xbf, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf,
    0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0xbf,
    0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0xbf, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0xbf,
    0x00, 0x00, 0x00, 0x00, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf,
    0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x40, 0xc4, 0x59, 0x3f,
    0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf,
    0x40, 0xc4, 0x59, 0x3f, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0xbf, 0x00, 0x00, 0x00, 0x00,
    0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0x3f, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f, 0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0xbf, 0x40, 0xc4, 0x59, 0x3f,
    0x40, 0xc4, 0x59, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x50, 0x96, 0x06, 0x3f, 0x00, 0x00, 0x00, 0x00,
    0x50, 0x96, 0x06, 0x3f, 0x40, 0xc4, 0x59, 0x3f,
};

/// Rays at a mesh's box from around it and inside it, with -0 and subnormal direction components
/// and a few NaN and empty-interval rays (which take the binary walk).
std::vector<Ray3f> file_test_rays(const std::vector<Triangle<float>>& tris, std::size_t n,
                                  std::uint64_t seed) {
    Aabb3f box;
    for (const auto& t : tris) box.grow(t.bounds());
    const Vec3f c = box.centroid(), e = box.max - box.min;
    const Aabb3f around(c - e, c + e);
    std::vector<Ray3f> rays = random_rays<float>(n, around, seed);
    SplitMix64 rng(seed);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const auto& t = tris[rng.below(std::uint32_t(tris.size()))];
        if (i % 3 == 0) rays[i].direction = t.p0 - rays[i].origin;  // at a vertex
        if (i % 5 == 1) rays[i].direction[i % 3] = (i / 5) % 2 ? 0.0f : -0.0f;
        if (i % 97 == 7) rays[i].direction[(i + 1) % 3] = 1e-41f;
        if (i % 89 == 3) rays[i].direction[i % 3] = std::numeric_limits<float>::quiet_NaN();
        if (i % 83 == 5) rays[i].tmin = rays[i].tmax + 1;
    }
    return rays;
}

template <class A, class B>
void expect_same_answers(const A& a, const B& b, const std::vector<Ray3f>& rays) {
    std::vector<Hit<float>> hits(rays.size());
    std::vector<std::uint8_t> blocked(rays.size(), 7);
    b.trace(rays, hits, 2);
    b.occluded(rays, blocked, 2);
    std::size_t hit_count = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hit<float> x = a.closest_hit(rays[i]), y = b.closest_hit(rays[i]);
        ASSERT_EQ(bool(x), bool(y)) << i;
        ASSERT_EQ(a.any_hit(rays[i]), b.any_hit(rays[i])) << i;
        ASSERT_EQ(blocked[i], a.any_hit(rays[i]) ? 1 : 0) << i;
        ASSERT_EQ(bool(hits[i]), bool(x)) << i;
        hit_count += bool(x);
        if (!x) continue;
        for (const Hit<float>& z : {y, hits[i]}) {
            ASSERT_EQ(x.primitive, z.primitive) << i;
            ASSERT_TRUE(same_bits(x.t, z.t) && same_bits(x.u, z.u) && same_bits(x.v, z.v)) << i;
            ASSERT_EQ(x.normal, z.normal) << i;
        }
    }
    EXPECT_GT(hit_count, rays.size() / 20);
    EXPECT_LT(hit_count, rays.size());
}

struct TempPath {
    std::filesystem::path path;
    explicit TempPath(const std::string& name)
        : path(std::filesystem::temp_directory_path() /
               ("bvhkit_wide_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                "_" + name)) {}
    ~TempPath() { std::filesystem::remove(path); }
};

// The payload offset of the wide header: after the four version-1 sections.
std::size_t wide_header_at(const std::vector<std::uint8_t>& file) {
    const auto u64 = [&](std::size_t at) {
        std::uint64_t v = 0;
        for (int i = 0; i < 8; ++i) v |= std::uint64_t(file[at + i]) << (8 * i);
        return v;
    };
    const auto padded = [](std::uint64_t n) { return (n + 7) / 8 * 8; };
    const std::uint64_t nodes = u64(24), slots = u64(32), skipped = u64(40);
    const std::uint64_t triangle = (file[18] & 0x0f) == 2 ? 48 : 36;  // float records
    return std::size_t(72 + padded(nodes * 32) + padded(slots * 4) + padded(slots * triangle) +
                       padded(skipped * 4));
}

// `file` with its wide sections replaced by `layout` (written by the library's section writer)
// and the header's payload size and checksum made right.
template <int W>
std::vector<std::uint8_t> with_wide(const std::vector<std::uint8_t>& file,
                                    const WideRayBvh<W>& layout) {
    const std::size_t at = wide_header_at(file);
    serial_detail::ByteWriter w;
    for (std::size_t i = 72; i < at; ++i) w.u8(file[i]);
    serial_detail::put_wide_layout<W>(w, layout.view());
    std::vector<std::uint8_t> out(72 + w.size());
    std::copy(file.begin(), file.begin() + 72, out.begin());
    std::copy(w.bytes().begin(), w.bytes().end(), out.begin() + 72);
    const std::uint64_t payload = out.size() - 72;
    for (int i = 0; i < 8; ++i) out[56 + i] = std::uint8_t(payload >> (8 * i));
    serial_detail::reseal_tree_file(out);
    return out;
}

// The version-1 form of a version-2 file: the wide sections cut off.
std::vector<std::uint8_t> as_version1(const std::vector<std::uint8_t>& file) {
    std::vector<std::uint8_t> out(file.begin(),
                                  file.begin() + std::ptrdiff_t(wide_header_at(file)));
    out[8] = 1;
    const std::uint64_t payload = out.size() - 72;
    for (int i = 0; i < 8; ++i) out[56 + i] = std::uint8_t(payload >> (8 * i));
    serial_detail::reseal_tree_file(out);
    return out;
}

void expect_refused(const std::vector<std::uint8_t>& bytes, const std::string& what,
                    const std::string& part, bool also_without_validation = true) {
    for (const bool validate : {true, false}) {
        if (!validate && !also_without_validation) continue;
        SCOPED_TRACE(what + (validate ? "" : " (validate off)"));
        try {
            (void)triangle_bvh_from_bytes<float>(bytes, LoadOptions{validate});
            ADD_FAILURE() << "loaded";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        }
        try {
            (void)view_triangle_bvh<float>(bytes, LoadOptions{validate});
            ADD_FAILURE() << "viewed in place";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        }
    }
}

TEST(WideLayoutFile, MappedTreesTraceWideAsTheTreeInMemory) {
    struct Case {
        std::string name;
        std::vector<Triangle<float>> tris;
    };
    std::vector<Case> cases{{"sphere", placed<float>(make_sphere(4), 1, 0)},
                            {"far torus", placed<float>(make_torus(64, 32), 1, 1e6)},
                            {"tiny sphere", placed<float>(make_sphere(3), 1e-6, 0)},
                            {"huge terrain", placed<float>(make_terrain(48), 1e6, 0)},
                            {"needles", random_needles(2000, 5, true)}};
    if (const auto bunny = shared_mesh("stanford-bunny.obj"); !bunny.empty())
        cases.push_back({"bunny", placed<float>(read_mesh(bunny), 1, 0)});
    for (const Case& c : cases) {
        const auto rays = file_test_rays(c.tris, scaled(6000, 10), 3);
        for (const RayLayout layout : {RayLayout::Auto, RayLayout::Wide4}) {
            TriangleBvhOptions options;
            options.ray_layout = layout;
            const TriangleBvh<float> tree(c.tris, options);
            SCOPED_TRACE(c.name + ", width " + std::to_string(tree.ray_width()));
            TempPath file(c.name + std::to_string(tree.ray_width()) + ".bvh");
            save(tree, file.path);
            for (const bool validate : {true, false}) {
                auto mapped = map_triangle_bvh<float>(file.path, LoadOptions{validate});
                EXPECT_EQ(mapped.ray_width(), tree.ray_width());
                EXPECT_TRUE(mapped.wide_layout_in_place());
                EXPECT_EQ(mapped.ray_layout_bytes(), tree.ray_layout_bytes());
                expect_same_answers(tree, mapped, rays);
                const auto loaded = load_triangle_bvh<float>(file.path, LoadOptions{validate});
                EXPECT_EQ(loaded.ray_width(), tree.ray_width());
                expect_same_answers(tree, loaded, rays);
                EXPECT_EQ(to_bytes(loaded), to_bytes(tree));
                // Every batch path the mapped tree can take.
                if (mapped.ray_width() == 8)
                    for (const RayBatchPath path : {RayBatchPath::OneByOne, RayBatchPath::Streams,
                                                    RayBatchPath::OctantStreams}) {
                        mapped.set_batch_path(path);
                        expect_same_answers(tree, mapped, rays);
                    }
                else
                    EXPECT_THROW(mapped.set_batch_path(RayBatchPath::Streams), Error);
                if (testing::Test::HasFatalFailure()) return;
            }
            // Bytes in a buffer aligned to 32 bytes but not 64, as the wide nodes need: their
            // sections are copied, with the same answers.
            const std::vector<std::uint8_t> bytes = to_bytes(tree);
            std::vector<std::uint64_t> words(bytes.size() / 8 + 16);
            auto* base = reinterpret_cast<std::uint8_t*>(words.data());
            base += (64 - reinterpret_cast<std::uintptr_t>(base) % 64) % 64 + 32;
            std::memcpy(base, bytes.data(), bytes.size());
            const auto viewed =
                view_triangle_bvh<float>(std::span<const std::uint8_t>(base, bytes.size()));
            EXPECT_FALSE(viewed.wide_layout_in_place());
            EXPECT_EQ(viewed.ray_width(), tree.ray_width());
            expect_same_answers(tree, viewed, rays);
        }
    }
}

// The bytes written before version 2 load by both loaders: the copying one derives the wide
// layout, the mapped one walks the binary tree. The answers are judged against every triangle of
// the mesh tested one by one (the watertight test; at a tie, the reported triangle is hit at the
// same t).
TEST(WideLayoutFile, Version1FilesStillLoad) {
    const std::vector<std::uint8_t> v1(std::begin(version1_sphere0), std::end(version1_sphere0));
    ASSERT_EQ(v1[8], 1);
    const TriangleMesh mesh = make_sphere(0);
    std::vector<Triangle<float>> tris;
    for (std::size_t i = 0; i < mesh.triangle_count(); ++i)
        tris.push_back(triangle_at<float>(mesh, i));
    const auto loaded = triangle_bvh_from_bytes<float>(v1);
    const auto mapped = view_triangle_bvh<float>(v1);
    EXPECT_EQ(loaded.ray_width(), TriangleBvh<float>(tris).ray_width());
    EXPECT_EQ(mapped.ray_width(), 2);
    EXPECT_EQ(loaded.triangle_count(), 20u);
    std::size_t hits = 0;
    for (const Ray3f& ray : file_test_rays(tris, 3000, 8)) {
        Hit<float> best;
        for (std::uint32_t i = 0; i < tris.size(); ++i)
            if (const auto h = tris[i].intersect_watertight(ray); h && (!best || h->t < best.t))
                best = Hit<float>{h->t, i, h->u, h->v, tris[i].normal()};
        for (const Hit<float> got : {loaded.closest_hit(ray), mapped.closest_hit(ray)}) {
            ASSERT_EQ(bool(got), bool(best));
            if (!best) continue;
            ASSERT_TRUE(same_bits(got.t, best.t));
            const auto h = tris[got.primitive].intersect_watertight(ray);
            ASSERT_TRUE(h && same_bits(h->t, got.t) && same_bits(h->u, got.u) &&
                        same_bits(h->v, got.v));
        }
        EXPECT_EQ(loaded.any_hit(ray), bool(best));
        EXPECT_EQ(mapped.any_hit(ray), bool(best));
        hits += bool(best);
    }
    EXPECT_GT(hits, 300u);
    // Saved again: version 2, with the wide layout; and a version-1 file cut from a version-2 one
    // loads to the same tree.
    const std::vector<std::uint8_t> again = to_bytes(loaded);
    EXPECT_EQ(again[8], 2);
    EXPECT_EQ(to_bytes(triangle_bvh_from_bytes<float>(as_version1(again))), again);
}

// A file whose wide layout is of another width than this CPU walks (here: a four-wide tree's
// file claiming an eight-wide layout, as a file written where AVX2 runs would be on a CPU
// without it): the copying load derives its own, the mapped one walks the binary tree.
TEST(WideLayoutFile, AnotherWidthIsDerivedOrWalkedBinary) {
    const auto tris = placed<float>(make_sphere(3), 1, 0);
    TriangleBvhOptions four;
    four.ray_layout = RayLayout::Wide4;
    const TriangleBvh<float> tree(tris, four);
    ASSERT_EQ(tree.ray_width(), 4);
    const auto layout8 = make_wide_ray_bvh<8>(
        tree.bvh(), [&](std::uint32_t s) { return tris[tree.bvh().primitive_indices[s]]; },
        [&](std::uint32_t s) { return tree.bvh().primitive_indices[s]; });
    const std::vector<std::uint8_t> file = with_wide<8>(to_bytes(tree), layout8);
    const auto rays = file_test_rays(tris, 2000, 4);
    for (const bool validate : {true, false}) {
        const auto loaded = triangle_bvh_from_bytes<float>(file, LoadOptions{validate});
        EXPECT_EQ(loaded.ray_width(), 4);
        expect_same_answers(tree, loaded, rays);
        const auto mapped = view_triangle_bvh<float>(file, LoadOptions{validate});
        EXPECT_EQ(mapped.ray_width(), 2);
        // The same tree loaded to walk the binary tree (a version-1 file, RayLayout::Binary).
        std::vector<std::uint8_t> binary = as_version1(file);
        binary[18] = std::uint8_t((binary[18] & 0x0f) | int(RayLayout::Binary) << 4);
        serial_detail::reseal_tree_file(binary);
        expect_same_answers(triangle_bvh_from_bytes<float>(binary), mapped, rays);
    }
}

// A layout written in the collapse's own lane order (lane order 0, as files were written before
// the order for occlusion rays) loads by both loaders, validated or not: the copying load takes it
// with the order applied (so it saves again as a tree built now does), the mapped one walks it as
// it lies; both answer as the tree in memory. The same layout claiming the current order is not
// the derived one, and a validating load refuses it.
TEST(WideLayoutFile, CollapseOrderFilesStillLoad) {
    const auto tris = placed<float>(make_sphere(3), 1, 0);
    const TriangleBvh<float> tree(tris);
    if (tree.ray_width() == 2) GTEST_SKIP() << "no wide layout on this CPU";
    const auto at = [&](std::uint32_t s) { return tris[tree.bvh().primitive_indices[s]]; };
    const auto index = [&](std::uint32_t s) { return tree.bvh().primitive_indices[s]; };
    const std::vector<std::uint8_t> now = to_bytes(tree);
    const auto old_file = [&](auto layout) {
        std::vector<std::uint8_t> file = with_wide(now, layout);
        EXPECT_NE(file, now);  // the two orders differ, else this test shows nothing
        const std::size_t header = wide_header_at(file);
        EXPECT_EQ(file[header + 4], 1);  // written as the current order
        file[header + 4] = 0;
        serial_detail::reseal_tree_file(file);
        return file;
    };
    const std::vector<std::uint8_t> file =
        tree.ray_width() == 8 ? old_file(make_wide_ray_bvh<8>(tree.bvh(), at, index, false))
                              : old_file(make_wide_ray_bvh<4>(tree.bvh(), at, index, false));
    const auto rays = file_test_rays(tris, 2000, 5);
    for (const bool validate : {true, false}) {
        SCOPED_TRACE(validate ? "validated" : "not validated");
        const auto loaded = triangle_bvh_from_bytes<float>(file, LoadOptions{validate});
        EXPECT_EQ(to_bytes(loaded), now);
        expect_same_answers(tree, loaded, rays);
        const auto mapped = view_triangle_bvh<float>(file, LoadOptions{validate});
        EXPECT_EQ(mapped.ray_width(), tree.ray_width());
        expect_same_answers(tree, mapped, rays);
    }
    std::vector<std::uint8_t> claimed = file;
    claimed[wide_header_at(claimed) + 4] = 1;
    serial_detail::reseal_tree_file(claimed);
    expect_refused(claimed, "the collapse's order as the current one",
                   "not the one the tree derives", false);
}

TEST(WideLayoutFile, LyingWideSectionsAreErrors) {
    TriangleBvhOptions options;
    options.ray_layout = RayLayout::Wide4;
    options.max_leaf_size = 2;
    const TriangleMesh mesh = make_sphere(2);
    const TriangleBvh<float> tree(mesh, options);  // 320 triangles
    const std::vector<std::uint8_t> file = to_bytes(tree);
    ASSERT_EQ(tree.ray_width(), 4);
    ASSERT_NO_THROW((void)view_triangle_bvh<float>(file));
    const std::size_t at = wide_header_at(file);
    const auto changed = [&](std::size_t offset, auto change) {
        std::vector<std::uint8_t> bad = file;
        change(bad.data() + offset);
        serial_detail::reseal_tree_file(bad);
        return bad;
    };
    const auto put32 = [](std::uint8_t* p, std::uint32_t v) { std::memcpy(p, &v, 4); };
    const auto put64 = [](std::uint8_t* p, std::uint64_t v) { std::memcpy(p, &v, 8); };
    expect_refused(changed(at, [&](auto* p) { put32(p, 3); }), "width 3", "width 3");
    expect_refused(changed(at + 4, [&](auto* p) { put32(p, 2); }), "lane order 2", "lane order 2");
    expect_refused(changed(at + 8, [&](auto* p) { put64(p, std::uint64_t(1) << 60); }),
                   "huge node count", "do not fill");
    expect_refused(changed(at + 16, [&](auto* p) { put64(p, ~std::uint64_t(0)); }),
                   "huge group count", "do not fill");
    const std::size_t pad = serial_detail::wide_padding(at - 72 + 24);
    if (pad > 0) expect_refused(changed(at + 24, [&](auto* p) { *p = 1; }), "padding", "padding");
    // The layout itself, changed through its records.
    WideRayBvh<4> layout = make_wide_ray_bvh<4>(
        tree.bvh(),
        [&](std::uint32_t s) { return triangle_at<float>(mesh, tree.bvh().primitive_indices[s]); },
        [&](std::uint32_t s) { return tree.bvh().primitive_indices[s]; });
    ASSERT_EQ(with_wide<4>(file, layout), file);  // the writer's layout, byte for byte
    const auto forged = [&](auto change) {
        WideRayBvh<4> l = layout;
        change(l);
        return with_wide<4>(file, l);
    };
    // Find an inner lane of the root and a leaf lane and an empty lane anywhere.
    int inner = -1;
    for (int c = 0; c < 4; ++c)
        if (layout.nodes[0].groups[c] == 0 && layout.nodes[0].child[c] != invalid_index) inner = c;
    ASSERT_GE(inner, 0);
    const std::uint32_t child = layout.nodes[0].child[inner];
    expect_refused(forged([&](auto& l) { l.nodes[0].child[inner] = 0; }), "root its own child",
                   "out of order");
    expect_refused(forged([&](auto& l) {
                       l.nodes[child].child[0] = 0;
                       l.nodes[child].groups[0] = 0;
                   }),
                   "a child links back to the root", "out of order");
    expect_refused(
        forged([&](auto& l) { l.nodes[0].child[inner] = std::uint32_t(l.nodes.size()); }),
        "child past the end", "out of range");
    expect_refused(forged([&](auto& l) {
                       for (int c = 0; c < 4; ++c)
                           if (c != inner) l.nodes[0].child[c] = child, l.nodes[0].groups[c] = 0;
                   }),
                   "shared child", "two parents");
    expect_refused(forged([&](auto& l) {
                       // A lane that names no child but has a box: a walk would follow it.
                       l.nodes.back().child[3] = invalid_index;
                       l.nodes.back().groups[3] = 0;
                       for (int a = 0; a < 3; ++a)
                           l.nodes.back().lo[a][3] = 0, l.nodes.back().lo[3 + a][3] = 1;
                   }),
                   "empty lane with a box", "empty");
    expect_refused(forged([&](auto& l) {
                       for (auto& n : l.nodes)
                           for (int c = 0; c < 4; ++c)
                               if (n.groups[c] > 0)
                                   n.groups[c] = std::uint32_t(l.groups.size()) + 1;
                   }),
                   "leaf runs past the groups", "out of range");
    expect_refused(forged([&](auto& l) {
                       for (auto& n : l.nodes)
                           for (int c = 0; c < 4; ++c)
                               if (n.groups[c] > 0) n.child[c] = 0xffffffffu;
                   }),
                   "leaf run at 2^32 - 1", "out of range");
    expect_refused(forged([&](auto& l) { l.groups[0].slot[0] = 320; }), "triangle 320 of 320",
                   "names triangle");
    expect_refused(forged([&](auto& l) { l.nodes.push_back(l.nodes.back()); }),
                   "an unreachable node", "unreachable");
    // A chain of nodes deeper than the walks' stacks hold (max_bvh_depth levels).
    expect_refused(forged([&](auto& l) {
                       constexpr float inf = std::numeric_limits<float>::infinity();
                       const auto empty = [&](RayNode<4>& n, int c) {
                           n.child[c] = invalid_index;
                           n.groups[c] = 0;
                           for (int a = 0; a < 3; ++a) n.lo[a][c] = inf, n.lo[3 + a][c] = -inf;
                       };
                       const RayNode<4> root = l.nodes[0];
                       l.nodes.clear();
                       for (std::uint32_t d = 0; d <= max_bvh_depth; ++d) {
                           RayNode<4> n = root;
                           for (int c = 0; c < 4; ++c)
                               if (n.groups[c] == 0) empty(n, c);
                           if (d < max_bvh_depth) {
                               n.child[0] = d + 1;
                               n.groups[0] = 0;
                               for (int a = 0; a < 3; ++a)
                                   n.lo[a][0] = -1e9f, n.lo[3 + a][0] = 1e9f;
                           } else {
                               empty(n, 0);
                           }
                           l.nodes.push_back(n);
                       }
                   }),
                   "a chain of 65 nodes", "deeper");
    // Geometry a structure check cannot see: a box moved, a triangle's corner moved. Validation
    // refuses them (the layout must be the derived one); without it they load and answer in range.
    for (const auto& bad : {forged([&](auto& l) { l.nodes[0].lo[0][inner] += 0.25f; }),
                            forged([&](auto& l) { l.groups[0].corner[0][0] += 0.25f; })}) {
        expect_refused(bad, "moved geometry", "not the one the tree derives", false);
        const auto loaded = triangle_bvh_from_bytes<float>(bad, LoadOptions{false});
        const auto mapped = view_triangle_bvh<float>(bad, LoadOptions{false});
        for (const auto& ray : random_rays<float>(200, Aabb3f({-2, -2, -2}, {2, 2, 2}), 6)) {
            EXPECT_EQ(bool(loaded.closest_hit(ray)), bool(mapped.closest_hit(ray)));
            EXPECT_EQ(loaded.any_hit(ray), mapped.any_hit(ray));
        }
    }
    // A wide layout in a tree that never walks one.
    TriangleBvhOptions binary = options;
    binary.ray_layout = RayLayout::Binary;
    expect_refused(with_wide<4>(to_bytes(TriangleBvh<float>(make_sphere(2), binary)), layout),
                   "a binary tree with a wide layout", "binary tree");
    TriangleBvhOptions fast = options;
    fast.triangle_test = TriangleTest::Fast;
    expect_refused(with_wide<4>(to_bytes(TriangleBvh<float>(make_sphere(2), fast)), layout),
                   "the fast test with a wide layout", "binary tree");
}

}  // namespace

// Every path a float ray can take through a TriangleBvh, forced, on every shared mesh and on the
// hard-geometry sets, against the one-ray binary walk with the watertight test: the binary walk
// (watertight and fast), the four- and eight-wide walks, and the batches' streams, octant
// streams and packets (RayBatchPath). No path is left to a size threshold (tuning.hpp), so none
// turns into a skip when one is retuned; only the eight-wide paths skip, naming AVX2, on a CPU
// without it.
//
// The wide walks open boxes in another order than the binary walk, so where a ray meets two
// triangles at the same t either may be reported: then the t must equal the reference's (a zero
// may differ in sign: each triangle's own t) and the reported triangle must be hit there, with the
// t, u and v the scalar test gives. Every other
// answer (t, u, v, triangle, normal, the any-hit flag) must be the reference's, bit for bit. The
// fast test (Moller-Trumbore) is another test whose answers differ in the last bits: its batches
// are held to its own one-ray calls.
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using bvhkit::test::same_bits;

namespace {

/// Rays at the triangles' box from around and inside it: a third aimed at a vertex (ties), axis
/// aligned ones with +0 and -0 components, subnormal components, NaN, empty and short intervals.
std::vector<Ray3f> path_test_rays(const std::vector<Triangle<float>>& tris, std::size_t n,
                                  std::uint64_t seed) {
    Aabb3f box;
    for (const auto& t : tris) box.grow(t.bounds());
    if (tris.empty()) box = Aabb3f({-1, -1, -1}, {1, 1, 1});
    const Vec3f c = box.centroid(), e = box.max - box.min;
    std::vector<Ray3f> rays = test::random_rays<float>(n, Aabb3f(c - e, c + e), seed);
    SplitMix64 rng(seed + 1);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        Ray3f& r = rays[i];
        if (i % 3 == 0 && !tris.empty())
            r.direction = tris[rng.below(std::uint32_t(tris.size()))].p1 - r.origin;
        if (i % 5 == 1) r.direction[i % 3] = (i / 5) % 2 ? 0.0f : -0.0f;
        if (i % 7 == 2) r.direction = {0, 0, 0}, r.direction[(i / 7) % 3] = i % 2 ? 1.0f : -1.0f;
        if (i % 97 == 7) r.direction[(i + 1) % 3] = 1e-41f;
        if (i % 89 == 3) r.direction[i % 3] = std::numeric_limits<float>::quiet_NaN();
        if (i % 83 == 5) r.tmin = r.tmax + 1;
        if (i % 13 == 6) r.tmax = 0.4f;
    }
    return rays;
}

/// The reference's answers: the binary walk with the watertight test, one ray at a time.
struct Reference {
    std::vector<Hit<float>> hits;
    std::vector<std::uint8_t> blocked;
};

Reference reference_answers(const std::vector<Triangle<float>>& tris,
                            const std::vector<Ray3f>& rays) {
    TriangleBvhOptions binary;
    binary.ray_layout = RayLayout::Binary;
    const TriangleBvh<float> tree(tris, binary);
    Reference ref;
    for (const Ray3f& ray : rays) {
        ref.hits.push_back(tree.closest_hit(ray));
        ref.blocked.push_back(tree.any_hit(ray) ? 1 : 0);
    }
    return ref;
}

/// `hit` is the reference's answer `want` for `ray`, or at a tie another triangle hit at an
/// equal t, with the t, u and v the scalar test gives for it.
::testing::AssertionResult same_answer(const Hit<float>& hit, const Hit<float>& want,
                                       const Ray3f& ray, const std::vector<Triangle<float>>& tris) {
    if (bool(hit) != bool(want)) return ::testing::AssertionFailure() << "hit differs from miss";
    if (!want) return ::testing::AssertionSuccess();
    // At a tie the t is equal but may differ in the sign of a zero: a ray starting on two
    // triangles of opposite winding meets one at +0 and the other at -0.
    if (!(hit.t == want.t))
        return ::testing::AssertionFailure() << "t " << hit.t << " vs " << want.t;
    if (hit.primitive == want.primitive)
        return same_bits(hit.t, want.t) && same_bits(hit.u, want.u) && same_bits(hit.v, want.v) &&
                       hit.normal == want.normal
                   ? ::testing::AssertionSuccess()
                   : ::testing::AssertionFailure() << "t, u, v or normal differ";
    const auto h = tris[hit.primitive].intersect_watertight(ray);
    if (h && same_bits(h->t, hit.t) && same_bits(h->u, hit.u) && same_bits(h->v, hit.v) &&
        hit.normal == tris[hit.primitive].normal())
        return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "tie with triangle " << hit.primitive << ", which is not hit so";
}

/// The batch calls of `tree` on the path it is set to: trace and occluded on 1 and 2 threads,
/// and the stream calls on runs of 1 to 1,000 rays (streams left part full).
void batch_answers(const TriangleBvh<float>& tree, const std::vector<Ray3f>& rays,
                   std::vector<std::vector<Hit<float>>>& hits,
                   std::vector<std::vector<std::uint8_t>>& blocked) {
    for (const unsigned threads : {1u, 2u}) {
        hits.emplace_back(rays.size());
        blocked.emplace_back(rays.size(), 7);
        tree.trace(rays, hits.back(), threads);
        tree.occluded(rays, blocked.back(), threads);
    }
    hits.emplace_back(rays.size());
    blocked.emplace_back(rays.size(), 7);
    const std::size_t runs[] = {1, 7, 8, 9, 31, 33, 1000};
    for (std::size_t b = 0, r = 0; b < rays.size(); ++r) {
        const std::size_t n = std::min(runs[r % std::size(runs)], rays.size() - b);
        const std::span<const Ray3f> chunk(rays.data() + b, n);
        tree.trace_on_calling_thread(chunk, std::span<Hit<float>>(hits.back().data() + b, n));
        tree.occluded_stream(chunk, std::span<std::uint8_t>(blocked.back().data() + b, n));
        b += n;
    }
}

/// Every path on `tris`, against the reference.
void check_every_path(const std::vector<Triangle<float>>& tris, std::size_t ray_count) {
    const std::vector<Ray3f> rays = path_test_rays(tris, ray_count, 11);
    const Reference ref = reference_answers(tris, rays);
    std::size_t hit_count = 0;
    for (const Hit<float>& h : ref.hits) hit_count += bool(h);
    if (!tris.empty()) {
        EXPECT_GT(hit_count, rays.size() / 50);  // the rays do reach the mesh
        EXPECT_LT(hit_count, rays.size());
    } else {
        EXPECT_EQ(hit_count, 0u);
    }

    struct Path {
        std::string name;
        RayLayout layout;
        TriangleTest test;
        int width;             // the width it must walk (2 for the binary walk)
        RayBatchPath batches;  // the batches' walk
    };
    const bool empty = tris.empty();
    const std::vector<Path> paths{
        {"binary, watertight", RayLayout::Binary, TriangleTest::Watertight, 2,
         RayBatchPath::OneByOne},
        {"binary, fast", RayLayout::Binary, TriangleTest::Fast, 2, RayBatchPath::OneByOne},
        {"four wide", RayLayout::Wide4, TriangleTest::Watertight, empty ? 2 : 4,
         RayBatchPath::OneByOne},
        {"eight wide", RayLayout::Auto, TriangleTest::Watertight, empty ? 2 : 8,
         RayBatchPath::OneByOne},
        {"eight-ray streams", RayLayout::Auto, TriangleTest::Watertight, empty ? 2 : 8,
         RayBatchPath::Streams},
        {"octant streams", RayLayout::Auto, TriangleTest::Watertight, empty ? 2 : 8,
         RayBatchPath::OctantStreams},
        {"packets", RayLayout::Auto, TriangleTest::Watertight, empty ? 2 : 8,
         RayBatchPath::Packets},
    };
    std::vector<std::string> skipped;
    for (const Path& p : paths) {
        SCOPED_TRACE(p.name);
        if (p.width == 8 && !cpu_has_avx2()) {
            skipped.push_back(p.name);
            continue;
        }
        TriangleBvhOptions options;
        options.ray_layout = p.layout;
        options.triangle_test = p.test;
        if (p.width == 8) options.batch_path = p.batches;
        TriangleBvh<float> tree(tris, options);
        ASSERT_EQ(tree.ray_width(), p.width);
        if (p.width < 8) {
            EXPECT_THROW(tree.set_batch_path(RayBatchPath::Streams), Error);
            EXPECT_THROW(tree.set_batch_path(RayBatchPath::OctantStreams), Error);
            EXPECT_THROW(tree.set_batch_path(RayBatchPath::Packets), Error);
            EXPECT_FALSE(tree.streams_rays());
        } else if (p.batches == RayBatchPath::OneByOne || p.batches == RayBatchPath::Streams) {
            EXPECT_EQ(tree.streams_rays(), p.batches == RayBatchPath::Streams);
        }
        std::vector<std::vector<Hit<float>>> hits;
        std::vector<std::vector<std::uint8_t>> blocked;
        batch_answers(tree, rays, hits, blocked);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Hit<float> one = tree.closest_hit(rays[i]);
            const bool one_blocked = tree.any_hit(rays[i]);
            if (p.test == TriangleTest::Watertight) {
                ASSERT_TRUE(same_answer(one, ref.hits[i], rays[i], tris)) << "ray " << i;
                ASSERT_EQ(one_blocked, ref.blocked[i] != 0) << "ray " << i;
            }
            // The batches give the one-ray calls' answers, bit for bit.
            for (std::size_t b = 0; b < hits.size(); ++b) {
                const Hit<float>& h = hits[b][i];
                ASSERT_EQ(bool(h), bool(one)) << "ray " << i << ", batch " << b;
                ASSERT_EQ(blocked[b][i], one_blocked ? 1 : 0) << "ray " << i << ", batch " << b;
                if (!one) continue;
                ASSERT_TRUE(same_bits(h.t, one.t) && same_bits(h.u, one.u) &&
                            same_bits(h.v, one.v) && h.primitive == one.primitive &&
                            h.normal == one.normal)
                    << "ray " << i << ", batch " << b;
            }
        }
    }
    if (!skipped.empty())
        GTEST_SKIP() << "this CPU has no AVX2: the eight-wide paths did not run (" << skipped.size()
                     << " of " << paths.size() << ")";
}

std::vector<Triangle<float>> coplanar_touching() {
    // A flat grid of squares, each two triangles sharing an edge, every square touching its
    // neighbours, and a second copy of the grid in the same plane (coplanar duplicates).
    std::vector<Triangle<float>> t;
    for (int copy = 0; copy < 2; ++copy)
        for (int i = 0; i < 24; ++i)
            for (int j = 0; j < 24; ++j) {
                const Vec3f a{float(i), float(j), 0}, b{float(i + 1), float(j), 0},
                    c{float(i + 1), float(j + 1), 0}, d{float(i), float(j + 1), 0};
                t.push_back({a, b, c});
                t.push_back({a, c, d});
            }
    return t;
}

TEST(RayPaths, EveryPathOnTheHardGeometry) {
    const std::vector<std::pair<std::string, std::vector<Triangle<float>>>> cases{
        {"sphere", test::placed<float>(make_sphere(4), 1, 0)},
        {"far sphere (1e6 away)", test::placed<float>(make_sphere(3), 1, 1e6)},
        {"tiny torus (1e-6)", test::placed<float>(make_torus(64, 32), 1e-6, 0)},
        {"huge terrain (1e6)", test::placed<float>(make_terrain(48), 1e6, 0)},
        {"needles, duplicates, zero area", test::random_needles(2000, 7, true)},
        {"coplanar, touching", coplanar_touching()},
        {"room", test::placed<float>(make_room(12), 1, 0)},
        {"one triangle", {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}},
        {"empty", {}},
    };
    for (const auto& [name, tris] : cases) {
        SCOPED_TRACE(name);
        check_every_path(tris, test::scaled(6000, 10));
        if (HasFatalFailure() || IsSkipped()) return;
    }
}

class RayPathsOnSharedMesh : public ::testing::TestWithParam<std::string> {};

TEST_P(RayPathsOnSharedMesh, EveryPath) {
    BVHKIT_REQUIRE_MESH(path, GetParam());
    check_every_path(test::placed<float>(read_mesh(path), 1, 0), test::scaled(5000, 10));
}

INSTANTIATE_TEST_SUITE_P(SharedMeshes, RayPathsOnSharedMesh,
                         ::testing::Values("stanford-bunny.obj", "igea.ply", "dragon-lowres.ply",
                                           "fandisk.obj", "spot.obj", "suzanne.obj", "teapot.obj"),
                         test::MeshFileName());

}  // namespace

// Packets of coherent rays (query/ray_octant_stream.hpp, query/ray_coherence.hpp): camera rays in
// rows and in 8x4 tiles, from outside the mesh and from inside its box, and shadow rays from the
// camera's hits towards one light, through trace (Auto chooses packets for coherent runs),
// trace_packets and RayBatchPath::Packets, on 1 and 2 threads and on runs of 1 to 1,000 rays
// (packets left part full): each answer the one-ray call's, bit for bit (t, u, v, triangle,
// normal; any hit). Every shared mesh and the hard-geometry sets (far from the origin, tiny, huge,
// needles, coplanar duplicates). And the tie rule that makes a packet's order free: at an equal t
// the lower triangle index, checked against copies of one triangle whose indices are known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/ray_coherence.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using bvhkit::test::same_bits;

namespace {

Aabb3f bounds_of(const std::vector<Triangle<float>>& tris) {
    Aabb3f box;
    for (const auto& t : tris) box.grow(t.bounds());
    return box;
}

/// A pinhole camera's rays at `box`, w x h pixels, from `eye`; in rows, or in 8x4 tiles (32
/// consecutive rays one tile) when `tiles`.
std::vector<Ray3f> camera_rays(const Aabb3f& box, Vec3d eye, int w, int h, bool tiles) {
    const Vec3d lo(box.min), hi(box.max);
    const Vec3d centre = (lo + hi) * 0.5;
    const Vec3d forward = normalize(centre - eye);
    const Vec3d right = normalize(cross(forward, Vec3d(0.1, 1, 0.2)));
    const Vec3d up = cross(right, forward);
    const auto ray = [&](int x, int y) {
        const double sx = (2.0 * (x + 0.5) / w - 1.0) * 0.6,
                     sy = (1.0 - 2.0 * (y + 0.5) / h) * 0.45;
        return Ray3f(Vec3f(eye), Vec3f(forward + right * sx + up * sy));
    };
    std::vector<Ray3f> rays;
    if (!tiles) {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) rays.push_back(ray(x, y));
        return rays;
    }
    for (int ty = 0; ty < h; ty += 4)
        for (int tx = 0; tx < w; tx += 8)
            for (int y = ty; y < std::min(h, ty + 4); ++y)
                for (int x = tx; x < std::min(w, tx + 8); ++x) rays.push_back(ray(x, y));
    return rays;
}

/// The coherent sets for `tris`: camera rays from outside (rows and tiles) and from inside the
/// box, and shadow rays from the outside camera's hits towards one light.
std::vector<Ray3f> coherent_test_rays(const TriangleBvh<float>& one,
                                      const std::vector<Triangle<float>>& tris, int side) {
    const Aabb3f box = bounds_of(tris);
    const Vec3d lo(box.min), hi(box.max), c = (lo + hi) * 0.5, e = hi - lo;
    const Vec3d outside = c + Vec3d(0.9 * e[0] + 1e-30, 0.7 * e[1], 1.6 * e[2] + 1e-30);
    std::vector<Ray3f> rays = camera_rays(box, outside, side, side * 3 / 4, false);
    const std::vector<Ray3f> tiled = camera_rays(box, outside, side, side * 3 / 4, true);
    rays.insert(rays.end(), tiled.begin(), tiled.end());
    const std::vector<Ray3f> inside = camera_rays(box, c + e * 0.05, side / 2, side / 2, true);
    rays.insert(rays.end(), inside.begin(), inside.end());
    const Vec3d light = c + Vec3d(0.3 * e[0], 2.0 * e[1] + 1e-30, -0.4 * e[2]);
    for (const Ray3f& r : tiled) {
        const Hit<float> h = one.closest_hit(r);
        if (!h) continue;
        Ray3f shadow(r.at(h.t), Vec3f(light) - r.at(h.t));
        shadow.tmin = 1e-4f;
        shadow.tmax = 1.0f;  // up to the light
        rays.push_back(shadow);
    }
    return rays;
}

::testing::AssertionResult same_hit(const Hit<float>& a, const Hit<float>& b) {
    if (bool(a) != bool(b)) return ::testing::AssertionFailure() << "hit differs from miss";
    if (!a) return ::testing::AssertionSuccess();
    if (same_bits(a.t, b.t) && same_bits(a.u, b.u) && same_bits(a.v, b.v) &&
        a.primitive == b.primitive && a.normal == b.normal)
        return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "triangle " << a.primitive << " t " << a.t
                                         << " vs triangle " << b.primitive << " t " << b.t;
}

/// Every batch call on the coherent sets of `tris` against the one-ray calls.
void check_packets(const std::vector<Triangle<float>>& tris, int side) {
    if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: no eight-wide layout";
    const TriangleBvh<float> tree(tris);  // Auto: coherent runs walk as packets
    ASSERT_EQ(tree.ray_width(), 8);
    TriangleBvhOptions forced;
    forced.batch_path = RayBatchPath::Packets;
    const TriangleBvh<float> packets(tris, forced);
    const std::vector<Ray3f> rays = coherent_test_rays(tree, tris, side);
    std::vector<Hit<float>> one(rays.size());
    std::vector<std::uint8_t> one_blocked(rays.size());
    std::size_t hit_count = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        one[i] = tree.closest_hit(rays[i]);
        one_blocked[i] = tree.any_hit(rays[i]) ? 1 : 0;
        hit_count += bool(one[i]);
    }
    EXPECT_GT(hit_count, rays.size() / 100);  // the rays do reach the mesh
    EXPECT_LT(hit_count, rays.size());
    const auto expect_equal = [&](const std::vector<Hit<float>>& hits, const char* what) {
        for (std::size_t i = 0; i < rays.size(); ++i)
            ASSERT_TRUE(same_hit(hits[i], one[i])) << what << ", ray " << i;
    };
    for (const unsigned threads : {1u, 2u}) {
        SCOPED_TRACE(threads);
        std::vector<Hit<float>> hits(rays.size());
        tree.trace(rays, hits, threads);
        expect_equal(hits, "trace (Auto)");
        std::fill(hits.begin(), hits.end(), Hit<float>{});
        tree.trace_packets(rays, hits, threads);
        expect_equal(hits, "trace_packets");
        std::fill(hits.begin(), hits.end(), Hit<float>{});
        packets.trace(rays, hits, threads);
        expect_equal(hits, "trace (Packets)");
        std::vector<std::uint8_t> blocked(rays.size(), 7);
        packets.occluded(rays, blocked, threads);
        for (std::size_t i = 0; i < rays.size(); ++i) ASSERT_EQ(blocked[i], one_blocked[i]) << i;
    }
    // Runs of 1 to 1,000 rays on the calling thread: packets left part full, runs that start
    // inside a tile.
    for (const TriangleBvh<float>* t : {&tree, &packets}) {
        std::vector<Hit<float>> hits(rays.size());
        const std::size_t runs[] = {1, 5, 31, 32, 33, 64, 1000};
        for (std::size_t b = 0, r = 0; b < rays.size(); ++r) {
            const std::size_t n = std::min(runs[r % std::size(runs)], rays.size() - b);
            t->trace_on_calling_thread(std::span<const Ray3f>(rays.data() + b, n),
                                       std::span<Hit<float>>(hits.data() + b, n));
            b += n;
        }
        expect_equal(hits, "runs");
    }
    std::vector<Hit<float>> hits(3);
    EXPECT_THROW(tree.trace_packets(rays, hits), Error);
}

std::vector<Triangle<float>> coplanar_duplicates() {
    // A grid of squares, two triangles each, twice over in one plane, and a third copy lifted.
    std::vector<Triangle<float>> t;
    for (int copy = 0; copy < 3; ++copy)
        for (int i = 0; i < 20; ++i)
            for (int j = 0; j < 20; ++j) {
                const float z = copy == 2 ? 0.5f : 0.0f;
                const Vec3f a{float(i), float(j), z}, b{float(i + 1), float(j), z},
                    c{float(i + 1), float(j + 1), z}, d{float(i), float(j + 1), z};
                t.push_back({a, b, c});
                t.push_back({a, c, d});
            }
    return t;
}

TEST(RayPackets, CoherentRaysOnTheHardGeometry) {
    const std::vector<std::pair<std::string, std::vector<Triangle<float>>>> cases{
        {"sphere", test::placed<float>(make_sphere(4), 1, 0)},
        {"far sphere (1e5 away)", test::placed<float>(make_sphere(4), 1, 1e5)},
        {"tiny torus (1e-6)", test::placed<float>(make_torus(64, 32), 1e-6, 0)},
        {"huge terrain (1e6)", test::placed<float>(make_terrain(48), 1e6, 0)},
        {"needles, duplicates, zero area", test::random_needles(3000, 7, true)},
        {"coplanar duplicates", coplanar_duplicates()},
        {"room", test::placed<float>(make_room(12), 1, 0)},
    };
    for (const auto& [name, tris] : cases) {
        SCOPED_TRACE(name);
        check_packets(tris, int(test::scaled(96, 3)));
        if (HasFatalFailure() || IsSkipped()) return;
    }
}

class RayPacketsOnSharedMesh : public ::testing::TestWithParam<std::string> {};

TEST_P(RayPacketsOnSharedMesh, CoherentRays) {
    BVHKIT_REQUIRE_MESH(path, GetParam());
    check_packets(test::placed<float>(read_mesh(path), 1, 0), int(test::scaled(128, 4)));
}

INSTANTIATE_TEST_SUITE_P(SharedMeshes, RayPacketsOnSharedMesh,
                         ::testing::Values("stanford-bunny.obj", "igea.ply", "dragon-lowres.ply",
                                           "fandisk.obj", "spot.obj", "suzanne.obj", "teapot.obj"),
                         test::MeshFileName());

// The tie rule: K copies of one mesh, the triangles of each copy at indices scattered by a
// shuffle. A ray through a triangle's inside meets all K copies at one t; the closest hit must
// be the copy of least index, known from the shuffle (not from any walk), on every path.
TEST(RayPackets, EqualTKeepsTheLowerIndex) {
    const std::vector<Triangle<float>> base = test::placed<float>(make_sphere(3), 1, 0);
    constexpr int copies = 4;
    std::vector<std::uint32_t> order(base.size() * copies);
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    SplitMix64 rng(5);
    for (std::size_t i = order.size(); i > 1; --i)
        std::swap(order[i - 1], order[rng.below(std::uint32_t(i))]);
    // order[k]: the place of copy k / base.size() of triangle k % base.size().
    std::vector<Triangle<float>> tris(order.size());
    std::vector<std::uint32_t> least(base.size(), ~0u);
    for (std::size_t k = 0; k < order.size(); ++k) {
        tris[order[k]] = base[k % base.size()];
        least[k % base.size()] = std::min(least[k % base.size()], order[k]);
    }
    // Rays from outside through each triangle's centroid (inside it, away from its edges).
    std::vector<Ray3f> rays;
    const Vec3f eye{2.5f, 1.7f, 3.1f};
    std::vector<std::uint32_t> want;
    for (std::size_t t = 0; t < base.size(); ++t) {
        const Vec3f c = (base[t].p0 + base[t].p1 + base[t].p2) / 3.0f;
        // Only the triangles facing the eye are the first surface the ray meets.
        if (dot(base[t].normal(), eye - c) <= 0) continue;
        rays.emplace_back(eye, c - eye);
        want.push_back(least[t]);
    }
    ASSERT_GT(rays.size(), 100u);
    for (const RayLayout layout : {RayLayout::Auto, RayLayout::Wide4}) {
        TriangleBvhOptions options;
        options.ray_layout = layout;
        const TriangleBvh<float> tree(tris, options);
        SCOPED_TRACE(tree.ray_width());
        std::vector<Hit<float>> hits(rays.size()), packed(rays.size());
        tree.trace(rays, hits, 1);
        tree.trace_packets(rays, packed, 1);
        std::size_t checked = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Hit<float> h = tree.closest_hit(rays[i]);
            ASSERT_TRUE(h) << i;
            // The sphere is convex and the eye outside: the ray's first hit is the facing
            // triangle it aims at, unless it grazes a neighbour within rounding of an edge.
            const Triangle<float>& got = tris[h.primitive];
            const Triangle<float>& aimed = tris[want[i]];
            if (got.p0 == aimed.p0 && got.p1 == aimed.p1 && got.p2 == aimed.p2) {
                EXPECT_EQ(h.primitive, want[i]) << "ray " << i;
                ++checked;
            }
            ASSERT_TRUE(same_hit(hits[i], h)) << "trace, ray " << i;
            ASSERT_TRUE(same_hit(packed[i], h)) << "trace_packets, ray " << i;
        }
        EXPECT_GT(checked, rays.size() * 9 / 10);
    }
}

TEST(RayPackets, CoherenceTest) {
    const Aabb3f box({-1, -1, -1}, {1, 1, 1});
    std::vector<Ray3f> row;
    for (int x = 0; x < 32; ++x)
        row.emplace_back(Vec3f{0, 0, 5}, Vec3f{0.01f * x - 0.2f, 0.1f, -1});
    EXPECT_FALSE(coherent_rays(row, box));  // x changes sign within the row
    for (int x = 0; x < 32; ++x) row[x].direction[0] = 0.002f * x + 0.05f;
    EXPECT_TRUE(coherent_rays(row, box));
    EXPECT_FALSE(coherent_rays(std::span<const Ray3f>(), box));
    std::vector<Ray3f> spread = row;
    spread.back().direction = {1, 0.1f, -0.2f};  // far from the others
    EXPECT_FALSE(coherent_rays(spread, box));
    spread = row;
    spread.back().origin = {0.8f, 0, 5};  // origins 0.8 apart in a box 2 wide
    EXPECT_FALSE(coherent_rays(spread, box));
    spread = row;
    spread.front().direction[1] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(coherent_rays(spread, box));
    spread = row;
    spread.front().direction = {0, 0, 0};
    EXPECT_FALSE(coherent_rays(spread, box));
    const std::vector<Ray3f> random = test::random_rays<float>(32, box, 3);
    EXPECT_FALSE(coherent_rays(random, box));
}

}  // namespace

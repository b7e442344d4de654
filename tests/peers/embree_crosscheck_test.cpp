// bvhkit and Embree 3 trace workload R1 and R2 rays on every shared mesh and must agree on at least
// 99.99% of rays: same hit or miss, and the same triangle or the same t within 1e-4 (relative).
// They use different triangle tests, so rays grazing an edge may legitimately differ. Where both
// hit the same triangle, Hit::normal must be Embree's Ng (same vector, up to rounding).
#include <gtest/gtest.h>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "embree_scene.hpp"
#include "ray_sets.hpp"
#include "test_support.hpp"

using namespace bvhkit;

#if BVHKIT_HAVE_EMBREE
class EmbreeCrossCheck : public ::testing::TestWithParam<const char*> {};

TEST_P(EmbreeCrossCheck, R1AndR2AgreeOnAtLeast9999Percent) {
    BVHKIT_REQUIRE_MESH(path, GetParam());
    const TriangleMesh mesh = read_mesh(path);
    const TriangleBvh<float> ours(mesh);
    const bench::EmbreeScene embree(mesh, 1);
    const std::uint32_t side = test::small_scale() ? 128 : 1024;
    struct Set {
        const char* name;
        std::vector<Ray3f> rays;
    };
    for (const Set& set : {Set{"R1", camera_rays(mesh.bounds(), side, side)},
                           Set{"R2", random_rays(mesh.bounds(), test::scaled(1000000), 1)}}) {
        std::size_t agree = 0, hits = 0;
        for (const auto& ray : set.rays) {
            const Hit<float> a = ours.closest_hit(ray), b = embree.closest_hit(ray);
            hits += bool(a);
            const bool same = bool(a) == bool(b) &&
                              (!a || a.primitive == b.primitive ||
                               std::fabs(a.t - b.t) <= 1e-4f * std::max(1.0f, std::fabs(b.t)));
            agree += same;
            if (a && a.primitive == b.primitive) {
                const float scale = length(b.normal);
                ASSERT_LE(length(a.normal - b.normal), 1e-4f * scale) << set.name;
            }
            // any-hit must agree with closest-hit's verdict within bvhkit.
            ASSERT_EQ(ours.any_hit(ray), bool(a));
        }
        const double fraction = double(agree) / double(set.rays.size());
        std::printf("%s %s: %zu rays, %zu hits, agreement %.6f\n", GetParam(), set.name,
                    set.rays.size(), hits, fraction);
        EXPECT_GT(hits, set.rays.size() / 100) << set.name;
        EXPECT_GE(fraction, 0.9999) << set.name;
    }
}

INSTANTIATE_TEST_SUITE_P(Meshes, EmbreeCrossCheck,
                         ::testing::Values("suzanne.obj", "teapot.obj", "spot.obj", "fandisk.obj",
                                           "dragon-lowres.ply", "stanford-bunny.obj", "igea.ply"),
                         test::MeshFileName{});
#else
TEST(EmbreeCrossCheck, SkippedWithoutEmbree) {
    GTEST_SKIP() << "Embree 3 not found at build time (apt-get install libembree-dev)";
}
#endif

// Ray queries against brute force over every triangle: same hit or miss, same t, same triangle
// unless two are tied at that t. For every builder, float and double, random soups and (in the mesh
// tests) the shared meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "brute_force.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/primitives/segment.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;

template <class T>
class RayQueries : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(RayQueries, Scalars);

TYPED_TEST(RayQueries, EveryBuilderMatchesBruteForceOnRandomSoups) {
    using T = TypeParam;
    const auto tris = test::random_soup<T>(test::scaled(3000, 3), 1234);
    Aabb<T, 3> box({-0.2, -0.2, -0.2}, {1.2, 1.2, 1.2});
    const auto rays = test::random_rays<T>(test::scaled(20000), box, 77);
    const test::BruteForce<T> reference(tris, rays);
    for (const auto& [name, options] : all_builder_configurations()) {
        SCOPED_TRACE(name);
        const TriangleBvh<T> bvh(tris, options);
        reference.check(bvh, rays);
    }
}

TYPED_TEST(RayQueries, FastModeAgreesWithItsBruteForce) {
    using T = TypeParam;
    const auto tris = test::random_soup<T>(2000, 99);
    const auto rays =
        test::random_rays<T>(test::scaled(10000), Aabb<T, 3>({0, 0, 0}, {1, 1, 1}), 5);
    TriangleBvhOptions fast;
    fast.triangle_test = TriangleTest::Fast;
    const test::BruteForce<T> reference(tris, rays, TriangleTest::Fast);
    reference.check(TriangleBvh<T>(tris, fast), rays);
}

TYPED_TEST(RayQueries, AllHitsEqualsTheBruteForceSet) {
    using T = TypeParam;
    const auto tris = test::random_soup<T>(1500, 31);
    const TriangleBvh<T> bvh(tris);
    const auto rays = test::random_rays<T>(2000, Aabb<T, 3>({0, 0, 0}, {1, 1, 1}), 32);
    std::size_t total = 0;
    for (const auto& ray : rays) {
        std::vector<std::uint32_t> got, want;
        bvh.all_hits(ray, [&](const Hit<T>& h) {
            got.push_back(h.primitive);
            return true;
        });
        for (std::uint32_t i = 0; i < tris.size(); ++i) {
            if (tris[i].intersect_watertight(ray)) want.push_back(i);
        }
        std::sort(got.begin(), got.end());
        ASSERT_EQ(got, want);
        total += want.size();
    }
    EXPECT_GT(total, rays.size());  // the rays must actually cross several triangles
    // Stopping early: the callback sees exactly one hit.
    int calls = 0;
    bvh.all_hits(Ray<T, 3>({-1, 0.5, 0.5}, {1, 0, 0}), [&](const Hit<T>&) { return ++calls < 1; });
    EXPECT_LE(calls, 1);
}

TYPED_TEST(RayQueries, TminTmaxWindowAndStatistics) {
    using T = TypeParam;
    // A stack of parallel unit squares at z = 0..9; a ray down the z axis through all of them.
    std::vector<Triangle<T>> tris;
    for (int z = 0; z < 10; ++z) {
        tris.push_back({{0, 0, T(z)}, {1, 0, T(z)}, {0, 1, T(z)}});
        tris.push_back({{1, 0, T(z)}, {1, 1, T(z)}, {0, 1, T(z)}});
    }
    const TriangleBvh<T> bvh(tris);
    const Ray<T, 3> ray({0.3, 0.2, -1}, {0, 0, 1}, 0, std::numeric_limits<T>::infinity());
    EXPECT_EQ(bvh.closest_hit(ray).primitive, 0u);
    EXPECT_EQ(bvh.closest_hit(ray).t, T(1));
    Ray<T, 3> window = ray;
    window.tmin = T(4.5);
    window.tmax = T(6.5);
    const auto h = bvh.closest_hit(window);
    EXPECT_EQ(h.primitive, 8u);  // the square at z = 4 (t = 5)
    EXPECT_EQ(h.t, T(5));
    window.tmax = T(4.9);
    EXPECT_FALSE(bvh.closest_hit(window));
    EXPECT_FALSE(bvh.any_hit(window));
    TraversalStats stats;
    bvh.closest_hit(ray, stats);
    EXPECT_GT(stats.nodes_visited, 0u);
    EXPECT_GE(stats.primitives_tested, 1u);
    EXPECT_LE(stats.primitives_tested, tris.size());
}

TYPED_TEST(RayQueries, RaysWithZeroDirectionComponentsAndDegenerateTrees) {
    using T = TypeParam;
    const auto tris = test::random_soup<T>(3000, 8);
    const auto rays_in =
        test::random_rays<T>(test::scaled(6000), Aabb<T, 3>({0, 0, 0}, {1, 1, 1}), 9);
    std::vector<Ray<T, 3>> rays;
    for (std::size_t i = 0; i < rays_in.size(); ++i) {
        Ray<T, 3> r = rays_in[i];
        // zero one or two components, with either sign
        r.direction[i % 3] = (i / 3) % 2 ? T(0) : -T(0);
        if (i % 5 == 0) r.direction[(i + 1) % 3] = T(0);
        rays.push_back(r);
    }
    const test::BruteForce<T> reference(tris, rays);
    reference.check(TriangleBvh<T>(tris), rays);

    // Empty tree: every query misses. One triangle: a single leaf that hits.
    const TriangleBvh<T> empty(std::vector<Triangle<T>>{});
    EXPECT_FALSE(empty.closest_hit(rays[0]));
    EXPECT_FALSE(empty.any_hit(rays[0]));
    const TriangleBvh<T> one(std::vector<Triangle<T>>{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
    EXPECT_EQ(one.closest_hit(Ray<T, 3>({0.2, 0.2, 1}, {0, 0, -1})).primitive, 0u);
}

TYPED_TEST(RayQueries, NanTrianglesAreSkippedAndTheRestStillHit) {
    using T = TypeParam;
    auto tris = test::random_soup<T>(2000, 70);
    for (std::size_t i = 0; i < tris.size(); i += 97)
        tris[i].p1[1] = std::numeric_limits<T>::quiet_NaN();
    const TriangleBvh<T> bvh(tris);
    EXPECT_EQ(bvh.skipped().size(), (tris.size() + 96) / 97);
    const auto rays =
        test::random_rays<T>(test::scaled(5000), Aabb<T, 3>({0, 0, 0}, {1, 1, 1}), 71);
    test::BruteForce<T>(tris, rays).check(bvh, rays);
}

TYPED_TEST(RayQueries, UntraceableRaysMissWithoutVisitingANode) {
    using T = TypeParam;
    constexpr T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
    const auto tris = test::random_soup<T>(2000, 12);
    const std::vector<Ray<T, 3>> bad{Ray<T, 3>({nan, 0.5, 0.5}, {1, 0, 0}),
                                     Ray<T, 3>({0.5, 0.5, inf}, {0, 0, -1}),
                                     Ray<T, 3>({0.5, 0.5, -1}, {0, nan, 1}),
                                     Ray<T, 3>({0.5, 0.5, -1}, {0, 0, inf}),
                                     Ray<T, 3>({0.5, 0.5, -1}, {-inf, 0, 1}),
                                     Ray<T, 3>({0.5, 0.5, -1}, {0, 0, 0}),
                                     Ray<T, 3>({0.5, 0.5, -1}, {-T(0), T(0), -T(0)}),
                                     Ray<T, 3>({0.5, 0.5, -1}, {0, 0, 1}, nan),
                                     Ray<T, 3>({0.5, 0.5, -1}, {0, 0, 1}, 0, nan),
                                     Ray<T, 3>({0.5, 0.5, -1}, {0, 0, 1}, 3, 2)};
    for (const TriangleTest mode : {TriangleTest::Watertight, TriangleTest::Fast}) {
        TriangleBvhOptions options;
        options.triangle_test = mode;
        const TriangleBvh<T> bvh(tris, options);
        for (std::size_t i = 0; i < bad.size(); ++i) {
            TraversalStats stats;
            EXPECT_FALSE(bvh.closest_hit(bad[i], stats)) << i;
            EXPECT_FALSE(bvh.any_hit(bad[i], stats)) << i;
            bvh.all_hits(
                bad[i], [](const Hit<T>&) { return true; }, stats);
            EXPECT_EQ(stats.nodes_visited, 0u) << i;
            EXPECT_EQ(stats.primitives_tested, 0u) << i;
        }
        // The same rays with the bad part mended do walk the tree and hit.
        TraversalStats stats;
        EXPECT_TRUE(bvh.closest_hit(Ray<T, 3>({0.5, 0.5, -1}, {0, 0, 1}), stats));
        EXPECT_GT(stats.nodes_visited, 0u);
    }
}

TYPED_TEST(RayQueries, HitNormalIsTheGeometricNormalInBothModes) {
    using T = TypeParam;
    const std::vector<Triangle<T>> tris{{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}},
                                        {{0, 0, 2}, {0, 1, 2}, {1, 0, 2}}};
    for (const TriangleTest mode : {TriangleTest::Watertight, TriangleTest::Fast}) {
        TriangleBvhOptions options;
        options.triangle_test = mode;
        const TriangleBvh<T> bvh(tris, options);
        EXPECT_EQ(bvh.triangle_test(), mode);
        // Counterclockwise seen from +z: the normal is +z, twice the area long, from either side.
        const Hit<T> up = bvh.closest_hit(Ray<T, 3>({T(0.2), T(0.2), 0}, {0, 0, 1}));
        EXPECT_EQ(up.normal, (Vec<T, 3>{0, 0, 1}));
        const Hit<T> down = bvh.closest_hit(Ray<T, 3>({T(0.2), T(0.2), 3}, {0, 0, -1}));
        EXPECT_EQ(down.primitive, 1u);
        EXPECT_EQ(down.normal, (Vec<T, 3>{0, 0, -1}));
        bvh.all_hits(Ray<T, 3>({T(0.2), T(0.2), 0}, {0, 0, 1}), [&](const Hit<T>& h) {
            EXPECT_EQ(h.normal, tris[h.primitive].normal());
            return true;
        });
        EXPECT_EQ(bvh.closest_hit(Ray<T, 3>({5, 5, 0}, {0, 0, 1})).normal, (Vec<T, 3>{}));
    }
}

TEST(RayQueries2d, SegmentsMatchBruteForce) {
    test::Random rng(101);
    std::vector<Segment<float>> segs(3000);
    for (auto& s : segs) {
        const Vec2f c{float(rng.uniform()), float(rng.uniform())};
        const Vec2f d{float(rng.uniform(-0.05, 0.05)), float(rng.uniform(-0.05, 0.05))};
        s = {c - d, c + d};
    }
    for (const auto& [name, options] : all_builder_configurations()) {
        SCOPED_TRACE(name);
        const auto bvh = build_bvh(segs, options);
        const auto test_segment = primitive_ray_test(bvh, std::span<const Segment<float>>(segs));
        for (int i = 0; i < 3000; ++i) {
            const Vec2f o{float(rng.uniform()), float(rng.uniform())};
            const double angle = rng.uniform(0, 6.283185307179586);
            Vec2f d{float(std::cos(angle)), float(std::sin(angle))};
            if (i % 7 == 0) d[i % 2] = 0;
            const Ray2f ray(o, d);
            const Hit<float, 2> got = closest_hit(bvh, ray, test_segment);
            float best = std::numeric_limits<float>::infinity();
            std::uint32_t best_i = invalid_index;
            for (std::uint32_t k = 0; k < segs.size(); ++k)
                if (auto h = segs[k].intersect(ray); h && h->t < best) best = h->t, best_i = k;
            ASSERT_EQ(bool(got), best_i != invalid_index) << i;
            if (got) {
                ASSERT_EQ(got.t, best);
                ASSERT_EQ(any_hit(bvh, ray, test_segment), true);
            }
        }
    }
}

// all_hits on a float tree walks the wide layout (query/ray_wide_walk.hpp's AllLeaves): the same
// hits as the binary walk's, bit for bit (t, u, v, normal), each once. Hard sets: far from the
// origin, tiny, needles, and coplanar overlapping squares whose shared edges and corners the
// vertical rays meet exactly (where both triangles of an edge report it).
TEST(AllHits, TheWideLayoutsGiveTheBinaryWalksHits) {
    std::vector<Triangle<float>> coplanar;
    for (int layer = 0; layer < 2; ++layer)
        for (int i = 0; i < 24; ++i)
            for (int j = 0; j < 24; ++j) {
                const float x = i + 0.5f * layer, y = j + 0.5f * layer, z = float(i % 3);
                coplanar.push_back({{x, y, z}, {x + 1, y, z}, {x, y + 1, z}});
                coplanar.push_back({{x + 1, y, z}, {x + 1, y + 1, z}, {x, y + 1, z}});
            }
    const std::vector<std::pair<std::string, std::vector<Triangle<float>>>> meshes{
        {"far sphere", test::placed<float>(make_sphere(4), 1, 1e5)},
        {"tiny torus", test::placed<float>(make_torus(64, 32), 1e-6, 0)},
        {"needles", test::random_needles(3000, 41)},
        {"coplanar", coplanar}};
    struct Seen {
        std::uint32_t primitive;
        float t, u, v;
        Vec<float, 3> normal;
    };
    const auto hits_of = [](const TriangleBvh<float>& bvh, const Ray<float, 3>& ray) {
        std::vector<Seen> out;
        bvh.all_hits(ray, [&](const Hit<float>& h) {
            out.push_back({h.primitive, h.t, h.u, h.v, h.normal});
            return true;
        });
        std::sort(out.begin(), out.end(),
                  [](const Seen& a, const Seen& b) { return a.primitive < b.primitive; });
        return out;
    };
    for (const auto& [name, tris] : meshes) {
        SCOPED_TRACE(name);
        TriangleBvhOptions binary, wide4;
        binary.ray_layout = RayLayout::Binary;
        wide4.ray_layout = RayLayout::Wide4;
        const TriangleBvh<float> reference(tris, binary);
        ASSERT_EQ(reference.ray_width(), 2);
        std::vector<Ray<float, 3>> rays = test::rays_through_box(tris, test::scaled(3000, 3), 43);
        if (name == "coplanar")  // straight down through grid corners, edges and cell centres
            for (int i = 0; i < 200; ++i)
                rays.push_back(
                    Ray<float, 3>({0.25f * float(i % 97), 0.5f * float(i / 7), 5}, {0, 0, -1}));
        for (std::size_t i = 7; i < rays.size(); i += 13) rays[i].tmax *= 0.5f;  // cut short
        for (const TriangleBvhOptions& options : {TriangleBvhOptions{}, wide4}) {
            const TriangleBvh<float> bvh(tris, options);
            SCOPED_TRACE(bvh.ray_width());
            std::size_t total = 0;
            for (std::size_t r = 0; r < rays.size(); ++r) {
                const std::vector<Seen> want = hits_of(reference, rays[r]);
                const std::vector<Seen> got = hits_of(bvh, rays[r]);
                ASSERT_EQ(got.size(), want.size()) << r;
                for (std::size_t k = 0; k < got.size(); ++k) {
                    ASSERT_EQ(got[k].primitive, want[k].primitive) << r;
                    ASSERT_TRUE(test::same_bits(got[k].t, want[k].t) &&
                                test::same_bits(got[k].u, want[k].u) &&
                                test::same_bits(got[k].v, want[k].v))
                        << r;
                    ASSERT_EQ(got[k].normal, want[k].normal) << r;
                }
                total += got.size();
            }
            EXPECT_GT(total, rays.size() / 40);  // the rays do cross the meshes (needles: a few %)
        }
    }
}

// At an equal t every walk names the triangle of lower index (query/ray.hpp, closer_hit in
// query/ray_wide.hpp): copies of one triangle placed at scattered indices among a soup, hit by
// rays of every kind a walk is chosen by (a plain direction, a subnormal component, which the
// binary walk serves), on every layout, both triangle tests and both scalar types. The expected
// index is the first copy's, known by construction.
TYPED_TEST(RayQueries, EqualTKeepsTheLowerIndexOnEveryPath) {
    using T = TypeParam;
    std::vector<Triangle<T>> tris = test::random_soup<T>(400, 17);
    for (auto& t : tris)  // the soup below z = 0.5, away from the copies
        for (auto* p : {&t.p0, &t.p1, &t.p2}) (*p)[2] *= T(0.4);
    const Triangle<T> copy{{0, 0, 2}, {1, 0, 2}, {0, 1, 2}};
    const std::uint32_t places[] = {377, 45, 200, 46, 3, 399};  // 3 is the lowest
    for (const std::uint32_t i : places) tris[i] = copy;
    std::vector<Ray<T, 3>> rays;
    for (int i = 0; i < 50; ++i) {
        const T x = T(0.01) + T(0.015) * T(i), y = T(0.3) - T(0.004) * T(i);
        rays.push_back(Ray<T, 3>({x, y, 5}, {0, 0, -1}));
        rays.push_back(Ray<T, 3>({x, y, 5}, {T(1e-40), 0, -1}));  // subnormal in float
        rays.push_back(Ray<T, 3>({x, y, 5}, {T(0.01), T(-0.02), -1}));
    }
    for (const TriangleTest mode : {TriangleTest::Watertight, TriangleTest::Fast})
        for (const RayLayout layout : {RayLayout::Auto, RayLayout::Wide4, RayLayout::Binary}) {
            TriangleBvhOptions options;
            options.triangle_test = mode;
            options.ray_layout = layout;
            const TriangleBvh<T> bvh(tris, options);
            SCOPED_TRACE(bvh.ray_width());
            std::vector<Hit<T>> batch(rays.size());
            bvh.trace(rays, batch, 2);
            for (std::size_t r = 0; r < rays.size(); ++r) {
                EXPECT_EQ(bvh.closest_hit(rays[r]).primitive, 3u) << r;
                EXPECT_EQ(batch[r].primitive, 3u) << r;
            }
        }
}

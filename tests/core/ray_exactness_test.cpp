// Ray answers judged against an independent long-double reference (exact_ray_reference.hpp), on
// hard geometry: meshes far from the origin and at tiny and huge scales, needles and slivers, rays
// with zero direction components of either sign; and rays aimed exactly at the shared edges and
// vertices of closed meshes, which the watertight test must never let through.
#include <gtest/gtest.h>

#include <map>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "exact_ray_reference.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

/// Needles (length ~1, width 1e-5..1e-2) and slivers (one vertex near the opposite edge).
template <class T>
std::vector<Triangle<T>> needles(std::size_t n, std::uint64_t seed) {
    test::Random rng(seed);
    std::vector<Triangle<T>> out;
    for (std::size_t i = 0; i < n; ++i) {
        Vec<double, 3> a, dir, side;
        for (int k = 0; k < 3; ++k) {
            a[k] = rng.uniform(-1, 1);
            dir[k] = rng.uniform(-1, 1);
            side[k] = rng.uniform(-1, 1);
        }
        const double width = std::pow(10.0, rng.uniform(-5, -2));
        const double s = i % 2 ? rng.uniform(0, 1) : 0.5;  // needle (0.5) or sliver
        Vec<double, 3> c = a + dir * s + side * width;
        Vec<double, 3> b = a + dir;
        const auto f = [](const Vec<double, 3>& p) { return Vec<T, 3>{T(p[0]), T(p[1]), T(p[2])}; };
        out.push_back({f(a), f(b), f(c)});
    }
    return out;
}

/// Rays from a sphere of radius 3 r around `center` towards points of random triangles: inside,
/// at a vertex exactly, or on an edge; some with one or two direction components set to +0 or -0.
template <class T>
std::vector<Ray<T, 3>> aimed_rays(const std::vector<Triangle<T>>& tris, Vec<double, 3> center,
                                  double r, std::size_t n, std::uint64_t seed) {
    test::Random rng(seed);
    std::vector<Ray<T, 3>> rays;
    for (std::size_t i = 0; i < n; ++i) {
        const Triangle<T>& tri = tris[rng.below(std::uint32_t(tris.size()))];
        const double a = rng.uniform(0, 1), b = rng.uniform(0, 1 - a);
        Vec<double, 3> target, origin;
        for (int k = 0; k < 3; ++k) {
            const double p0 = tri.p0[k], p1 = tri.p1[k], p2 = tri.p2[k];
            switch (i % 3) {
                case 0:
                    target[k] = p0 + (p1 - p0) * a + (p2 - p0) * b;
                    break;
                case 1:
                    target[k] = p0;
                    break;
                default:
                    target[k] = p0 + (p1 - p0) * a;
                    break;
            }
        }
        Vec<double, 3> u;
        for (int k = 0; k < 3; ++k) u[k] = rng.uniform(-1, 1);
        origin = center + u * (3 * r / std::max(1e-9, length(u)));
        Ray<T, 3> ray;
        for (int k = 0; k < 3; ++k) {
            ray.origin[k] = T(origin[k]);
            ray.direction[k] = T(target[k] - double(ray.origin[k]));
        }
        if (i % 4 == 0) ray.direction[i % 3] = (i / 4) % 2 ? T(0) : -T(0);
        if (i % 8 == 0) ray.direction[(i + 1) % 3] = (i / 8) % 2 ? -T(0) : T(0);
        rays.push_back(ray);
    }
    return rays;
}

struct Tally {
    std::size_t certain_hits = 0, ambiguous = 0;
};

/// The tree's closest hit and any hit for `ray` against the reference over all triangles.
template <class T>
void check_ray(const TriangleBvh<T>& bvh, const std::vector<Triangle<T>>& tris,
               const Ray<T, 3>& ray, Tally& tally) {
    using L = long double;
    L best_certain = std::numeric_limits<L>::infinity(), best_tol = 0;
    std::vector<test::RefResult> refs(tris.size());
    bool any_ambiguous = false;
    for (std::size_t i = 0; i < tris.size(); ++i) {
        refs[i] = test::reference_intersect(ray, tris[i]);
        if (refs[i].cls == test::RefClass::Hit && refs[i].t < best_certain)
            best_certain = refs[i].t, best_tol = refs[i].t_tol;
        any_ambiguous = any_ambiguous || refs[i].cls == test::RefClass::Ambiguous;
    }
    const bool certain = best_certain < std::numeric_limits<L>::infinity();
    tally.certain_hits += certain;
    tally.ambiguous += any_ambiguous;
    const Hit<T> got = bvh.closest_hit(ray);
    if (certain) {
        ASSERT_TRUE(got) << "a certain hit at t = " << double(best_certain) << " missed";
        ASSERT_TRUE(bvh.any_hit(ray));
    }
    if (!got) return;
    const test::RefResult& mine = refs[got.primitive];
    ASSERT_NE(mine.cls, test::RefClass::Miss) << "hit a triangle the ray certainly misses";
    ASSERT_LE(std::fabs(L(got.t) - mine.t), mine.t_tol) << "t off";
    if (certain) {
        ASSERT_LE(L(got.t), best_certain + best_tol + mine.t_tol) << "not the closest";
    }
    ASSERT_EQ(got.normal, tris[got.primitive].normal());
}

template <class T>
class RayExactness : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(RayExactness, Scalars);

TYPED_TEST(RayExactness, HardGeometryAgreesWithTheLongDoubleReference) {
    using T = TypeParam;
    struct Case {
        const char* name;
        std::vector<Triangle<T>> tris;
        Vec<double, 3> center;
        double radius;
    };
    const TriangleMesh sphere = make_sphere(3);  // 1,280 triangles
    std::vector<Case> cases;
    for (const auto& [scale, offset] :
         {std::pair{1.0, 0.0}, std::pair{1e-6, 0.0}, std::pair{1e6, 0.0}, std::pair{1.0, 1e4},
          std::pair{1.0, 1e5}, std::pair{1.0, 1e6}, std::pair{1e3, 1e6}, std::pair{1e-6, 1e-3}})
        cases.push_back({"sphere", test::placed<T>(sphere, scale, offset),
                         Vec<double, 3>{offset, offset, offset}, scale});
    cases.push_back({"needles", needles<T>(1500, 4), Vec<double, 3>{0, 0, 0}, 1.5});
    const std::size_t per_case = test::scaled(1000, 10);
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(c.name) + " radius " + std::to_string(c.radius) + " center " +
                     std::to_string(c.center[0]));
        // The default tree, and the one with spatial splits (clipped leaf boxes).
        TriangleBvhOptions spatial;
        spatial.spatial_splits = true;
        spatial.spatial.alpha = 0;
        const TriangleBvh<T> trees[] = {TriangleBvh<T>(c.tris), TriangleBvh<T>(c.tris, spatial)};
        EXPECT_TRUE(trees[1].has_split_references() || c.name == std::string("sphere"));
        Tally tally;
        const auto rays = aimed_rays<T>(c.tris, c.center, c.radius, per_case, 11);
        for (const TriangleBvh<T>& bvh : trees)
            for (std::size_t r = 0; r < rays.size(); ++r) {
                SCOPED_TRACE("ray " + std::to_string(r) +
                             (bvh.has_split_references() ? ", spatial splits" : ""));
                check_ray(bvh, c.tris, rays[r], tally);
                if (testing::Test::HasFatalFailure()) return;
            }
        // The rays must mostly be decided, or the test proves little (on needles many rays pass
        // within the band of an edge, in float most).
        EXPECT_GT(tally.certain_hits,
                  2 * rays.size() / (c.name == std::string("needles") ? 20 : 3));
    }
}

/// Rays aimed exactly at vertices and points of edges of a closed mesh, from a side where every
/// triangle around that vertex or edge faces the ray the same way (so that in exact arithmetic the
/// ray crosses the surface there). Returns how many found nothing at or before the aimed point.
template <class T>
std::size_t gaps(const TriangleMesh& mesh, TriangleTest test, std::size_t n, std::uint64_t seed,
                 bool spatial_splits = false) {
    const std::vector<Triangle<T>> tris = test::placed<T>(mesh, 1.0, 0.0);
    TriangleBvhOptions options;
    options.triangle_test = test;
    options.spatial_splits = spatial_splits;
    options.spatial.alpha = 0;  // split wherever it pays: many leaf boxes cut through edges
    const TriangleBvh<T> bvh(tris, options);
    // Triangles around each edge and each vertex.
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edges;
    std::vector<std::vector<std::uint32_t>> around(mesh.vertices.size());
    for (std::uint32_t i = 0; i < mesh.triangles.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = mesh.triangles[i][k], b = mesh.triangles[i][(k + 1) % 3];
            edges[{std::min(a, b), std::max(a, b)}].push_back(i);
            around[a].push_back(i);
        }
    std::vector<std::pair<std::uint32_t, std::uint32_t>> shared;
    for (const auto& [e, f] : edges)
        if (f.size() == 2) shared.push_back(e);
    const double diag = length(mesh.bounds().max - mesh.bounds().min);
    test::Random rng(seed);
    std::size_t missed = 0, tried = 0;
    while (tried < n) {
        const auto [a, b] = shared[rng.below(std::uint32_t(shared.size()))];
        const bool at_vertex = rng.below(3) == 0;
        const auto& fan = at_vertex ? around[a] : edges[{a, b}];
        Vec<double, 3> target, normal{};
        const double s = rng.uniform(0, 1);
        for (int k = 0; k < 3; ++k) {
            const double pa = double(mesh.vertices[a][k]);
            target[k] = at_vertex ? pa : pa + (double(mesh.vertices[b][k]) - pa) * s;
        }
        for (std::uint32_t f : fan) {
            const auto nf = tris[f].normal();
            normal = normal + Vec<double, 3>{nf[0], nf[1], nf[2]} * (1 / length(nf));
        }
        Vec<double, 3> jitter{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
        const Vec<double, 3> origin =
            target + (normal * (1 / length(normal)) + jitter * 0.7) * (diag * rng.uniform(0.2, 2));
        Ray<T, 3> ray;
        for (int k = 0; k < 3; ++k) {
            ray.origin[k] = T(origin[k]);
            ray.direction[k] = T(target[k] - double(ray.origin[k]));
        }
        // Every triangle of the fan must face the ray the same way, clearly.
        int front = 0, back = 0;
        for (std::uint32_t f : fan) {
            const auto nf = tris[f].normal();
            const double c =
                dot(Vec<double, 3>{nf[0], nf[1], nf[2]},
                    Vec<double, 3>{ray.direction[0], ray.direction[1], ray.direction[2]}) /
                (length(nf) * length(ray.direction));
            front += c < -0.05;
            back += c > 0.05;
        }
        if (front != int(fan.size()) && back != int(fan.size())) continue;
        ++tried;
        const Hit<T> h = bvh.closest_hit(ray);
        missed += !h || h.t > T(1) + T(1e-3);
    }
    return missed;
}

TEST(Watertight, NoGapAtSharedEdgesAndVerticesOfClosedMeshes) {
    std::vector<std::pair<std::string, TriangleMesh>> meshes{{"sphere", make_sphere(4)},
                                                             {"torus", make_torus(96, 48)}};
    if (const auto spot = test::shared_mesh("spot.obj"); !spot.empty())
        meshes.emplace_back("spot", read_mesh(spot));
    const std::size_t n = test::scaled(60000, 20);
    std::size_t fast_gaps = 0;
    for (const auto& [name, mesh] : meshes) {
        SCOPED_TRACE(name);
        EXPECT_EQ(gaps<float>(mesh, TriangleTest::Watertight, n, 5), 0u);
        EXPECT_EQ(gaps<double>(mesh, TriangleTest::Watertight, n / 4, 6), 0u);
        EXPECT_EQ(gaps<float>(mesh, TriangleTest::Watertight, n / 2, 7, true), 0u);
        const std::size_t f = gaps<float>(mesh, TriangleTest::Fast, n, 5);
        std::printf("%s: the fast test let %zu of %zu aimed rays through\n", name.c_str(), f, n);
        fast_gaps += f;
    }
    // The same rays do find gaps with the fast test, so this test can fail.
    if (!test::small_scale()) {
        EXPECT_GT(fast_gaps, 0u);
    }
}

}  // namespace

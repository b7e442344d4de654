// Rays (closest hit: triangle and t; any hit) on a sphere scaled by 10^k (float 1e-30..1e30,
// double 1e-300..1e300), at the origin and moved 1e3 (float) or 1e6 (double) times its size from
// it, judged against the long double reference with its proved margin
// (tests/support/exact_ray_reference.hpp; its products of three coordinate differences stay
// within long double's range at both ends).
#include <gtest/gtest.h>

#include <cmath>

#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "exact_ray_reference.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

using LD = long double;

template <class T>
void rays_at_scale(const TriangleMesh& unit, double scale, double offset, std::size_t count,
                   std::uint64_t seed) {
    const std::vector<Triangle<T>> tris = test::placed<T>(unit, scale, offset);
    const TriangleBvh<T> bvh(tris);
    test::Random rng(seed);
    std::size_t certain = 0;
    for (std::size_t i = 0; i < count; ++i) {
        // From 3 sizes off towards a point of a random triangle (inside it, a corner, an edge),
        // or, every fourth ray, away from the sphere (a certain miss but for the ambiguous band).
        const Triangle<T>& tri = tris[rng.below(std::uint32_t(tris.size()))];
        const double a = rng.uniform(0, 1), b = rng.uniform(0, 1 - a);
        const Vec<double, 3> u = rng.unit_vector<double>();
        Ray<T, 3> ray;
        for (int k = 0; k < 3; ++k) {
            const double p0 = tri.p0[k], p1 = tri.p1[k], p2 = tri.p2[k];
            const double target = i % 3 == 0   ? p0 + (p1 - p0) * a + (p2 - p0) * b
                                  : i % 3 == 1 ? p0
                                               : p0 + (p1 - p0) * a;
            ray.origin[k] = T(offset + 3 * scale * u[k]);
            ray.direction[k] = T(target - double(ray.origin[k]));
            if (i % 4 == 3) ray.direction[k] = T(u[k] * scale);
        }
        SCOPED_TRACE("ray " + std::to_string(i));
        LD best = std::numeric_limits<LD>::infinity(), best_tol = 0;
        std::vector<test::RefResult> refs(tris.size());
        for (std::size_t f = 0; f < tris.size(); ++f) {
            refs[f] = test::reference_intersect(ray, tris[f]);
            if (refs[f].cls == test::RefClass::Hit && refs[f].t < best)
                best = refs[f].t, best_tol = refs[f].t_tol;
        }
        const bool hit = best < std::numeric_limits<LD>::infinity();
        certain += hit;
        const Hit<T> got = bvh.closest_hit(ray);
        if (hit) {
            ASSERT_TRUE(got) << "a certain hit at t = " << double(best) << " missed";
            ASSERT_TRUE(bvh.any_hit(ray));
        }
        if (!got) continue;
        const test::RefResult& mine = refs[got.primitive];
        ASSERT_NE(mine.cls, test::RefClass::Miss) << "hit a triangle the ray certainly misses";
        ASSERT_TRUE(std::isfinite(got.t));
        ASSERT_LE(std::fabs(LD(got.t) - mine.t), mine.t_tol) << "t off";
        if (hit) {
            ASSERT_LE(LD(got.t), best + best_tol + mine.t_tol) << "not the closest";
        }
    }
    // Most aimed rays must be decided, or the test proves little.
    EXPECT_GT(certain, count / 3);
}

template <class T>
void rays_across_the_range(int lowest, int highest, int step, double offset_sizes) {
    const TriangleMesh unit = make_sphere(2);  // 320 triangles
    const std::size_t count = test::scaled(60, 4);
    std::uint64_t seed = 1;
    test::for_each_scale(lowest, highest, step, offset_sizes, [&](double scale, double offset) {
        rays_at_scale<T>(unit, scale, offset, count, seed++);
    });
}

TEST(RayExtremeScale, Float) {
    rays_across_the_range<float>(-30, 30, 5, 1e3);
}
// Across double's range: beyond 1e+-60 the watertight test's products of two and three
// coordinates would leave it without the scaled path (primitives/triangle.hpp).
TEST(RayExtremeScale, Double) {
    rays_across_the_range<double>(-300, 300, 20, 1e6);
}

}  // namespace
}  // namespace bvhkit

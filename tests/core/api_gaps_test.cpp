// Small API gaps a reader of the headers found: each test fails (or fails to compile) without the
// fix it names.
#include <gtest/gtest.h>

#include <type_traits>
#include <vector>

#include "bvhkit/build/build.hpp"
#include "bvhkit/build/refit.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/bvh/wide_bvh.hpp"  // compiles on its own (it names invalid_index)
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "bvhkit/volumes/sphere.hpp"

namespace bvhkit {
namespace {

// refit() takes a std::vector of boxes as validate() does (the functor overload used to catch it).
TEST(ApiGaps, RefitTakesAVectorOfBoxes) {
    std::vector<Aabb3f> boxes;
    std::vector<Vec3f> centroids;
    for (int i = 0; i < 50; ++i) {
        boxes.emplace_back(Vec3f(float(i)), Vec3f(float(i) + 1));
        centroids.push_back(boxes.back().centroid());
    }
    AabbBvh<float, 3> bvh = build_bvh<float, 3>(boxes, centroids, BuildOptions{});
    for (auto& b : boxes) b.max = b.max + Vec3f(0.5f);
    refit(bvh, boxes);
    EXPECT_NO_THROW(validate(bvh, boxes));
    EXPECT_FLOAT_EQ(bvh.nodes[0].bounds.max[0], 50.5f);
}

// An empty sphere (radius -1) overlaps nothing, not even another empty one at the same centre.
TEST(ApiGaps, EmptySpheresOverlapNothing) {
    using Traits = VolumeTraits<Sphere<float>>;
    const Sphere<float> empty{};
    const Sphere<float> unit{Vec3f(0), 1.0f};
    ASSERT_LT(empty.radius, 0.0f);
    EXPECT_FALSE(Traits::overlaps(empty, empty));
    EXPECT_FALSE(Traits::overlaps(empty, unit));
    EXPECT_FALSE(
        Traits::overlaps(empty, empty, Traits::prepare(Transform<float>::identity(), 0.0f)));
    EXPECT_TRUE(Traits::overlaps(unit, unit));
}

// The names deprecated for one release (docs/api.md, "Deprecated names") still compile and do
// what their replacements do.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
TEST(DeprecatedNames, DoWhatTheirReplacementsDo) {
    static_assert(std::is_same_v<WideBvh4<float>, WideSlotBvh<float>>);
    static_assert(std::is_same_v<WideBvh<double, 8>, WideSlotBvh<double, 8>>);
    static_assert(std::is_same_v<WideNode4<float>, WideSlotNode<float>>);
    static_assert(std::is_same_v<WideNode<float, 8>, WideSlotNode<float, 8>>);

    const TriangleMesh mesh = make_sphere(3);
    TriangleBvhOptions wide8;
    wide8.ray_layout = RayLayout::Wide8;
    const TriangleBvh<float> automatic(mesh), old(mesh, wide8);
    EXPECT_EQ(old.ray_width(), automatic.ray_width());
    std::vector<Ray3f> rays;
    for (int i = 0; i < 64; ++i)
        rays.emplace_back(Vec3f(float(i % 8) * 0.25f - 1.0f, float(i / 8) * 0.25f - 1.0f, -3.0f),
                          Vec3f(0.0f, 0.0f, 1.0f));
    std::vector<Hit<float>> now(rays.size()), before(rays.size());
    automatic.trace_on_calling_thread(rays, now);
    automatic.trace_stream(rays, before);
    int hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        ASSERT_EQ(now[i].primitive, before[i].primitive) << i;
        ASSERT_EQ(now[i].t, before[i].t) << i;
        hits += now[i] ? 1 : 0;
    }
    EXPECT_GT(hits, 16);

    // The ray along z through (0.2, 0.3): sheared corners are the corners less the origin.
    const Ray<double, 3> ray(Vec3d(0.2, 0.3, -1.0), Vec3d(0.0, 0.0, 1.0));
    const WatertightRay<double> r(ray);
    const Vec3d p[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    double c[3][3];
    for (int k = 0; k < 3; ++k) {
        const double z = p[k][r.kz] - r.oz;
        c[k][0] = (p[k][r.kx] - r.ox) - r.sx * z, c[k][1] = (p[k][r.ky] - r.oy) - r.sy * z;
        c[k][2] = z;
    }
    TriangleHit<double> a, b;
    ASSERT_TRUE(
        watertight_finish(r,
                          ShearedTriangle<double>{c[0][0], c[0][1], c[0][2], c[1][0], c[1][1],
                                                  c[1][2], c[2][0], c[2][1], c[2][2]},
                          0.0, 10.0, a));
    ASSERT_TRUE(watertight_finish(r, c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0],
                                  c[2][1], c[2][2], 0.0, 10.0, b));
    EXPECT_EQ(a.t, 1.0);
    EXPECT_EQ(b.t, a.t);
    EXPECT_EQ(b.u, a.u);
    EXPECT_EQ(b.v, a.v);
}
#pragma GCC diagnostic pop

}  // namespace
}  // namespace bvhkit

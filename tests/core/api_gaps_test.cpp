// Small API gaps a reader of the headers found: each test fails (or fails to compile) without the
// fix it names.
#include <gtest/gtest.h>

#include <vector>

#include "bvhkit/build/build.hpp"
#include "bvhkit/build/refit.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/bvh/wide_bvh.hpp"  // compiles on its own (it names invalid_index)
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
    EXPECT_FALSE(Traits::overlaps(empty, empty, Traits::prepare(Transform<float>::identity(), 0.0f)));
    EXPECT_TRUE(Traits::overlaps(unit, unit));
}

}  // namespace
}  // namespace bvhkit

#include <gtest/gtest.h>

#include "bvhkit/math/aabb.hpp"
#include "test_support.hpp"

using namespace bvhkit;

TEST(Aabb, EmptyBoxHasNoMeasureAndGrowsToWhatItIsGiven) {
    Aabb3f b;
    EXPECT_TRUE(b.is_empty());
    EXPECT_EQ(b.area(), 0.0f);
    EXPECT_EQ(b.extent(), Vec3f(0.0f));
    b.grow(Vec3f(1, 2, 3));
    EXPECT_FALSE(b.is_empty());
    EXPECT_EQ(b.min, Vec3f(1, 2, 3));
    EXPECT_EQ(b.max, Vec3f(1, 2, 3));
}

// spatial_order (query/point_order.hpp): a permutation of the batch, non-finite points last, and
// the finite points in the order of a Morton key computed here independently (quantized in long
// double, bits interleaved one at a time), ties in index order. The batch queries that use it are
// checked against one-at-a-time answers in nearest_test.cpp and inside_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "bvhkit/query/point_order.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

// Ten bits an axis of p's cell in [lo, hi] (1024 cells an axis, the lowest for a flat axis), x
// highest.
std::uint64_t reference_key(const Vec3f& p, const Vec3f& lo, const Vec3f& hi) {
    std::uint64_t cell[3];
    for (int a = 0; a < 3; ++a) {
        const long double extent = static_cast<long double>(hi[a]) - lo[a];
        const long double t = extent > 0 ? (static_cast<long double>(p[a]) - lo[a]) / extent : 0;
        cell[a] = std::uint64_t(std::clamp(std::floor(t * 1024), 0.0L, 1023.0L));
    }
    std::uint64_t key = 0;
    for (int bit = 9; bit >= 0; --bit)
        for (int a = 0; a < 3; ++a) key = key << 1 | (cell[a] >> bit & 1);
    return key;
}

// An executor whose parallel_for calls the chunks last first: the order must not depend on the
// order in which the chunks run.
struct LastChunkFirst {
    template <class Body>
    void parallel_for(std::size_t count, std::size_t grain, Body&& body) const {
        for (std::size_t c = (count + grain - 1) / grain; c-- > 0;)
            body(c * grain, std::min(count, (c + 1) * grain));
    }
};

// Each run of `run` points (the last may be shorter) is a permutation of its own indices, its
// finite points in the order of their key over the run's box, then its non-finite ones.
template <class Exec = Executor>
void expect_order(const std::vector<Vec3f>& points, unsigned threads,
                  std::size_t run = spatial_order_run, const Exec& exec = Exec()) {
    const std::vector<std::uint32_t> order =
        std::is_same_v<Exec, Executor>
            ? spatial_order(std::span<const Vec3f>(points), Executor(threads), run)
            : spatial_order(std::span<const Vec3f>(points), exec, run);
    ASSERT_EQ(order.size(), points.size());
    for (std::size_t first = 0; first < points.size(); first += run) {
        const std::size_t end = std::min(points.size(), first + run);
        std::vector<char> seen(points.size(), 0);
        for (std::size_t k = first; k < end; ++k) {
            const std::uint32_t i = order[k];
            ASSERT_GE(i, first);
            ASSERT_LT(i, end);
            ASSERT_FALSE(seen[i]) << "index " << i << " twice";
            seen[i] = 1;
        }
        Vec3f lo(std::numeric_limits<float>::infinity());
        Vec3f hi(-std::numeric_limits<float>::infinity());
        for (std::size_t i = first; i < end; ++i)
            if (is_finite(points[i])) lo = min(lo, points[i]), hi = max(hi, points[i]);
        bool finite_part = true;
        for (std::size_t k = first; k < end; ++k) {
            const Vec3f& p = points[order[k]];
            if (!is_finite(p)) {
                finite_part = false;
                continue;
            }
            ASSERT_TRUE(finite_part) << "a finite point after a non-finite one, at " << k;
            if (k == first || !is_finite(points[order[k - 1]])) continue;
            const std::uint64_t a = reference_key(points[order[k - 1]], lo, hi);
            const std::uint64_t b = reference_key(p, lo, hi);
            ASSERT_TRUE(a < b || (a == b && order[k - 1] < order[k])) << "at " << k;
        }
    }
}

}  // namespace

TEST(SpatialOrder, IsTheMortonOrderOfTheBatch) {
    test::Random rng(5);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    // Random points, a grid (many points per cell on no axis), far from the origin, a flat batch
    // (one axis of zero extent), duplicates, and non-finite points among them.
    std::vector<Vec3f> random, grid, far, flat;
    for (std::size_t i = 0; i < test::scaled(20000, 10); ++i) {
        random.push_back(rng.point_in(Aabb3f({-1, -2, -3}, {3, 2, 1})));
        far.push_back(Vec3f(1e6f) + rng.point_in(Aabb3f({0, 0, 0}, {1, 1, 1})));
        flat.push_back({float(rng.uniform(0, 1)), 7.0f, float(rng.uniform(0, 1))});
    }
    for (int i = 0; i < 24; ++i)
        for (int j = 0; j < 24; ++j)
            for (int k = 0; k < 24; ++k) grid.push_back({float(i), float(j) * 0.5f, float(k)});
    for (auto* set : {&random, &grid, &far, &flat}) {
        set->push_back(set->front());  // a duplicate
        set->insert(set->begin() + 3, {nan, 0, 0});
        set->push_back({0, inf, 0});
        set->push_back({0, 0, -inf});
        for (unsigned threads : {1u, 0u}) expect_order(*set, threads);
        expect_order(*set, 0, spatial_order_run, LastChunkFirst{});
        // Runs shorter than the batch, as a batch past spatial_order_run points is sorted.
        expect_order(*set, 0, 1000);
        expect_order(*set, 1, 7);
    }
    // Runs past the size from which they are sorted in buckets: random points with non-finite
    // ones, and points bunched in one coarse cell but for one (nearly all in one bucket).
    std::vector<Vec3f> big, bunched;
    for (std::size_t i = 0; i < 70000; ++i) {
        big.push_back(rng.point_in(Aabb3f({-1, -2, -3}, {3, 2, 1})));
        bunched.push_back(Vec3f(5.0f) + rng.point_in(Aabb3f({0, 0, 0}, {1e-3f, 1e-3f, 1e-3f})));
    }
    big.insert(big.begin() + 5, {nan, 0, 0});
    big.push_back({0, 0, inf});
    big.push_back(big[17]);  // a duplicate
    bunched.push_back({100, 100, 100});
    for (auto* set : {&big, &bunched}) {
        for (unsigned threads : {1u, 0u}) expect_order(*set, threads);
        expect_order(*set, 0, spatial_order_run, LastChunkFirst{});
    }
    expect_order({}, 1);
    expect_order({{nan, nan, nan}}, 1);
    expect_order({{1, 2, 3}}, 1);
}

TEST(SpatialOrder, SmallBatchesKeepTheirOrder) {
    std::vector<Vec3f> points;
    for (std::size_t i = 0; i + 1 < spatial_order_from; ++i) points.push_back(Vec3f(float(i % 7)));
    const auto order = batch_order(
        points.size(), [&](std::size_t i) { return points[i]; }, Executor(1));
    for (std::size_t i = 0; i < order.size(); ++i) ASSERT_EQ(order[i], i);
}

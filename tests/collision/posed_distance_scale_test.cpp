// distance under a pose on meshes scaled by 10^k across each type's range and far from the
// origin, against an analytic answer: box A = [0, s]^3 about `origin`, box B = [-s/2, s/2]^3 turned
// about the x axis and moved beyond A along x by a gap. Turning about x leaves x alone (the first
// row of R is exactly (1, 0, 0)), and the boxes' yz projections overlap, so the
// distance is B's least x minus A's largest x, from the rounded inputs, taken in long double.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bvhkit/query/distance.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

template <class T>
BasicTriangleMesh<T> box(T lo, T hi, T lo_yz, T hi_yz) {
    BasicTriangleMesh<T> m;
    for (int i = 0; i < 8; ++i)
        m.vertices.push_back({(i & 1) ? hi : lo, (i & 2) ? hi_yz : lo_yz, (i & 4) ? hi_yz : lo_yz});
    m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return m;
}

template <class V>
void check_box_distances(int lo, int hi, int step, double far) {
    using T = typename V::Scalar;
    using L = long double;
    std::mt19937_64 rng(38);
    std::uniform_real_distribution<double> angle(0, 6.283), gap(0.05, 2);
    for (int k = lo; k <= hi; k += step)
        for (const double away : {0.0, far}) {
            const double s = std::pow(10.0, k), origin = away * s;
            const T a_lo = T(origin), a_hi = T(origin + s), half = T(s / 2);
            const auto ma = box<T>(a_lo, a_hi, a_lo, a_hi);
            const auto mb = box<T>(-half, half, -half, half);
            const CollisionModel<V> a(ma), b(mb);
            Transform<T> pose;
            const double turn = angle(rng);
            const T c = T(std::cos(turn)), sn = T(std::sin(turn));
            pose.rotation.row[1] = {0, c, -sn};
            pose.rotation.row[2] = {0, sn, c};
            const double g = gap(rng);
            const double mid = (double(a_lo) + double(a_hi)) / 2;
            pose.translation = {T(double(a_hi) + s * (0.5 + g)), T(mid), T(mid)};
            const L want = (L(pose.translation[0]) - L(half)) - L(a_hi);
            const DistanceResult<T> r = distance(a, b, pose);
            const L m = std::fabs(L(origin)) + 4 * L(s);
            // The documented bound (docs/accuracy.md), the long double reference's own rounding,
            // and the result's rounding to T.
            const L margin = std::ldexp(m, -40) + std::ldexp(want, -48) + std::ldexp(m, -60) +
                             L(std::numeric_limits<T>::epsilon()) * want;
            ASSERT_TRUE(std::isfinite(r.distance)) << "10^" << k << " at " << away;
            EXPECT_LE(std::fabs(L(r.distance) - want), margin)
                << "10^" << k << " at " << away << ": " << r.distance << " vs " << double(want);
            // The closest points are the answer's ends: on A's face x = a_hi and B's x face.
            EXPECT_LE(std::fabs(L(r.point_a[0]) - L(a_hi)), margin + L(a_hi) * 0x1p-50L);
        }
}

TEST(PosedDistanceScales, FloatBoxesAcrossTheRange) {
    // 1e-30 to 1e30, at the origin and 1e3 sizes away: squares stay in double's range.
    check_box_distances<Obb<float>>(-30, 30, 6, 1e3);
    check_box_distances<Rss<float>>(-30, 30, 12, 1e3);
    check_box_distances<Aabb<float, 3>>(-30, 30, 12, 1e3);
}

TEST(PosedDistanceScales, DoubleBoxesAcrossTheRange) {
    // 1e-60 to 1e60, at the origin and 1e6 sizes away: the segment-segment step forms fourth
    // powers of the coordinates, which leave double's range past about 1e+-75.
    check_box_distances<Obb<double>>(-60, 60, 10, 1e6);
    check_box_distances<Rss<double>>(-60, 60, 30, 1e6);
    check_box_distances<Aabb<double, 3>>(-60, 60, 30, 1e6);
}

}  // namespace
}  // namespace bvhkit::test

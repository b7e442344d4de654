// Triangle-triangle distance on slivers, needles, far from the origin and at extreme scales,
// against a long double reference that minimises over the features by another route (each
// feature pair's quadratic: its critical point when inside, else its boundary, parametrised from
// the feature's first corner).
#include <gtest/gtest.h>

#include "bvhkit/primitives/triangle_distance.hpp"
#include "hard_pairs.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

using L = long double;
using VL = Vec<L, 3>;

L point_segment2(const VL& p, const VL& a, const VL& b) {
    const VL d = b - a;
    const L dd = dot(d, d);
    L t = dd > 0 ? dot(p - a, d) / dd : 0;
    t = std::clamp(t, L(0), L(1));
    return length_squared(a + d * t - p);
}

L point_triangle2(const VL& p, const VL* t) {
    // Critical point of |t0 + s e1 + u e2 - p|^2: the 2x2 normal equations.
    const VL e1 = t[1] - t[0], e2 = t[2] - t[0], r = p - t[0];
    const L a = dot(e1, e1), b = dot(e1, e2), c = dot(e2, e2), d = dot(e1, r), e = dot(e2, r);
    const L den = a * c - b * b;
    L best = std::min({point_segment2(p, t[0], t[1]), point_segment2(p, t[1], t[2]),
                       point_segment2(p, t[2], t[0])});
    if (den > 0) {
        const L s = (c * d - b * e) / den, u = (a * e - b * d) / den;
        if (s >= 0 && u >= 0 && s + u <= 1)
            best = std::min(best, length_squared(r - e1 * s - e2 * u));
    }
    return best;
}

L segment_segment2(const VL& p, const VL& q, const VL& r, const VL& s) {
    const VL d1 = q - p, d2 = s - r, w = p - r;
    const L a = dot(d1, d1), b = dot(d1, d2), c = dot(d2, d2), d = dot(d1, w), e = dot(d2, w);
    const L den = a * c - b * b;
    L best = std::min({point_segment2(p, r, s), point_segment2(q, r, s), point_segment2(r, p, q),
                       point_segment2(s, p, q)});
    if (den > 0) {
        const L x = (b * e - c * d) / den, y = (a * e - b * d) / den;
        if (x >= 0 && x <= 1 && y >= 0 && y <= 1)
            best = std::min(best, length_squared(w + d1 * x - d2 * y));
    }
    return best;
}

template <class T>
L reference_distance(const Triangle<T>& a, const Triangle<T>& b) {
    const VL u[3] = {VL(a.p0), VL(a.p1), VL(a.p2)}, v[3] = {VL(b.p0), VL(b.p1), VL(b.p2)};
    L best = std::numeric_limits<L>::infinity();
    for (int i = 0; i < 3; ++i) {
        best = std::min({best, point_triangle2(u[i], v), point_triangle2(v[i], u)});
        for (int j = 0; j < 3; ++j)
            best = std::min(best, segment_segment2(u[i], u[(i + 1) % 3], v[j], v[(j + 1) % 3]));
    }
    return std::sqrt(best);
}

template <class T>
void check_accuracy(std::uint64_t seed, std::size_t count) {
    SplitMix64 rng(seed);
    double worst = 0;
    for (std::size_t n = 0; n < count; ++n) {
        auto [a, b] = hard_pair<T>(rng, int(n % 5));
        // Moved apart by up to ~the pair's size, often by much less.
        const T size = length(a.p1 - a.p0) + length(b.p1 - b.p0);
        const Vec<T, 3> gap(rng.unit_vector() *
                            (double(size) * std::pow(10.0, rng.uniform(-6, 0))));
        b = {b.p0 + gap, b.p1 + gap, b.p2 + gap};
        const double got = std::sqrt(triangle_distance(a, b).distance_squared);
        const L want = reference_distance(a, b);
        if (got == 0) continue;  // they meet: decided exactly (exact_test.cpp)
        double reach = 0;        // the largest coordinate: rounding is relative to it
        for (const Vec<T, 3>& p : {a.p0, a.p1, a.p2, b.p0, b.p1, b.p2})
            reach = std::max(reach, double(max_component(abs(p))));
        const double err = std::fabs(got - double(want));
        // The bound of docs/accuracy.md: 2^-40 of the largest coordinate, plus 2^-48 of d.
        ASSERT_LE(err, 0x1p-40 * reach + 0x1p-48 * double(want)) << n << " d " << double(want);
        worst = std::max(worst, err / reach);
    }
    ::testing::Test::RecordProperty("worst_error_over_reach", std::to_string(worst));
}

TEST(TriangleDistanceAccuracy, FloatHardPairsMatchLongDouble) {
    check_accuracy<float>(21, scaled(40000));
}

TEST(TriangleDistanceAccuracy, DoubleHardPairsMatchLongDouble) {
    check_accuracy<double>(22, scaled(20000));
}

TEST(TriangleDistanceAccuracy, FarApartTrianglesAreFinite) {
    const Triangle<float> a{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const Triangle<float> b{{3e37f, 0, 0}, {3e37f, 1, 0}, {3e37f, 0, 1}};
    const auto d = triangle_distance(a, b);
    EXPECT_TRUE(std::isfinite(d.distance_squared));
    EXPECT_NEAR(std::sqrt(d.distance_squared) / 3e37, 1.0, 1e-7);
}

}  // namespace
}  // namespace bvhkit::test

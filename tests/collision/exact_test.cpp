// The exact triangle-triangle decision against an exact integer reference that shares no method
// with it (exact_reference.hpp), on hard pairs (hard_pairs.hpp); and the orientation predicate
// against the integer determinant.
#include <gtest/gtest.h>

#include <limits>

#include "bvhkit/math/predicates.hpp"
#include "bvhkit/primitives/triangle_triangle.hpp"
#include "bvhkit/query/self_collision.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "collision_support.hpp"
#include "exact_reference.hpp"
#include "hard_pairs.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

/// `factor` scales every quadruple (double only: 1e-300 and 1e300 reach the ends of its range).
template <class T>
void check_orientations(std::size_t count, double factor = 1) {
    SplitMix64 rng(71);
    std::size_t zeros = 0;
    for (std::size_t n = 0; n < count; ++n) {
        const double scale = std::pow(10.0, rng.uniform(-6, 6)) * factor;
        const Vec3d off =
            rng.unit_vector() * (rng.below(2) ? std::pow(10.0, rng.uniform(4, 6)) * factor : 0);
        const Vec3d a = rng.unit_vector(), b = rng.unit_vector(), c = rng.unit_vector();
        // d near the plane of a, b, c (on it before rounding), or on a line, or a copy.
        Vec3d d = a + (b - a) * rng.uniform(-2, 2) + (c - a) * rng.uniform(-2, 2);
        if (rng.below(4) == 0) d = a + (b - a) * rng.uniform(-2, 2);
        const Vec<T, 3> p[4] = {Vec<T, 3>(a * scale + off), Vec<T, 3>(b * scale + off),
                                Vec<T, 3>(c * scale + off), Vec<T, 3>(d * scale + off)};
        const Vec<T, 3> q = rng.below(8) == 0 ? p[int(rng.below(3))] : p[3];
        const int want = exact_orient3d(p[0], p[1], p[2], q);
        zeros += want == 0;
        ASSERT_EQ(orient3d_sign(p[0], p[1], p[2], q), want) << n;
        ASSERT_EQ(orient3d_sign(p[1], p[2], p[0], q), want) << n;
        ASSERT_EQ(orient3d_sign(p[0], p[2], p[1], q), -want) << n;
        int three[3];
        const Vec<T, 3> ds[3] = {q, p[3], p[0]};
        orient3d_signs(p[0], p[1], p[2], ds, three);
        ASSERT_EQ(three[0], want) << n;
        // The same points projected on a coordinate plane.
        const auto k = std::size_t(rng.below(3)), x = (k + 1) % 3, y = (k + 2) % 3;
        const int want2 = exact_orient2d(p[0], p[1], q, x, y);
        ASSERT_EQ(orient2d_sign(double(p[0][x]), double(p[0][y]), double(p[1][x]), double(p[1][y]),
                                double(q[x]), double(q[y])),
                  want2)
            << n;
    }
    EXPECT_GT(zeros, count / 20);  // the generator does reach the exact zeros
}

TEST(ExactPredicates, Orient3dMatchesIntegerDeterminant) {
    check_orientations<float>(scaled(20000));
    check_orientations<double>(scaled(20000));
}

TEST(ExactPredicates, DoubleOrientationsExactAtTheEndsOfTheRange) {
    // Products of three differences of 1e-300 underflow and of 1e300 overflow in double: the
    // predicates scale such calls by a power of two (or fall back to integers) and stay exact.
    for (const double factor : {1e-300, 1e-200, 1e-105, 1e-100, 1e200, 1e300})
        check_orientations<double>(scaled(5000), factor);
}

TEST(ExactPredicates, Orient3dExactOnTinyDeterminants) {
    // Differences of floats far apart in exponent are not exact in double: the filter must
    // leave these to the exact stage.
    const Vec3f a{1e30f, 0, 0}, b{1e-30f, 1, 0}, c{0, 0, 1};
    const Vec3f d{1e30f, 1e-30f, 1e-30f};
    EXPECT_EQ(orient3d_sign(a, b, c, d), exact_orient3d(a, b, c, d));
    EXPECT_EQ(orient2d_sign(0.0, 0.0, 1e-300, 1e-300, 1.0, 1.0), 0);
    EXPECT_EQ(orient2d_sign(0.1, 0.1, 0.2, 0.2, 0.3, 0.3), 0);  // on y = x
    EXPECT_EQ(orient2d_sign(0.1, 0.1, 0.2, 0.2, 0.3, std::nextafter(0.3, 1.0)), 1);
}

// No exact sign exists for a NaN or infinite coordinate, or where the products overflow: the
// answer is 0, and the exact stage (whose expansions would overflow their buffers on a NaN) is
// never reached; ASan watches.
TEST(ExactPredicates, NonFiniteInputGivesZero) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
    for (const double bad : {nan, inf, -inf}) {
        for (int k = 0; k < 3; ++k) {
            Vec3d d{0.25, 0.25, 1};
            d[k] = bad;
            EXPECT_EQ(orient3d_sign(a, b, c, d), 0) << bad << " at " << k;
            EXPECT_EQ(orient3d_sign(d, b, c, a), 0) << bad << " at " << k;
            const Vec3d ds[3] = {d, d, d};
            int out[3] = {9, 9, 9};
            orient3d_signs(a, b, c, ds, out);
            EXPECT_EQ(out[0], 0);
        }
        EXPECT_EQ(orient2d_sign(0.0, 0.0, 1.0, 0.0, bad, 1.0), 0) << bad;
    }
    const Vec3f fnan{std::numeric_limits<float>::quiet_NaN(), 0, 0};
    EXPECT_EQ(orient3d_sign(Vec3f{0, 0, 0}, Vec3f{1, 0, 0}, Vec3f{0, 1, 0}, fnan), 0);
    // Finite double input has an exact sign, even where the products overflow or underflow.
    EXPECT_EQ(orient3d_sign(a, Vec3d{1e300, 0, 0}, Vec3d{0, 1e300, 0}, Vec3d{0, 0, 1e300}), 1);
    EXPECT_EQ(orient3d_sign(a, Vec3d{0, 1e300, 0}, Vec3d{1e300, 0, 0}, Vec3d{0, 0, 1e300}), -1);
    EXPECT_EQ(orient3d_sign(a, Vec3d{1e-300, 0, 0}, Vec3d{0, 1e-300, 0}, Vec3d{0, 0, 1e-300}), 1);
    EXPECT_EQ(orient3d_sign(a, Vec3d{1e-320, 0, 0}, Vec3d{0, 1e-320, 0}, Vec3d{0, 0, 1e-320}), 1);
    EXPECT_EQ(orient3d_sign(a, Vec3d{1e300, 0, 0}, Vec3d{0, 1e300, 0}, Vec3d{0, 0, 1e-300}), 1);
    EXPECT_EQ(orient2d_sign(0, 0, 1e300, 0, 0, 1e300), 1);
    EXPECT_EQ(orient2d_sign(0, 0, 1e-300, 0, 0, 1e-300), 1);
    EXPECT_EQ(orient2d_sign(0, 0, 1e-320, 0, 0, 1e300), 1);
}

/// The pair's corners times `factor` (rounded), as in check_orientations.
template <class T>
Triangle<T> times(const Triangle<T>& t, double factor) {
    return {Vec<T, 3>(Vec3d(t.p0) * factor), Vec<T, 3>(Vec3d(t.p1) * factor),
            Vec<T, 3>(Vec3d(t.p2) * factor)};
}

template <class T>
void check_hard_pairs(std::size_t count, std::uint64_t seed, double factor = 1) {
    SplitMix64 rng(seed);
    constexpr int kinds = 5;
    std::size_t hits[kinds] = {}, misses[kinds] = {};
    for (std::size_t n = 0; n < count; ++n) {
        const int kind = int(n % kinds);
        auto [a, b] = hard_pair<T>(rng, kind);
        if (factor != 1) a = times(a, factor), b = times(b, factor);
        const bool want = exact_triangles_meet(a, b);
        (want ? hits : misses)[kind]++;
        ASSERT_EQ(triangles_intersect(a, b), want) << "pair " << n << " kind " << kind;
        ASSERT_EQ(triangles_intersect(b, a), want) << "pair " << n << " kind " << kind;
        const auto x = intersect_triangles(a, b);
        ASSERT_EQ(x.hit, want) << "pair " << n << " kind " << kind;
        if (want) {  // the segment lies in the pair's box (a hair wider), at every scale
            Aabb<double, 3> box;
            for (const auto& p : {a.p0, a.p1, a.p2, b.p0, b.p1, b.p2}) box.grow(Vec3d(p));
            const Vec3d pad = (box.max * 0.5 - box.min * 0.5) * 1e-6;
            box.min = box.min - pad;
            box.max = box.max + pad;
            EXPECT_TRUE(box.contains(Vec3d(x.p)) && box.contains(Vec3d(x.q)))
                << "pair " << n << " kind " << kind << " at " << factor;
        }
    }
    // Every kind yields both answers in good number (the generators are near the boundary).
    for (int k = 0; k < kinds; ++k) {
        EXPECT_GT(hits[k], count / kinds / 20) << "kind " << k;
        EXPECT_GT(misses[k], count / kinds / 20) << "kind " << k;
    }
}

TEST(ExactTriangleTriangle, FloatHardPairsMatchExactReference) {
    check_hard_pairs<float>(scaled(100000, 50), 11);
}

TEST(ExactTriangleTriangle, DoubleHardPairsMatchExactReference) {
    check_hard_pairs<double>(scaled(20000, 50), 12);
}

TEST(ExactTriangleTriangle, DoubleHardPairsExactAtTheEndsOfTheRange) {
    // The hard pairs (1e-6..1e6 across, up to 1e6 from the origin) times 1e-300, 1e-105 (their
    // determinants subnormal) and 1e300: coordinates from ~1e-306 to ~4e306.
    for (const double factor : {1e-300, 1e-105, 1e300})
        check_hard_pairs<double>(scaled(5000, 50), 13, factor);
}

TEST(ExactTriangleTriangle, ZeroAreaTrianglesAreSegmentsAndPoints) {
    using Tri3 = Triangle<double>;
    const Tri3 a{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const Tri3 needle{{0.2, 0.2, -1}, {0.2, 0.2, 1}, {0.2, 0.2, 0}};  // collinear, through a
    const Tri3 point{{0.2, 0.2, 0}, {0.2, 0.2, 0}, {0.2, 0.2, 0}};    // on a
    const Tri3 above{{0.2, 0.2, 1e-9}, {0.2, 0.2, 1e-9}, {0.2, 0.2, 1e-9}};
    EXPECT_TRUE(is_degenerate(needle));
    EXPECT_TRUE(is_degenerate(point));
    EXPECT_FALSE(is_degenerate(a));
    EXPECT_TRUE(triangles_intersect(a, needle));
    EXPECT_TRUE(triangles_intersect(needle, a));
    const auto x = intersect_triangles(needle, a);
    EXPECT_TRUE(x.hit);
    EXPECT_EQ(x.p, (Vec3d{0.2, 0.2, 0}));
    EXPECT_TRUE(triangles_intersect(point, a));
    EXPECT_TRUE(triangles_intersect(point, point));
    EXPECT_TRUE(triangles_intersect(point, needle));
    EXPECT_FALSE(triangles_intersect(above, a));
    EXPECT_FALSE(triangles_intersect(above, point));
}

TEST(ExactTriangleTriangle, SegmentLiesOnBothTriangles) {
    // The reported segment of crossing needles: both ends within rounding of both triangles'
    // planes (the decision is exact; the segment is interpolated in double).
    SplitMix64 rng(5);
    for (int n = 0; n < int(scaled(2000)); ++n) {
        const auto [a, b] = hard_pair<double>(rng, 0);
        const auto x = intersect_triangles(a, b);
        if (!x.hit || x.coplanar) continue;
        double size = 0;
        for (const Vec3d& v : {a.p0, a.p1, a.p2, b.p0, b.p1, b.p2})
            size = std::max(size, length(v));
        for (const Triangle<double>& t : {a, b}) {
            const Vec3d nrm = normalize(cross(t.p1 - t.p0, t.p2 - t.p0));
            const double reach = 1e-13 * size;
            EXPECT_LE(std::fabs(dot(nrm, x.p - t.p0)), reach);
            EXPECT_LE(std::fabs(dot(nrm, x.q - t.p0)), reach);
        }
    }
}

/// One mesh of many hard pairs (corners not shared, so every meeting pair counts) times `factor`,
/// plus pairs that share a corner index (neighbours: never reported): self_collide's pairs are
/// the exact reference's.
template <class T>
void check_self_collision(double factor) {
    SplitMix64 rng(31);
    BasicTriangleMesh<T> m;
    const auto add = [&](const Triangle<T>& t) {
        const auto v = std::uint32_t(m.vertices.size());
        m.vertices.insert(m.vertices.end(), {t.p0, t.p1, t.p2});
        m.triangles.push_back({v, v + 1, v + 2});
    };
    for (std::size_t n = 0; n < scaled(400, 10); ++n) {
        const auto [a, b] = hard_pair<T>(rng, int(n % 5));
        add(factor == 1 ? a : times(a, factor));
        add(factor == 1 ? b : times(b, factor));
    }
    const auto v = std::uint32_t(m.vertices.size());
    const T f = T(factor);
    m.vertices.insert(m.vertices.end(), {Vec<T, 3>{0, 0, 0}, Vec<T, 3>{f, 0, 0}, Vec<T, 3>{0, f, 0},
                                         Vec<T, 3>{f / 5, f / 5, -f}});
    m.triangles.push_back({v, v + 1, v + 2});
    m.triangles.push_back({v, v + 3, v + 3});  // zero-area, shares corner v: a neighbour
    const auto tris = mesh_triangles(m);
    std::vector<Aabb<T, 3>> boxes(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i) boxes[i] = tris[i].bounds();
    PairSet want;
    for_each_box_pair(boxes, boxes, [&](std::uint32_t i, std::uint32_t j) {
        if (i >= j) return;
        for (auto x : m.triangles[i])
            for (auto y : m.triangles[j])
                if (x == y) return;
        if (exact_triangles_meet(tris[i], tris[j])) want.insert({i, j});
    });
    std::vector<Contact<T>> contacts;
    self_collide(CollisionModel<Obb<T>>(m), contacts);
    PairSet got;
    for (const auto& c : contacts) got.insert({c.triangle_a, c.triangle_b});
    EXPECT_EQ(got, want) << factor;
    EXPECT_GT(want.size(), scaled(400, 10) / 4) << factor;
}

TEST(ExactTriangleTriangle, SelfCollisionMatchesExactReference) {
    check_self_collision<float>(1);
}

TEST(ExactTriangleTriangle, DoubleSelfCollisionExactAtTheEndsOfTheRange) {
    for (const double factor : {1e-300, 1.0, 1e300}) check_self_collision<double>(factor);
}

}  // namespace
}  // namespace bvhkit::test

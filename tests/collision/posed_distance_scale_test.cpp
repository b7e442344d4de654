// distance under a pose on meshes scaled by 10^k across each type's range and far from the
// origin, against an analytic answer: box A = [0, s]^3 about `origin`, box B = [-s/2, s/2]^3 turned
// about the x axis and moved beyond A along x by a gap. Turning about x leaves x alone (the first
// row of R is exactly (1, 0, 0)), and the boxes' yz projections overlap, so the
// distance is B's least x minus A's largest x, from the rounded inputs, taken in long double.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "bvhkit/query/distance.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/kdop.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "collision_support.hpp"
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
            const L b_face = L(pose.translation[0]) - L(half);
            EXPECT_LE(std::fabs(L(r.point_b[0]) - b_face),
                      margin + std::fabs(b_face) * L(std::numeric_limits<T>::epsilon()))
                << "10^" << k << " at " << away;
        }
}

TEST(PosedDistanceScales, FloatBoxesAcrossTheRange) {
    // 1e-30 to 1e30, at the origin and 1e3 sizes away: squares stay in double's range.
    check_box_distances<Obb<float>>(-30, 30, 6, 1e3);
    check_box_distances<Rss<float>>(-30, 30, 12, 1e3);
    check_box_distances<Aabb<float, 3>>(-30, 30, 12, 1e3);
}

TEST(PosedDistanceScales, DoubleBoxesAcrossTheRange) {
    // 1e-300 to 1e300, at the origin and 1e6 sizes away (up to 1e306).
    check_box_distances<Obb<double>>(-300, 300, 20, 1e6);
    check_box_distances<Rss<double>>(-300, 300, 40, 1e6);
    check_box_distances<Aabb<double, 3>>(-300, 300, 40, 1e6);
}

// One triangle of A in the plane z = 0 and two of B above it in one leaf (max_leaf_size 2), the
// far one at z = 3s measured first in one of the two orders: the near one at z = s must not be
// dropped by the plane test, whose squares of squares of s leave double's range (1e60) or sink
// to zero (1e-60). B's corner (0, 0, z) is on the turn's axis: the distance is s exactly.
template <class V>
void check_near_after_far(double s) {
    using T = typename V::Scalar;
    BasicTriangleMesh<T> ma;
    ma.vertices = {{0, 0, 0}, {T(s), 0, 0}, {0, T(s), 0}};
    ma.triangles = {{0, 1, 2}};
    // B above and below A, each in both mesh orders: whichever order the builder keeps in the
    // leaf, one of the cases meets the far triangle first.
    for (const double side : {1.0, -1.0})
        for (const bool far_first : {true, false}) {
            BasicTriangleMesh<T> mb;
            for (const double z : far_first ? std::array{3 * s, s} : std::array{s, 3 * s})
                for (const auto& c : {Vec<T, 3>{0, 0, T(side * z)}, Vec<T, 3>{T(s), 0, T(side * z)},
                                      Vec<T, 3>{0, T(s), T(side * z)}})
                    mb.vertices.push_back(c);
            mb.triangles = {{0, 1, 2}, {3, 4, 5}};
            const CollisionModel<V> a(ma), b(mb);
            // A turn about z (z carried exactly): the pose is not applied exactly, so contacts
            // are decided on the exact integer level (posed_triangles.hpp).
            Transform<T> pose;
            const T c = T(std::cos(0.5)), sn = T(std::sin(0.5));
            pose.rotation.row[0] = {c, -sn, 0};
            pose.rotation.row[1] = {sn, c, 0};
            const DistanceResult<T> r = distance(a, b, pose);
            const char* order = far_first ? " far first" : " near first";
            EXPECT_NEAR(double(r.distance) / s, 1.0, 1e-12) << s << order << " side " << side;
            EXPECT_EQ(r.triangle_b, far_first ? 1u : 0u) << s << order << " side " << side;
            EXPECT_NEAR(double(r.point_b[2]) / s, side, 1e-12) << s;
            EXPECT_NEAR(double(r.point_a[2]) / s, 0.0, 1e-12) << s;
        }
}

TEST(PosedDistanceScales, PlaneTestNeverDropsTheNearerTriangle) {
    for (const double s : {1e52, 1e60, 1e100, 1e140, 1e200, 1e-60, 1e-100, 1e-200}) {
        check_near_after_far<Obb<double>>(s);
        check_near_after_far<Rss<double>>(s);
        check_near_after_far<Aabb<double, 3>>(s);
    }
}

// The plane test itself, on coordinates as given: B's triangle at height s over A's plane is not
// 3s beyond it, at any scale (its sixth powers overflow to inf >= inf from about 1e52 and sink to
// 0 >= 0 below about 1e-52); where they stay normal it is s/2 beyond.
TEST(PosedDistanceScales, PlaneTestNeverRejectsOnOverflowOrUnderflow) {
    using V = Vec<double, 3>;
    for (const double s : {1e-300, 1e-100, 1e-60, 1e-52, 1.0, 1e40, 1e52, 1e60, 1e100, 1e300}) {
        const Triangle<double> a{V{0, 0, 0}, V{s, 0, 0}, V{0, s, 0}};
        const Triangle<double> b{V{0, 0, s}, V{s, 0, s}, V{0, s, s}};
        EXPECT_FALSE(detail::beyond_plane(a, b, 3 * s)) << s;
        EXPECT_FALSE(detail::beyond_plane(b, a, 3 * s)) << s;
        if (s >= 1e-40 && s <= 1e40) {
            EXPECT_TRUE(detail::beyond_plane(a, b, s / 2)) << s;
            EXPECT_TRUE(detail::beyond_plane(b, a, s / 2)) << s;
        }
    }
}

// Random soups scaled by 2^k where the volumes' squared lengths sink below T's normal range
// (double near 1e-161, float near 1e-21): the distance must be the one at scale 1 (brute force
// over every pair) times 2^k, the scaling being exact. A rooted subnormal square is off by up
// to sqrt(denorm_min), a large part of such a model's size: without room for that in the slack,
// bounds exceed the true distance and the closest pair is dropped.
template <class V>
void check_soups_scaled(int k) {
    using T = typename V::Scalar;
    std::mt19937_64 rng(k + 1000);
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> shift(0, 1.2);
    for (std::uint64_t seed = 0; seed < 2; ++seed) {
        const auto ma = random_soup<T>(60, 0.08, 40 + seed),
                   mb = random_soup<T>(50, 0.08, 50 + seed);
        auto sa = ma, sb = mb;
        for (auto* m : {&sa, &sb})
            for (auto& v : m->vertices)
                for (int i = 0; i < 3; ++i) v[i] = std::ldexp(v[i], k);
        const CollisionModel<V> a(sa), b(sb);
        const auto ta = mesh_triangles(ma), tb = mesh_triangles(mb);
        for (int p = 0; p < 6; ++p) {
            double q[4] = {normal(rng), normal(rng), normal(rng), normal(rng)};
            const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
            const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
            Transform<T> pose;
            pose.rotation.row[0] = {T(1 - 2 * (y * y + z * z)), T(2 * (x * y - w * z)),
                                    T(2 * (x * z + w * y))};
            pose.rotation.row[1] = {T(2 * (x * y + w * z)), T(1 - 2 * (x * x + z * z)),
                                    T(2 * (y * z - w * x))};
            pose.rotation.row[2] = {T(2 * (x * z - w * y)), T(2 * (y * z + w * x)),
                                    T(1 - 2 * (x * x + y * y))};
            pose.translation = {T(shift(rng)), T(shift(rng)), T(shift(rng))};
            const double want = double(brute_force_distance(ta, tb, pose));
            Transform<T> scaled = pose;
            for (int i = 0; i < 3; ++i) scaled.translation[i] = std::ldexp(pose.translation[i], k);
            const double got = std::ldexp(double(distance(a, b, scaled).distance), -k);
            // The reference carries B's corners in T, the query in double: T's rounding of
            // coordinates up to about 2.
            const double tol = 1e-9 * want + 64 * double(std::numeric_limits<T>::epsilon());
            EXPECT_NEAR(got, want, tol) << "2^" << k << " soup " << seed << " pose " << p;
        }
    }
}

TEST(PosedDistanceScales, SubnormalSquaresNeverDropTheClosestPair) {
    for (const int k : {-530, -535, -545}) {
        check_soups_scaled<Aabb<double, 3>>(k);
        check_soups_scaled<Obb<double>>(k);
        check_soups_scaled<Rss<double>>(k);
        check_soups_scaled<Kdop<double, 18>>(k);
    }
    for (const int k : {-70, -75}) {
        check_soups_scaled<Aabb<float, 3>>(k);
        check_soups_scaled<Obb<float>>(k);
        check_soups_scaled<Rss<float>>(k);
    }
}

// triangle_distance on two configurations with a known answer h, across double's range: skew
// edges (A in the plane y = 0 below z = 0, B in the plane x = 0 above z = h; the closest points
// are the origin and (0, 0, h)) and a corner over a face (B's corner (s, s, h) over A's face in
// z = 0). The bound is docs/accuracy.md's, M the largest |coordinate|.
TEST(TriangleDistanceScales, KnownAnswersAcrossDoubleRange) {
    using V = Vec<double, 3>;
    for (const double s : {1e-300, 1e-250, 1e-200, 1e-160, 1e-140, 1e-100, 1.0, 1e100, 1e120, 1e140,
                           1e160, 1e200, 1e250, 1e300}) {
        const double h = 0.375 * s;
        const Triangle<double> edges_a{V{-s, 0, 0}, V{s, 0, 0}, V{0, 0, -s}};
        const Triangle<double> edges_b{V{0, -s, h}, V{0, s, h}, V{0, 0, h + s}};
        const Triangle<double> face_a{V{0, 0, 0}, V{4 * s, 0, 0}, V{0, 4 * s, 0}};
        const Triangle<double> corner_b{V{s, s, h}, V{2 * s, s, h + s}, V{s, 2 * s, h + s}};
        // A parallel copy of face_a h above it: every point of the overlap is a closest one, so
        // only the distance is checked.
        const Triangle<double> face_b{V{0, 0, h}, V{4 * s, 0, h}, V{0, 4 * s, h}};
        struct Case {
            const Triangle<double>&a, &b;
            V p, q;
            double m;
            bool points = true;
        };
        for (const Case& c : {Case{edges_a, edges_b, V{0, 0, 0}, V{0, 0, h}, h + s},
                              Case{face_a, corner_b, V{s, s, 0}, V{s, s, h}, 4 * s},
                              Case{face_a, face_b, V{}, V{}, 4 * s, false}}) {
            for (const bool swap : {false, true}) {
                // Both entry points: triangle_distance() first decides exactly whether the two
                // meet (math/predicates.hpp, exact at every finite scale), then measures.
                for (const bool decide : {false, true}) {
                    const auto d =
                        decide ? (swap ? triangle_distance(c.b, c.a) : triangle_distance(c.a, c.b))
                               : (swap ? triangle_distance_apart(c.b, c.a)
                                       : triangle_distance_apart(c.a, c.b));
                    const double bound = std::ldexp(c.m, -40) + std::ldexp(h, -48);
                    EXPECT_LE(std::fabs(d.distance - h), bound) << s;
                    if (!c.points) continue;
                    const V p = swap ? d.q : d.p, q = swap ? d.p : d.q;
                    for (int i = 0; i < 3; ++i) {
                        EXPECT_LE(std::fabs(p[i] - c.p[i]), 2 * bound) << s << " p" << i;
                        EXPECT_LE(std::fabs(q[i] - c.q[i]), 2 * bound) << s << " q" << i;
                    }
                }
            }
        }
    }
}

}  // namespace
}  // namespace bvhkit::test

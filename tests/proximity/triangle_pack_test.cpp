// TrianglePack4 (primitives/triangle_pack.hpp): the pack's squared distance against Ericson's
// closest point evaluated in long double from the same (float or double) corners, on well-shaped
// triangles, slivers, needles, collinear and degenerate ones, at many scales (1e-9 to 1e9 in
// float) and far from the origin; the exact-lane flags against the shapes; lanes_within (the SSE
// path for float) against distance_squared lane by lane; empty lanes and NaN points.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

#include "bvhkit/primitives/closest_point.hpp"
#include "bvhkit/primitives/triangle_pack.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

enum class Shape {
    Well,           // three random corners
    SliverAtP0,     // the angle at p0 tiny (sin^2 far below 1e-2): must be flagged
    FlatAtP0,       // the angle at p0 near 180 degrees: must be flagged
    NeedleAtP1,     // the tiny angle at p1, a moderate one at p0: not a sliver by the rule
    NeedleAtP2,     // the tiny angle at p2
    NearThreshold,  // sin^2 of the angle at p0 in [1.2e-2, 5e-2]: not flagged, poorly conditioned
    Collinear,      // p2 on the line through p0 and p1
    ZeroEdge,       // two corners equal
    AllEqual,       // a point
};
constexpr int shape_count = 9;

Vec3d perpendicular(const Vec3d& u, test::Random& rng) {
    while (true) {
        const Vec3d w = cross(u, rng.unit_vector<double>());
        if (length(w) > 0.1) return normalize(w);
    }
}

/// A triangle of the shape, of size about `size`, near `centre`, rounded to T.
template <class T>
Triangle<T> make_triangle(Shape shape, const Vec3d& centre, double size, test::Random& rng) {
    const Vec3d u = rng.unit_vector<double>(), w = perpendicular(u, rng);
    const double eps = std::pow(10.0, rng.uniform(-7, -3));  // a sliver's thinness
    Vec3d a = centre, b, c;
    switch (shape) {
        case Shape::Well:
            a = centre + rng.unit_vector<double>() * (size * rng.uniform(0.2, 1));
            b = centre + rng.unit_vector<double>() * (size * rng.uniform(0.2, 1));
            c = centre + rng.unit_vector<double>() * (size * rng.uniform(0.2, 1));
            break;
        case Shape::SliverAtP0:
            b = a + u * size;
            c = a + (u + w * eps) * (size * rng.uniform(0.3, 1.5));
            break;
        case Shape::FlatAtP0:
            b = a - u * (size * rng.uniform(0.3, 1));
            c = a + (u + w * eps) * (size * rng.uniform(0.3, 1));
            break;
        case Shape::NeedleAtP1:
        case Shape::NeedleAtP2: {
            // p0 and the near corner a short distance apart, at an angle of 30..150 degrees.
            const double angle = rng.uniform(0.52, 2.62);
            const Vec3d far = a + u * size;
            const Vec3d near = a + (u * std::cos(angle) + w * std::sin(angle)) * (size * eps * 1e2);
            b = shape == Shape::NeedleAtP1 ? far : near;
            c = shape == Shape::NeedleAtP1 ? near : far;
            break;
        }
        case Shape::NearThreshold: {
            const double s = std::sqrt(rng.uniform(1.2e-2, 5e-2));  // sin of the angle at p0
            b = a + u * (size * rng.uniform(0.3, 1));
            c = a + (u * std::sqrt(1 - s * s) * (rng.uniform() < 0.5 ? 1 : -1) + w * s) *
                        (size * rng.uniform(0.3, 1));
            break;
        }
        case Shape::Collinear:
            b = a + u * size;
            c = a + u * (size * rng.uniform(-0.5, 1.5));
            break;
        case Shape::ZeroEdge: {
            const Vec3d p = a + u * size;
            switch (rng.below(3)) {
                case 0:
                    b = a, c = p;
                    break;  // p0 == p1
                case 1:
                    b = p, c = a;
                    break;  // p0 == p2
                default:
                    b = c = p;  // p1 == p2
            }
            break;
        }
        case Shape::AllEqual:
            b = c = a;
            break;
    }
    return {Vec<T, 3>(a), Vec<T, 3>(b), Vec<T, 3>(c)};
}

template <class T>
Triangle<double> widen(const Triangle<T>& t) {
    return {Vec3d(t.p0), Vec3d(t.p1), Vec3d(t.p2)};
}

/// The reference: Ericson's closest point in long double (64-bit mantissa on x86, else at least
/// double), with p moved to the origin so that the reference's own rounding is relative to the
/// triangle's distance and size, not to its coordinates (far from the origin those are 1e4 times
/// larger). Double alone is not enough to judge the double pack.
template <class T>
double reference(const Triangle<T>& t, const Vec<T, 3>& p) {
    using L = long double;
    const Vec<L, 3> q(p);
    const Triangle<L> w{Vec<L, 3>(t.p0) - q, Vec<L, 3>(t.p1) - q, Vec<L, 3>(t.p2) - q};
    return double(length_squared(closest_point(w, Vec<L, 3>(L(0))).point));
}

/// sin^2 of the angle at p0, from the cross product (not the pack's own formula).
double sin2_at_p0(const Triangle<double>& t) {
    const Vec3d ab = t.p1 - t.p0, ac = t.p2 - t.p0;
    const double d = length_squared(ab) * length_squared(ac);
    return d > 0 ? length_squared(cross(ab, ac)) / d : 0.0;
}

/// A point near the triangle (a point of it, or of its edges' extensions a little beyond,
/// pushed off by up to 1% of `size` in a random direction) or far (1 to 10 sizes away).
template <class T>
Vec<T, 3> query_point(const Triangle<T>& t, double size, bool near, test::Random& rng) {
    const Triangle<double> d = widen(t);
    if (!near) {
        const Vec3d c = (d.p0 + d.p1 + d.p2) / 3.0;
        return Vec<T, 3>(c + rng.unit_vector<double>() * (size * rng.uniform(1, 10)));
    }
    double x = rng.uniform(-0.05, 1.05), y = rng.uniform(-0.05, 1.05);
    if (x + y > 1.1) x = 1 - x, y = 1 - y;
    const Vec3d on = d.p0 + (d.p1 - d.p0) * x + (d.p2 - d.p0) * y;
    // The push: sometimes none at all (on the plane), sometimes down to 1e-6 of the size.
    const double push = rng.uniform() < 0.1 ? 0.0 : size * 0.01 * std::pow(rng.uniform(), 4);
    return Vec<T, 3>(on + rng.unit_vector<double>() * push);
}

/// How far the pack's distance (not squared) may be from the reference, for a lane that is not
/// flagged exact. Argument: every quantity of the pack formula is formed from differences of the
/// corners and the point, each exact or one rounding of eps * S, S = the largest distance from p
/// to a corner (it also bounds every edge); then dot and cross products. The plane distance is
/// h / |n| with n = ab x ac, |n| = |ab| |ac| sin A: n's components carry ~2 eps |ab| |ac| each
/// (3.5 in length), the dot product h = n . ap another ~3 eps |n| |ap|, ap one eps |ap|; so the
/// distance errs by up to ~8 eps S / sin A to first order. An "inside" misjudged near the edge
/// p1-p2 is worse: Cramer's rule divides by det = |ab|^2 |ac|^2 sin^2 A, so the barycentrics err
/// by ~eps S / (|ab| sin^2 A), and for a point near the plane the edge's distance returned instead
/// is larger by that much times the edge's length: first order, ~eps S / sin^2 A (a review found
/// a thin triangle at sin^2 A = 1e-3 past 1024 eps S). So E = 16 eps S / sin A + 4 eps S / sin^2 A
/// (the worst measured by the review at sin^2 A >= 1e-2: ~1.5 eps S / sin^2 A). With sin^2 A >=
/// 1e-2 for an unflagged lane, E <= 560 eps S, within the slack ClosestPointMesh widens its radius
/// by (1024 eps (r + coordinate scale)), so a pack that passes cannot make the mesh miss a
/// triangle. A wrong formula (a sign, a missing term, a wrong clamp) errs by a fraction of the
/// size, orders of magnitude above E. In squared terms: |pack - ref| <= 2 E sqrt(ref) + E^2, plus
/// 1e-6 ref for the roundings of the squares. (A plain relative bound such as 1e-4 ref does not
/// fit: the error of the distance is absolute, ~eps S, so the relative error of its square grows as
/// eps S / d near the surface; the E^2 term plays the part of an absolute term in S^2, at most
/// ~(560 eps)^2 S^2 ~ 4.4e-9 S^2 for float at the sliver cut, and far less for well-shaped
/// triangles.)
template <class T>
double tolerance(const Triangle<T>& t, const Vec<T, 3>& p, double ref) {
    const Triangle<double> d = widen(t);
    const Vec3d q(p);
    const double s = std::sqrt(
        std::max({length_squared(d.p0 - q), length_squared(d.p1 - q), length_squared(d.p2 - q)}));
    const double sin2_a = std::max(sin2_at_p0(d), 1e-2);
    const double eps = double(std::numeric_limits<T>::epsilon());
    const double e = 16.0 * eps * s / std::sqrt(sin2_a) + 4.0 * eps * s / sin2_a;
    return 2 * e * std::sqrt(ref) + e * e + 1e-6 * ref;
}

struct Summary {
    std::size_t lanes = 0, exact = 0, compared = 0;
    double worst = 0;  // the largest |pack - ref| / tolerance over compared lanes
};

/// Fills packs with random shapes (and some empty lanes) at the scale and offset, and checks
/// every lane against the reference, lanes_within against the reference and against
/// distance_squared, and the flags against the shapes.
template <class T>
void check_packs(double size, const Vec3d& offset, std::size_t pack_count, std::uint64_t seed,
                 Summary& sum) {
    test::Random rng(seed);
    for (std::size_t k = 0; k < pack_count; ++k) {
        TrianglePack4<T> pack;
        Triangle<T> tris[4];
        unsigned used = 0;
        for (int l = 0; l < 4; ++l) {
            if (rng.uniform() < 0.1) continue;  // an empty lane
            const Shape shape = Shape(rng.below(shape_count));
            const Vec3d centre = offset + rng.unit_vector<double>() * (size * rng.uniform(0, 3));
            tris[l] = make_triangle<T>(shape, centre, size, rng);
            pack.set(l, tris[l], std::uint32_t(100 + l));
            ASSERT_EQ(pack.slot[l], std::uint32_t(100 + l));
            used |= 1u << l;
            // The flag: set below sin^2 = 1e-2; clear above it for a triangle whose products of
            // four lengths (aa * cc) lie well inside T's range (set() also flags those near
            // overflow or denormals). Margins for the rounding.
            const Triangle<double> wide = widen(tris[l]);
            const double s2 = sin2_at_p0(wide);
            const double aacc =
                length_squared(wide.p1 - wide.p0) * length_squared(wide.p2 - wide.p0);
            const bool in_range = aacc > double(std::numeric_limits<T>::min()) * 1e10 &&
                                  aacc < double(std::numeric_limits<T>::max()) * 1e-10;
            const bool flagged = pack.exact_lanes >> l & 1u;
            if (s2 < 0.9e-2) {
                ASSERT_TRUE(flagged) << "shape " << int(shape) << " sin^2 " << s2;
            }
            if (s2 > 1.1e-2 && in_range) {
                ASSERT_FALSE(flagged) << "shape " << int(shape) << " sin^2 " << s2;
            }
            // Equal corners stay equal when rounded: always a sliver. (A thin or collinear one
            // may not stay thin when rounded far from the origin; sin^2 above decides those.)
            if (shape == Shape::ZeroEdge || shape == Shape::AllEqual) {
                ASSERT_TRUE(flagged) << "shape " << int(shape);
            }
        }
        ASSERT_EQ(pack.exact_lanes & ~used, 0u) << "an empty lane flagged";
        const unsigned exact = pack.exact_lanes;
        for (int q = 0; q < 8; ++q) {
            // A point near (or far from) one of the pack's triangles.
            const int l0 = std::countr_zero(used | 16u);
            if (l0 == 4) break;
            int target = l0;
            for (int l = 0; l < 4; ++l)
                if ((used >> l & 1u) && rng.uniform() < 0.5) target = l;
            const Vec<T, 3> p = query_point(tris[target], size, q % 2 == 0, rng);
            // Exact lanes are always reported, empty lanes never.
            ASSERT_EQ(pack.lanes_within(p, T(-1)), exact) << "pack " << k;
            ASSERT_EQ(pack.lanes_within(p, std::numeric_limits<T>::infinity()) & ~used, 0u);
            for (int l = 0; l < 4; ++l) {
                if (!(used >> l & 1u)) continue;
                ++sum.lanes;
                const T d = pack.distance_squared(l, p);
                // lanes_within (SSE for float) against distance_squared, a few ulps away.
                const T above = d * T(1 + 8 * std::numeric_limits<T>::epsilon()) +
                                std::numeric_limits<T>::denorm_min();
                const T below = d > T(0) ? d * T(1 - 8 * std::numeric_limits<T>::epsilon()) : T(-1);
                ASSERT_TRUE(pack.lanes_within(p, above) >> l & 1u)
                    << "pack " << k << " lane " << l << " d " << d;
                if (exact >> l & 1u) {
                    ++sum.exact;
                    continue;
                }
                ASSERT_FALSE(pack.lanes_within(p, below) >> l & 1u)
                    << "pack " << k << " lane " << l << " d " << d;
                // The distance against the reference, by distance_squared and by lanes_within.
                ++sum.compared;
                const double ref = reference(tris[l], p), tol = tolerance(tris[l], p, ref);
                const double err = double(d) - ref;
                sum.worst = std::max(sum.worst, std::abs(err) / tol);
                ASSERT_LE(std::abs(err), tol)
                    << "pack " << k << " lane " << l << " pack " << d << " ref " << ref << " sin^2 "
                    << sin2_at_p0(widen(tris[l]));
                if (ref - tol > 0) {
                    ASSERT_FALSE(pack.lanes_within(p, T(ref - tol)) >> l & 1u)
                        << "pack " << k << " lane " << l << " ref " << ref;
                }
                ASSERT_TRUE(pack.lanes_within(p, T(ref + tol)) >> l & 1u)
                    << "pack " << k << " lane " << l << " ref " << ref;
            }
        }
    }
}

template <class T>
void check_scales() {
    const std::size_t packs = test::scaled(3000, 10);
    // Sizes from 1e-4 to 1e5 around the origin, and size 1 and 100 far from it (offset 1e4).
    const struct {
        double size;
        Vec3d offset;
    } cases[] = {{1, Vec3d(0.0)},       {1e-4, Vec3d(0.0)},           {1e5, Vec3d(0.0)},
                 {1, Vec3d(1e4)},       {100, Vec3d(1e4, -1e4, 1e4)}, {3e-3, Vec3d(0.5)},
                 {1, Vec3d(-1e4, 0, 0)}};
    std::uint64_t seed = 40;
    for (const auto& c : cases) {
        SCOPED_TRACE(::testing::Message() << "size " << c.size << " offset " << c.offset[0]);
        Summary s;
        check_packs<T>(c.size, c.offset, packs, seed++, s);
        if (::testing::Test::HasFatalFailure()) return;
        // Every kind of lane was there.
        EXPECT_GT(s.compared, s.lanes / 4);
        EXPECT_GT(s.exact, s.lanes / 4);
        ::testing::Test::RecordProperty("worst_" + std::to_string(seed), std::to_string(s.worst));
    }
}

TEST(TrianglePack, FloatAgainstDoubleReferenceAtManyScales) {
    check_scales<float>();
}

TEST(TrianglePack, DoubleAgainstReferenceAtManyScales) {
    check_scales<double>();
}

// Sizes where the pack formula's products of four and six lengths would overflow or sink into
// denormals in float (Ericson's closest point in float, whose largest terms are fourth powers,
// is accurate from about 1e-9 to 1e9): every lane the pack does not flag exact must still be
// accurate. (Before the pack flagged such triangles and formed h * (h / nn), a size of 1e7
// overestimated by 6% and 1e-7 by 0.2%, enough for ClosestPointMesh to miss the nearest triangle.)
// Double likewise, far beyond float's range.
template <class T>
void check_extreme_scales(std::initializer_list<double> sizes, double well_inside_lo,
                          double well_inside_hi) {
    std::uint64_t seed = 60;
    for (double size : sizes) {
        SCOPED_TRACE(::testing::Message() << "size " << size);
        for (const Vec3d& offset : {Vec3d(0.0), Vec3d(size * 10)}) {
            Summary s;
            check_packs<T>(size, offset, test::scaled(1000, 10), seed++, s);
            if (::testing::Test::HasFatalFailure()) return;
            // Well inside T's range most well-shaped lanes are compared, not flagged.
            if (size >= well_inside_lo && size <= well_inside_hi) {
                EXPECT_GT(s.compared, s.lanes / 4);
            }
        }
    }
}

TEST(TrianglePack, ExtremeScalesFloat) {
    check_extreme_scales<float>({1e-9, 1e-8, 1e-7, 1e-6, 1e6, 1e7, 1e8, 1e9}, 1e-6, 1e6);
}

TEST(TrianglePack, ExtremeScalesDouble) {
    check_extreme_scales<double>({1e-60, 1e-20, 1e20, 1e60}, 1e-60, 1e60);
}

TEST(TrianglePack, HugeFloatScaleSingleTriangle) {
    // The plainest case: a right triangle of legs 1e7 and a point 1e7 above its interior. The
    // distance is 1e7 (squared: 1e14); the nearest edge is ~1.03e7 away.
    const float s = 1e7f;
    TrianglePack4<float> pack;
    pack.set(0, Trianglef{{0, 0, 0}, {s, 0, 0}, {0, s, 0}}, 0);
    ASSERT_EQ(pack.exact_lanes, 0u);
    const Vec3f p(0.25f * s, 0.25f * s, s);
    EXPECT_NEAR(pack.distance_squared(0, p), 1e14f, 1e14f * 1e-5f);
    EXPECT_EQ(pack.lanes_within(p, 1.0001e14f), 1u);
}

template <class T>
void check_empty_and_nan() {
    const T inf = std::numeric_limits<T>::infinity(), nan = std::numeric_limits<T>::quiet_NaN();
    // An empty pack reports nothing, even where its zero corners are.
    const TrianglePack4<T> none;
    EXPECT_EQ(none.exact_lanes, 0u);
    EXPECT_EQ(none.lanes_within(Vec<T, 3>(T(0)), inf), 0u);
    EXPECT_EQ(none.lanes_within(Vec<T, 3>(nan), inf), 0u);

    // Lanes 1 and 3 used (3 a sliver), 0 and 2 empty; the point at the empty lanes' zero
    // corners.
    TrianglePack4<T> pack;
    pack.set(1, Triangle<T>{{1, 0, 0}, {2, 0, 0}, {1, 1, 0}}, 7);
    pack.set(3, Triangle<T>{{1, 0, 1}, {3, 0, 1}, {5, T(1e-4), 1}}, 9);
    EXPECT_EQ(pack.exact_lanes, 8u);
    EXPECT_EQ(pack.lanes_within(Vec<T, 3>(T(0)), inf), 10u);
    EXPECT_EQ(pack.lanes_within(Vec<T, 3>(T(0)), T(1)), 10u);  // lane 1 at distance 1 exactly
    EXPECT_EQ(pack.lanes_within(Vec<T, 3>(T(0)), T(0.99)), 8u);
    EXPECT_EQ(pack.lanes_within(Vec<T, 3>(T(0)), T(0)), 8u);

    // A NaN point (one coordinate or all) reports no lane but the exact ones, whatever the
    // bound.
    pack.set(0, Triangle<T>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, 5);
    for (const Vec<T, 3>& p : {Vec<T, 3>(nan), Vec<T, 3>(T(0.2), nan, T(0)),
                               Vec<T, 3>(T(0.2), T(0.2), nan), Vec<T, 3>(nan, T(0), T(0))})
        for (T bound : {inf, T(1e30), T(1), T(0)})
            EXPECT_EQ(pack.lanes_within(p, bound), 8u) << bound;
}

TEST(TrianglePack, EmptyLanesAndNaNPointsFloatAndDouble) {
    check_empty_and_nan<float>();
    check_empty_and_nan<double>();
}

// The same triangle gives the same distance in every lane, whatever its neighbours (no lane
// reads another's corners).
TEST(TrianglePack, LanesAreIndependent) {
    test::Random rng(70);
    for (int k = 0; k < 200; ++k) {
        const Trianglef t = make_triangle<float>(Shape::Well, Vec3d(0.0), 1, rng);
        const Vec3f p = query_point(t, 1, k % 2 == 0, rng);
        float first = 0;
        for (int l = 0; l < 4; ++l) {
            TrianglePack4<float> pack;
            for (int o = 0; o < 4; ++o)
                if (o != l)
                    pack.set(
                        o, make_triangle<float>(Shape(rng.below(shape_count)), Vec3d(0.0), 1, rng),
                        std::uint32_t(o));
            pack.set(l, t, std::uint32_t(l));
            const float d = pack.distance_squared(l, p);
            if (l == 0) first = d;
            ASSERT_EQ(d, first);
            if ((pack.exact_lanes >> l & 1u) || d == 0.0f) continue;
            ASSERT_TRUE(pack.lanes_within(p, d * (1 + 1e-6f)) >> l & 1u);
            ASSERT_FALSE(pack.lanes_within(p, d * (1 - 1e-6f)) >> l & 1u);
        }
    }
}

// A review's counterexample to the first sliver cut (sin^2 = 1e-3): a triangle pointed at p0,
// just thin enough to pass a cut at 1e-3, and points on its plane just inside the edge p1-p2,
// where the inside test's error (growing as 1/sin^2 of the angle at p0) made the pack return the
// edge's distance, thousands of ulps above the plane's. At sin^2 >= 1e-2 lanes stay unflagged
// only where the pack is within tolerance; thinner ones must be flagged.
TEST(TrianglePack, ThinTriangleNearItsFarEdge) {
    test::Random rng(77);
    for (int k = 0; k < 2000; ++k) {
        const double aim = rng.uniform(2e-4, 3e-2);  // about sin^2 of the angle at p0
        const double s = std::sqrt(aim), c = std::sqrt(1 - aim);
        const double len = rng.uniform(0.5, 2.0);
        const Trianglef t{{0.0f, 0.0f, 0.0f},
                          {float(len), 0.0f, 0.0f},
                          {float(len * c * rng.uniform(0.9, 1.1)), float(len * s), 0.0f}};
        const double s2 = sin2_at_p0(widen(t));
        TrianglePack4<float> pack;
        pack.set(0, t, 0);
        const bool flagged = pack.exact_lanes & 1u;
        if (s2 < 0.9e-2) {
            ASSERT_TRUE(flagged) << "sin^2 " << s2;
            continue;
        }
        // A point inside, near the edge p1-p2 (up to 0.2% of the way to p0), a hair above the
        // plane: where the inside test's error band lies.
        const double w = rng.uniform(0.0, 1.0);
        const Vec3d on_edge = Vec3d(t.p1) * (1 - w) + Vec3d(t.p2) * w;
        const Vec3d q = on_edge * (1 - 2e-3 * rng.uniform()) + Vec3d(0, 0, 1e-7 * rng.uniform());
        const Vec3f p(q);
        const double ref = reference(t, p);
        const double d = double(pack.distance_squared(0, p));
        ASSERT_LE(std::abs(d - ref), tolerance(t, p, ref))
            << "sin^2 " << s2 << " pack " << d << " ref " << ref;
    }
}

// The review's triangle itself (sin^2 at p0 = 1.007e-3) and its point, 3.4e-8 from the interior
// and 2.4e-4 from the edge p1-p2: with the cut at 1e-3 the pack said 2.4e-4 and the mesh found
// nothing within Ericson's own distance.
TEST(TrianglePack, ReviewedThinTriangle) {
    const Trianglef t{{0x1.9327aap-3f, 0x1.acc892p-3f, -0x1.b4e702p-1f},
                      {-0x1.247606p-1f, -0x1.b43016p-2f, -0x1.2a507ep-3f},
                      {-0x1.2b9154p-1f, -0x1.91c544p-2f, -0x1.0e9a3ep-3f}};
    const Vec3f p{-0x1.2a893cp-1f, -0x1.9645f8p-2f, -0x1.129becp-3f};
    const float accurate = float(distance_squared_accurate(t, p));
    const ClosestPointMesh<float> one(std::vector<Trianglef>{t});
    NearestScratch<float> scratch;
    const auto got = one.closest_point(p, scratch, accurate);
    ASSERT_TRUE(got);
    EXPECT_EQ(got.distance_squared, accurate);
    // With a point triangle a little farther than it, and no search limit.
    Vec3f x = p;
    x[2] += std::sqrt(accurate) * 1.5f;  // (1.5: x is rounded to ~7e-9, a fifth of it)
    const ClosestPointMesh<float> two(std::vector<Trianglef>{t, {x, x, x}});
    EXPECT_EQ(two.closest_point(p, scratch).triangle, 0u);
}

}  // namespace
}  // namespace bvhkit

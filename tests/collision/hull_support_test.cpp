// HullSupport: the climb over the hull's neighbours against a brute force that shares none of its
// arithmetic: the largest d . p over every input point (not only the hull's vertices), each dot
// product an exact integer (ExactInt on the doubles scaled to integers), compared with the exact
// value at the vertex the climb returns. Equal values are required, not equal vertices (on ties
// the climb may stop at another maximiser). Point sets: points on a sphere, boxes and lattices
// (many exact ties), a sphere clamped to a cube (flat facets with vertices inside them), needles,
// coplanar polygons, far from the origin, tiny and huge scales; directions random, along the axes,
// of small integers (more ties), the facets' normals, zero and of extreme magnitudes; starts cold,
// from the previous answer and from every vertex.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "bvhkit/convex/polytope.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/volumes/hull_support.hpp"
#include "exact_int.hpp"
#include "test_support.hpp"

// A namespace of its own: the unity build puts this file beside hull_references.hpp's helpers.
namespace bvhkit::test::climb_cases {
namespace {

using Vec3d = Vec<double, 3>;

/// The exact d . p of every point (one common scale for the points, one for d).
class ExactDots {
  public:
    explicit ExactDots(const std::vector<Vec3d>& points) {
        for (const Vec3d& p : points)
            for (std::size_t a = 0; a < 3; ++a)
                shift_ = std::max(shift_, ExactInt::shift_needed(p[a]));
    }
    ExactInt dot(const Vec3d& d, const Vec3d& p) const {
        int sd = -100000;
        for (std::size_t a = 0; a < 3; ++a) sd = std::max(sd, ExactInt::shift_needed(d[a]));
        ExactInt total;
        for (std::size_t a = 0; a < 3; ++a)
            total = total + ExactInt::scaled(d[a], sd) * ExactInt::scaled(p[a], shift_);
        return total;
    }

  private:
    int shift_ = -100000;
};

bool less(const ExactInt& a, const ExactInt& b) {
    return (b - a).sign() > 0;
}

template <class T>
std::vector<Vec<T, 3>> sorted_unique(const std::vector<Vec3d>& points) {
    std::vector<Vec<T, 3>> p;
    for (const Vec3d& q : points) p.push_back(Vec<T, 3>(q));
    std::sort(p.begin(), p.end(), lexicographic_less<T>);
    p.erase(std::unique(p.begin(), p.end()), p.end());
    return p;
}

std::vector<Vec3d> directions(SplitMix64& rng, std::size_t random_count) {
    std::vector<Vec3d> d;
    for (std::size_t a = 0; a < 3; ++a)
        for (double s : {1.0, -1.0}) {
            Vec3d e{};
            e[a] = s;
            d.push_back(e);
        }
    for (int i = -1; i <= 1; ++i)
        for (int j = -1; j <= 1; ++j)
            for (int k = -1; k <= 1; ++k) d.push_back(Vec3d{double(i), double(j), double(k)});
    for (std::size_t i = 0; i < random_count; ++i) {
        const Vec3d u = rng.unit_vector();
        d.push_back(u);
        d.push_back(Vec3d{std::round(u[0] * 3), std::round(u[1] * 3), std::round(u[2] * 3)});
    }
    d.push_back(rng.unit_vector() * 1e-300);  // products underflow
    d.push_back(rng.unit_vector() * 1e250);
    return d;
}

/// Every answer of `h` (built from `points`, as T) along `dirs` is an exact maximiser over the
/// points: cold, warm (the previous answer as hint) and from `extra_hints`.
template <class T>
void expect_exact_support(const std::vector<Vec3d>& raw, const std::vector<Vec3d>& dirs,
                          const char* what, std::size_t hint_stride = 0) {
    const std::vector<Vec<T, 3>> points = sorted_unique<T>(raw);
    const HullSupport<T> h{std::span<const Vec<T, 3>>(points)};
    ASSERT_FALSE(h.empty()) << what;
    std::vector<Vec3d> exact_points;
    for (const Vec<T, 3>& p : points) exact_points.push_back(Vec3d(p));
    const ExactDots dots(exact_points);
    std::uint32_t warm = HullSupport<T>::none;
    std::size_t checked = 0;
    for (const Vec3d& d64 : dirs) {
        // Directions of extreme magnitude test double's underflow and overflow; in float
        // (whose values the climb takes in double, where nothing underflows) they are not float
        // directions at all.
        const double m = max_component(abs(d64));
        if (m > double(std::numeric_limits<T>::max()) ||
            (m != 0 && m < double(std::numeric_limits<T>::min())))
            continue;
        const Vec<T, 3> d(d64);
        const Vec3d dd(d);  // the direction as the climb sees it
        ExactInt best = dots.dot(dd, exact_points[0]);
        for (const Vec3d& p : exact_points) {
            const ExactInt v = dots.dot(dd, p);
            if (less(best, v)) best = v;
        }
        const auto check = [&](std::uint32_t hint, const char* start) {
            const std::uint32_t i = h.support_index(d, hint);
            if (i >= h.size()) {
                ADD_FAILURE() << what << ": index " << i << " out of range";
                return std::uint32_t(0);
            }
            EXPECT_TRUE(dots.dot(dd, Vec3d(h.vertices()[i])) == best)
                << what << ", " << start << " start, d = " << d64[0] << " " << d64[1] << " "
                << d64[2];
            ++checked;
            return i;
        };
        check(HullSupport<T>::none, "cold");
        warm = check(warm, "warm");
        if (hint_stride != 0)
            for (std::uint32_t k = 0; k < h.size(); k += std::uint32_t(hint_stride))
                check(k, "every");
    }
    EXPECT_GT(checked, 0u);
}

std::vector<Vec3d> sphere(SplitMix64& rng, std::size_t n, double radius, Vec3d centre) {
    std::vector<Vec3d> p;
    for (std::size_t i = 0; i < n; ++i) p.push_back(centre + rng.unit_vector() * radius);
    return p;
}

// The sign of d . (u - v) against exact integers, on inputs where the double filter cannot decide:
// exact ties (axis and lattice directions on lattice points, where the rounded values are exact),
// near ties that round to ties, products that underflow, and mixed huge and tiny terms.
TEST(HullSupport, DotDifferenceSignIsExact) {
    SplitMix64 rng(77);
    int ties = 0, cases = 0;
    const auto check = [&](const Vec3d& d, const Vec3d& u, const Vec3d& v) {
        const ExactDots dots(std::vector<Vec3d>{u, v});
        const int want = (dots.dot(d, u) - dots.dot(d, v)).sign();
        ASSERT_EQ(support_detail::dot_difference_sign(d, u, v), want)
            << "d " << d[0] << " " << d[1] << " " << d[2] << " u " << u[0] << " " << u[1] << " "
            << u[2] << " v " << v[0] << " " << v[1] << " " << v[2];
        ties += want == 0;
        ++cases;
    };
    const auto lattice = [&](double step) {
        return Vec3d{step * double(rng.next() % 5), step * double(rng.next() % 5),
                     step * double(rng.next() % 5)};
    };
    for (int i = 0; i < 20000; ++i) {
        const double step = std::ldexp(1.0, int(rng.next() % 200) - 100);
        Vec3d d{double(int(rng.next() % 5) - 2), double(int(rng.next() % 5) - 2),
                double(int(rng.next() % 5) - 2)};
        const Vec3d u = lattice(step), v = lattice(step);
        check(d, u, v);
        // Near ties: one coordinate moved by one unit in the last place.
        Vec3d w = v;
        w[i % 3] = std::nextafter(u[i % 3], 1e300);
        check(d, u, w);
        // Far from the origin: both points shifted by a large offset, the difference exact or not.
        const Vec3d far{1e15, -3e14, 7e13};
        check(d, u + far, v + far);
        // Random directions: exact ties only when the differences cancel term by term.
        const Vec3d r = rng.unit_vector();
        check(r, u, v);
        // Products in the subnormal range: ties that only the exact path may call.
        check(d * 1e-300, u * 1e-10, v * 1e-10);
        check(r * 1e-300, u * 1e-20, w * 1e-20);
        // Mixed: a huge term beside tiny ones.
        check(Vec3d{1e200, 1e-200, 1.0}, Vec3d{0.0, u[1], u[2]}, Vec3d{0.0, v[1], v[2]});
    }
    EXPECT_GT(ties, 10000);  // the tie paths ran
    EXPECT_GT(cases - ties, 10000);
}

TEST(HullSupport, SpheresAtEveryScale) {
    SplitMix64 rng(11);
    const std::vector<Vec3d> dirs = directions(rng, scaled(200, 10));
    for (const double scale : {1.0, 1e-30, 1e30}) {
        const auto p = sphere(rng, 1500, scale, Vec3d{});
        expect_exact_support<double>(p, dirs, "sphere");
        expect_exact_support<float>(p, dirs, "sphere, float");
    }
    // Far from the origin: unit spacing at 1e6 (double) and coarse float steps.
    expect_exact_support<double>(sphere(rng, 800, 1.0, Vec3d{1e6, -2e6, 3e6}), dirs, "far");
    expect_exact_support<float>(sphere(rng, 800, 1.0, Vec3d{1e4, -2e4, 3e4}), dirs, "far float");
    // Every vertex as the start.
    expect_exact_support<double>(sphere(rng, 300, 1.0, Vec3d{}), directions(rng, 8), "hints", 1);
}

TEST(HullSupport, BoxesAndLatticesWithTies) {
    SplitMix64 rng(12);
    const std::vector<Vec3d> dirs = directions(rng, scaled(100, 10));
    // The surface of a box as a lattice: most points lie inside facets or on edges.
    std::vector<Vec3d> box;
    for (int i = -6; i <= 6; ++i)
        for (int j = -6; j <= 6; ++j)
            for (int k = -6; k <= 6; ++k)
                if (std::max({std::abs(i), std::abs(j), std::abs(k)}) == 6)
                    box.push_back(Vec3d{i * 0.5, j * 0.25, k * 2.0});
    expect_exact_support<double>(box, dirs, "box lattice");
    // A rounded sphere (coordinates on a 1/8 grid): many exactly coplanar and tied vertices.
    std::vector<Vec3d> rounded;
    for (const Vec3d& q : sphere(rng, 3000, 1.0, Vec3d{}))
        rounded.push_back(
            Vec3d{std::round(q[0] * 8) / 8, std::round(q[1] * 8) / 8, std::round(q[2] * 8) / 8});
    expect_exact_support<double>(rounded, dirs, "rounded sphere", 3);
    expect_exact_support<float>(rounded, dirs, "rounded sphere, float", 3);
}

TEST(HullSupport, FlatFacetsWithVerticesInside) {
    SplitMix64 rng(13);
    // A sphere clamped to a cube: six flat facets holding many points; Quickhull keeps some of
    // them as vertices inside a facet, where the facet's inward normal makes every neighbour tie.
    std::vector<Vec3d> clamped;
    for (Vec3d q : sphere(rng, 3000, 1.0, Vec3d{})) {
        for (std::size_t a = 0; a < 3; ++a) q[a] = std::clamp(q[a], -0.7, 0.7);
        clamped.push_back(q);
    }
    const std::vector<Vec3d> dirs = directions(rng, scaled(100, 10));
    expect_exact_support<double>(clamped, dirs, "clamped sphere", 1);

    const std::vector<Vec3d> points = sorted_unique<double>(clamped);
    const HullSupport<double> h{std::span<const Vec3d>(points)};
    ASSERT_TRUE(h.climbs());
    std::size_t inside = 0;
    for (std::uint32_t i = 0; i < h.size(); ++i) {
        if (!h.inside_facet(i)) continue;
        ++inside;
        // The inward normal of its facet, from the start inside the facet: the answer is on the
        // opposite facet.
        const Vec3d v = h.vertices()[i];
        for (std::size_t a = 0; a < 3; ++a)
            if (std::fabs(v[a]) == 0.7) {
                Vec3d d{};
                d[a] = v[a] > 0 ? -1.0 : 1.0;
                const Vec3d s = h.vertices()[h.support_index(d, i)];
                EXPECT_EQ(s[a], -v[a]) << "vertex " << i;
                // And the outward normal: the start itself (or a vertex of the same facet).
                EXPECT_EQ(h.vertices()[h.support_index(-d, i)][a], v[a]);
            }
    }
    EXPECT_GT(inside, 0u) << "the set no longer exercises vertices inside facets";
}

TEST(HullSupport, NeedlesAndFlatSets) {
    SplitMix64 rng(14);
    const std::vector<Vec3d> dirs = directions(rng, scaled(100, 10));
    // A needle: rings of radius 1e-7 along a unit segment.
    std::vector<Vec3d> needle;
    for (int k = 0; k <= 20; ++k)
        for (int i = 0; i < 16; ++i) {
            const double a = 2 * 3.141592653589793 * i / 16;
            needle.push_back(Vec3d{1e-7 * std::cos(a), 1e-7 * std::sin(a), k * 0.05});
        }
    expect_exact_support<double>(needle, dirs, "needle", 7);
    expect_exact_support<float>(needle, dirs, "needle, float", 7);
    // A coplanar polygon (z = 0 exactly), with points inside: the ring of its corners.
    std::vector<Vec3d> disc;
    for (int i = 0; i < 200; ++i) {
        const double a = 2 * 3.141592653589793 * i / 200;
        disc.push_back(Vec3d{std::cos(a), std::sin(a), 0.0});
        disc.push_back(Vec3d{0.5 * std::cos(a), 0.3 * std::sin(a), 0.0});
    }
    expect_exact_support<double>(disc, dirs, "disc", 5);
    {
        const std::vector<Vec3d> points = sorted_unique<double>(disc);
        const HullSupport<double> h{std::span<const Vec3d>(points)};
        EXPECT_TRUE(h.climbs());
        EXPECT_EQ(h.size(), 200u);
    }
    // Collinear points and a few points: scanned.
    std::vector<Vec3d> line;
    for (int i = 0; i < 50; ++i) line.push_back(Vec3d{i * 0.1, i * 0.2, -i * 0.3});
    expect_exact_support<double>(line, dirs, "line");
    expect_exact_support<double>({Vec3d{1, 2, 3}}, dirs, "point");
    expect_exact_support<double>(sphere(rng, 10, 1.0, Vec3d{}), dirs, "ten points");
}

TEST(HullSupport, BadDirectionsStayInRange) {
    SplitMix64 rng(15);
    const auto p = sorted_unique<double>(sphere(rng, 200, 1.0, Vec3d{}));
    const HullSupport<double> h{std::span<const Vec3d>(p)};
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const Vec3d d : {Vec3d{nan, 0, 0}, Vec3d{inf, 1, 0}, Vec3d{0, 0, 0}})
        for (std::uint32_t hint : {HullSupport<double>::none, 3u, 100000u})
            EXPECT_LT(h.support_index(d, hint), h.size());
}

TEST(HullSupport, PolytopeSupportIsExact) {
    // ConvexPolytope's support with and without a hint (the path GJK and EPA take).
    SplitMix64 rng(16);
    const auto raw = sphere(rng, 500, 2.0, Vec3d{3, 4, 5});
    const ConvexPolytope<double> poly{std::span<const Vec3d>(raw)};
    const ExactDots dots(raw);
    std::uint32_t hint = HullSupport<double>::none;
    for (const Vec3d& d : directions(rng, scaled(200, 10))) {
        ExactInt best = dots.dot(d, raw[0]);
        for (const Vec3d& q : raw)
            if (less(best, dots.dot(d, q))) best = dots.dot(d, q);
        EXPECT_TRUE(dots.dot(d, poly.support(d)) == best);
        EXPECT_TRUE(dots.dot(d, poly.support(d, hint)) == best);
    }
}

}  // namespace
}  // namespace bvhkit::test::climb_cases

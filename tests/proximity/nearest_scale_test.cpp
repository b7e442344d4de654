// k nearest and within a radius where squared distances leave the type's range (issue 38): a
// float mesh 1e-25 across (squares sink to 0), 1e20 across (squares overflow), a point 1e16 away
// (squares round by more than the gaps between the triangles' distances); double likewise at
// 1e+-200 and 1e150.
//
// References that share nothing with the library's arithmetic: near the mesh, the exact rational
// distance to every triangle (tests/support/exact_point_triangle.hpp); from far off, the analytic
// support of far_point_test.cpp (a triangle's distance is D - h + e, h its largest p^.x over the
// corners, 0 <= e <= R^2 / (D - R)); for a tree of points, points on a line whose distances are
// multiples of the scale.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "bvhkit/build/build.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "exact_point_triangle.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit {
namespace {

using LD = long double;

template <class T>
std::vector<Triangle<T>> scaled_soup(const TriangleMesh& unit, double scale, double offset) {
    std::vector<Vec<T, 3>> v;
    for (const auto& u : unit.vertices) {
        Vec<T, 3> w;
        for (int k = 0; k < 3; ++k) w[k] = T(double(u[k]) * scale + offset);
        v.push_back(w);
    }
    std::vector<Triangle<T>> tris;
    for (const auto& t : unit.triangles) tris.push_back({v[t[0]], v[t[1]], v[t[2]]});
    return tris;
}

/// k_nearest and within_radius for points around one scaled sphere, against the exact distances:
/// the j-th triangle found is no farther than the j-th nearest by more than the bound B of
/// docs/accuracy.md (128 eps_W (d + E + L)), the list is in order within B, every distance is
/// finite and non-zero and within the closest point's bound; a radius strictly between two exact
/// distances (by more than B) finds exactly the triangles within it.
template <class T>
void check_ranking_at_scale(const TriangleMesh& unit, double scale, double offset,
                            std::size_t points, std::uint64_t seed) {
    const std::vector<Triangle<T>> tris = scaled_soup<T>(unit, scale, offset);
    const ClosestPointMesh<T> mesh(tris);
    const LD eps_t = std::numeric_limits<T>::epsilon();
    const LD eps_w = std::numeric_limits<AccurateScalar<T>>::epsilon();
    LD longest = 0;
    for (const auto& t : tris)
        for (const auto& [a, b] : {std::pair{t.p0, t.p1}, {t.p1, t.p2}, {t.p2, t.p0}}) {
            LD e2 = 0;
            for (int k = 0; k < 3; ++k) e2 += (LD(a[k]) - LD(b[k])) * (LD(a[k]) - LD(b[k]));
            longest = std::max(longest, std::sqrt(e2));
        }
    const LD diagonal = 2 * std::sqrt(LD(3)) * LD(scale);
    const double radii[] = {0.3, 0.7, 1.05, 1.5, 3, 30, 1e3, 1e6};
    test::Random rng(seed);
    NearestScratch<T> scratch;
    std::vector<MeshPoint<T>> got;
    std::size_t radius_checks = 0;
    for (std::size_t i = 0; i < points; ++i) {
        const double r = radii[i % std::size(radii)];
        const Vec<double, 3> u = rng.unit_vector<double>();
        Vec<T, 3> p;
        for (int k = 0; k < 3; ++k) p[k] = T(u[k] * r * scale + offset);
        SCOPED_TRACE("point " + std::to_string(i) + " radius " + std::to_string(r));
        std::vector<LD> exact(tris.size());
        for (std::size_t f = 0; f < tris.size(); ++f)
            exact[f] = std::sqrt(test::pt_exact::exact_distance_squared(tris[f], p).value());
        std::vector<LD> sorted = exact;
        std::sort(sorted.begin(), sorted.end());
        const std::size_t k = 12;
        const LD bound = 128 * eps_w * (sorted[k - 1] + diagonal + longest);
        mesh.k_nearest(p, k, got, scratch);
        ASSERT_EQ(got.size(), k);
        for (std::size_t j = 0; j < k; ++j) {
            const LD e = exact[got[j].triangle];
            EXPECT_LE(e, sorted[j] + bound) << "rank " << j << ": a farther triangle";
            if (j > 0) {
                EXPECT_LE(exact[got[j - 1].triangle], e + bound) << "rank " << j;
            }
            ASSERT_TRUE(std::isfinite(got[j].distance)) << "rank " << j;
            EXPECT_GT(got[j].distance, T(0)) << "rank " << j;
            EXPECT_NEAR(LD(got[j].distance), e, 2 * eps_t * e + 96 * eps_w * (e + longest))
                << "rank " << j;
        }
        // closest_point_within: a limit just below the least distance finds nothing, one just
        // above finds it.
        using W = AccurateScalar<T>;
        EXPECT_FALSE(mesh.closest_point_within(p, W(sorted[0] * 0.999L), {}, scratch));
        const MeshPoint<T> within =
            mesh.closest_point_within(p, W(sorted[0] * 1.001L), {}, scratch);
        ASSERT_TRUE(within);
        EXPECT_LE(exact[within.triangle], sorted[0] + bound);
        // A radius between two distances farther apart than the bound, representable in T.
        for (std::size_t m = 5; m + 1 < sorted.size(); ++m) {
            const T radius = T((sorted[m - 1] + sorted[m]) / 2);
            if (!(LD(radius) - sorted[m - 1] > bound && sorted[m] - LD(radius) > bound)) continue;
            mesh.within_radius(p, radius, got);
            std::set<std::uint32_t> want, found;
            for (std::uint32_t f = 0; f < tris.size(); ++f)
                if (exact[f] <= LD(radius)) want.insert(f);
            for (const auto& h : got) found.insert(h.triangle);
            EXPECT_EQ(found, want) << "radius " << double(radius);
            EXPECT_EQ(got.size(), want.size());
            ++radius_checks;
            break;
        }
    }
    EXPECT_GT(radius_checks, points / 2);  // the premise: most points get a radius to test
}

template <class T>
void ranking_across_the_range(int lowest, int highest, int step, double offset_sizes) {
    const TriangleMesh unit = make_sphere(1);  // 80 triangles
    const std::size_t points = test::scaled(16, 8);
    std::uint64_t seed = 1;
    test::for_each_scale(lowest, highest, step, offset_sizes, [&](double scale, double offset) {
        check_ranking_at_scale<T>(unit, scale, offset, points, seed++);
    });
}

// Before: the float squares of a mesh 1e-25 across were all 0 and of one 1e20 across all inf, so
// every triangle tied (the lowest slots won) and a radius held all of them or none.
TEST(NearestScale, FloatKNearestAndRadiusAcrossTheRange) {
    ranking_across_the_range<float>(-30, 30, 5, 1e3);
}
TEST(NearestScale, DoubleKNearestAndRadiusAcrossTheRange) {
    ranking_across_the_range<double>(-300, 300, 50, 1e6);
}

/// The k nearest for points far from a unit sphere around the origin: ranked by the analytic
/// support (see the file's comment), within its slack e and the ranking bound.
template <class T>
void ranking_from_afar(std::initializer_list<double> distances) {
    const TriangleMesh unit = make_sphere(3);  // 1280 triangles
    const std::vector<Triangle<T>> tris = scaled_soup<T>(unit, 1.0, 0.0);
    const ClosestPointMesh<T> mesh(tris);
    NearestScratch<T> scratch;
    std::vector<MeshPoint<T>> got;
    test::Random rng(38);
    const std::size_t k = 8;
    for (const double d : distances) {
        SCOPED_TRACE("distance " + std::to_string(d));
        std::vector<Vec<double, 3>> dirs = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                            {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
        for (int i = 0; i < 20; ++i) dirs.push_back(rng.unit_vector<double>());
        for (const auto& u : dirs) {
            const Vec<T, 3> p(u * d);
            LD D = 0, R = 0;
            for (int c = 0; c < 3; ++c) D += LD(p[c]) * LD(p[c]);
            D = std::sqrt(D);
            const auto support = [&](const Triangle<T>& t) {
                LD h = -std::numeric_limits<LD>::infinity();
                for (const Vec<T, 3>* v : {&t.p0, &t.p1, &t.p2}) {
                    LD dot = 0, len2 = 0;
                    for (int c = 0; c < 3; ++c)
                        dot += LD(p[c]) * LD((*v)[c]), len2 += LD((*v)[c]) * LD((*v)[c]);
                    h = std::max(h, dot / D);
                    R = std::max(R, std::sqrt(len2));
                }
                return h;
            };
            std::vector<LD> h(tris.size());
            for (std::size_t f = 0; f < tris.size(); ++f) h[f] = support(tris[f]);
            std::vector<LD> sorted = h;
            std::sort(sorted.begin(), sorted.end(), std::greater<LD>());
            const LD eps_w = std::numeric_limits<AccurateScalar<T>>::epsilon();
            const LD tol =
                R * R / (D - R) + 64 * std::numeric_limits<LD>::epsilon() * R + 128 * eps_w * 4 * R;
            mesh.k_nearest(p, k, got, scratch);
            ASSERT_EQ(got.size(), k);
            for (std::size_t j = 0; j < k; ++j) {
                const LD hj = h[got[j].triangle];
                EXPECT_GE(hj, sorted[j] - 2 * tol) << "rank " << j << ": a farther triangle";
                if (j > 0) {
                    EXPECT_GE(h[got[j - 1].triangle], hj - 2 * tol) << "rank " << j;
                }
                ASSERT_TRUE(std::isfinite(got[j].distance));
                EXPECT_NEAR(LD(got[j].distance), D - hj,
                            4 * LD(std::numeric_limits<T>::epsilon()) * D + 2 * tol);
            }
            if (testing::Test::HasFailure()) return;
        }
    }
}

// Before: from 1e16 off a float unit sphere the float squares (1e32, an ulp of 1e25) tied, and
// the triangles came in slot order; past 1.8e19 they were inf.
TEST(NearestScale, FloatKNearestFromAfar) {
    ranking_from_afar<float>({1e4, 1e8, 1e12, 1e16, 1e20, 1e25, 1e30, 1e35, 3e38});
}
TEST(NearestScale, DoubleKNearestFromAfar) {
    ranking_from_afar<double>({1e8, 1e16, 1e50, 1e150, 1e154, 1e200, 1e250, 1e300});
}

/// The generic walks over a tree of points with a key wider than T: points (i s, 0, 0) for
/// i = 1..n, shuffled, queried from the origin, so that the i-th nearest is i s away and a
/// radius (m + 1/2) s holds exactly the first m.
template <class T>
void points_on_a_line(double scale) {
    using W = AccurateScalar<T>;
    const std::uint32_t n = 200;
    std::vector<Vec<T, 3>> pts;
    for (std::uint32_t i = 1; i <= n; ++i) pts.push_back({T(double(i) * scale), T(0), T(0)});
    test::Random rng(7);
    for (std::uint32_t i = n - 1; i > 0; --i) std::swap(pts[i], pts[rng.below(i + 1)]);
    std::vector<Aabb<T, 3>> boxes;
    for (const auto& q : pts) boxes.push_back({q, q});
    const Bvh<Aabb<T, 3>> bvh = build_bvh<T, 3>(boxes, pts);
    // The squared distance in W (exact for float): increasing with i, however large or small.
    const auto key = [&](std::uint32_t slot, const Vec<T, 3>& p, W) {
        const Vec<T, 3>& q = pts[bvh.primitive_indices[slot]];
        W d2 = 0;
        for (int c = 0; c < 3; ++c) d2 += (W(q[c]) - W(p[c])) * (W(q[c]) - W(p[c]));
        return d2;
    };
    const Vec<T, 3> origin(T(0));
    NearestScratch<T> scratch;
    std::vector<std::pair<W, std::uint32_t>> near;
    k_nearest(bvh, origin, 10, key, scratch, near);
    ASSERT_EQ(near.size(), 10u);
    for (std::uint32_t j = 0; j < 10; ++j)
        EXPECT_EQ(pts[bvh.primitive_indices[near[j].second]][0], T(double(j + 1) * scale))
            << "rank " << j;
    for (const std::uint32_t m : {0u, 1u, 7u, 150u}) {
        std::set<T> found;
        within_radius(bvh, origin, T((m + 0.5) * scale), key, [&](LeafSlot s, W) {
            found.insert(pts[bvh.primitive_indices[s.value]][0]);
            return true;
        });
        EXPECT_EQ(found.size(), m) << "radius " << m << ".5";
        if (m > 0) {
            EXPECT_EQ(*found.rbegin(), T(double(m) * scale));
        }
    }
}

TEST(NearestScale, TreeOfPointsWithAWideKey) {
    for (const double s : {1e-30, 1e-20, 1.0, 1e20, 1e30, 1e36}) {
        SCOPED_TRACE("float scale " + std::to_string(s));
        points_on_a_line<float>(s);
    }
    for (const double s : {1e-300, 1e-160, 1.0, 1e160, 1e300}) {
        SCOPED_TRACE("double scale " + std::to_string(s));
        points_on_a_line<double>(s);
    }
}

}  // namespace
}  // namespace bvhkit

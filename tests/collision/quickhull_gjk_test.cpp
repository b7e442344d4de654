// Quickhull and GJK, the parts of the convex-hull volume, against references that share none of
// their arithmetic: Quickhull's vertices against exact support values (floating-point expansions)
// along many directions; GJK's point-to-hull distance against a long-double nearest point over
// every triangle of the point set, and exact inside tests. Hard point sets in every test: cube
// grids (many coplanar and collinear points), flat and collinear sets, slivers, needles, points far
// from the origin, tiny and huge scales.
#include <gtest/gtest.h>

#include "hull_references.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

TEST(Quickhull, HullVerticesHoldEveryPointExactly) {
    SplitMix64 rng(5);
    // A cube grid: 8 corners, everything else on faces, edges or inside.
    {
        const Points g = sorted_unique(cube_grid(6, Vec3f(0.0f), 1.0f));
        const auto h = quickhull_vertices<float>(g);
        EXPECT_EQ(h.size(), 8u);
        expect_supports_match(g, h, rng, "grid");
    }
    // Far from the origin (1e6 offsets, unit spacing: float steps of 1/16) and tiny.
    for (float offset : {1e6f, -3e5f}) {
        const Points g = sorted_unique(cube_grid(5, Vec3f(offset, -offset, offset), 0.0625f * 16));
        expect_supports_match(g, quickhull_vertices<float>(g), rng, "far");
    }
    {
        const Points g = sorted_unique(cube_grid(4, Vec3f(1e-6f), 1e-7f));
        EXPECT_EQ(quickhull_vertices<float>(g).size(), 8u);
    }
    // Random clouds (inside a ball, on a sphere), random sizes, huge and tiny scales.
    for (int trial = 0; trial < int(scaled(60, 10)); ++trial) {
        const double scale = std::pow(10.0, rng.uniform(-6, 6));
        const bool on_sphere = trial % 2 == 0;
        Points p;
        const std::size_t n = 4 + rng.below(400);
        for (std::size_t i = 0; i < n; ++i) {
            Vec3d q(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            if (on_sphere) q = normalize(q);
            p.push_back(Vec3f(q * scale));
        }
        const Points s = sorted_unique(p);
        const auto h = quickhull_vertices<float>(s);
        expect_supports_match(s, h, rng, on_sphere ? "sphere" : "ball");
        if (on_sphere) {
            EXPECT_GE(h.size(), s.size() * 9 / 10) << "almost all are vertices";
        }
    }
}

TEST(Quickhull, FlatAndThinSets) {
    SplitMix64 rng(6);
    // Coplanar points in a tilted plane: a 2D hull.
    Points flat;
    const Vec3f u(1, 2, 0.5f), v(-0.25f, 0.5f, 3);
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) flat.push_back(u * float(i) + v * float(j));
    flat = sorted_unique(flat);
    const auto hf = quickhull_vertices<float>(flat);
    EXPECT_EQ(hf.size(), 4u);
    expect_supports_match(flat, hf, rng, "flat");
    // Collinear: the two ends.
    Points line;
    for (int i = 0; i < 30; ++i) line.push_back(Vec3f(1, -2, 3) * float(i) + Vec3f(7, 7, 7));
    line = sorted_unique(line);
    const auto hl = quickhull_vertices<float>(line);
    EXPECT_EQ(hl.size(), 2u);
    expect_supports_match(line, hl, rng, "line");
    // A needle and a sliver: nearly collinear and nearly coplanar sets.
    Points needle, sliver;
    for (int i = 0; i < 200; ++i) {
        const float t = float(rng.uniform(0, 1000));
        needle.push_back(
            Vec3f(t, t * 1e-6f * float(rng.uniform(-1, 1)), float(rng.uniform(0, 1e-3))));
        sliver.push_back(Vec3f(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)),
                               float(rng.uniform(-1e-6, 1e-6))));
    }
    needle = sorted_unique(needle);
    sliver = sorted_unique(sliver);
    expect_supports_match(needle, quickhull_vertices<float>(needle), rng, "needle");
    expect_supports_match(sliver, quickhull_vertices<float>(sliver), rng, "sliver");
    // Few points.
    for (std::size_t n = 1; n <= 4; ++n) {
        Points p(sliver.begin(), sliver.begin() + n);
        EXPECT_EQ(quickhull_vertices<float>(p).size(), n);
    }
}

TEST(Quickhull, CollinearPickFromRoundingIsCheckedExactly) {
    // a, c, b exactly on one line through (1, 3, 5), but the differences from a round
    // differently per coordinate, so their rounded cross product is not zero and c (on the line)
    // beat f (off it by one ulp in x) as the third corner: every orientation was zero, the set
    // "flat", and the planar hull dropped f.
    const double t0 = 1.5 * 0x1p-52;
    const Vec3d d(1, 3, 5);
    for (double dev : {0x1p-53, 0x1p-54}) {
        Vec3d f = d * 0.25;
        f[0] += dev;
        std::vector<Vec3d> p{d * -t0, f, d * 0.5, d};
        p = hull_detail::sorted_unique(std::move(p));
        const auto h = quickhull_vertices<double>(p);
        std::vector<Vec3d> kept;
        for (std::uint32_t i : h) kept.push_back(p[i]);
        EXPECT_EQ(h.size(), 3u);
        EXPECT_NE(std::find(kept.begin(), kept.end(), f), kept.end()) << "dev " << dev;
    }
}

TEST(Gjk, PointToHullIsAnUpperBoundAndTight) {
    SplitMix64 rng(8);
    for (int trial = 0; trial < int(scaled(400, 40)); ++trial) {
        const std::size_t n = 1 + rng.below(9);
        const double scale = std::pow(10.0, rng.uniform(-4, 4));
        const Vec3d offset = trial % 3 == 0 ? Vec3d(1e4, -2e4, 3e3) * scale : Vec3d(0.0);
        std::vector<Vec3d> s;
        for (std::size_t i = 0; i < n; ++i) {
            Vec3d q(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            if (trial % 4 == 1) q[2] *= 1e-7;  // a sliver
            s.push_back(offset + q * scale);
        }
        Vec3d p =
            offset + Vec3d(rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3)) * scale;
        if (trial % 5 == 2) {  // the centroid: inside (or on a flat set)
            p = Vec3d(0.0);
            for (const Vec3d& q : s) p = p + q * (1.0 / double(n));
        }
        // The hull's boundary is covered by the triangles of its points, and every such triangle
        // lies in the hull: for p outside, the least triangle distance is the distance.
        long double brute = std::numeric_limits<long double>::infinity();
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = i; j < n; ++j)
                for (std::size_t k = j; k < n; ++k)
                    brute = std::min(brute, point_triangle(p, s[i], s[j], s[k]));
        const double got = hull_detail::distance_to_hull<double>(p, s);
        const double tol = 1e-9 * (length(offset) + scale);
        if (inside_some_tetrahedron(p, s)) {
            ASSERT_LE(got, tol) << "trial " << trial;
            continue;
        }
        // Outside: the least triangle distance is the distance, and GJK may only be above it.
        ASSERT_GE(got, double(brute) * (1 - 1e-9) - tol) << "trial " << trial;
        ASSERT_NEAR(got, double(brute), 1e-6 * double(brute) + tol) << "trial " << trial;
    }
}

// Points inside the hull (convex combinations, and the vertices of noisy spheres' nodes) are at
// distance zero up to rounding: GJK must not stop at a worse step (rounding once made it cycle
// between a face and an edge and report the edge's distance).
TEST(Gjk, InteriorPointsAreAtZero) {
    SplitMix64 rng(21);
    for (int trial = 0; trial < int(scaled(300, 30)); ++trial) {
        std::vector<Vec3f> s;
        const std::size_t n = 4 + rng.below(16);
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3d r(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            s.push_back(Vec3f(normalize(r) * (1 + 0.01 * rng.uniform(-1, 1))));
        }
        for (int k = 0; k < 20; ++k) {
            Vec3d p(0.0);
            double total = 0;
            for (const Vec3f& q : s) {
                const double w = rng.uniform(0, 1);
                p = p + Vec3d(q) * w;
                total += w;
            }
            const Vec3f pf(p * (1 / total));
            ASSERT_LE(hull_detail::distance_to_hull<float>(pf, s), 1e-6) << "trial " << trial;
        }
    }
}

TEST(Gjk, RoundedInsideTestIsCheckedExactly) {
    // Random slivers in double, the point just outside: GJK's rounded face tests put the origin
    // inside the tetrahedron and distance_to_hull returned its pad (2.3e-12, 1.9e-13) though the
    // point lies outside a face by at least the distances below (found with rational arithmetic:
    // the largest signed distance to a facet plane, a lower bound of the distance).
    struct Case {
        Vec3d q;
        std::vector<Vec3d> s;
        double at_least;
    };
    const std::vector<Case> cases{
        {{79.520782037245937, -29.592916531077492, 13.230815542446948},
         {{335.71405244148036, 74.160405537921832, 80.359631830553894},
          {-557.62647497680837, -287.628919906222, -153.71898106139378},
          {147.3429943665366, -2.1164516061711964, 31.00677877808166},
          {57.737806595652984, -102.1094081109344, 143.7154004062171}},
         9.36e-11},
        {{16.395144804189275, -14.991500562597004, -46.66923102651883},
         {{15.753780003919671, -15.475764813852713, -45.420452945014823},
          {17.023049503455688, -14.517399185594087, -47.891801739198961},
          {16.205397699734696, -15.134770629588875, -46.299779909061421},
          {17.340315307454468, -13.935647831356603, -47.336503841886085}},
         2.16e-12},
    };
    for (const Case& c : cases)
        EXPECT_GE(hull_detail::distance_to_hull<double>(c.q, c.s), c.at_least);
}

}  // namespace
}  // namespace bvhkit::test

// The convex-hull volume and its parts, against references that share none of their arithmetic:
// Quickhull's vertices against exact support values (floating-point expansions) along many
// directions; GJK's point-to-hull distance against a long-double nearest point over every triangle
// of the point set; the capped volume's containment of every vertex it was fitted to. Hard point
// sets in every test: cube grids (many coplanar and collinear points), flat and collinear sets,
// slivers, points far from the origin, tiny and huge scales.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/math/predicates.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/collision_model.hpp"
#include "bvhkit/volumes/convex_hull.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

using Points = std::vector<Vec3f>;

/// Sign of d.p - d.q, exactly: each term d_i (p_i - q_i) as a floating-point expansion.
int compare_along(const Vec3d& d, const Vec3f& p, const Vec3f& q) {
    exact::Expansion<4> t[3];
    for (int i = 0; i < 3; ++i) exact::scale(exact::difference(p[i], q[i]), d[i], t[i]);
    exact::Expansion<8> two;
    exact::sum(t[0], t[1], two);
    exact::Expansion<12> all;
    exact::sum(two, t[2], all);
    return exact::sign(all);
}

/// Every direction's extreme point of the whole set is matched by a hull vertex, exactly.
void expect_supports_match(const Points& sorted, const std::vector<std::uint32_t>& hull,
                           SplitMix64& rng, const char* what) {
    ASSERT_FALSE(hull.empty()) << what;
    for (int k = 0; k < 200; ++k) {
        Vec3d d;
        for (int i = 0; i < 3; ++i) d[i] = rng.uniform(-1, 1);
        if (k < 6) {  // the axes first
            d = Vec3d(0.0);
            d[k % 3] = k < 3 ? 1 : -1;
        }
        Vec3f all = sorted[0], kept = sorted[hull[0]];
        for (const Vec3f& p : sorted)
            if (compare_along(d, p, all) > 0) all = p;
        for (std::uint32_t i : hull)
            if (compare_along(d, sorted[i], kept) > 0) kept = sorted[i];
        ASSERT_EQ(compare_along(d, all, kept), 0) << what << ": direction " << k;
    }
}

Points sorted_unique(Points p) {
    return hull_detail::sorted_unique(std::move(p));
}

Points cube_grid(int n, Vec3f origin, float step) {
    Points p;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k)
                p.push_back(origin + Vec3f(float(i), float(j), float(k)) * step);
    return p;
}

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

/// Distance from p to triangle (a, b, c) in long double, by the plane when p projects inside and
/// by the three edges otherwise.
long double point_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    using L = long double;
    auto seg = [&](const Vec3d& s, const Vec3d& e) {
        L t = 0, len2 = 0;
        for (int i = 0; i < 3; ++i) {
            t += (L(p[i]) - s[i]) * (L(e[i]) - s[i]);
            len2 += (L(e[i]) - s[i]) * (L(e[i]) - s[i]);
        }
        t = len2 > 0 ? std::clamp(t / len2, L(0), L(1)) : L(0);
        L d2 = 0;
        for (int i = 0; i < 3; ++i) {
            const L x = L(s[i]) + t * (L(e[i]) - s[i]) - p[i];
            d2 += x * x;
        }
        return std::sqrt(d2);
    };
    L best = std::min({seg(a, b), seg(b, c), seg(c, a)});
    L ab[3], ac[3], ap[3], n[3];
    for (int i = 0; i < 3; ++i) {
        ab[i] = L(b[i]) - a[i];
        ac[i] = L(c[i]) - a[i];
        ap[i] = L(p[i]) - a[i];
    }
    n[0] = ab[1] * ac[2] - ab[2] * ac[1];
    n[1] = ab[2] * ac[0] - ab[0] * ac[2];
    n[2] = ab[0] * ac[1] - ab[1] * ac[0];
    const L n2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (n2 > 0) {
        // Barycentrics of the projection, by the sub-triangle normals.
        auto side = [&](const L* e0, const L* e1) {
            const L m[3] = {e0[1] * e1[2] - e0[2] * e1[1], e0[2] * e1[0] - e0[0] * e1[2],
                            e0[0] * e1[1] - e0[1] * e1[0]};
            return m[0] * n[0] + m[1] * n[1] + m[2] * n[2];
        };
        L bp[3], bc[3], cp[3], ca[3];
        for (int i = 0; i < 3; ++i) {
            bp[i] = L(p[i]) - b[i];
            bc[i] = L(c[i]) - b[i];
            cp[i] = L(p[i]) - c[i];
            ca[i] = L(a[i]) - c[i];
        }
        if (side(ab, ap) >= 0 && side(bc, bp) >= 0 && side(ca, cp) >= 0)
            best = std::min(best,
                            std::fabs(ap[0] * n[0] + ap[1] * n[1] + ap[2] * n[2]) / std::sqrt(n2));
    }
    return best;
}

/// p lies in the hull of s when it lies in a tetrahedron of four of its points (Caratheodory),
/// decided by exact orientations.
bool inside_some_tetrahedron(const Vec3d& p, const std::vector<Vec3d>& s) {
    const std::size_t n = s.size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
            for (std::size_t k = j + 1; k < n; ++k)
                for (std::size_t l = k + 1; l < n; ++l) {
                    const Vec3d c[4] = {s[i], s[j], s[k], s[l]};
                    const int whole = orient3d_sign(c[0], c[1], c[2], c[3]);
                    if (whole == 0) continue;
                    bool in = true;
                    for (int f = 0; f < 4 && in; ++f) {
                        Vec3d q[4] = {c[0], c[1], c[2], c[3]};
                        q[f] = p;  // p in place of one corner: same orientation or flat
                        const int o = orient3d_sign(q[0], q[1], q[2], q[3]);
                        in = o == 0 || o == whole;
                    }
                    if (in) return true;
                }
    return false;
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

TEST(ConvexHullVolume, NoisySphereNodesHoldTheirVerticesByGjk) {
    TriangleMesh m = make_sphere(3);
    SplitMix64 rng(3);
    for (auto& v : m.vertices)
        v = v + Vec3f(float(rng.uniform(-0.01, 0.01)), float(rng.uniform(-0.01, 0.01)),
                      float(rng.uniform(-0.01, 0.01)));
    const CollisionModel<ConvexHull<float>> model(m);
    const auto& bvh = model.bvh();
    const auto runs = node_slot_runs(bvh);
    const auto tris = model.slot_triangles();
    const double tol = 16 * double(std::numeric_limits<float>::epsilon()) * model.scale();
    for (std::size_t n = 0; n < bvh.nodes.size(); ++n) {
        const auto& v = bvh.nodes[n].bounds;
        for (std::uint32_t t = runs[n].first; t < runs[n].second; ++t)
            for (const Vec3f& p : {tris[t].p0, tris[t].p1, tris[t].p2})
                ASSERT_LE(hull_detail::distance_to_hull<float>(p, v.vertices()), v.margin + tol)
                    << "node " << n;
    }
}

/// Along many directions (the axes, the cube's diagonals, random ones), no point reaches past the
/// volume: d.p <= max over the kept vertices of d.q + margin, in long double with a margin far
/// below the volume's own rounding allowance.
void expect_covers(const ConvexHull<float, 16>& v, const Points& points, SplitMix64& rng,
                   const std::string& what) {
    using L = long double;
    auto along = [](const Vec3d& d, const Vec3f& p) {
        return L(d[0]) * p[0] + L(d[1]) * p[1] + L(d[2]) * p[2];
    };
    for (int k = 0; k < 100; ++k) {
        Vec3d d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        if (k < 26) d = Vec3d(double(k % 3) - 1, double(k / 3 % 3) - 1, double(k / 9 % 3) - 1);
        if (length(d) == 0) continue;
        d = normalize(d);
        L core = -std::numeric_limits<L>::infinity(), all = core, size = 0;
        for (const Vec3f& q : v.vertices()) core = std::max(core, along(d, q));
        for (const Vec3f& p : points) {
            all = std::max(all, along(d, p));
            size = std::max(size, L(length(Vec3d(p))));
        }
        ASSERT_LE(all, core + v.margin + 1e-12L * size) << what << ": direction " << k;
    }
}

TEST(ConvexHullVolume, EveryNodeCoversItsVertices) {
    BVHKIT_REQUIRE_MESH(path, "suzanne.obj");
    SplitMix64 rng(10);
    const auto m = read_mesh(path);
    const CollisionModel<ConvexHull<float, 16>> model(m);
    const auto& bvh = model.bvh();
    const auto runs = node_slot_runs(bvh);
    const auto tris = model.slot_triangles();
    std::size_t capped = 0;
    for (std::size_t n = 0; n < bvh.nodes.size(); n += (n < 64 ? 1 : 5)) {
        const auto& v = bvh.nodes[n].bounds;
        ASSERT_GE(v.count, 1u);
        ASSERT_LE(v.count, 16u);
        capped += v.margin > 0;
        Points points;
        for (std::uint32_t t = runs[n].first; t < runs[n].second; ++t)
            points.insert(points.end(), {tris[t].p0, tris[t].p1, tris[t].p2});
        expect_covers(v, points, rng, "node " + std::to_string(n));
        if (points.size() <= 16) {
            EXPECT_EQ(v.margin, 0.0f) << "small nodes are exact";
        }
    }
    EXPECT_GT(capped, 0u) << "the large nodes need the swept margin";
}

TEST(ConvexHullVolume, HardPointSetsAreCovered) {
    SplitMix64 rng(12);
    std::vector<std::pair<std::string, Points>> sets;
    sets.push_back({"grid far away", cube_grid(7, Vec3f(1e5f, -1e5f, 3e4f), 0.5f)});
    sets.push_back({"tiny grid", cube_grid(5, Vec3f(0.0f), 1e-6f)});
    sets.push_back({"huge grid", cube_grid(5, Vec3f(0.0f), 1e6f)});
    Points sphere, sliver, needle, flat;
    for (int i = 0; i < 500; ++i) {
        const Vec3d r(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        sphere.push_back(Vec3f(normalize(r) * 3.0));
        sliver.push_back(Vec3f(float(r[0]), float(r[1] * 1e-5), float(r[2])));
        needle.push_back(Vec3f(float(r[0] * 1e3), float(r[1] * 1e-4), float(r[2] * 1e-4)));
        flat.push_back(Vec3f(float(r[0]), float(r[1]), float(r[0] + r[1])));
    }
    sets.push_back({"sphere", sphere});
    sets.push_back({"sliver", sliver});
    sets.push_back({"needle", needle});
    sets.push_back({"flat", flat});
    for (const auto& [name, raw] : sets) {
        const Points s = sorted_unique(raw);
        const auto v = hull_detail::hull_of<float, 16>(s, 0.0);
        EXPECT_LE(v.count, 16u);
        expect_covers(v, s, rng, name);
        // The bounding sphere holds everything too.
        for (const Vec3f& p : s) ASSERT_LE(length(p - v.center), v.reach) << name;
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

TEST(ConvexHullVolume, NonFinitePointsAreLeftOut) {
    // merge() and fit() on points holding NaN or infinity: the sort and the exact predicates
    // need finite input (a NaN once overflowed a stack buffer in orient3d's expansions).
    using Tr = VolumeTraits<ConvexHull<float, 16>>;
    EXPECT_TRUE(Tr::fit(std::span<const Triangle<float>>{}).is_empty());
    SplitMix64 rng(4);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (int trial = 0; trial < 50; ++trial) {
        ConvexHull<float, 16> a, b;
        a.count = b.count = 16;
        Points finite;
        for (std::size_t i = 0; i < 16; ++i) {
            a.points[i] = Vec3f(rng.unit_vector());
            b.points[i] = Vec3f(rng.unit_vector());
            finite.push_back(b.points[i]);
            if (rng.below(3) == 0)
                a.points[i][rng.below(3)] =
                    rng.below(2) ? nan : std::numeric_limits<float>::infinity();
            else
                finite.push_back(a.points[i]);
        }
        const auto m = Tr::merge(a, b);
        ASSERT_GE(m.count, 1u);
        for (const Vec3f& p : m.vertices()) ASSERT_TRUE(std::isfinite(length(p)));
        expect_covers(m, finite, rng, "merge with non-finite points");
    }
}

/// A lower bound of the distance from p to conv(s): the largest signed distance to a plane of a
/// facet of conv(s) (facets found exactly; the plane's distance in long double, less a bound on
/// its rounding).
template <class T>
long double facet_distance_lower_bound(const Vec<T, 3>& p, std::span<const Vec<T, 3>> s) {
    using L = long double;
    using VL = Vec<L, 3>;
    auto to_l = [](const Vec<T, 3>& x) { return VL(L(x[0]), L(x[1]), L(x[2])); };
    L best = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
        for (std::size_t j = i + 1; j < s.size(); ++j)
            for (std::size_t k = j + 1; k < s.size(); ++k) {
                int above = 0, below = 0;
                for (const auto& x : s) {
                    const int o = orient3d_sign(s[i], s[j], s[k], x);
                    above += o > 0;
                    below += o < 0;
                }
                if (above && below) continue;
                const VL e1 = to_l(s[j]) - to_l(s[i]), e2 = to_l(s[k]) - to_l(s[i]);
                const VL dp = to_l(p) - to_l(s[i]), n = cross(e1, e2);
                const L len = length(n);
                if (!(len > 0)) continue;
                const L err =
                    8e-19L * length(e1) * length(e2) * length(dp) / len + 8e-19L * length(dp);
                L h = dot(n, dp) / len;
                h = !above && !below ? std::fabs(h) : above ? -h : h;
                best = std::max(best, h - err);
            }
    return best;
}

TEST(ConvexHullVolume, NeedleFacesAreCoveredInDouble) {
    // A tetrahedron with a needle-thin face and points just outside that face: all hull vertices,
    // so a capped volume drops some and its margin comes from distance_to_hull, whose rounded
    // "inside" once made the margin 9e-15 for a point 6.5e-11 outside the kept hull.
    SplitMix64 rng(1);
    for (int trial = 0, trials = int(scaled(4000)); trial < trials; ++trial) {
        const Vec3d ax = rng.unit_vector(), by = rng.unit_vector();
        const Vec3d o = rng.unit_vector() * std::pow(10.0, rng.uniform(0, 3));
        const Vec3d b2 = normalize(cross(ax, by)), b3 = normalize(cross(ax, b2));
        const double scale = std::pow(10.0, rng.uniform(-2, 3));
        const double thin = std::pow(10.0, rng.uniform(-14, -4));
        std::vector<Vec3d> p{
            ax * -1.0, ax, ax * rng.uniform(-1, 1) + b2 * thin,
            b3 * rng.uniform(-1, 1) + ax * rng.uniform(-1, 1) + b2 * rng.uniform(-1, 1) * 1e-3};
        Vec3d n = normalize(cross(p[1] - p[0], p[2] - p[0]));
        if (dot(n, p[3] - p[0]) > 0) n = -n;
        for (int k = 0, extra = 1 + int(rng.below(8)); k < extra; ++k) {
            const Vec3d f =
                (p[0] * rng.uniform(0, 1) + p[1] * rng.uniform(0, 1)) * 0.5 + p[2] * 0.1;
            p.push_back(f + n * std::pow(10.0, rng.uniform(-15, -8)));
        }
        for (Vec3d& x : p) x = x * scale + o;
        p = hull_detail::sorted_unique(std::move(p));
        const auto v = hull_detail::hull_of<double, 4>(p, 0.0);
        for (const Vec3d& x : p)
            ASSERT_LE(facet_distance_lower_bound<double>(x, v.vertices()), (long double)v.margin)
                << "trial " << trial;
    }
}

/// B placed so that its support point along -n is `target` from A's support point along n:
/// the cores' distance is then exactly that of those two points (the planes through them
/// perpendicular to n separate the cores), computed here in long double from the pose as
/// rounded to T. Whenever it is within the margins and slack, the volumes meet: overlaps() must
/// say so, and distance_lower_bound must not exceed it less the margins.
template <class T, std::size_t Cap>
void touching_poses(SplitMix64& rng, int trials, int& met) {
    using Tr = VolumeTraits<ConvexHull<T, Cap>>;
    using L = long double;
    using VL = Vec<L, 3>;
    auto to_l = [](const Vec<T, 3>& x) { return VL(L(x[0]), L(x[1]), L(x[2])); };
    auto random_set = [&](int kind) {
        double off = 0, sc = 1;
        const int o = int(rng.below(4)), s = int(rng.below(3));
        off = o == 1 ? 1e5 : o == 2 ? 3e6 : o == 3 ? -1e7 : 0;
        sc = s == 1 ? 1e-6 : s == 2 && o == 0 ? 1e6 : 1;
        const Vec3d ax = rng.unit_vector(), by = normalize(cross(ax, rng.unit_vector()));
        std::vector<Triangle<T>> tris;
        const int n = 1 + int(rng.below(rng.below(2) ? 12 : 120));
        std::vector<Vec<T, 3>> p;
        for (int i = 0; i < n; ++i) {
            const Vec3d r(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            Vec3d q = r;
            if (kind == 1) q = normalize(r);
            if (kind == 2) q = Vec3d(r[0], r[1] * 1e-5, r[2]);
            if (kind == 3) q = ax * r[0] + by * r[1];
            if (kind == 4) q = ax * r[0];
            if (kind == 5)
                q = Vec3d(std::floor(r[0] * 2), std::floor(r[1] * 2), std::floor(r[2] * 2));
            p.push_back(Vec<T, 3>(q * sc + Vec3d(off, -off * 0.5, off * 0.25)));
        }
        for (int i = 0; i < n; i += 3) tris.push_back({p[i], p[(i + 1) % n], p[(i + 2) % n]});
        return Tr::fit(tris);
    };
    for (int trial = 0; trial < trials; ++trial) {
        const auto a = random_set(int(rng.below(6))), b = random_set(int(rng.below(6)));
        const Vec3d q = rng.unit_vector();
        const double w = rng.uniform(-1, 1), qn = std::sqrt(w * w + 1);
        Transform<T> pose;
        pose.rotation =
            rotation_from_quaternion<T>(T(w / qn), T(q[0] / qn), T(q[1] / qn), T(q[2] / qn));
        auto rotated = [&](const Vec<T, 3>& x) {
            VL y;
            for (int i = 0; i < 3; ++i) y[i] = dot(to_l(pose.rotation.row[i]), to_l(x));
            return y;
        };
        Vec3d nd = rng.unit_vector();
        if (rng.below(4) == 0) nd = Vec3d(0.0), nd[rng.below(3)] = 1;  // face to face on grids
        const VL n{L(nd[0]), L(nd[1]), L(nd[2])};
        VL pa = to_l(a.points[0]), pb = rotated(b.points[0]);
        for (const auto& x : a.vertices())
            if (dot(n, to_l(x)) > dot(n, pa)) pa = to_l(x);
        for (const auto& x : b.vertices())
            if (dot(n, rotated(x)) < dot(n, pb)) pb = rotated(x);
        const T slack =
            rng.below(2) ? T(0) : T(std::pow(10.0, rng.uniform(-8, 0)) * double(a.reach));
        const L inflate = L(a.margin) + L(b.margin) + L(slack);
        const L scale = length(pa) + length(pb) + L(a.reach) + L(b.reach);
        L target = inflate + L(std::numeric_limits<T>::epsilon()) * scale * L(rng.uniform(-64, 64));
        if (target < 0) target = -target * L(0.1);
        const VL t = pa + n * target - pb;
        pose.translation = Vec<T, 3>(T(t[0]), T(t[1]), T(t[2]));
        const L gap = length(pb + to_l(pose.translation) - pa) * (1 + 1e-17L) + 1e-18L * scale;
        const auto prepared = Tr::prepare(pose, slack);
        if (gap <= inflate) {
            ++met;
            ASSERT_TRUE(Tr::overlaps(a, b, prepared))
                << "trial " << trial << ": gap " << double(gap) << " within " << double(inflate);
        }
        ASSERT_LE(L(Tr::distance_lower_bound(a, b, prepared)), std::max(L(0), gap - inflate))
            << "trial " << trial;
    }
}

TEST(ConvexHullVolume, TouchingPosesAreNeverApart) {
    SplitMix64 rng(21);
    const int trials = int(scaled(400, 5));
    int met = 0;
    touching_poses<float, 4>(rng, trials, met);
    touching_poses<float, 8>(rng, trials, met);
    touching_poses<float, 16>(rng, trials, met);
    touching_poses<float, 32>(rng, trials / 2, met);
    touching_poses<double, 4>(rng, trials, met);
    touching_poses<double, 16>(rng, trials, met);
    EXPECT_GT(met, 0) << "no pose within the margins: the test tests nothing";
}

}  // namespace
}  // namespace bvhkit::test

// The spatial-split build (build/spatial_splits.hpp): its clipping judged against crossings
// computed in long double; its trees checked for shape and for covering every point of every
// triangle with a leaf that names it; its rays against brute force over all triangles; bad input
// and options.
#include <gtest/gtest.h>

#include <map>

#include "bvhkit/build/spatial_splits.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

using L = long double;
using LPoint = Vec<L, 3>;

/// Whether the double box holds the long double point (compared in long double).
bool holds(const Aabb<double, 3>& box, const LPoint& p) {
    for (std::size_t a = 0; a < 3; ++a)
        if (!(L(box.min[a]) <= p[a] && p[a] <= L(box.max[a]))) return false;
    return true;
}

template <class T>
bool holds(const Aabb<T, 3>& box, const LPoint& p) {
    for (std::size_t a = 0; a < 3; ++a)
        if (!(L(box.min[a]) <= p[a] && p[a] <= L(box.max[a]))) return false;
    return true;
}

/// A triangle of hard shape at `scale` around `offset`: ordinary, needle, sliver or nearly flat.
std::array<Vec<double, 3>, 3> hard_triangle(test::Random& rng, double scale, double offset) {
    std::array<Vec<double, 3>, 3> v;
    for (auto& p : v)
        for (std::size_t a = 0; a < 3; ++a) p[a] = rng.uniform(-1, 1);
    const double thin = std::pow(10.0, rng.uniform(-7, -1));
    switch (rng.below(4)) {
        case 1:  // needle: the third corner near the first
            v[2] = v[0] + (v[2] - v[0]) * thin;
            break;
        case 2:  // sliver: the third corner near the middle of the first edge
            v[2] = (v[0] + v[1]) * 0.5 + (v[2] - v[0]) * thin;
            break;
        case 3:  // nearly flat in z
            for (auto& p : v) p[2] = v[0][2] + (p[2] - v[0][2]) * thin;
            break;
        default:
            break;
    }
    for (auto& p : v)
        for (std::size_t a = 0; a < 3; ++a) p[a] = float(p[a] * scale + offset);  // float corners
    return v;
}

TEST(SpatialSplits, ClipHoldsEveryCrossingComputedInLongDouble) {
    test::Random rng(7);
    std::size_t crossings = 0;
    for (const auto& [scale, offset] :
         {std::pair{1.0, 0.0}, std::pair{1e-6, 0.0}, std::pair{1e6, 0.0}, std::pair{1.0, 1e5},
          std::pair{1e-3, 1e6}, std::pair{1e-30, 1e-28}, std::pair{1e30, 0.0}}) {
        for (std::size_t n = 0; n < test::scaled(20000, 10); ++n) {
            const auto tri = hard_triangle(rng, scale, offset);
            const spatial_detail::Point v[3] = {tri[0], tri[1], tri[2]};
            Aabb<double, 3> whole;
            for (const auto& p : v) whole.grow(p);
            // A reference box cut from the triangle's on one axis, and a slab on another.
            Aabb<double, 3> ref = whole;
            const std::size_t cut = rng.below(3), axis = rng.below(3);
            ref.min[cut] = whole.min[cut] + (whole.max[cut] - whole.min[cut]) * rng.uniform(0, 0.5);
            const double span = whole.max[axis] - whole.min[axis];
            double lo = whole.min[axis] + span * rng.uniform(-0.2, 1.0);
            double hi = lo + span * rng.uniform(0, 0.8);
            if (rng.below(4) == 0) lo = -std::numeric_limits<double>::infinity();
            if (rng.below(4) == 0) hi = std::numeric_limits<double>::infinity();
            const Aabb<double, 3> got = spatial_detail::clip_to_slab(v, ref, axis, lo, hi);
            // The extreme points of triangle, slab and ref box: corners and edge crossings with
            // the slab's planes, in long double; those inside the slab and the ref box must be
            // in the clipped box.
            std::vector<LPoint> points;
            for (int k = 0; k < 3; ++k) {
                const LPoint a{L(v[k][0]), L(v[k][1]), L(v[k][2])};
                const LPoint b{L(v[(k + 1) % 3][0]), L(v[(k + 1) % 3][1]), L(v[(k + 1) % 3][2])};
                points.push_back(a);
                for (const double q : {lo, hi}) {
                    if (!std::isfinite(q) ||
                        !((a[axis] < q && q < b[axis]) || (b[axis] < q && q < a[axis])))
                        continue;
                    const L t = (L(q) - a[axis]) / (b[axis] - a[axis]);
                    LPoint x;
                    for (std::size_t c = 0; c < 3; ++c) x[c] = a[c] + t * (b[c] - a[c]);
                    x[axis] = L(q);
                    points.push_back(x);
                    ++crossings;
                }
            }
            for (const LPoint& p : points) {
                if (!(p[axis] >= L(lo) && p[axis] <= L(hi))) continue;
                bool in_ref = true;
                for (std::size_t c = 0; c < 3; ++c)
                    in_ref = in_ref && L(ref.min[c]) <= p[c] && p[c] <= L(ref.max[c]);
                if (!in_ref) continue;
                ASSERT_TRUE(holds(got, p))
                    << "scale " << scale << " offset " << offset << " axis " << axis << " point "
                    << double(p[0]) << " " << double(p[1]) << " " << double(p[2]);
            }
            // Never larger than the ref box, and inside the slab.
            if (!got.is_empty()) {
                EXPECT_TRUE(ref.contains(got));
                EXPECT_GE(got.min[axis], lo);
                EXPECT_LE(got.max[axis], hi);
            }
        }
    }
    EXPECT_GT(crossings, test::scaled(20000, 10));  // the crossings were exercised
}

/// For every usable triangle: the leaves naming it, and points of it (corners, points on its edges
/// and inside it, in long double) each inside one of those leaves' boxes. Plus the shape, and every
/// node's box holding its children's.
template <class T>
void expect_covers(const Bvh<Aabb<T, 3>>& bvh, const std::vector<Triangle<T>>& tris,
                   const std::vector<std::uint32_t>& skipped, test::Random& rng) {
    const auto fail = [](const std::string& m) { throw Error(m); };
    std::map<std::uint32_t, std::vector<Aabb<T, 3>>> leaves_of;
    ASSERT_NO_THROW(check_structure(
        bvh, fail,
        [&](const auto& leaf, std::uint32_t s) {
            leaves_of[bvh.primitive_indices[s]].push_back(leaf.bounds);
        },
        [&](const auto& node, std::uint32_t c) {
            if (!node.bounds.contains(bvh.nodes[c].bounds)) fail("a child outside its parent");
        }));
    std::vector<char> is_skipped(tris.size(), 0);
    for (std::uint32_t s : skipped) is_skipped[s] = 1;
    for (std::uint32_t t = 0; t < tris.size(); ++t) {
        if (is_skipped[t]) {
            EXPECT_EQ(leaves_of.count(t), 0u);
            continue;
        }
        ASSERT_TRUE(leaves_of.count(t)) << "triangle " << t << " is in no leaf";
        const auto& boxes = leaves_of[t];
        const LPoint p[3] = {{L(tris[t].p0[0]), L(tris[t].p0[1]), L(tris[t].p0[2])},
                             {L(tris[t].p1[0]), L(tris[t].p1[1]), L(tris[t].p1[2])},
                             {L(tris[t].p2[0]), L(tris[t].p2[1]), L(tris[t].p2[2])}};
        for (int k = 0; k < 12; ++k) {
            L u = k < 3 ? L(k == 1) : L(rng.uniform()), w = k < 3 ? L(k == 2) : L(rng.uniform());
            if (k >= 3 && k < 6) w = 0;           // on the first edge
            if (k >= 6 && k < 9) w = 1 - u;       // on the second
            if (u + w > 1) u = 1 - u, w = 1 - w;  // inside
            // x's own rounding (long double) is far below T's and the boxes' padding; kept
            // inside the triangle's box, where the exact point lies.
            LPoint x;
            for (std::size_t a = 0; a < 3; ++a)
                x[a] = std::clamp(p[0][a] + u * (p[1][a] - p[0][a]) + w * (p[2][a] - p[0][a]),
                                  std::min({p[0][a], p[1][a], p[2][a]}),
                                  std::max({p[0][a], p[1][a], p[2][a]}));
            bool found = false;
            for (const auto& b : boxes) found = found || holds(b, x);
            ASSERT_TRUE(found) << "a point of triangle " << t << " lies in none of its "
                               << boxes.size() << " leaves";
        }
    }
}

template <class T>
class SpatialSplitTrees : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(SpatialSplitTrees, Scalars);

TYPED_TEST(SpatialSplitTrees, EveryPointOfEveryTriangleLiesInALeafThatNamesIt) {
    using T = TypeParam;
    test::Random rng(3);
    std::vector<std::pair<std::string, std::vector<Triangle<T>>>> cases;
    const TriangleMesh room = make_room(20, 2), soup = make_soup(3000, 5);
    for (const auto& [scale, offset] :
         {std::pair{1.0, 0.0}, std::pair{1e-6, 0.0}, std::pair{1.0, 1e5}, std::pair{1e6, 1e7}}) {
        cases.emplace_back("room", test::placed<T>(room, scale, offset));
        cases.emplace_back("soup", test::placed<T>(soup, scale, offset));
    }
    // Needles and slivers crossing each other, with a NaN triangle and a duplicate.
    std::vector<Triangle<T>> needles;
    for (int i = 0; i < 2000; ++i) {
        const auto v = hard_triangle(rng, 1.0, 0.0);
        needles.push_back({{T(v[0][0]), T(v[0][1]), T(v[0][2])},
                           {T(v[1][0]), T(v[1][1]), T(v[1][2])},
                           {T(v[2][0]), T(v[2][1]), T(v[2][2])}});
    }
    needles[5].p1[1] = std::numeric_limits<T>::quiet_NaN();
    needles.push_back(needles[7]);
    cases.emplace_back("needles", needles);
    for (const auto& [name, tris] : cases) {
        SCOPED_TRACE(name);
        for (const double alpha : {0.0, 1e-3}) {
            BuildOptions options;
            options.costs.leaf_block = 4;
            SpatialSplitOptions spatial;
            spatial.alpha = alpha;
            BuildReport report;
            const auto bvh = build_spatial_split_bvh<T>([&](std::size_t i) { return tris[i]; },
                                                        tris.size(), options, spatial, &report);
            // Spatial splits did happen (else this proves nothing), within the budget.
            const std::size_t usable = tris.size() - report.skipped.size();
            EXPECT_GT(bvh.primitive_indices.size(), usable);
            EXPECT_LE(bvh.primitive_indices.size(), 2 * usable);
            EXPECT_EQ(report.skipped.size(), name == "needles" ? 1u : 0u);
            expect_covers(bvh, tris, report.skipped, rng);
            if (testing::Test::HasFatalFailure()) return;
        }
    }
}

TEST(SpatialSplits, BudgetBoundsTheReferences) {
    const TriangleMesh soup = make_soup(5000, 9);
    const auto tris = test::placed<float>(soup, 1.0, 0.0);
    for (const double budget : {0.0, 0.1, 0.5}) {
        SpatialSplitOptions spatial;
        spatial.budget = budget;
        const auto bvh = build_spatial_split_bvh<float>([&](std::size_t i) { return tris[i]; },
                                                        tris.size(), BuildOptions{}, spatial);
        EXPECT_LE(bvh.primitive_indices.size(), tris.size() + std::size_t(budget * tris.size()));
        if (budget > 0) {
            EXPECT_GT(bvh.primitive_indices.size(), tris.size());
        }
    }
}

TEST(SpatialSplits, BudgetIsSharedAcrossTheTree) {
    // Depth first, a greedy build would spend a small budget in the first subtree it builds: each
    // half of the root must get its share.
    const TriangleMesh soup = make_soup(20000, 3);
    const auto tris = test::placed<float>(soup, 1.0, 0.0);
    SpatialSplitOptions spatial;
    spatial.budget = 0.02;
    const auto bvh = build_spatial_split_bvh<float>([&](std::size_t i) { return tris[i]; },
                                                    tris.size(), BuildOptions{}, spatial);
    ASSERT_FALSE(bvh.nodes.front().is_leaf());
    for (const std::uint32_t half : {bvh.nodes.front().left(), bvh.nodes.front().right()}) {
        std::size_t slots = 0;
        std::map<std::uint32_t, int> seen;
        std::vector<std::uint32_t> stack{half};
        while (!stack.empty()) {
            const auto& node = bvh.nodes[stack.back()];
            stack.pop_back();
            if (!node.is_leaf()) {
                stack.push_back(node.left());
                stack.push_back(node.right());
                continue;
            }
            for (std::uint32_t s = node.first; s < node.first + node.count; ++s, ++slots)
                ++seen[bvh.primitive_indices[s]];
        }
        // Extra references inside this half: slots beyond one per triangle.
        EXPECT_GT(slots - seen.size(), 0u) << "half " << half;
    }
}

/// Closest hit by brute force over every triangle, with the scalar watertight test: a reference
/// for the tree walk (which triangles the tree lets a ray reach), not for the triangle test.
template <class T>
Hit<T> brute_closest(const std::vector<Triangle<T>>& tris, const Ray<T, 3>& ray) {
    const WatertightRay<T> w(ray);
    Hit<T> best;
    T tmax = ray.tmax;
    for (std::uint32_t i = 0; i < tris.size(); ++i) {
        TriangleHit<T> h;
        if (intersect_watertight(w, tris[i].p0, tris[i].p1, tris[i].p2, ray.tmin, tmax, h)) {
            tmax = h.t;
            best = Hit<T>{h.t, i, h.u, h.v, tris[i].normal()};
        }
    }
    return best;
}

TYPED_TEST(SpatialSplitTrees, RaysEqualBruteForceOnEveryLayout) {
    using T = TypeParam;
    const TriangleMesh room = make_room(30, 4);
    for (const auto& [scale, offset] : {std::pair{1.0, 0.0}, std::pair{1.0, 1e5}}) {
        const auto tris = test::placed<T>(room, scale, offset);
        Aabb<T, 3> bounds;
        for (const auto& t : tris) bounds.grow(t.bounds());
        const auto rays = test::random_rays<T>(test::scaled(3000, 10), bounds, 21);
        for (const RayLayout layout : {RayLayout::Auto, RayLayout::Wide4, RayLayout::Binary}) {
            TriangleBvhOptions o;
            o.spatial_splits = true;
            o.ray_layout = layout;
            const TriangleBvh<T> bvh(tris, o);
            ASSERT_TRUE(bvh.has_split_references());
            std::size_t hits = 0;
            for (const auto& ray : rays) {
                const Hit<T> want = brute_closest(tris, ray), got = bvh.closest_hit(ray);
                ASSERT_EQ(bool(want), bool(got));
                EXPECT_EQ(bvh.any_hit(ray), bool(want));
                if (!want) continue;
                ++hits;
                EXPECT_EQ(got.t, want.t);
                // Tied hits (a ray through a shared edge) may name either triangle: t is compared.
                // all_hits names each triangle the ray meets once, however many leaves hold it.
                std::map<std::uint32_t, int> seen;
                bvh.all_hits(ray, [&](const Hit<T>& h) {
                    ++seen[h.primitive];
                    return true;
                });
                std::size_t expected = 0;
                const WatertightRay<T> w(ray);
                for (const auto& t : tris) {
                    TriangleHit<T> h;
                    expected +=
                        intersect_watertight(w, t.p0, t.p1, t.p2, ray.tmin, ray.tmax, h) ? 1 : 0;
                }
                EXPECT_EQ(seen.size(), expected);
                for (const auto& [tri, n] : seen) ASSERT_EQ(n, 1) << "triangle " << tri;
            }
            EXPECT_GT(hits, rays.size() / 2);
        }
    }
}

TEST(SpatialSplits, AutomaticWhereTheOverlapSaysAndRaysEqualBruteForce) {
    // A room and a soup overlap enough (spatial_split_choice.hpp), a sphere does not; far from the
    // origin too. The tree kept answers as brute force does.
    struct Case {
        TriangleMesh mesh;
        bool splits;
    };
    std::vector<Case> cases;
    cases.push_back({make_room(30, 4), true});
    cases.push_back({make_procedural("soup:n=3000,seed=3"), true});
    cases.push_back({make_procedural("sphere:subdiv=4"), false});
    for (const auto& [mesh, splits] : cases)
        for (const double offset : {0.0, 1e5}) {
            const auto tris = test::placed<float>(mesh, 1.0, offset);
            Aabb<float, 3> bounds;
            for (const auto& t : tris) bounds.grow(t.bounds());
            const auto rays = test::random_rays<float>(test::scaled(2000, 10), bounds, 22);
            TriangleBvhOptions o;
            o.auto_spatial_splits = true;
            const TriangleBvh<float> bvh(tris, o);
            EXPECT_EQ(bvh.has_split_references(), splits) << "offset " << offset;
            EXPECT_EQ(spatial_splits_pay(child_overlap(TriangleBvh<float>(tris).bvh())), splits);
            for (const auto& ray : rays) {
                const Hit<float> want = brute_closest(tris, ray), got = bvh.closest_hit(ray);
                ASSERT_EQ(bool(want), bool(got));
                EXPECT_EQ(bvh.any_hit(ray), bool(want));
                if (want) {
                    EXPECT_EQ(got.t, want.t);
                }
            }
            // Other builders and the optimizer keep the default build alone.
            o.builder = Builder::SweepSah;
            EXPECT_FALSE(TriangleBvh<float>(tris, o).has_split_references());
            o.builder = Builder::BinnedSah;
            o.optimize = true;
            EXPECT_FALSE(TriangleBvh<float>(tris, o).has_split_references());
        }
}

TEST(SpatialSplits, RefitKeepsRaysRight) {
    TriangleMesh mesh = make_room(20, 6);
    TriangleBvhOptions o;
    o.spatial_splits = true;
    TriangleBvh<float> bvh(mesh, o);
    ASSERT_TRUE(bvh.has_split_references());
    for (auto& v : mesh.vertices) v = v * 1.25f + Vec3f{0.5f, -0.25f, 2.0f};
    bvh.refit(mesh);
    const auto tris = test::placed<float>(mesh, 1.0, 0.0);
    const auto rays = test::random_rays<float>(test::scaled(4000, 10), mesh.bounds(), 5);
    for (const auto& ray : rays) {
        const Hit<float> want = brute_closest(tris, ray), got = bvh.closest_hit(ray);
        ASSERT_EQ(bool(want), bool(got));
        if (want) {
            EXPECT_EQ(got.t, want.t);
        }
    }
}

TEST(SpatialSplits, BadInputAndOptions) {
    const TriangleMesh mesh = make_room(5, 1);
    const auto build = [&](const TriangleBvhOptions& o) { return TriangleBvh<float>(mesh, o); };
    TriangleBvhOptions o;
    o.spatial_splits = true;
    for (const double alpha : {-1.0, std::nan(""), HUGE_VAL}) {
        auto x = o;
        x.spatial.alpha = alpha;
        EXPECT_THROW(build(x), Error);
    }
    for (const double budget : {-0.5, 4.5, std::nan("")}) {
        auto x = o;
        x.spatial.budget = budget;
        EXPECT_THROW(build(x), Error);
    }
    for (const std::uint32_t bins : {0u, 1u, 257u}) {
        auto x = o;
        x.spatial.bins = bins;
        EXPECT_THROW(build(x), Error);
    }
    {
        auto x = o;
        x.builder = Builder::Lbvh;
        EXPECT_THROW(build(x), Error);
        x = o;
        x.optimize = true;
        EXPECT_THROW(build(x), Error);
    }
    // Empty, one triangle, all degenerate, all NaN: trees that answer, no crash.
    const Ray3f ray{{0.1f, 0.2f, -5.0f}, {0.0f, 0.0f, 1.0f}};
    EXPECT_FALSE(TriangleBvh<float>(std::vector<Triangle<float>>{}, o).closest_hit(ray));
    const Triangle<float> one{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
    EXPECT_TRUE(TriangleBvh<float>(std::vector<Triangle<float>>{one}, o).closest_hit(ray));
    const Triangle<float> point{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
    EXPECT_FALSE(TriangleBvh<float>(std::vector<Triangle<float>>(50, point), o).closest_hit(ray));
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const TriangleBvh<float> nans(
        std::vector<Triangle<float>>(9, {{nan, 0, 0}, {1, 0, 0}, {0, 1, 0}}), o);
    EXPECT_EQ(nans.skipped().size(), 9u);
    EXPECT_FALSE(nans.closest_hit(ray));
    auto reject = o;
    reject.non_finite = NonFinitePolicy::Reject;
    EXPECT_THROW(TriangleBvh<float>(
                     std::vector<Triangle<float>>(2, {{nan, 0, 0}, {1, 0, 0}, {0, 1, 0}}), reject),
                 Error);
    // A tree with split triangles is not saved (its format holds each triangle once).
    const TriangleBvh<float> split = build(o);
    ASSERT_TRUE(split.has_split_references());
    EXPECT_THROW(to_bytes(split), Error);
}

}  // namespace

// The convex-hull volume: every node holds the vertices it was fitted to (by GJK distances, by
// support values along many directions in long double, and against exact facet planes), on meshes
// and hard point sets (far from the origin, tiny, huge, slivers, needles, NaN); and under poses
// where the volumes touch it never says "apart" nor bounds the distance above the truth.
#include <gtest/gtest.h>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/collision_model.hpp"
#include "hull_references.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

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

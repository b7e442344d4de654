// The 2D BSP over segments: split lengths, rays against a long-double brute force, visibility order
// along rays, inside/outside against a long-double winding number, degenerate input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "bvhkit/bsp/bsp.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit::test {
namespace {

using LD = long double;
using V2 = Vec<double, 2>;

// A star-shaped outline (counter-clockwise) with a round hole (clockwise): closed, outward edges.
std::vector<Segment<double>> star_with_hole(std::size_t n, std::uint64_t seed) {
    Random rng(seed);
    std::vector<Segment<double>> out;
    std::vector<V2> outer, inner;
    for (std::size_t i = 0; i < n; ++i) {
        const double a = 2 * std::numbers::pi * double(i) / double(n);
        const double r = 1 + 0.4 * std::sin(5 * a) + 0.05 * rng.uniform();
        outer.push_back({r * std::cos(a), r * std::sin(a)});
        inner.push_back({0.25 * std::cos(-a), 0.25 * std::sin(-a)});
    }
    for (std::size_t i = 0; i < n; ++i) out.push_back({outer[i], outer[(i + 1) % n]});
    for (std::size_t i = 0; i < n / 4; ++i) out.push_back({inner[4 * i], inner[(4 * i + 4) % n]});
    return out;
}

// Long-double ray against segment: t and the position s along it (0..1); false when parallel.
bool ld_ray_segment(const V2& o2, const V2& d2, const Segment<double>& seg, LD& t, LD& s) {
    const LD ox = o2[0], oy = o2[1], dx = d2[0], dy = d2[1];
    const LD ax = seg.p0[0], ay = seg.p0[1], ex = LD(seg.p1[0]) - ax, ey = LD(seg.p1[1]) - ay;
    const LD den = dx * ey - dy * ex;
    if (den == 0) return false;
    const LD cx = ax - ox, cy = ay - oy;
    t = (cx * ey - cy * ex) / den;
    s = (cx * dy - cy * dx) / den;
    return true;
}

LD ld_winding_2d(const std::vector<Segment<double>>& segs, const V2& q) {
    LD sum = 0;
    for (const auto& sg : segs) {
        const LD ax = LD(sg.p0[0]) - q[0], ay = LD(sg.p0[1]) - q[1];
        const LD bx = LD(sg.p1[0]) - q[0], by = LD(sg.p1[1]) - q[1];
        sum += std::atan2(ax * by - ay * bx, ax * bx + ay * by);
    }
    return sum / (2 * std::numbers::pi_v<LD>);
}

LD ld_distance_to_segment(const Segment<double>& sg, const V2& q) {
    const LD ex = LD(sg.p1[0]) - sg.p0[0], ey = LD(sg.p1[1]) - sg.p0[1];
    const LD px = LD(q[0]) - sg.p0[0], py = LD(q[1]) - sg.p0[1];
    const LD s = std::clamp((px * ex + py * ey) / (ex * ex + ey * ey), LD(0), LD(1));
    return std::hypot(px - s * ex, py - s * ey);
}

TEST(Bsp2d, PartsKeepEverySegmentsLength) {
    const auto segs = star_with_hole(200, 1);
    for (const double w : {0.0, 0.5, 1.0}) {
        BspOptions o;
        o.split_weight = w;
        const BspTree<double, 2> tree(segs, o);
        const auto& s = tree.statistics();
        EXPECT_EQ(s.polygons, segs.size() + s.splits);
        EXPECT_TRUE(tree.is_solid());
        std::vector<LD> len(segs.size(), 0);
        for (std::uint32_t i = 0; i < tree.polygons().size(); ++i)
            len[tree.polygons().polygons[i].source] += tree.polygons().area(i);
        for (std::size_t i = 0; i < segs.size(); ++i) {
            const LD want =
                std::hypot(LD(segs[i].p1[0]) - segs[i].p0[0], LD(segs[i].p1[1]) - segs[i].p0[1]);
            ASSERT_LE(std::fabs(len[i] - want), 1e-12L * want) << "segment " << i;
        }
    }
}

TEST(Bsp2d, ClosestHitEqualsBruteForce) {
    const auto segs = star_with_hole(300, 2);
    const BspTree<double, 2> tree(segs);
    Random rng(5);
    const std::size_t count = scaled(20000);
    std::size_t hits = 0;
    constexpr LD delta = 1e-9;
    for (std::size_t r = 0; r < count; ++r) {
        const V2 o{rng.uniform(-1.6, 1.6), rng.uniform(-1.6, 1.6)};
        const double a = rng.uniform(0, 2 * std::numbers::pi);
        const V2 d{std::cos(a), std::sin(a)};
        LD grown = std::numeric_limits<LD>::infinity(), shrunk = grown;
        for (const auto& sg : segs) {
            LD t, s;
            if (!ld_ray_segment(o, d, sg, t, s) || t < 0) continue;
            if (s >= -delta && s <= 1 + delta) grown = std::min(grown, t);
            if (s >= delta && s <= 1 - delta) shrunk = std::min(shrunk, t);
        }
        const auto got = closest_hit(tree, Ray<double, 2>(o, d));
        if (!got) {
            ASSERT_TRUE(std::isinf(shrunk)) << "ray " << r;
            continue;
        }
        ++hits;
        ASSERT_GE(LD(got.t), grown - 1e-9L) << "ray " << r;
        ASSERT_LE(LD(got.t), shrunk + 1e-9L) << "ray " << r;
        LD t, s;
        ASSERT_TRUE(ld_ray_segment(o, d, segs[got.source], t, s));
        EXPECT_NEAR(double(t), got.t, 1e-9) << "ray " << r;
    }
    EXPECT_GT(hits, count / 2);
}

TEST(Bsp2d, FrontToBackAlongRays) {
    const auto segs = star_with_hole(120, 3);
    const BspTree<double, 2> tree(segs);
    const auto& pool = tree.polygons();
    const std::size_t n = pool.size();
    Random rng(9);
    std::size_t pairs = 0;
    for (int e = 0; e < 20; ++e) {
        const V2 eye{rng.uniform(-2, 2), rng.uniform(-2, 2)};
        std::vector<std::size_t> pos(n, n);
        std::size_t k = 0;
        for_each_front_to_back(tree, eye, [&](std::uint32_t i) { pos[i] = k++; });
        ASSERT_EQ(k, n);
        for (int r = 0; r < 100; ++r) {
            const double a = rng.uniform(0, 2 * std::numbers::pi);
            const V2 d{std::cos(a), std::sin(a)};
            std::vector<std::pair<LD, std::size_t>> hits;
            bool skip = false;
            for (std::size_t i = 0; i < n; ++i) {
                const auto v = pool.vertices_of(i);
                LD t, s;
                if (!ld_ray_segment(eye, d, Segment<double>{v[0], v[1]}, t, s) || t <= 0) continue;
                if (std::fabs(s) < 1e-9 || std::fabs(s - 1) < 1e-9) skip = true;
                if (s > 0 && s < 1) hits.emplace_back(t, i);
            }
            if (skip) continue;
            std::sort(hits.begin(), hits.end());
            for (std::size_t h = 1; h < hits.size(); ++h) {
                ASSERT_LT(pos[hits[h - 1].second], pos[hits[h].second]) << "eye " << e;
                ++pairs;
            }
        }
    }
    EXPECT_GT(pairs, 200u);
}

TEST(Bsp2d, InsideOutsideEqualsTheWindingNumber) {
    const auto segs = star_with_hole(200, 4);
    const BspTree<double, 2> tree(segs);
    ASSERT_TRUE(tree.is_solid());
    Random rng(13);
    std::size_t inside = 0, checked = 0;
    for (std::size_t k = 0; k < scaled(3000); ++k) {
        const V2 p{rng.uniform(-1.6, 1.6), rng.uniform(-1.6, 1.6)};
        LD dist = std::numeric_limits<LD>::infinity();
        for (const auto& sg : segs) dist = std::min(dist, ld_distance_to_segment(sg, p));
        if (dist <= 1e-6L * 4.5) continue;
        const LD w = ld_winding_2d(segs, p);
        const auto want = w > 0.5 ? PointLocation::Inside : PointLocation::Outside;
        ASSERT_EQ(classify_point(tree, p), want) << "point " << k << " winding " << double(w);
        inside += want == PointLocation::Inside;
        ++checked;
    }
    EXPECT_GT(inside, checked / 10);
    EXPECT_LT(inside, checked);
    EXPECT_EQ(classify_point(tree, V2{0, 0}), PointLocation::Outside);  // in the hole
}

TEST(Bsp2d, DegenerateInput) {
    const BspTree<double, 2> empty{std::vector<Segment<double>>{}};
    EXPECT_EQ(empty.statistics().nodes, 1u);
    EXPECT_FALSE(closest_hit(empty, Ray<double, 2>({0, 0}, {1, 0})));
    std::vector<Segment<double>> segs = {{{0, 0}, {1, 0}}, {{2, 2}, {2, 2}}};
    const BspTree<double, 2> one(segs);
    EXPECT_EQ(one.statistics().dropped_degenerate, 1u);
    EXPECT_EQ(one.statistics().polygons, 1u);
    const auto hit = closest_hit(one, Ray<double, 2>({0.5, 1}, {0, -1}));
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit.t, 1.0);
    // Front of (0,0) -> (1,0) is to its right: -y.
    EXPECT_EQ(classify_point(one, V2{0.5, -1}), PointLocation::Outside);
    EXPECT_EQ(classify_point(one, V2{0.5, 1}), PointLocation::Inside);
    segs[1].p1[0] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW((BspTree<double, 2>{segs}), Error);
    // All collinear: one node holds them, split by facing.
    const std::vector<Segment<double>> line = {
        {{0, 0}, {1, 0}}, {{3, 0}, {2, 0}}, {{4, 0}, {5, 0}}};
    const BspTree<double, 2> flat(line);
    EXPECT_EQ(flat.statistics().nodes, 3u);
    EXPECT_EQ(flat.root().front_facing, 2u);
}

}  // namespace
}  // namespace bvhkit::test

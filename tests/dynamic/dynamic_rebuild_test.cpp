// DynamicTree::rebuild() (the in-place binned builder of bvh/linked_rebuild.hpp) on inputs that
// push its arithmetic and its recursion: points, all-equal centroids, centroids at exponentially
// growing distances, boxes far from the origin (past a quarter of the float range, where the
// builder switches to its overflow-safe centre keys), denormal sizes, and partial rebuilds after
// enlarge(). After every rebuild the tree must validate and answer box queries and closest-hit ray
// casts exactly as brute force over the test's own copy of the boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "test_support.hpp"

namespace {

using bvhkit::DynamicTree;
using bvhkit::ProxyId;

template <class T, std::size_t N>
struct Fixture {
    using Box = bvhkit::Aabb<T, N>;
    using Vec = bvhkit::Vec<T, N>;
    DynamicTree<T, N> tree;
    std::vector<Box> boxes;
    std::vector<ProxyId> ids;

    explicit Fixture(T margin) : tree(options(margin)) {}
    static bvhkit::DynamicTreeOptions<T> options(T margin) {
        bvhkit::DynamicTreeOptions<T> o;
        o.margin_absolute = margin;
        return o;
    }
    void add(const Box& b) {
        boxes.push_back(b);
        ids.push_back(tree.create(b));
    }

    /// Overlap written out per axis (touching counts), independent of Aabb::overlaps.
    static bool brute_overlap(const Box& a, const Box& b) {
        for (std::size_t i = 0; i < N; ++i)
            if (a.max[i] < b.min[i] || b.max[i] < a.min[i]) return false;
        return true;
    }
    void check_query(const Box& q) const {
        std::vector<ProxyId> got, want;
        tree.query(q, [&](ProxyId id) { return got.push_back(id), true; });
        for (std::size_t k = 0; k < boxes.size(); ++k)
            if (brute_overlap(boxes[k], q)) want.push_back(ids[k]);
        std::sort(got.begin(), got.end());
        std::sort(want.begin(), want.end());
        ASSERT_EQ(got, want);
    }

    /// Entry fraction of origin + s * dir, s in [0, max_fraction], into box b, in long double
    /// (every float or double step below is exact there or rounds the same way for both the tree's
    /// callback and the brute force, which call this same function); -1 when it misses.
    static long double entry(const Box& b, const Vec& o, const Vec& d, long double max_fraction) {
        long double t0 = 0, t1 = max_fraction;
        for (std::size_t a = 0; a < N; ++a) {
            if (d[a] == 0) {
                if (o[a] < b.min[a] || o[a] > b.max[a]) return -1;
                continue;
            }
            long double n = ((long double)b.min[a] - o[a]) / d[a];
            long double f = ((long double)b.max[a] - o[a]) / d[a];
            if (n > f) std::swap(n, f);
            t0 = std::max(t0, n);
            t1 = std::min(t1, f);
        }
        return t0 <= t1 ? t0 : -1;
    }
    void check_ray(const Vec& o, const Vec& d) const {
        long double got = 2;
        tree.ray_cast(o, d, T(1), [&](ProxyId id, T max_fraction) {
            const long double f =
                entry(boxes[std::size_t(id.index())], o, d, (long double)max_fraction);
            if (f < 0) return T(-1);
            got = std::min(got, f);
            // Clip to the hit, rounded up so that a box entered at the same fraction still counts.
            return std::nextafter(T(f), std::numeric_limits<T>::max());
        });
        long double want = 2;
        for (const Box& b : boxes) {
            const long double f = entry(b, o, d, 1);
            if (f >= 0) want = std::min(want, f);
        }
        ASSERT_EQ(got, want);
    }
};

/// The builder's bound on the height: 64 levels of SAH, then halves by count, down to ranges of at
/// most 6 split at their middle (at most 5 more levels where 3 would do).
int height_bound(std::size_t n) {
    return 64 + int(std::ceil(std::log2(double(std::max<std::size_t>(n, 2))))) + 2;
}

TEST(DynamicTreeRebuild, RandomBoxesFullThenPartialAfterEnlarge) {
    Fixture<float, 2> f(0.1f);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> pos(0.0f, 1000.0f), size(0.0f, 20.0f);
    const int n = bvhkit::test::small_scale() ? 1500 : 5000;
    for (int i = 0; i < n; ++i) {
        const bvhkit::Vec2f lo{pos(rng), pos(rng)};
        // every fifth box is a point
        f.add({lo, i % 5 == 0 ? lo : lo + bvhkit::Vec2f{size(rng), size(rng)}});
    }
    f.tree.rebuild(true);
    f.tree.validate();
    EXPECT_LE(f.tree.height(), 2 * int(std::log2(double(n))) + 2);
    for (int q = 0; q < 100; ++q) {
        const bvhkit::Vec2f lo{pos(rng), pos(rng)};
        f.check_query({lo, lo + bvhkit::Vec2f{size(rng) * 5, size(rng) * 5}});
        f.check_ray({pos(rng), pos(rng)}, {pos(rng) - 500.0f, pos(rng) - 500.0f});
    }
    for (int round = 0; round < 4; ++round) {
        for (int k = 0; k < n / 10; ++k) {
            const std::size_t i = std::size_t(rng()) % f.boxes.size();
            const bvhkit::Vec2f step{size(rng) - 10.0f, size(rng) - 10.0f};
            f.boxes[i] = {f.boxes[i].min + step, f.boxes[i].max + step};
            f.tree.enlarge(f.ids[i], f.boxes[i]);
        }
        f.tree.rebuild(false);
        f.tree.validate();
        for (int q = 0; q < 50; ++q) {
            const bvhkit::Vec2f lo{pos(rng), pos(rng)};
            f.check_query({lo, lo + bvhkit::Vec2f{size(rng) * 5, size(rng) * 5}});
            f.check_ray({pos(rng), pos(rng)}, {pos(rng) - 500.0f, pos(rng) - 500.0f});
        }
    }
    // A full rebuild of a tree that partial rebuilds shaped, twice in a row.
    f.tree.rebuild(true);
    f.tree.rebuild(true);
    f.tree.validate();
    f.check_query({{0, 0}, {1000, 1000}});
}

TEST(DynamicTreeRebuild, AllEqualCentroidsGiveABalancedTree) {
    for (const bool nested : {false, true}) {
        Fixture<float, 2> f(0.0f);
        const int n = 2000;
        for (int i = 0; i < n; ++i) {
            const float r = nested ? float(i % 97 + 1) : 3.0f;  // same centre, sizes vary or not
            f.add({{5 - r, -7 - r}, {5 + r, -7 + r}});
        }
        f.tree.rebuild(true);
        f.tree.validate();
        EXPECT_LE(f.tree.height(), int(std::ceil(std::log2(double(n)))) + 1) << nested;
        f.check_query({{5, -7}, {5, -7}});
        f.check_query({{7.5f, -7}, {9, -6}});
        f.check_ray({-100, -100}, {200, 190});
    }
}

TEST(DynamicTreeRebuild, ExponentiallySpacedCentroidsStayShallow) {
    // SAH peels one point per level off such a row (a tree ~250 high without the builder's depth
    // limit); past the limit the ranges are halved.
    Fixture<double, 2> f(0.0);
    const int n = 997;  // 2^996 < 1e300
    for (int i = 0; i < n; ++i) {
        const double x = std::ldexp(1.0, i);
        f.add({{x, 1}, {x, 1}});
    }
    f.tree.rebuild(true);
    f.tree.validate();
    EXPECT_LE(f.tree.height(), height_bound(std::size_t(n)));
    f.check_query({{0, 0}, {1e3, 2}});
    f.check_query({{1e20, 0}, {1e29, 2}});
    f.check_query({{1e200, 0}, {1e300, 2}});
    f.check_ray({-1, 1}, {1e300, 0});
}

TEST(DynamicTreeRebuild, FarFromTheOriginAndNearTheEndsOfTheRange) {
    const float big = std::numeric_limits<float>::max();
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    // Centres past big / 4 (the overflow-safe keys), and around 1e30 (the plain keys), where unit
    // boxes are points at float precision.
    for (const float centre : {0.6f * big, -0.9f * big, 1e30f}) {
        Fixture<float, 2> f(0.1f);
        const float spread = std::abs(centre) * 0.05f;
        for (int i = 0; i < 800; ++i) {
            const bvhkit::Vec2f lo{centre + spread * u(rng), centre - spread * u(rng)};
            f.add({lo, bvhkit::min(lo + bvhkit::Vec2f{spread * 0.01f * u(rng), 1.0f},
                                   bvhkit::Vec2f(big))});
        }
        f.add({{-big, -big}, {big, big}});  // the whole range
        f.add({{0, 0}, {1, 1}});            // and one box at the origin
        f.tree.rebuild(true);
        f.tree.validate();
        EXPECT_LE(f.tree.height(), height_bound(f.boxes.size()));
        for (int q = 0; q < 40; ++q) {
            const bvhkit::Vec2f lo{centre + spread * u(rng), centre - spread * u(rng)};
            f.check_query({lo, lo + bvhkit::Vec2f{spread * 0.05f, spread * 0.05f}});
        }
        f.check_query({{0, 0}, {0.5f, 0.5f}});
    }
}

TEST(DynamicTreeRebuild, DenormalAndHugeSizesTogether) {
    Fixture<double, 3> f(0.0);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double tiny = std::numeric_limits<double>::denorm_min();
    for (int i = 0; i < 1500; ++i) {
        const double scale = i % 3 == 0 ? 1e-310 : (i % 3 == 1 ? 1e-3 : 1e150);
        const bvhkit::Vec3d lo{scale * u(rng), scale * u(rng), scale * u(rng)};
        f.add({lo, lo + bvhkit::Vec3d{tiny * (i % 7), scale * u(rng), 0}});
    }
    f.tree.rebuild(true);
    f.tree.validate();
    EXPECT_LE(f.tree.height(), height_bound(f.boxes.size()));
    f.check_query({{0, 0, 0}, {1e-310, 1e-310, 1e-310}});
    f.check_query({{0, 0, 0}, {1e-3, 1e-3, 1e-3}});
    f.check_query({{1e149, 0, 0}, {1e150, 1e150, 1e150}});
    f.check_ray({-1, 0.5e-3, 0.5e-3}, {2, 0, 0});
}

TEST(DynamicTreeRebuild, FewProxies) {
    for (int n = 1; n <= 9; ++n) {
        Fixture<float, 2> f(0.1f);
        for (int i = 0; i < n; ++i) f.add({{float(i), 0}, {float(i) + 0.5f, 1}});
        f.tree.rebuild(true);
        f.tree.validate();
        f.tree.rebuild(false);
        f.tree.validate();
        f.check_query({{-1, -1}, {100, 100}});
        f.check_ray({-1, 0.5f}, {20, 0});
    }
}

}  // namespace

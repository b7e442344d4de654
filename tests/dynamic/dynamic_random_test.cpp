// Randomized differential test of DynamicTree: about 10^6 mixed operations (create, destroy, small
// and far moves, enlarge, rebuild, optimize) over 2D/3D, float/double and both insertion
// strategies. The tree is validated every 1,000 operations and at the end, and every kind of query
// and the pair finding are checked against brute force over all live proxies (the test keeps its
// own copy of every box, so nothing is compared with the tree's own output).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "test_support.hpp"

namespace {

using bvhkit::InsertionStrategy;
using bvhkit::ProxyId;

using Long = long double;

/// Independent slab test in long double, zero direction components handled explicitly. Returns the
/// entry fraction in [0, max_fraction] or -1. `grow` widens (> 0) or shrinks (< 0) the box by that
/// much on every side, to bracket the tree's rounding.
template <class T, std::size_t N>
Long exact_entry(const bvhkit::Vec<T, N>& o, const bvhkit::Vec<T, N>& d,
                 const bvhkit::Aabb<T, N>& b, const bvhkit::Vec<T, N>& pad, Long max_fraction,
                 Long grow) {
    Long t0 = 0, t1 = max_fraction;
    for (std::size_t i = 0; i < N; ++i) {
        const Long lo = Long(b.min[i]) - Long(pad[i]) - grow,
                   hi = Long(b.max[i]) + Long(pad[i]) + grow;
        if (lo > hi) return -1;
        if (d[i] == 0) {
            if (Long(o[i]) < lo || Long(o[i]) > hi) return -1;
            continue;
        }
        Long a = (lo - Long(o[i])) / Long(d[i]), c = (hi - Long(o[i])) / Long(d[i]);
        if (a > c) std::swap(a, c);
        t0 = std::max(t0, a);
        t1 = std::min(t1, c);
    }
    return t0 <= t1 ? t0 : -1;
}

template <class T, std::size_t N>
struct Harness {
    using Tree = bvhkit::DynamicTree<T, N>;
    using Box = bvhkit::Aabb<T, N>;
    using V = bvhkit::Vec<T, N>;

    std::mt19937_64 rng;
    Tree tree;
    std::vector<Box> boxes;        // by slot; the test's own copy
    std::vector<char> alive;       // by slot
    std::set<ProxyId> moved;       // created or moved since the last find_pairs
    std::vector<ProxyId> live;     // ids, for picking
    std::set<ProxyId> handed_out;  // every id create() returned: none twice
    std::vector<ProxyId> dead;     // some destroyed ids: stale for good, slots reused or not
    T world = T(100);
    std::size_t target = 800;

    Harness(std::uint64_t seed, const bvhkit::DynamicTreeOptions<T>& o) : rng(seed), tree(o) {}

    T uni(T a, T b) { return std::uniform_real_distribution<T>(a, b)(rng); }
    std::size_t pick(std::size_t n) {
        return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
    }

    Box random_box() {
        V lo, size;
        const int kind = int(pick(10));
        for (std::size_t i = 0; i < N; ++i) {
            lo[i] = uni(0, world);
            size[i] = kind == 0 ? T(0) : uni(0, T(3));  // one in ten has zero size
        }
        if (kind == 1) lo = V(T(50));  // and one in ten sits at the same place
        return {lo, lo + size};
    }

    void remember(ProxyId id, const Box& b) {
        const auto slot = std::size_t(id.index());
        if (slot >= boxes.size()) boxes.resize(slot + 1), alive.resize(slot + 1, 0);
        boxes[id.index()] = b;
        alive[id.index()] = 1;
        moved.insert(id);
    }

    void op_create() {
        const Box b = random_box();
        const ProxyId id = tree.create(b, std::uint64_t(id_salt(b)));
        ASSERT_TRUE(id.index() >= 0);
        ASSERT_FALSE(std::size_t(id.index()) < alive.size() && alive[id.index()])
            << "id " << id << " handed out twice";
        ASSERT_TRUE(handed_out.insert(id).second) << "id " << id << " handed out again";
        remember(id, b);
        live.push_back(id);
    }
    static std::uint64_t id_salt(const Box& b) { return std::uint64_t(std::abs(b.min[0]) * 1000); }

    void op_destroy() {
        const std::size_t k = pick(live.size());
        const ProxyId id = live[k];
        tree.destroy(id);
        alive[id.index()] = 0;
        ASSERT_FALSE(tree.contains(id));
        if (dead.size() < 64) dead.push_back(id);
        moved.erase(id);
        live[k] = live.back();
        live.pop_back();
    }

    void op_move(bool far, bool use_enlarge) {
        const ProxyId id = live[pick(live.size())];
        Box b = boxes[id.index()];
        V d;
        if (far) {
            b = random_box();
        } else {
            for (std::size_t i = 0; i < N; ++i) d[i] = uni(T(-0.3), T(0.3));
            b = Box(b.min + d, b.max + d);
        }
        ASSERT_EQ(tree.user_data(id), id_salt(boxes[id.index()])) << "user data of " << id;
        use_enlarge ? tree.enlarge(id, b, d) : tree.move(id, b, d);
        tree.user_data(id) = id_salt(b);
        remember(id, b);
    }

    // ---- brute-force checks

    void check_box_query() {
        const Box q = random_box();
        std::vector<ProxyId> got, want;
        bvhkit::QueryStats st;
        tree.query(
            q, [&](ProxyId id) { return got.push_back(id), true; }, &st);
        for (ProxyId id : live)
            if (boxes[id.index()].overlaps(q)) want.push_back(id);
        std::sort(got.begin(), got.end());
        std::sort(want.begin(), want.end());
        ASSERT_EQ(got, want) << "box query";
        ASSERT_GE(st.leaves_tested, got.size());
    }

    void check_point_query() {
        // Half the points are box corners, to hit boundaries exactly.
        V p;
        if (pick(2) && !live.empty()) {
            p = boxes[live[pick(live.size())].index()].max;
        } else {
            for (std::size_t i = 0; i < N; ++i) p[i] = uni(0, world);
        }
        std::vector<ProxyId> got, want;
        tree.query_point(p, [&](ProxyId id) { return got.push_back(id), true; });
        for (ProxyId id : live)
            if (boxes[id.index()].contains(p)) want.push_back(id);
        std::sort(got.begin(), got.end());
        std::sort(want.begin(), want.end());
        ASSERT_EQ(got, want) << "point query";
    }

    /// Ray (pad = 0) or box cast: every proxy surely hit is reported, nothing clearly missed is.
    void check_cast(bool box_cast) {
        V o, d, pad;
        for (std::size_t i = 0; i < N; ++i) {
            o[i] = uni(-10, world + 10);
            d[i] = uni(-world, world);
        }
        const int zero = int(pick(N + 2));  // sometimes a zero (+0 or -0) direction component
        if (zero < int(N)) d[zero] = pick(2) ? T(0) : -T(0);
        Box cast_box(o, o);
        if (box_cast) {
            for (std::size_t i = 0; i < N; ++i) pad[i] = uni(0, 2);
            cast_box = Box(o - pad, o + pad);
        }
        const T maxf = uni(T(0.05), T(1.5));
        std::vector<ProxyId> got;
        const auto cb = [&](ProxyId id, T) { return got.push_back(id), T(-1); };
        box_cast ? tree.box_cast(cast_box, d, maxf, cb) : tree.ray_cast(o, d, maxf, cb);
        // The padding used by the tree is the half extent of cast_box, recomputed in T.
        const V half = cast_box.extent() * T(0.5);
        const Long tol = Long(1e-3) * (std::is_same_v<T, float> ? 1 : Long(1e-6));
        std::set<ProxyId> got_set(got.begin(), got.end());
        ASSERT_EQ(got_set.size(), got.size()) << "cast reported a proxy twice";
        for (ProxyId id : live) {
            const bool sure = exact_entry(o, d, boxes[id.index()], half, Long(maxf), -tol) >= 0;
            const bool maybe = exact_entry(o, d, boxes[id.index()], half, Long(maxf), tol) >= 0;
            if (sure) {
                ASSERT_TRUE(got_set.count(id))
                    << (box_cast ? "box" : "ray") << " cast missed " << id;
            }
            if (!maybe) {
                ASSERT_FALSE(got_set.count(id))
                    << (box_cast ? "box" : "ray") << " cast reported " << id;
            }
        }
        // Closest hit by clipping: the smallest entry fraction must be found.
        Long best = -1;
        for (ProxyId id : live) {
            const Long t = exact_entry(o, d, boxes[id.index()], half, Long(maxf), 0);
            if (t >= 0 && (best < 0 || t < best)) best = t;
        }
        Long found = -1;
        const auto clip = [&](ProxyId id, T mf) -> T {
            const Long t = exact_entry(o, d, boxes[id.index()], half, Long(mf), 0);
            if (t < 0) return T(-1);
            found = found < 0 ? t : std::min(found, t);
            return std::max(T(t), std::numeric_limits<T>::min());  // clip there, keep it > 0
        };
        box_cast ? tree.box_cast(cast_box, d, maxf, clip) : tree.ray_cast(o, d, maxf, clip);
        if (best >= 0) {
            ASSERT_NEAR(double(found), double(best), 1e-4) << "closest hit";
        }
    }

    void check_pairs() {
        std::vector<bvhkit::ProxyPair> got;
        tree.find_pairs(got);
        std::vector<bvhkit::ProxyPair> want;
        for (ProxyId m : moved)
            for (ProxyId o : live)
                if (o != m && boxes[m.index()].overlaps(boxes[o.index()]) &&
                    !(moved.count(o) && o < m))
                    want.push_back({std::min(m, o), std::max(m, o)});
        std::sort(want.begin(), want.end());
        ASSERT_EQ(got.size(), want.size()) << "pair count";
        ASSERT_TRUE(got == want) << "pairs differ";
        moved.clear();
    }

    void check_tree_vs_tree(Tree& other, const std::vector<Box>& other_boxes) {
        std::vector<std::pair<ProxyId, ProxyId>> got, want;
        tree.query_tree(other, [&](ProxyId a, ProxyId b) { return got.emplace_back(a, b), true; });
        for (ProxyId a : live)
            for (std::int32_t b = 0; b < std::int32_t(other_boxes.size()); ++b)
                if (boxes[a.index()].overlaps(other_boxes[std::size_t(b)]))
                    want.emplace_back(a, ProxyId(b, 0));  // `other` never destroys
        std::sort(got.begin(), got.end());
        std::sort(want.begin(), want.end());
        ASSERT_TRUE(got == want) << "tree against tree: " << got.size() << " vs " << want.size();
    }

    void run(std::size_t ops) {
        // A second, fixed tree for the tree-against-tree check.
        Tree other;
        std::vector<Box> other_boxes;
        for (int i = 0; i < 150; ++i) {
            other_boxes.push_back(random_box());
            other.create(other_boxes.back());
        }
        int enlarged = 0;
        for (std::size_t k = 1; k <= ops; ++k) {
            const std::size_t r = pick(1000);
            const bool grow = live.size() < target;
            if (live.empty() || (r < 300 && grow) || (r < 200)) {
                op_create();
            } else if (r < 450) {
                op_destroy();
            } else if (r < 800) {
                op_move(false, false);
            } else if (r < 900) {
                op_move(true, false);
            } else if (r < 990) {
                op_move(r < 950, true);
                ++enlarged;
            } else if (r < 993) {
                tree.rebuild(pick(2) == 0);
            } else if (r < 996) {
                tree.optimize(int(pick(20)));
            } else {
                ASSERT_NO_FATAL_FAILURE(check_pairs());
            }
            if (::testing::Test::HasFatalFailure()) return;
            if (enlarged > 200) tree.rebuild(false), enlarged = 0;
            if (k % 1000 == 0) {
                ASSERT_NO_THROW(tree.validate()) << "after op " << k;
                for (const ProxyId id : dead) ASSERT_FALSE(tree.contains(id)) << id;
                for (int q = 0; q < 3; ++q) {
                    ASSERT_NO_FATAL_FAILURE(check_box_query());
                    ASSERT_NO_FATAL_FAILURE(check_point_query());
                    ASSERT_NO_FATAL_FAILURE(check_cast(false));
                    ASSERT_NO_FATAL_FAILURE(check_cast(true));
                }
                ASSERT_NO_FATAL_FAILURE(check_pairs());
                if (k % 5000 == 0) {
                    ASSERT_NO_FATAL_FAILURE(check_tree_vs_tree(other, other_boxes));
                }
                // The size wanders between a few hundred and about two thousand proxies.
                if (k % 50000 == 0) target = 200 + pick(1800);
            }
        }
        ASSERT_NO_THROW(tree.validate());
        ASSERT_EQ(tree.size(), live.size());
        ASSERT_NO_FATAL_FAILURE(check_pairs());
        // Empty it completely.
        while (!live.empty()) op_destroy();
        ASSERT_NO_THROW(tree.validate());
        ASSERT_EQ(tree.height(), 0);
    }
};

template <class T, std::size_t N>
void run_random(std::uint64_t seed, InsertionStrategy strategy, T margin_rel) {
    bvhkit::DynamicTreeOptions<T> o;
    o.insertion = strategy;
    o.margin_relative = margin_rel;
    o.margin_absolute = T(0.05);
    Harness<T, N> h(seed, o);
    // 8 configurations x 125,000 = 10^6 operations in the Release run.
    h.run(bvhkit::test::scaled(125000));
}

constexpr auto BnB = InsertionStrategy::BranchAndBound;
constexpr auto Greedy = InsertionStrategy::Greedy;
constexpr auto Guided = InsertionStrategy::Guided;

TEST(DynamicTreeRandom, Float2Guided) {
    run_random<float, 2>(9, Guided, 0.0f);
}
TEST(DynamicTreeRandom, Double3Guided) {
    run_random<double, 3>(10, Guided, 0.1);
}

TEST(DynamicTreeRandom, Float2BranchAndBound) {
    run_random<float, 2>(1, BnB, 0.1f);
}
TEST(DynamicTreeRandom, Float2Greedy) {
    run_random<float, 2>(2, Greedy, 0.0f);
}
TEST(DynamicTreeRandom, Double2BranchAndBound) {
    run_random<double, 2>(3, BnB, 0.0);
}
TEST(DynamicTreeRandom, Double2Greedy) {
    run_random<double, 2>(4, Greedy, 0.2);
}
TEST(DynamicTreeRandom, Float3BranchAndBound) {
    run_random<float, 3>(5, BnB, 0.0f);
}
TEST(DynamicTreeRandom, Float3Greedy) {
    run_random<float, 3>(6, Greedy, 0.1f);
}
TEST(DynamicTreeRandom, Double3BranchAndBound) {
    run_random<double, 3>(7, BnB, 0.1);
}
TEST(DynamicTreeRandom, Double3Greedy) {
    run_random<double, 3>(8, Greedy, 0.0);
}

}  // namespace

// D1/D2/D3: see dynamic_bench.hpp. The motion is generated once per workload from a fixed seed and
// replayed identically for every library; each library runs single threaded in this process.
#include "dynamic_bench.hpp"

#include "dynamic_motion.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <string>

#include "bvhkit/dynamic/dynamic_tree.hpp"

#ifdef BVHKIT_HAVE_BOX2D
#include <box2d/b2_broad_phase.h>
#endif
#ifdef BVHKIT_HAVE_BULLET
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#endif

namespace bvhkit::bench {
namespace {

using namespace dynamic_workload;

// ---------------------------------------------------------------- bvhkit

template <std::size_t N>
RunResult run_bvhkit(const Motion& m, InsertionStrategy strategy) {
    using Tree = DynamicTree<float, N>;
    using Box = Aabb<float, N>;
    using V = Vec<float, N>;
    DynamicTreeOptions<float> o;
    o.insertion = strategy;
    // A box moving at up to 0.5 per move stays in a fat box stretched by 4 moves of prediction; the
    // margin covers turning a little (bounces) without restructuring.
    o.margin_absolute = 0.1f;
    o.displacement_multiplier = 4.0f;
    Tree tree(o);
    const auto box_at = [&](const float* p) {
        V lo;
        for (std::size_t a = 0; a < N; ++a) lo[a] = p[a];
        return Box(lo, lo + V(1.0f));
    };
    RunResult r;
    std::vector<ProxyPair> pairs;
    auto t0 = Clock::now();
    for (int i = 0; i < m.n; ++i) tree.create(box_at(&m.start[i * 3]), std::uint64_t(i));
    tree.find_pairs(pairs);
    r.build_ms = ms_since(t0);
    const auto summarize = [&] {
        PairSummary s;  // slots are the indices: a fresh tree hands out 0, 1, 2, ...
        for (const ProxyPair& p : pairs)
            s.add(std::uint32_t(p.a.index()), std::uint32_t(p.b.index()));
        r.per_step.push_back(s);
    };
    summarize();
    double total = 0, moving = 0;
    for (const auto& moves : m.steps) {
        t0 = Clock::now();
        for (const auto& mv : moves) {
            V d;
            for (std::size_t a = 0; a < N; ++a) d[a] = mv.v[a];
            r.touched += tree.move(ProxyId(mv.id, 0), box_at(mv.p), d);  // never destroyed
        }
        moving += ms_since(t0);
        tree.find_pairs(pairs);
        total += ms_since(t0);
        summarize();
    }
    r.step_ms = m.steps.empty() ? 0 : total / double(m.steps.size());
    r.move_ms = m.steps.empty() ? 0 : moving / double(m.steps.size());
    tree.validate();
    r.height = tree.height();
    r.sah = tree.sah_cost();
    r.ratio = tree.area_ratio();
    return r;
}

// ---------------------------------------------------------------- Box2D 2.4.1

#ifdef BVHKIT_HAVE_BOX2D
struct Box2dPairs {
    std::vector<std::pair<std::uintptr_t, std::uintptr_t>> pairs;
    void AddPair(void* a, void* b) {
        pairs.emplace_back(reinterpret_cast<std::uintptr_t>(a),
                           reinterpret_cast<std::uintptr_t>(b));
    }
};

RunResult run_box2d(const Motion& m) {
    // Box2D reports pairs of fat boxes (margin b2_aabbExtension = 0.1, stretched by 4x the
    // displacement) and only for proxies whose fat box was re-inserted; a Box2D world keeps a
    // contact until the fat boxes part. To get the same answer as bvhkit (the pairs of tight boxes
    // that involve a moved box), every moved proxy whose fat box did not change is touched
    // (TouchProxy), and the pairs it reports are filtered by the tight boxes and made unique
    // afterwards, outside the timing. The timed work is Box2D's own: MoveProxy/TouchProxy and
    // UpdatePairs with a callback that stores the (possibly repeated) pairs.
    b2BroadPhase bp;
    const auto aabb_at = [](const float* p) {
        b2AABB b;
        b.lowerBound.Set(p[0], p[1]);
        b.upperBound.Set(p[0] + 1.0f, p[1] + 1.0f);
        return b;
    };
    RunResult r;
    Tight tight(m);
    Box2dPairs cb;
    cb.pairs.reserve(1 << 20);
    std::vector<int32> ids(m.n);
    const auto summarize = [&] {
        std::vector<std::pair<std::uint32_t, std::uint32_t>> ps;
        for (auto [a, b] : cb.pairs) {
            const auto ia = std::uint32_t(a - 1),
                       ib = std::uint32_t(b - 1);  // user data = index + 1
            if (tight.overlap(int(ia), int(ib), 2))
                ps.emplace_back(std::min(ia, ib), std::max(ia, ib));
        }
        std::sort(ps.begin(), ps.end());
        ps.erase(std::unique(ps.begin(), ps.end()), ps.end());
        PairSummary s;
        for (auto [a, b] : ps) s.add(a, b);
        r.per_step.push_back(s);
        cb.pairs.clear();
    };
    auto t0 = Clock::now();
    for (int i = 0; i < m.n; ++i)
        ids[i] = bp.CreateProxy(aabb_at(&m.start[i * 3]),
                                reinterpret_cast<void*>(std::uintptr_t(i) + 1));
    bp.UpdatePairs(&cb);
    r.build_ms = ms_since(t0);
    summarize();
    double total = 0, moving = 0;
    for (const auto& moves : m.steps) {
        t0 = Clock::now();
        for (const auto& mv : moves) {
            const int32 id = ids[mv.id];
            const b2AABB before = bp.GetFatAABB(id);
            bp.MoveProxy(id, aabb_at(mv.p), b2Vec2(mv.v[0], mv.v[1]));
            const b2AABB& after = bp.GetFatAABB(id);
            const bool same =
                before.lowerBound == after.lowerBound && before.upperBound == after.upperBound;
            if (same) {
                bp.TouchProxy(id);
            } else {
                ++r.touched;
            }
        }
        moving += ms_since(t0);
        bp.UpdatePairs(&cb);
        total += ms_since(t0);
        tight.apply(moves);
        summarize();
    }
    r.step_ms = m.steps.empty() ? 0 : total / double(m.steps.size());
    r.move_ms = m.steps.empty() ? 0 : moving / double(m.steps.size());
    r.height = bp.GetTreeHeight();
    // GetTreeQuality() is (sum of the perimeters of all nodes, leaves included) / root perimeter.
    // Take the leaves (their fat boxes) out to get the same measure as bvhkit's area ratio; the
    // root of Box2D's tree is the union of the fat boxes.
    double leaves = 0;
    b2AABB root = bp.GetFatAABB(ids[0]);
    for (int i = 0; i < m.n; ++i) {
        const b2AABB& f = bp.GetFatAABB(ids[i]);
        leaves += f.GetPerimeter();
        root.Combine(f);
    }
    const double root_perimeter = root.GetPerimeter();
    r.ratio = double(bp.GetTreeQuality()) - leaves / root_perimeter;
    r.sah = r.ratio * root_perimeter;
    return r;
}
#endif

// ---------------------------------------------------------------- Bullet

#ifdef BVHKIT_HAVE_BULLET
void dbvt_measure(const btDbvtNode* root, double& internal_area, int& height, btVector3& lo,
                  btVector3& hi) {
    if (!root) return;
    lo.setMin(root->volume.Mins());
    hi.setMax(root->volume.Maxs());
    std::vector<std::pair<const btDbvtNode*, int>> stack{{root, 0}};
    while (!stack.empty()) {
        auto [n, depth] = stack.back();
        stack.pop_back();
        height = std::max(height, depth);
        if (n->isleaf()) continue;
        const btVector3 e = n->volume.Maxs() - n->volume.Mins();
        internal_area +=
            2.0 * (double(e.x()) * e.y() + double(e.y()) * e.z() + double(e.z()) * e.x());
        stack.push_back({n->childs[0], depth + 1});
        stack.push_back({n->childs[1], depth + 1});
    }
}

RunResult run_bullet(const Motion& m) {
    // btDbvtBroadphase keeps a persistent pair cache of overlapping fat boxes (margin 0.05, two
    // trees: moving and resting proxies). The step's pairs are read from that cache after
    // calculateOverlappingPairs, filtered to the tight boxes and to the pairs with a moved box: the
    // same set as bvhkit's. That reading is outside the timing.
    btDbvtBroadphase bp;
    RunResult r;
    r.touched = -1;  // not observable from outside
    Tight tight(m);
    std::vector<btBroadphaseProxy*> proxies(m.n);
    std::vector<char> moved(m.n, 1);
    const auto summarize = [&] {
        PairSummary s;
        const btBroadphasePairArray& arr = bp.getOverlappingPairCache()->getOverlappingPairArray();
        for (int k = 0; k < arr.size(); ++k) {
            const int a =
                int(reinterpret_cast<std::uintptr_t>(arr[k].m_pProxy0->m_clientObject) - 1);
            const int b =
                int(reinterpret_cast<std::uintptr_t>(arr[k].m_pProxy1->m_clientObject) - 1);
            if ((moved[a] || moved[b]) && tight.overlap(a, b, 3))
                s.add(std::uint32_t(a), std::uint32_t(b));
        }
        r.per_step.push_back(s);
    };
    const auto corner = [](const float* p, float add) {
        return btVector3(p[0] + add, p[1] + add, p[2] + add);
    };
    auto t0 = Clock::now();
    for (int i = 0; i < m.n; ++i) {
        const float* p = &m.start[i * 3];
        proxies[i] = bp.createProxy(
            corner(p, 0), corner(p, 1), 0, reinterpret_cast<void*>(std::uintptr_t(i) + 1),
            btBroadphaseProxy::DefaultFilter, btBroadphaseProxy::AllFilter, nullptr);
    }
    bp.calculateOverlappingPairs(nullptr);
    r.build_ms = ms_since(t0);
    summarize();
    double total = 0, moving = 0;
    for (const auto& moves : m.steps) {
        std::fill(moved.begin(), moved.end(), 0);
        t0 = Clock::now();
        for (const auto& mv : moves)
            bp.setAabb(proxies[mv.id], corner(mv.p, 0), corner(mv.p, 1), nullptr);
        moving += ms_since(t0);
        bp.calculateOverlappingPairs(nullptr);
        total += ms_since(t0);
        for (const auto& mv : moves) moved[mv.id] = 1;
        tight.apply(moves);
        summarize();
    }
    r.step_ms = m.steps.empty() ? 0 : total / double(m.steps.size());
    r.move_ms = m.steps.empty() ? 0 : moving / double(m.steps.size());
    double area = 0;
    btVector3 lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), hi = -lo;
    dbvt_measure(bp.m_sets[0].m_root, area, r.height, lo, hi);
    dbvt_measure(bp.m_sets[1].m_root, area, r.height, lo, hi);
    const btVector3 e = hi - lo;
    const double root_area =
        2.0 * (double(e.x()) * e.y() + double(e.y()) * e.z() + double(e.z()) * e.x());
    r.sah = area;
    r.ratio = root_area > 0 ? area / root_area : 0;
    return r;
}
#endif

// ---------------------------------------------------------------- medians and rows

/// The last run with its times replaced by the medians over all runs.
RunResult collapse_runs(const std::vector<RunResult>& runs) {
    std::vector<double> build, step, move;
    for (const auto& r : runs)
        build.push_back(r.build_ms), step.push_back(r.step_ms), move.push_back(r.move_ms);
    RunResult out = runs.back();
    out.build_ms = median(build);
    out.step_ms = median(step);
    out.move_ms = median(move);
    return out;
}

template <class F>
RunResult median_run(int reps, F&& run) {
    std::vector<RunResult> runs;
    for (int k = 0; k < std::max(1, reps); ++k) runs.push_back(run());
    return collapse_runs(runs);
}

/// Medians of f() and g() with their repetitions interleaved (f, g, f, g, ...), so that a change of
/// load on a shared machine affects both alike.
template <class F, class G>
std::pair<RunResult, RunResult> median_runs_interleaved(int reps, F&& f, G&& g) {
    std::vector<RunResult> a, b;
    for (int k = 0; k < std::max(1, reps); ++k) {
        a.push_back(f());
        b.push_back(g());
    }
    return {collapse_runs(a), collapse_runs(b)};
}

long long total_pairs(const RunResult& r) {
    long long s = 0;
    for (std::size_t k = 1; k < r.per_step.size(); ++k) s += r.per_step[k].count;
    return s;
}

Row make_row(const std::string& workload, const std::string& library, const RunResult& r,
             const RunResult* reference) {
    Row row;
    row.set("workload", workload).set("library", library);
    row.set("build_ms", r.build_ms).set("step_ms", r.step_ms).set("move_ms", r.move_ms);
    if (reference && r.step_ms > 0) {
        row.set("speedup", r.step_ms / reference->step_ms);
    } else {
        row.set("speedup", std::string(reference ? "" : "-"));
    }
    row.set("pairs", r.reported >= 0 ? r.reported : total_pairs(r));
    if (reference) {
        row.set("agree", std::string(r.per_step == reference->per_step ? "yes" : "NO"));
    } else {
        row.set("agree", std::string("-"));
    }
    if (r.tree_measured) {
        row.set("height", (long long)r.height).set("sah_cost", r.sah).set("area_ratio", r.ratio);
    } else {
        row.set("height", std::string("-")).set("sah_cost", std::string("-"));
        row.set("area_ratio", std::string("-"));
    }
    if (r.touched >= 0) {
        row.set("touched", r.touched);
    } else {
        row.set("touched", std::string("-"));
    }
    return row;
}

/// D1-own: D1 in Box2D's own semantics (dynamic_events_bench.cpp). "pairs" counts what each library
/// reported (bvhkit: begin events; Box2D: fat pairs of re-inserted proxies); "agree": the tight
/// pairs overlapping after every step, rebuilt from each library's reports, are the same.
void own_semantics(const Motion& m, const DynamicBenchConfig& c, std::vector<Row>& rows) {
    const auto ours = [&] { return run_bvhkit_events(m); };
#ifdef BVHKIT_HAVE_BOX2D
    auto [events, box2d] = median_runs_interleaved(c.reps, ours, [&] { return run_box2d_own(m); });
    rows.push_back(make_row("D1-own", "bvhkit-events", events, nullptr));
    rows.push_back(make_row("D1-own", "box2d-2.4.1", box2d, &events));
#else
    rows.push_back(make_row("D1-own", "bvhkit-events", median_run(c.reps, ours), nullptr));
#endif
}

void crowd(const char* workload, int dim, const DynamicBenchConfig& c, std::FILE* log,
           std::vector<Row>& rows) {
    const Motion m = make_motion(c.n, dim, c.steps, dim == 2 ? 1001 : 2002);
    std::fprintf(log, "%s: %d boxes, %d steps, %d repetitions\n", workload, c.n, c.steps, c.reps);
    const auto run_ours = [&] {
        return dim == 2 ? run_bvhkit<2>(m, InsertionStrategy::Guided)
                        : run_bvhkit<3>(m, InsertionStrategy::Guided);
    };
    // bvhkit and the peer alternate repetitions; without the peer, bvhkit runs alone.
    RunResult base;
    std::optional<std::pair<const char*, RunResult>> peer;
#ifdef BVHKIT_HAVE_BOX2D
    if (dim == 2) {
        auto [mine, theirs] =
            median_runs_interleaved(c.reps, run_ours, [&] { return run_box2d(m); });
        base = mine;
        peer.emplace("box2d-2.4.1", theirs);
    }
#else
    if (dim == 2)
        std::fprintf(log, "%s: Box2D not built in (libbox2d-dev missing); skipped\n", workload);
#endif
#ifdef BVHKIT_HAVE_BULLET
    if (dim == 3) {
        auto [mine, theirs] =
            median_runs_interleaved(c.reps, run_ours, [&] { return run_bullet(m); });
        base = mine;
        peer.emplace("bullet-dbvt", theirs);
    }
#else
    if (dim == 3)
        std::fprintf(log, "%s: Bullet not built in (libbullet-dev missing); skipped\n", workload);
#endif
    if (!peer) base = median_run(c.reps, run_ours);
    rows.push_back(make_row(workload, "bvhkit", base, nullptr));
    // The other insertion strategies, one repetition each to keep the whole bench near a minute:
    // the exact search builds slightly cheaper trees at twice the cost of a move; the greedy
    // descent much costlier trees (see sah_cost) that make the step an order of magnitude slower.
    for (const auto& [name, strategy] :
         {std::pair{"bvhkit-exact", InsertionStrategy::BranchAndBound},
          std::pair{"bvhkit-greedy", InsertionStrategy::Greedy}}) {
        const auto other = median_run(
            1, [&, s = strategy] { return dim == 2 ? run_bvhkit<2>(m, s) : run_bvhkit<3>(m, s); });
        rows.push_back(make_row(workload, name, other, &base));
    }
    if (peer) rows.push_back(make_row(workload, peer->first, peer->second, &base));
    if (dim == 2) own_semantics(m, c, rows);
}

/// D3: churn. Starts from n / 10 boxes; then rounds of 1,000 operations (inserts, removes, moves in
/// equal parts) each followed by find_pairs; validate() after every round, outside the timing.
RunResult run_churn(int n0, int rounds, std::uint64_t seed) {
    DynamicTree<float, 3> tree;
    std::mt19937_64 rng(seed);
    const float side = float(3.0 * std::cbrt(double(n0)));
    std::uniform_real_distribution<float> pos(0.0f, side), step(-0.5f, 0.5f);
    std::vector<ProxyId> live;
    const auto unit = [](Vec3f p) { return Aabb3f(p, p + Vec3f(1.0f)); };
    const auto random_point = [&] { return Vec3f(pos(rng), pos(rng), pos(rng)); };
    RunResult r;
    std::vector<ProxyPair> pairs;
    auto t0 = Clock::now();
    for (int i = 0; i < n0; ++i) live.push_back(tree.create(unit(random_point())));
    tree.find_pairs(pairs);
    r.build_ms = ms_since(t0);
    // Pre-draw every round's operations so the timing holds only the tree's work.
    struct Op {
        int kind;
        std::size_t pick;
        Vec3f p;
    };
    std::vector<Op> ops(1000);
    double total = 0;
    long long pair_count = 0;
    for (int round = 0; round < rounds; ++round) {
        for (auto& op : ops) {
            op.kind = int(rng() % 3);
            op.pick = std::size_t(rng());
            op.p = op.kind == 2 ? Vec3f(step(rng), step(rng), step(rng)) : random_point();
        }
        t0 = Clock::now();
        for (const Op& op : ops) {
            if (op.kind == 0 || live.empty()) {
                live.push_back(tree.create(unit(op.p)));
            } else if (op.kind == 1) {
                const std::size_t k = op.pick % live.size();
                tree.destroy(live[k]);
                live[k] = live.back();
                live.pop_back();
            } else {
                const ProxyId id = live[op.pick % live.size()];
                const Aabb3f b = tree.box(id);
                r.touched += tree.move(id, Aabb3f(b.min + op.p, b.max + op.p), op.p);
            }
        }
        tree.find_pairs(pairs);
        total += ms_since(t0);
        pair_count += (long long)pairs.size();
        tree.validate();
    }
    r.step_ms = total / std::max(1, rounds);
    r.per_step.assign(2, PairSummary{});
    r.per_step[1].count = pair_count;
    r.height = tree.height();
    r.sah = tree.sah_cost();
    r.ratio = tree.area_ratio();
    return r;
}

}  // namespace

std::vector<Row> run_dynamic_bench(const DynamicBenchConfig& c, std::FILE* log) {
    std::vector<Row> rows;
    if (c.d1) crowd("D1", 2, c, log, rows);
    if (c.d2) crowd("D2", 3, c, log, rows);
    if (c.d3) {
        std::fprintf(log,
                     "D3: churn from %d boxes, %d rounds of 1,000 ops (step_ms is per round)\n",
                     c.n / 10, c.steps);
        const auto r =
            median_run(c.reps, [&] { return run_churn(std::max(1, c.n / 10), c.steps, 3003); });
        rows.push_back(make_row("D3", "bvhkit", r, nullptr));
    }
    if (c.d4) dynamic_ray_casts(c, log, rows);
    return rows;
}

}  // namespace bvhkit::bench

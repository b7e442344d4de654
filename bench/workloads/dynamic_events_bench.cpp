// D1 in Box2D's own semantics. Each library does what a physics engine asks of its broadphase every
// step, and nothing more:
//  - bvhkit: move() every moved proxy, then update_pairs(), which reports the tight-box pairs that
//    began and ended since the last step;
//  - Box2D 2.4.1: MoveProxy() every moved proxy (no TouchProxy), then UpdatePairs(), which reports
//  the
//    fat-box pairs of the proxies that were re-inserted. A Box2D world keeps those pairs as
//    contacts until their fat boxes part, and narrows them itself.
// The callbacks only store what they are given. Outside the timing, each library's answer is turned
// into the set of tight pairs overlapping after the step (bvhkit: begins added, ends removed;
// Box2D: reported pairs added, pairs whose fat boxes parted removed, then filtered by the tight
// boxes), and the two sets are compared every step.
#include <algorithm>
#include <unordered_set>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "dynamic_motion.hpp"

#ifdef BVHKIT_HAVE_BOX2D
#include <box2d/b2_broad_phase.h>
#endif

namespace bvhkit::bench::dynamic_workload {
namespace {

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return std::uint64_t(a) << 32 | b;
}

PairSummary summarize(const std::unordered_set<std::uint64_t>& set) {
    PairSummary s;
    for (const std::uint64_t k : set) s.add(std::uint32_t(k >> 32), std::uint32_t(k));
    return s;
}

}  // namespace

RunResult run_bvhkit_events(const Motion& m) {
    using Box = Aabb<float, 2>;
    DynamicTreeOptions<float> o;  // as in D1's same-answer run
    o.margin_absolute = 0.1f;
    o.displacement_multiplier = 4.0f;
    DynamicTree<float, 2> tree(o);
    const auto box_at = [](const float* p) {
        const Vec2f lo(p[0], p[1]);
        return Box(lo, lo + Vec2f(1.0f));
    };
    std::vector<ProxyPair> begins, ends;
    begins.reserve(1 << 16), ends.reserve(1 << 16);
    const auto on_begin = [&](ProxyId a, ProxyId b) { begins.push_back({a, b}); };
    const auto on_end = [&](ProxyId a, ProxyId b) { ends.push_back({a, b}); };
    RunResult r;
    r.reported = 0;
    std::unordered_set<std::uint64_t> current;
    const auto apply = [&] {
        for (const ProxyPair& p : ends)
            current.erase(pair_key(std::uint32_t(p.a.index()), std::uint32_t(p.b.index())));
        for (const ProxyPair& p : begins)
            current.insert(pair_key(std::uint32_t(p.a.index()), std::uint32_t(p.b.index())));
        r.per_step.push_back(summarize(current));
        r.reported += (long long)begins.size();
        begins.clear(), ends.clear();
    };
    auto t0 = Clock::now();
    for (int i = 0; i < m.n; ++i) tree.create(box_at(&m.start[i * 3]), std::uint64_t(i));
    tree.update_pairs(on_begin, on_end);
    r.build_ms = ms_since(t0);
    apply();
    double total = 0, moving = 0;
    for (const auto& moves : m.steps) {
        t0 = Clock::now();
        for (const auto& mv : moves)
            r.touched += tree.move(ProxyId(mv.id, 0), box_at(mv.p), Vec2f(mv.v[0], mv.v[1]));
        moving += ms_since(t0);
        tree.update_pairs(on_begin, on_end);
        total += ms_since(t0);
        apply();
    }
    r.step_ms = m.steps.empty() ? 0 : total / double(m.steps.size());
    r.move_ms = m.steps.empty() ? 0 : moving / double(m.steps.size());
    r.height = tree.height();
    r.sah = tree.sah_cost();
    r.ratio = tree.area_ratio();
    return r;
}

#ifdef BVHKIT_HAVE_BOX2D
namespace {
struct StorePairs {
    std::vector<std::pair<void*, void*>> pairs;
    void AddPair(void* a, void* b) { pairs.emplace_back(a, b); }
};
}  // namespace

RunResult run_box2d_own(const Motion& m) {
    b2BroadPhase bp;
    const auto aabb_at = [](const float* p) {
        b2AABB b;
        b.lowerBound.Set(p[0], p[1]);
        b.upperBound.Set(p[0] + 1.0f, p[1] + 1.0f);
        return b;
    };
    RunResult r;
    r.reported = 0;
    Tight tight(m);
    StorePairs cb;
    cb.pairs.reserve(1 << 16);
    std::vector<int32> ids(m.n);
    std::unordered_set<std::uint64_t> contacts;  // fat pairs kept until their fat boxes part
    const auto apply = [&] {
        for (auto [a, b] : cb.pairs)  // user data = index + 1
            contacts.insert(pair_key(std::uint32_t(reinterpret_cast<std::uintptr_t>(a) - 1),
                                     std::uint32_t(reinterpret_cast<std::uintptr_t>(b) - 1)));
        std::unordered_set<std::uint64_t> touching;
        for (auto it = contacts.begin(); it != contacts.end();) {
            const auto a = std::uint32_t(*it >> 32), b = std::uint32_t(*it);
            if (!b2TestOverlap(bp.GetFatAABB(ids[a]), bp.GetFatAABB(ids[b]))) {
                it = contacts.erase(it);
                continue;
            }
            if (tight.overlap(int(a), int(b), 2)) touching.insert(*it);
            ++it;
        }
        r.per_step.push_back(summarize(touching));
        r.reported += (long long)cb.pairs.size();
        cb.pairs.clear();
    };
    auto t0 = Clock::now();
    for (int i = 0; i < m.n; ++i)
        ids[i] = bp.CreateProxy(aabb_at(&m.start[i * 3]),
                                reinterpret_cast<void*>(std::uintptr_t(i) + 1));
    bp.UpdatePairs(&cb);
    r.build_ms = ms_since(t0);
    apply();
    double total = 0, moving = 0;
    for (const auto& moves : m.steps) {
        t0 = Clock::now();
        for (const auto& mv : moves)
            bp.MoveProxy(ids[mv.id], aabb_at(mv.p), b2Vec2(mv.v[0], mv.v[1]));
        moving += ms_since(t0);
        bp.UpdatePairs(&cb);
        total += ms_since(t0);
        tight.apply(moves);
        apply();
    }
    r.step_ms = m.steps.empty() ? 0 : total / double(m.steps.size());
    r.move_ms = m.steps.empty() ? 0 : moving / double(m.steps.size());
    r.height = bp.GetTreeHeight();
    r.touched = -1;           // b2BroadPhase::MoveProxy does not say whether it re-inserted
    r.tree_measured = false;  // the same tree as D1's Box2D row
    return r;
}
#endif

}  // namespace bvhkit::bench::dynamic_workload

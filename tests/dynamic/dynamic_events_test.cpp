// DynamicTree's pair events (update_pairs: only pairs that began or ended since the last step)
// against brute force over random moving, created and destroyed boxes, and the cast input handed
// to ray_cast / box_cast callbacks.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "test_support.hpp"

namespace {

using bvhkit::Aabb2f;
using bvhkit::DynamicTree;
using bvhkit::ProxyId;
using bvhkit::Vec2f;
using Tree = DynamicTree<float, 2>;
using SerialPair = std::pair<long, long>;  // pair of objects, by a serial never reused

bool overlap(const Aabb2f& a, const Aabb2f& b) {
    return !(a.max[0] < b.min[0] || b.max[0] < a.min[0] || a.max[1] < b.min[1] ||
             b.max[1] < a.min[1]);
}

struct World {
    std::mt19937 rng{21};
    Tree tree;
    std::map<ProxyId, std::pair<long, Aabb2f>> live;  // id -> (serial, box)
    long next_serial = 0;

    Aabb2f random_box() {
        std::uniform_real_distribution<float> pos(0, 60), size(0.5f, 4);
        const float x = pos(rng), y = pos(rng);
        return {{x, y}, {x + size(rng), y + size(rng)}};
    }
    void create() {
        const Aabb2f b = random_box();
        live[tree.create(b)] = {next_serial++, b};
    }
    std::set<SerialPair> brute_pairs() const {
        std::set<SerialPair> s;
        for (auto i = live.begin(); i != live.end(); ++i)
            for (auto j = std::next(i); j != live.end(); ++j)
                if (overlap(i->second.second, j->second.second))
                    s.insert(std::minmax(i->second.first, j->second.first));
        return s;
    }
};

TEST(DynamicTreeEvents, UpdatePairsMatchesBruteForce) {
    World w;
    for (int i = 0; i < 300; ++i) w.create();
    std::set<SerialPair> before;  // the overlapping objects after the last step
    std::map<ProxyId, long> serial_before;
    const int steps = int(bvhkit::test::scaled(300, 10));
    std::uniform_real_distribution<float> step(-1.5f, 1.5f), unit(0, 1);
    for (int s = 0; s < steps; ++s) {
        // Move about a third, destroy and create a few (ids get reused), sometimes shrink.
        std::vector<ProxyId> ids;
        for (const auto& kv : w.live) ids.push_back(kv.first);
        for (const ProxyId id : ids) {
            const float r = unit(w.rng);
            if (r < 0.3f) {
                Aabb2f& b = w.live[id].second;
                const Vec2f d{step(w.rng), step(w.rng)};
                b = Aabb2f(b.min + d, b.max + d);
                w.tree.move(id, b, d);
            } else if (r < 0.33f) {
                w.tree.destroy(id);
                w.live.erase(id);
            }
        }
        while (w.live.size() < 300) w.create();
        if (s % 25 == 24) {
            // Destroy the largest slots so that shrink_to_fit() drops them (their pairs must end).
            for (int k = 0; k < 20; ++k) {
                ProxyId id = w.live.begin()->first;
                for (const auto& kv : w.live)
                    if (kv.first.index() > id.index()) id = kv.first;
                w.tree.destroy(id);
                w.live.erase(id);
            }
            w.tree.shrink_to_fit();
        }
        if (s % 40 == 39) {  // find_pairs() in between makes the set stale, never wrong
            std::vector<bvhkit::ProxyPair> ignored;
            w.tree.find_pairs(ignored);
        }
        std::vector<bvhkit::ProxyPair> begins, ends;
        w.tree.update_pairs(
            [&](ProxyId a, ProxyId b) {
                begins.push_back({a, b});
            },
            [&](ProxyId a, ProxyId b) {
                ends.push_back({a, b});
            });
        ASSERT_TRUE(std::is_sorted(begins.begin(), begins.end()));
        ASSERT_TRUE(std::is_sorted(ends.begin(), ends.end()));
        ASSERT_TRUE(std::adjacent_find(begins.begin(), begins.end()) == begins.end());
        std::set<SerialPair> got_begin, got_end;
        for (const auto& p : begins) {
            ASSERT_LT(p.a, p.b);
            got_begin.insert(std::minmax(w.live.at(p.a).first, w.live.at(p.b).first));
        }
        for (const auto& p : ends)
            got_end.insert(std::minmax(serial_before.at(p.a), serial_before.at(p.b)));
        const std::set<SerialPair> now = w.brute_pairs();
        std::set<SerialPair> want_begin, want_end;
        std::set_difference(now.begin(), now.end(), before.begin(), before.end(),
                            std::inserter(want_begin, want_begin.end()));
        std::set_difference(before.begin(), before.end(), now.begin(), now.end(),
                            std::inserter(want_end, want_end.end()));
        ASSERT_EQ(got_begin, want_begin) << "step " << s;
        ASSERT_EQ(got_end, want_end) << "step " << s;
        ASSERT_EQ(begins.size(), want_begin.size());
        ASSERT_EQ(ends.size(), want_end.size());
        ASSERT_EQ(w.tree.current_pairs().size(), now.size());
        before = now;
        serial_before.clear();
        for (const auto& kv : w.live) serial_before[kv.first] = kv.second.first;
        if (s % 50 == 0) w.tree.validate();
    }
    // A step without changes reports nothing.
    int events = 0;
    w.tree.update_pairs([&](ProxyId, ProxyId) { ++events; }, [&](ProxyId, ProxyId) { ++events; });
    EXPECT_EQ(events, 0);
}

TEST(DynamicTreeEvents, DestroyAndRecreateInOneStepIsAnEndAndABegin) {
    Tree t;
    const ProxyId a = t.create(Aabb2f({0, 0}, {1, 1}));
    const ProxyId b = t.create(Aabb2f({0.5f, 0}, {1.5f, 1}));
    std::vector<bvhkit::ProxyPair> begins, ends;
    const auto on_begin = [&](ProxyId x, ProxyId y) { begins.push_back({x, y}); };
    const auto on_end = [&](ProxyId x, ProxyId y) { ends.push_back({x, y}); };
    t.update_pairs(on_begin, on_end);
    EXPECT_EQ(begins, (std::vector<bvhkit::ProxyPair>{{a, b}}));
    begins.clear();
    t.destroy(b);
    const ProxyId c = t.create(Aabb2f({0.5f, 0}, {1.5f, 1}));
    EXPECT_EQ(c.index(), b.index());  // the same slot, a new object: a new id
    EXPECT_NE(c, b);
    t.update_pairs(on_begin, on_end);
    EXPECT_EQ(ends, (std::vector<bvhkit::ProxyPair>{{a, b}}));
    EXPECT_EQ(begins, (std::vector<bvhkit::ProxyPair>{{a, c}}));
}

// Issue 38: the end event of a pair whose proxy was destroyed, its slot then taken by a new proxy,
// named the new proxy (and so its user data). It names the proxy that was in the pair: a stale id,
// which every call refuses, naming it.
TEST(DynamicTreeEvents, EndEventNamesTheDestroyedProxyNotItsSlotsNewOne) {
    Tree t;
    const ProxyId body = t.create(Aabb2f({0, 0}, {1, 1}), 7);
    const ProxyId old = t.create(Aabb2f({0.5f, 0}, {1.5f, 1}), 8);
    std::vector<bvhkit::ProxyPair> begins, ends;
    const auto on_begin = [&](ProxyId x, ProxyId y) { begins.push_back({x, y}); };
    const auto on_end = [&](ProxyId x, ProxyId y) {
        ends.push_back({x, y});
        // In the callback: the old proxy is gone, whatever now lives in its slot.
        EXPECT_TRUE(t.contains(x) != t.contains(y));
    };
    t.update_pairs(on_begin, on_end);
    ASSERT_EQ(begins, (std::vector<bvhkit::ProxyPair>{{body, old}}));
    begins.clear();
    t.destroy(old);
    const ProxyId fresh = t.create(Aabb2f({50, 50}, {51, 51}), 9);  // far away, same slot
    ASSERT_EQ(fresh.index(), old.index());
    t.update_pairs(on_begin, on_end);
    ASSERT_EQ(ends.size(), 1u);
    EXPECT_TRUE(begins.empty());
    const ProxyId gone = ends[0].a == body ? ends[0].b : ends[0].a;
    EXPECT_EQ(gone, old);
    EXPECT_NE(gone, fresh);
    EXPECT_FALSE(t.contains(gone));
    EXPECT_TRUE(t.contains(fresh));
    EXPECT_EQ(t.user_data(fresh), 9u);
    EXPECT_EQ(t.user_data(body), 7u);
    // A stale id is an error naming it, for every call that takes an id.
    const auto refuses = [&](auto&& call) {
        try {
            call();
            ADD_FAILURE() << "a stale id was accepted";
        } catch (const bvhkit::Error& e) {
            EXPECT_NE(std::string(e.what()).find("was destroyed"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(bvhkit::to_string(old)), std::string::npos)
                << e.what();
        }
    };
    refuses([&] { (void)t.user_data(old); });
    refuses([&] { (void)t.box(old); });
    refuses([&] { t.move(old, Aabb2f({0, 0}, {1, 1})); });
    refuses([&] { t.enlarge(old, Aabb2f({0, 0}, {1, 1})); });
    refuses([&] { t.destroy(old); });
    EXPECT_TRUE(t.contains(fresh));  // nothing happened to the slot's new proxy
    EXPECT_EQ(t.box(fresh), Aabb2f({50, 50}, {51, 51}));
    t.validate();
}

// Ids of a slot reused many times never repeat; shrink_to_fit() and clear() drop slots without
// letting a new proxy take an id handed out before.
TEST(DynamicTreeEvents, IdsNeverRepeatThroughReuseShrinkAndClear) {
    Tree t;
    std::set<ProxyId> seen;
    const auto fresh = [&](ProxyId id) { EXPECT_TRUE(seen.insert(id).second) << id; };
    std::vector<ProxyId> live;
    for (int round = 0; round < 50; ++round) {
        for (int i = 0; i < 8; ++i)
            live.push_back(t.create(Aabb2f({0, 0}, {1, 1}))), fresh(live.back());
        for (int i = 0; i < 5; ++i) t.destroy(live.back()), live.pop_back();
        if (round % 7 == 3) t.shrink_to_fit();
        if (round % 11 == 5) t.clear(), live.clear();
        t.validate();
    }
    for (const ProxyId id : seen)
        EXPECT_EQ(t.contains(id), std::find(live.begin(), live.end(), id) != live.end()) << id;
}

TEST(DynamicTreeEvents, CastCallbacksReceiveTheInput) {
    Tree t;
    std::vector<Aabb2f> boxes;
    for (int i = 0; i < 10; ++i) {
        boxes.push_back(Aabb2f({float(i) * 3 + 2, 0}, {float(i) * 3 + 3, 1}));
        t.create(boxes.back());
    }
    // Closest hit, clipping with the input as a physics engine's ray cast does: the entry fraction
    // along x is computed here from the input alone.
    const Vec2f origin{0, 0.5f}, dir{40, 0};
    int calls = 0;
    ProxyId closest = bvhkit::kNullProxy;
    float last_max = 2;
    t.ray_cast(origin, dir, 1.0f, [&](const bvhkit::CastInput<float, 2>& in, ProxyId id) {
        ++calls;
        EXPECT_EQ(in.origin, origin);
        EXPECT_EQ(in.translation, dir);
        EXPECT_EQ(in.half_extent, (Vec2f{0, 0}));
        EXPECT_LE(in.max_fraction, last_max);
        last_max = in.max_fraction;
        const float entry = (t.box(id).min[0] - in.origin[0]) / in.translation[0];
        if (entry > in.max_fraction) return -1.0f;
        closest = id;
        return entry;
    });
    EXPECT_EQ(closest, ProxyId(0, 0));
    EXPECT_GE(calls, 1);
    // Box cast: origin is the box's centre, half_extent its half size.
    const Aabb2f cast({-1, 0}, {0, 2});
    t.box_cast(cast, Vec2f{10, 0}, 1.0f, [&](const bvhkit::CastInput<float, 2>& in, ProxyId) {
        EXPECT_EQ(in.origin, (Vec2f{-0.5f, 1}));
        EXPECT_EQ(in.half_extent, (Vec2f{0.5f, 1}));
        EXPECT_EQ(in.translation, (Vec2f{10, 0}));
        return -1.0f;
    });
}

}  // namespace

// DynamicTree memory: the move buffer stays bounded by the proxy table however long find_pairs is
// not called, clear() returns everything, and shrink_to_fit() repacks the pool while keeping ids.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "test_geometry.hpp"
#include "test_support.hpp"

namespace {

using bvhkit::Aabb2f;
using bvhkit::DynamicTree;
using bvhkit::ProxyId;
using Tree = DynamicTree<float, 2>;

using bvhkit::test::box2;

TEST(DynamicTreeMemory, MoveBufferIsBoundedWithoutFindPairs) {
    Tree t;
    std::vector<ProxyId> keep;
    for (int i = 0; i < 10; ++i) keep.push_back(t.create(box2(float(i) * 3, 0)));
    const int cycles = int(bvhkit::test::scaled(1000000, 50));
    for (int c = 0; c < cycles; ++c) {
        // Create, move and destroy (the id is reused every time), and move the others.
        const ProxyId id = t.create(box2(float(c % 100), 5));
        t.move(id, box2(float(c % 100) + 0.5f, 5));
        t.destroy(id);
        t.move(keep[std::size_t(c) % keep.size()], box2(float(c % 10) * 3, 0));
        ASSERT_LE(t.move_buffer_size(), std::size_t(t.id_bound())) << "cycle " << c;
    }
    EXPECT_LE(t.move_buffer_size(), 11u);
    t.validate();
    std::vector<bvhkit::ProxyPair> pairs;
    t.find_pairs(pairs);
    EXPECT_EQ(t.move_buffer_size(), 0u);
    for (const auto& p : pairs) EXPECT_TRUE(t.contains(p.a) && t.contains(p.b));
}

TEST(DynamicTreeMemory, ClearReturnsAllMemory) {
    Tree t;
    const int n = int(bvhkit::test::scaled(100000));
    for (int i = 0; i < n; ++i) t.create(box2(float(i % 300), float(i / 300)));
    t.rebuild();
    t.optimize(100);
    std::vector<bvhkit::ProxyPair> pairs;
    t.find_pairs(pairs);
    EXPECT_GT(t.memory_bytes(), std::size_t(n) * 32);
    t.clear();
    EXPECT_EQ(t.memory_bytes(), 0u);
    EXPECT_EQ(t.stats().node_capacity, 0u);
    t.validate();
    const ProxyId a = t.create(box2(0, 0));  // usable again
    EXPECT_EQ(a.index(), 0);
    EXPECT_GT(a.generation(), 0u);  // not the id slot 0's proxy had before clear()
    t.validate();
}

TEST(DynamicTreeMemory, ShrinkToFitKeepsIdsAndAnswers) {
    Tree t;
    const int n = int(bvhkit::test::scaled(100000));
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0, 400);
    std::vector<Aabb2f> boxes;
    std::vector<ProxyId> ids;
    for (int i = 0; i < n; ++i) {
        boxes.push_back(box2(u(rng), u(rng)));
        ids.push_back(t.create(boxes.back()));
    }
    std::vector<bvhkit::ProxyPair> pairs;
    t.find_pairs(pairs);
    // Destroy everything but every tenth proxy, and the whole upper half of the ids.
    std::vector<char> alive(std::size_t(n), 0);
    for (int i = 0; i < n; ++i) {
        if (i % 10 == 0 && i < n / 2)
            alive[std::size_t(i)] = 1;
        else
            t.destroy(ids[std::size_t(i)]);
    }
    const std::size_t before = t.memory_bytes();
    t.shrink_to_fit();
    t.validate();
    EXPECT_LT(t.memory_bytes() * 4, before);
    EXPECT_EQ(t.stats().node_capacity, t.stats().nodes);
    EXPECT_LE(std::size_t(t.id_bound()), std::size_t(n) / 2);
    for (int q = 0; q < 100; ++q) {
        const Aabb2f qb = box2(u(rng), u(rng), 20, 20);
        std::vector<ProxyId> got, want;
        t.query(qb, [&](ProxyId id) { return got.push_back(id), true; });
        for (int i = 0; i < n; ++i)
            if (alive[std::size_t(i)] && boxes[std::size_t(i)].overlaps(qb))
                want.push_back(ProxyId(i, 0));
        std::sort(got.begin(), got.end());
        ASSERT_EQ(got, want);
    }
    for (int i = 0; i < n; i += 10)
        if (alive[std::size_t(i)]) {
            ASSERT_EQ(t.box(ProxyId(i, 0)), boxes[std::size_t(i)]);
        }
    // Growing again after the shrink reuses the freed ids first and stays valid.
    for (int i = 0; i < 1000; ++i) {
        const ProxyId id = t.create(box2(u(rng), u(rng)));
        EXPECT_LT(id.index(), n / 2);
    }
    t.validate();
    t.find_pairs(pairs);
    t.validate();
}

}  // namespace

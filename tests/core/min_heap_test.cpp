// MinHeap4 (walk/min_heap.hpp) against a sorted multiset: random interleavings of pushes and pops,
// with many equal keys, always pop the least key, and every pushed entry comes out exactly once.
#include <gtest/gtest.h>

#include <set>

#include "bvhkit/math/random.hpp"
#include "bvhkit/walk/min_heap.hpp"

using namespace bvhkit;

namespace {

struct Item {
    float key;
    std::uint32_t id;
};

}  // namespace

TEST(MinHeap4, PopsInKeyOrderLikeAMultiset) {
    SplitMix64 rng(5);
    std::vector<Item> storage;
    for (int trial = 0; trial < 200; ++trial) {
        MinHeap4 heap(storage, [](const Item& i) { return i.key; });
        std::multiset<std::pair<float, std::uint32_t>> truth;
        std::uint32_t next_id = 0;
        const int steps = int(rng.below(2000)) + 1;
        const std::uint32_t distinct = 1 + rng.below(trial % 2 ? 8 : 100000);  // ties or not
        for (int s = 0; s < steps; ++s) {
            if (truth.empty() || rng.below(3) != 0) {
                const Item it{float(rng.below(distinct)), next_id++};
                heap.push(it);
                truth.insert({it.key, it.id});
            } else {
                ASSERT_EQ(heap.top().key, truth.begin()->first);
                const Item got = heap.pop();
                ASSERT_EQ(got.key, truth.begin()->first) << "trial " << trial << " step " << s;
                const auto found = truth.find({got.key, got.id});
                ASSERT_NE(found, truth.end()) << "popped an entry twice or never pushed";
                truth.erase(found);
            }
            ASSERT_EQ(heap.empty(), truth.empty());
        }
        while (!heap.empty()) {
            const Item got = heap.pop();
            ASSERT_FALSE(truth.empty());
            ASSERT_EQ(got.key, truth.begin()->first);
            const auto found = truth.find({got.key, got.id});
            ASSERT_NE(found, truth.end());
            truth.erase(found);
        }
        ASSERT_TRUE(truth.empty()) << truth.size() << " entries never came out";
    }
}

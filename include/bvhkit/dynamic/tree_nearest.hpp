#pragma once
// The dynamic tree's best-first walk from a point: proxies in increasing order of the distance from
// the point to their boxes, for a caller that measures its own shapes and keeps a running bound
// (the closest point over a scene of instances). walk_best_first (walk/walks.hpp) over a min-heap
// keyed by the squared distance to each node's fat box (and to each reached proxy's tight box): a
// popped entry farther than the bound ends the walk, since every entry left is farther still.
// Distances are taken in a wider type W (double for float trees, long double for double ones), so
// squares neither overflow nor sink to zero at the scales T holds.
#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "bvhkit/dynamic/tree_queries.hpp"
#include "bvhkit/dynamic/tree_types.hpp"
#include "bvhkit/walk/walks.hpp"

namespace bvhkit {

/// The type the nearest walk measures in: double for float trees, long double for double ones.
template <class T>
using NearestWalkScalar = std::conditional_t<(sizeof(T) < sizeof(double)), double, long double>;

namespace dynamic_detail {

template <class W>
struct NearestEntry {
    W key;              // squared distance from the point to the node's box
    std::int32_t node;  // a node, or -(slot + 1) for a proxy keyed by its tight box
};

/// Squared distance from p to the box in W (0 inside or on it); the box's bounds and p are exact in
/// W and each difference is rounded once.
template <class W, class T, std::size_t N>
W box_distance_squared(const Aabb<T, N>& box, const Vec<T, N>& p) {
    W sum = 0;
    for (std::size_t i = 0; i < N; ++i) {
        const W below = W(box.min[i]) - W(p[i]), above = W(p[i]) - W(box.max[i]);
        const W gap = std::max(std::max(below, above), W(0));
        sum += gap * gap;
    }
    return sum;
}

/// The nearest walk's heap: a binary heap (std::push_heap and std::pop_heap) on the caller's
/// vector. Its order among equal keys, not MinHeap4's, decides which of two equally near proxies
/// is reported first, and so which of two equally near instances a scene query returns.
template <class W>
class NearestHeap {
  public:
    explicit NearestHeap(std::vector<NearestEntry<W>>& storage) : v_(storage) { v_.clear(); }
    bool empty() const { return v_.empty(); }
    W key(const NearestEntry<W>& e) const { return e.key; }
    void push(const NearestEntry<W>& e) {
        v_.push_back(e);
        std::push_heap(v_.begin(), v_.end(), Later{});
    }
    NearestEntry<W> pop() {
        std::pop_heap(v_.begin(), v_.end(), Later{});
        const NearestEntry<W> e = v_.back();
        v_.pop_back();
        return e;
    }

  private:
    // A function object, not a function: its calls inline into the heap's sifts.
    struct Later {
        bool operator()(const NearestEntry<W>& a, const NearestEntry<W>& b) const {
            return a.key > b.key;
        }
    };
    std::vector<NearestEntry<W>>& v_;
};

/// callback(ProxyId, W box_distance_squared) -> W: the new bound (squared), kept when smaller; a
/// negative value stops the walk. Proxies are reported in increasing distance of their tight
/// boxes, each while that distance is within the bound (inclusive): a leaf met in the walk goes
/// back into the heap under its tight box's key.
template <class T, std::size_t N, class U, class W, class F>
void nearest_first(const TreeView<T, N, U>& t, const Vec<T, N>& p, W bound_squared, F&& callback,
                   std::vector<NearestEntry<W>>& heap, QueryStats* stats) {
    if (t.root == kNullNode) return;
    std::uint64_t visited = 1, tested = 0;
    NearestHeap<W> queue(heap);
    const W root_key = box_distance_squared<W>(t.nodes[t.root].box, p);
    if (root_key <= bound_squared) queue.push({root_key, t.root});
    // Every entry left is at least as far as a popped one beyond the bound.
    const auto hopeless = [&](W key) { return key > bound_squared; };
    const auto step = [&](NearestEntry<W>& e, NearestHeap<W>& q) {
        if (e.node < 0) {  // a proxy, keyed by its tight box: its turn in the order
            const std::int32_t slot = -e.node - 1;
            const W next = callback(proxy_id(t, slot), e.key);
            if (next < W(0)) return Step::Stop;
            bound_squared = std::min(bound_squared, next);
            return Step::Pop;
        }
        const Node<T, N>& n = t.nodes[e.node];
        if (n.is_leaf()) {
            // Requeued under its tight box, which may be farther than other nodes' fat boxes.
            ++tested;
            const W key = box_distance_squared<W>(t.proxies[n.value()].box, p);
            if (!(key > bound_squared)) q.push({key, -n.value() - 1});
            return Step::Pop;
        }
        visited += 2;
        for (const std::int32_t c : {n.child1, n.child2}) {
            const W key = box_distance_squared<W>(t.nodes[c].box, p);
            if (!(key > bound_squared)) q.push({key, c});
        }
        return Step::Pop;
    };
    walk_best_first(queue, hopeless, step);
    if (stats) stats->nodes_visited += visited, stats->leaves_tested += tested;
}

}  // namespace dynamic_detail
}  // namespace bvhkit

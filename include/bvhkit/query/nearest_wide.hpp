#pragma once
// The best-first nearest walk of nearest.hpp over a WideSlotBvh: a min-heap of nodes keyed by their
// squared distance from the point and a search radius that shrinks as closer primitives are
// found. A node measures its four children at once; leaf children within the radius are opened
// on the spot (shrinking the radius before the inner children are judged), the nearest inner
// child is walked into, and the others within the radius wait in the heap.
//
// on_leaf(first_group, group_count) opens a leaf child and may lower `radius2`; the optional
// on_leaf.address(first_group) gives the address of its data (as an integer) to prefetch.
#include "bvhkit/bvh/wide_bvh.hpp"
#include "bvhkit/math/select.hpp"
#include "bvhkit/query/nearest.hpp"
#include "bvhkit/simd/simd.hpp"

namespace bvhkit {

namespace wide_detail {

/// Squared distances from p to the node's child boxes (0 inside) in `d`; returns a bit per
/// child that exists and lies within `radius2`.
template <class T>
[[gnu::always_inline]] inline unsigned children_within(const WideSlotNode<T>& node,
                                                       const Vec<T, 3>& p, T radius2, T d[4]) {
#if BVHKIT_SIMD
    if constexpr (std::is_same_v<T, float>) {
        using F = simd::Float<4>;
        F sum = F::zero();
        for (int a = 0; a < 3; ++a) {
            const F q(p[a]);
            const F gap = max(max(F::load(node.lo[a]) - q, q - F::load(node.hi[a])), F::zero());
            sum = sum + gap * gap;
        }
        sum.store_unaligned(d);
        return (sum <= F(radius2)).bits() & ~lanes_equal(node.child, invalid_index);
    }
#endif
    unsigned within = 0;
    for (int c = 0; c < 4; ++c) {
        T s = 0;
        for (int a = 0; a < 3; ++a) {
            const T g = max_of(max_of(node.lo[a][c] - p[a], p[a] - node.hi[a][c]), T(0));
            s += g * g;
        }
        d[c] = s;
        within |= unsigned(node.has(c) && s <= radius2) << c;
    }
    return within;
}

/// A bit per child that is a leaf.
template <class T>
[[gnu::always_inline]] inline unsigned leaf_children(const WideSlotNode<T>& node) {
    return 15u & ~lanes_equal(node.groups, 0u);
}

}  // namespace wide_detail

/// Walks `wide` best first from p while nodes lie within `radius2`, calling on_leaf for each leaf
/// child within it (see above); stats.node() counts child boxes measured.
template <class T, class OnLeaf, class Stats>
void nearest_wide(const WideSlotBvh<T>& wide, const Vec<T, 3>& p, NearestScratch<T>& scratch,
                  T& radius2, OnLeaf&& on_leaf, Stats&& stats) {
    if (wide.empty()) return;
    const WideSlotNode<T>* nodes = wide.nodes.data();
    MinHeap4 heap(scratch.heap, [](const NearestEntry<T>& e) { return e.distance_squared; });
    heap.push({T(0), 0});
    const auto hopeless = [&](T d2) { return d2 > radius2; };  // every node left is farther
    walk_best_first(heap, hopeless, [&](NearestEntry<T>& e, auto& queue) {
        const WideSlotNode<T>& node = nodes[e.node];
        T d[4];
        const unsigned within = wide_detail::children_within(node, p, radius2, d);
        for (int c = 0; c < 4; ++c)
            if (node.has(c)) stats.node();
        const unsigned leaves = wide_detail::leaf_children(node) & within;
        // Ask for every child within the radius before opening any: the leaves' triangles
        // and the inner nodes' lines load together instead of one after another. (The lanes'
        // addresses chosen without jumps, for all four lanes, cost more than the jumps.)
        for (unsigned m = within; m; m &= m - 1) {
            const int c = __builtin_ctz(m);
            std::uintptr_t line;
            if (!(leaves >> c & 1u))
                line = reinterpret_cast<std::uintptr_t>(nodes + node.child[c]);
            else if constexpr (requires { on_leaf.address(0u); })
                line = on_leaf.address(node.child[c]);
            else
                continue;
            const char* at = reinterpret_cast<const char*>(line);
            __builtin_prefetch(at);
            __builtin_prefetch(at + 64);
            __builtin_prefetch(at + 128);
        }
        for (unsigned m = leaves; m; m &= m - 1) {
            const int c = __builtin_ctz(m);
            on_leaf(node.child[c], node.groups[c]);
        }
        // The nearest inner child within the (perhaps smaller) radius is next; the others wait.
        unsigned inner = within & ~leaves;
        if (leaves)
            for (unsigned m = inner; m; m &= m - 1)
                inner &= ~(unsigned(d[__builtin_ctz(m)] > radius2) << __builtin_ctz(m));
        if (!inner) return Step::Pop;
        int next = __builtin_ctz(inner);
        for (unsigned m = inner & (inner - 1); m; m &= m - 1) {
            const int c = __builtin_ctz(m);
            next = d[c] < d[next] ? c : next;
        }
        for (unsigned m = inner & ~(1u << next); m; m &= m - 1) {
            const int c = __builtin_ctz(m);
            queue.push({d[c], node.child[c]});
        }
        e.node = node.child[next];
        return Step::Continue;
    });
}

}  // namespace bvhkit

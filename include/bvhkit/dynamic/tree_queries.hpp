#pragma once
// The dynamic tree's queries, written against a read-only view of its arrays: box overlap, point,
// ray cast, box cast and tree against tree. None recurses: box and point queries and the casts walk
// on walk_depth_first and tree against tree on walk_pairs (walk/walks.hpp), with a SmallStack (on
// the caller's frame); a cast's node handles carry the entry fraction that lets a shortened
// segment drop them. Leaves are reported when the proxy's own (tight) box passes the test; the fat
// boxes in the nodes only steer the descent.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "bvhkit/dynamic/small_stack.hpp"
#include "bvhkit/dynamic/tree_types.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/walk/walks.hpp"

namespace bvhkit::dynamic_detail {

template <class T, std::size_t N, class U>
struct TreeView {
    const Node<T, N>* nodes;
    const Proxy<T, N, U>* proxies;
    std::int32_t root;
};

/// The tree's shape as a NodeView (walk/walks.hpp), for the walk skeletons. Its depth has no bound,
/// so the walks run on a SmallStack, which grows past its inline entries.
template <class T, std::size_t N>
struct DynamicNodes {
    using Ref = std::int32_t;
    const Node<T, N>* nodes;
    std::int32_t root_node;
    Ref root() const { return root_node; }
    bool is_leaf(Ref r) const { return nodes[r].is_leaf(); }
    Ref child(Ref r, unsigned k) const { return k == 0 ? nodes[r].child1 : nodes[r].child2; }
};

template <class T, std::size_t N, class U>
DynamicNodes<T, N> node_view(const TreeView<T, N, U>& t) {
    return {t.nodes, t.root};
}

/// The id of the proxy in slot `i`: its generation sits in the record the leaf test just read.
template <class T, std::size_t N, class U>
inline ProxyId proxy_id(const TreeView<T, N, U>& t, std::int32_t i) {
    return ProxyId(i, t.proxies[i].generation);
}

template <class T, std::size_t N, class U>
inline void prefetch_next(const TreeView<T, N, U>& t, const Node<T, N>& n) {
#if defined(__GNUC__)
    if (n.is_leaf()) {
        __builtin_prefetch(&t.proxies[n.value()]);
    } else {
        __builtin_prefetch(&t.nodes[n.child1]);
        __builtin_prefetch(&t.nodes[n.child2]);
    }
#else
    (void)t, (void)n;
#endif
}

/// Box overlap: callback(ProxyId) -> bool, false stops the query. Pre-order, child1 first.
template <class T, std::size_t N, class U, class F>
void query_box(const TreeView<T, N, U>& t, const Aabb<T, N>& box, F&& callback, QueryStats* stats) {
    if (t.root == kNullNode) return;
    std::uint64_t visited = 0, tested = 0;
    // Children are tested before they are pushed, so the stack only ever holds nodes that overlap.
    const auto enter = [&](std::int32_t i) {
        ++visited;
        const Node<T, N>& n = t.nodes[i];
        if (!n.box.overlaps(box)) return false;
        // The tree is scattered in memory: ask for what the node will read when it is opened
        // (its children, or its proxy) now, so the loads overlap with other work.
        prefetch_next(t, n);
        return true;
    };
    const auto on_leaf = [&](std::int32_t i) {
        ++tested;
        const std::int32_t slot = t.nodes[i].value();
        return !t.proxies[slot].box.overlaps(box) || callback(proxy_id(t, slot));
    };
    SmallStack<std::int32_t> stack;
    walk_depth_first<Gate::BeforePush>(node_view(t), stack, enter, on_leaf, FirstChild::Left);
    if (stats) stats->nodes_visited += visited, stats->leaves_tested += tested;
}

/// Point: every proxy whose box contains p (boundary included). callback(ProxyId) -> bool.
template <class T, std::size_t N, class U, class F>
void query_point(const TreeView<T, N, U>& t, const Vec<T, N>& p, F&& callback, QueryStats* stats) {
    query_box(t, Aabb<T, N>(p, p), callback, stats);
}

/// A cast's segment origin + s * direction, s in [0, max_fraction], tested with the library's slab
/// test (math/ray.hpp: exact for +0/-0 direction components, conservative after Ize 2013) against
/// boxes grown by a pad (zero for a ray cast, the cast box's half extents for a box cast).
template <class T, std::size_t N>
struct CastSegment {
    RaySlabData<T, N> slab;

    CastSegment(const Vec<T, N>& o, const Vec<T, N>& d) : slab(Ray<T, N>(o, d)) {}

    /// The entry fraction (0 when the origin is inside), or a negative value on a miss.
    T entry(const Aabb<T, N>& box, const Vec<T, N>& pad, T max_fraction) const {
        T t0 = T(0), t1 = max_fraction;
        return slab.clip(Aabb<T, N>(box.min - pad, box.max + pad), t0, t1) ? t0 : T(-1);
    }
};

/// A node of a cast's walk and where the segment enters its box (a fraction of it).
template <class T>
struct CastRef {
    std::int32_t node;
    T entry;
};

/// Ray (or box) cast of `in` (every box grown by in.half_extent: zero for a ray, the cast box's
/// half extents for a box cast) along `seg`, its slab form. The callback is either
/// callback(ProxyId, T max_fraction) or callback(const CastInput&, ProxyId), returning T, as games
/// expect:
///   < 0  ignore this proxy, go on with the same max fraction
///   == 0 stop the query
///   > 0  go on, clipping the segment to this new max fraction (never lengthening it: a value
///        above the current max fraction leaves it as it is)
/// Children are clipped before they are pushed and the nearer one (by entry fraction) is walked
/// first, so a callback that clips (closest hit) shortens the segment early and the farther
/// subtrees are dropped when popped: their entry then lies beyond the new max fraction.
template <class T, std::size_t N, class U, class F>
void cast(const TreeView<T, N, U>& t, const CastSegment<T, N>& seg, CastInput<T, N> in,
          F&& callback, QueryStats* stats) {
    if (t.root == kNullNode) return;
    const Vec<T, N> pad = in.half_extent;
    T& max_fraction = in.max_fraction;
    std::uint64_t visited = 1, tested = 0;
    const T root_entry = seg.entry(t.nodes[t.root].box, pad, max_fraction);
    if (root_entry < T(0)) {
        if (stats) stats->nodes_visited += visited;
        return;
    }
    // A node stays pending with the fraction where the segment enters its box: popped after the
    // segment was clipped short of that, it is dropped.
    const auto enter = [&](const CastRef<T>& r) { return !(r.entry > max_fraction); };
    const auto on_leaf = [&](const CastRef<T>& r) {
        ++tested;
        const std::int32_t slot = t.nodes[r.node].value();
        if (seg.entry(t.proxies[slot].box, pad, max_fraction) < T(0)) return true;
        T value;
        if constexpr (std::is_invocable_v<F&, const CastInput<T, N>&, ProxyId>)
            value = callback(std::as_const(in), proxy_id(t, slot));
        else
            value = callback(proxy_id(t, slot), max_fraction);
        if (value == T(0)) return false;
        // A value above the current max leaves it: subtrees beyond it were dropped at push.
        if (value > T(0)) max_fraction = std::min(max_fraction, value);
        return true;
    };
    // Both children clipped; the nearer (by entry fraction) is gone on with, the farther pushed.
    const auto open = [&](CastRef<T>& r, SmallStack<CastRef<T>>& stack) -> bool {
        const Node<T, N>& n = t.nodes[r.node];
        visited += 2;
        const T e1 = seg.entry(t.nodes[n.child1].box, pad, max_fraction);
        const T e2 = seg.entry(t.nodes[n.child2].box, pad, max_fraction);
        const bool first_is_1 = e1 <= e2;
        const CastRef<T> near{first_is_1 ? n.child1 : n.child2, first_is_1 ? e1 : e2};
        const CastRef<T> far{first_is_1 ? n.child2 : n.child1, first_is_1 ? e2 : e1};
        if (far.entry >= T(0)) {
            if (near.entry < T(0)) {
                r = far;
                prefetch_next(t, t.nodes[far.node]);
                return true;
            }
            stack.push(far);
            prefetch_next(t, t.nodes[far.node]);
        }
        if (near.entry < T(0)) return false;
        r = near;
        prefetch_next(t, t.nodes[near.node]);
        return true;
    };
    SmallStack<CastRef<T>> stack;
    walk_depth_first(CarryingNodes<Node<T, N>, CastRef<T>>{t.nodes, {t.root, root_entry}}, stack,
                     enter, on_leaf, open);
    if (stats) stats->nodes_visited += visited, stats->leaves_tested += tested;
}

/// Every pair (proxy of a, proxy of b) whose boxes overlap. callback(ProxyId a, ProxyId b) -> bool.
/// Descent: a pair of nodes whose boxes overlap is split on the side that is internal and, when
/// both are, on the one with the larger area (so the two boxes stay of similar size).
template <class T, std::size_t N, class U, class V, class F>
void query_tree(const TreeView<T, N, U>& a, const TreeView<T, N, V>& b, F&& callback,
                QueryStats* stats) {
    if (a.root == kNullNode || b.root == kNullNode) return;
    struct NodePair {
        std::int32_t a, b;
    };
    std::uint64_t visited = 0, tested = 0;
    const auto enter = [&](const NodePair& p) {
        ++visited;
        return a.nodes[p.a].box.overlaps(b.nodes[p.b].box);
    };
    const auto on_leaves = [&](const NodePair& p) {
        ++tested;
        const std::int32_t sa = a.nodes[p.a].value(), sb = b.nodes[p.b].value();
        return !a.proxies[sa].box.overlaps(b.proxies[sb].box) ||
               callback(proxy_id(a, sa), proxy_id(b, sb));
    };
    // The descent rule (see above); the first child's pair is pushed last, so it is walked first.
    const auto open = [&](const NodePair& p, auto& pairs) {
        const Node<T, N>& na = a.nodes[p.a];
        const Node<T, N>& nb = b.nodes[p.b];
        if (nb.is_leaf() || (!na.is_leaf() && na.box.area() >= nb.box.area())) {
            pairs.push({na.child2, p.b});
            pairs.push({na.child1, p.b});
        } else {
            pairs.push({p.a, nb.child2});
            pairs.push({p.a, nb.child1});
        }
    };
    SmallStack<NodePair> stack;
    walk_pairs(node_view(a), node_view(b), stack, NodePair{a.root, b.root}, enter, on_leaves, open);
    if (stats) stats->nodes_visited += visited, stats->leaves_tested += tested;
}

}  // namespace bvhkit::dynamic_detail

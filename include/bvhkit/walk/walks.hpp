#pragma once
// The three walk skeletons every query stands on but the ray walks and the tree-against-tree pairs
// of query/pairs.hpp, and the node view they read a tree through. A query is its tests and its
// answer; the loop, the stack or heap and the stop rules are here, once:
//
//   walk_depth_first  one tree, pre-order, with an optional child order: enter(ref) says whether
//                     the walk goes into a node (asked as it is reached, or of both children
//                     before either is pushed), on_leaf(ref) takes a leaf and may stop the walk.
//                     It pushes one child and goes straight on into the other, so the stack holds
//                     at most one entry per level. A query that opens nodes itself (clips the
//                     children, drops some, orders them, or has more than two) passes an opener
//                     open(ref, stack) instead of a child order: it pushes the children for later
//                     and hands back the one to go on with.
//   walk_best_first   entries in one heap (MinHeap4, walk/min_heap.hpp) keyed by a lower bound on
//                     their distance; the walk ends at the first popped entry that is hopeless
//                     (its bound cannot beat the answer: nothing left in the heap can).
//                     step(entry, heap) opens an entry and may hand back a child to go on with at
//                     once (a trip through the heap saved), or stop the walk.
//   walk_pairs        two trees (or one against itself) depth first over pairs of nodes: a pair of
//                     leaves goes to on_leaves(pair), which may stop the walk; any other pair to
//                     open(pair, stack), the descent rule, which pushes the child pairs worth
//                     visiting (which side to split, which test, which order: the query's).
//
// The node view (NodeView) is what the skeletons ask of a tree: the root and whether a node is a
// leaf, by a small handle (Ref) that need not be an index into one array: it may carry what the
// walk knows of the node on the way down (the part of a ray inside its cell, say); BinaryNodeView
// adds the children, for walks that let the skeleton open nodes. A leaf's contents are the
// query's business: the skeletons hand over the leaf's Ref and never look inside, so a tree whose
// leaves are instances of other trees is walked by a view of the top level whose on_leaf starts a
// walk of the instance's own view.
//
// The skeletons are forced inline: a query's callbacks then read its locals in its own frame, not
// through a closure in memory, and the query costs what its own loop did.
//
// Stacks and heaps come from the caller, so a query allocates nothing: a FixedStack
// (bvh/traversal_stack.hpp) for trees whose depth max_bvh_depth bounds; any type with
// push/pop/empty/clear works, so the dynamic tree, whose depth nothing bounds, walks on its
// growable SmallStack, and the BSP on a stack sized by its depth. Any heap with
// push/pop/empty/key works the same way.
//
// This folder includes nothing of volumes/ and nothing above: bvh/ and bsp/ (one layer, which may
// not include each other) both walk on it.
#include <concepts>
#include <type_traits>

#include "bvhkit/walk/min_heap.hpp"

namespace bvhkit {

/// A read-only view of a tree's shape: Ref names a node (and may carry what the walk knows of it);
/// root() and is_leaf(ref).
template <class V>
concept NodeView = requires(const V& v, typename V::Ref r) {
    { v.root() } -> std::same_as<typename V::Ref>;
    { v.is_leaf(r) } -> std::convertible_to<bool>;
};

/// A NodeView of a binary tree that names the children: child(ref, k) for k = 0, 1 (the first
/// child, then the second).
template <class V>
concept BinaryNodeView = NodeView<V> && requires(const V& v, typename V::Ref r) {
    { v.child(r, 0) } -> std::same_as<typename V::Ref>;
};

/// A NodeView over one array of nodes whose handles carry what the walk knows of each node: Ref has
/// a member `node` (the index into `nodes`, whose elements have is_leaf()), and the walk starts at
/// `start`. For walks that open nodes themselves (an opener, below).
template <class Node, class R>
struct CarryingNodes {
    using Ref = R;
    const Node* nodes;
    Ref start;
    constexpr Ref root() const { return start; }
    constexpr bool is_leaf(const Ref& r) const { return nodes[r.node].is_leaf(); }
};

enum class FirstChild { Left, Right };

/// When a depth-first walk asks enter(): as it reaches a node (OnEntry), or for both children of
/// an inner node before either is pushed (BeforePush: only children that pass are pushed, which
/// pays where most are rejected and a push costs more than a test, as on a growable stack).
enum class Gate { OnEntry, BeforePush };

/// Depth first from the view's root; see the top of this file. `first` says how an inner node is
/// opened:
///   FirstChild::Left or FirstChild::Right, or a callable first(ref) -> unsigned (0 or 1) for an
///   order that depends on the node (nearer child first): the skeleton takes the view's two
///   children (a BinaryNodeView), entering that one first;
///   an opener open(Ref& ref, Stack& stack) -> bool: the query opens the node itself, pushes the
///   children to visit later (the last pushed is popped first), and either sets ref to the child
///   to go on with and returns true, or returns false (the walk pops). Gate::OnEntry only: enter()
///   is asked of every child as it is reached, the one gone on with and each popped one.
/// Returns false when on_leaf stopped the walk.
template <Gate gate = Gate::OnEntry, NodeView View, class Stack, class Enter, class OnLeaf,
          class First>
[[gnu::always_inline]] inline bool walk_depth_first(const View& view, Stack& stack, Enter&& enter,
                                                    OnLeaf&& on_leaf, First&& first) {
    using Ref = typename View::Ref;
    constexpr bool opener = std::is_invocable_r_v<bool, First&, Ref&, Stack&>;
    static_assert(!opener || gate == Gate::OnEntry, "an opener's children are entered as reached");
    stack.clear();
    Ref current = view.root();
    if constexpr (gate == Gate::BeforePush)
        if (!enter(current)) return true;
    while (true) {
        if (gate == Gate::BeforePush || enter(current)) {
            if (!view.is_leaf(current)) {
                if constexpr (opener) {
                    if (first(current, stack)) continue;
                } else {
                    static_assert(BinaryNodeView<View>, "the skeleton opens nodes by child()");
                    unsigned k;
                    if constexpr (std::is_same_v<std::decay_t<First>, FirstChild>)
                        k = first == FirstChild::Left ? 0u : 1u;
                    else
                        k = unsigned(first(current));
                    const Ref near = view.child(current, k), far = view.child(current, 1u - k);
                    if constexpr (gate == Gate::OnEntry) {
                        stack.push(far);
                        current = near;
                        continue;
                    } else {
                        const bool in_near = enter(near), in_far = enter(far);
                        if (in_near) {
                            if (in_far) stack.push(far);
                            current = near;
                            continue;
                        }
                        if (in_far) {
                            current = far;
                            continue;
                        }
                    }
                }
            } else if (!on_leaf(current)) {
                return false;
            }
        }
        if (stack.empty()) return true;
        current = stack.pop();
    }
}

/// What a best-first step does next.
enum class Step {
    Pop,       // take the least entry from the heap
    Continue,  // go on with the entry the step left in its argument (not checked again)
    Stop,      // end the walk
};

/// Best first over `heap` (entries already pushed: usually the root); see the top of this file.
/// hopeless(key) says an entry of that key cannot improve the answer; it is asked of every popped
/// entry, and ends the walk, the heap being ordered. step(Entry& e, Heap& heap) opens e.
template <class Heap, class Hopeless, class StepF>
[[gnu::always_inline]] inline void walk_best_first(Heap& heap, Hopeless&& hopeless, StepF&& step) {
    while (!heap.empty()) {
        auto e = heap.pop();
        if (hopeless(heap.key(e))) return;
        Step s;
        while ((s = step(e, heap)) == Step::Continue) {
        }
        if (s == Step::Stop) return;
    }
}

/// Pairs of nodes depth first from `root`; see the top of this file. A pair is a struct with
/// members a and b (Refs of view_a and view_b); enter(pair) is asked of each pair as it is popped
/// (return true where the pushes were already tested). Returns false when on_leaves stopped the
/// walk.
template <NodeView ViewA, NodeView ViewB, class Stack, class Pair, class Enter, class OnLeaves,
          class Open>
[[gnu::always_inline]] inline bool walk_pairs(const ViewA& view_a, const ViewB& view_b,
                                              Stack& stack, const Pair& root, Enter&& enter,
                                              OnLeaves&& on_leaves, Open&& open) {
    stack.clear();
    stack.push(root);
    while (!stack.empty()) {
        const Pair p = stack.pop();
        if (!enter(p)) continue;
        if (view_a.is_leaf(p.a) && view_b.is_leaf(p.b)) {
            if (!on_leaves(p)) return false;
            continue;
        }
        open(p, stack);
    }
    return true;
}

/// Always true: enter() for walks that test before they push.
struct EnterAll {
    template <class... A>
    constexpr bool operator()(const A&...) const {
        return true;
    }
};

}  // namespace bvhkit

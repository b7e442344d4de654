#pragma once
// The node of a linked tree (bvh/linked_tree.hpp) and the SAH algorithms that work on an array of
// them: choosing the sibling of a new leaf or subtree (greedy descent, guided descent, exact branch
// and bound), refitting a node, and the four tree rotations. The dynamic tree, the insertion
// builder and the reinsertion optimizer all run these.
//
// Cost model (MacDonald and Booth's SAH): the cost of a tree is the sum of the areas of
// its internal nodes ("area" = perimeter in 2D, surface area in 3D). The root and the leaves are
// the same in every tree over the same leaves, so only the internal nodes matter.
//
// Inserting leaf L as the sibling of node S creates a new parent P = S u L and grows every ancestor
// of S to include L. The increase in tree cost is
//     cost(S) = area(S u L)                                  -- the direct cost: the new node P
//             + sum over ancestors A of S: area(A u L) - area(A)   -- the inherited cost
// and the best sibling is the S that minimizes it.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "bvhkit/math/aabb.hpp"

namespace bvhkit::linked {

/// The index that links to nothing: no parent (the root), no child (a leaf), end of the free list.
inline constexpr std::int32_t null = -1;

/// One node of a linked tree's pool, linked to its parent and children by index. 32 bytes for 2D
/// float, 40 for 3D float. The fields by kind of node:
///   internal: parent, child1, child2;
///   leaf:     parent, child1 == null, and the owner's number for the leaf (value()) in child2;
///   free:     height -1, the next free node in parent.
/// The height has 31 bits: a pool of at most 2^31 nodes cannot be taller, whatever the input.
template <class T, std::size_t N>
struct Node {
    Aabb<T, N> box;  // the leaf's box; an internal node's: the union of its children's
    std::int32_t parent = null;
    std::int32_t child1 = null;
    std::int32_t child2 = null;
    std::int32_t height : 31 = 0;    // leaf 0, free -1
    std::uint32_t enlarged : 1 = 0;  // grown in place (LinkedTree::enlarge), not yet rebuilt

    bool is_leaf() const { return child1 == null; }
    bool is_free() const { return height < 0; }
    /// A leaf's number, chosen by the tree's owner (a proxy id, a primitive's position).
    std::int32_t value() const { return child2; }
    std::int32_t next_free() const { return parent; }
};
static_assert(sizeof(Node<float, 2>) == 32 && sizeof(Node<float, 3>) == 40);

/// Areas and SAH costs are computed in `Cost`, double by default: for a float tree every extent (up
/// to 2 * FLT_MAX) and every area (up to ~1e78) is then finite, so costs never overflow to inf and
/// tie (which would turn the tree into a list). A double tree keeps them ordered while extents stay
/// below ~1e150; past that it stays correct but may lose balance. A float tree whose boxes are all
/// small enough (float_costs_fit) computes them in float: the conversions are a large share of
/// an insertion.
template <class Cost, std::size_t N>
inline Cost area_of_extents(const Cost (&e)[N]) {
    if constexpr (N == 2) {
        return 2 * (e[0] + e[1]);
    } else {
        return 2 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
    }
}

/// Area (perimeter in 2D) of a box known to be non-empty: Aabb::area() without its clamp at zero.
template <class Cost = double, class T, std::size_t N>
inline Cost box_area(const Aabb<T, N>& a) {
    Cost e[N];
    for (std::size_t i = 0; i < N; ++i) e[i] = Cost(a.max[i]) - Cost(a.min[i]);
    return area_of_extents(e);
}

/// area(a u b) for two non-empty boxes, without building the union.
template <class Cost = double, class T, std::size_t N>
inline Cost union_area(const Aabb<T, N>& a, const Aabb<T, N>& b) {
    Cost e[N];
    for (std::size_t i = 0; i < N; ++i)
        e[i] = Cost(a.max[i] > b.max[i] ? a.max[i] : b.max[i]) -
               Cost(a.min[i] < b.min[i] ? a.min[i] : b.min[i]);
    return area_of_extents(e);
}

/// Whether every cost of an insertion or rotation inside `bounds` (the root's box united with the
/// new leaf's) stays finite and ordered in float: an insertion's cost is at most (height + 1) times
/// the area of `bounds` and the height stays below 2^31, so an area below FLT_MAX / 2^31 / 16
/// (~1e28) leaves room to spare. Always false for a double tree: its costs stay in double.
template <class T, std::size_t N>
inline bool float_costs_fit(const Aabb<T, N>& bounds) {
    if constexpr (!std::is_same_v<T, float>) {
        return false;
    } else {
        return box_area<double>(bounds) < 1e28;
    }
}

/// Recomputes an internal node's box, height and enlarged flag from its two children.
template <class T, std::size_t N>
inline void refit(Node<T, N>* nodes, std::int32_t i) {
    Node<T, N>& n = nodes[i];
    const Node<T, N>& c1 = nodes[n.child1];
    const Node<T, N>& c2 = nodes[n.child2];
    n.box = unite(c1.box, c2.box);
    n.height = 1 + std::max<std::int32_t>(c1.height, c2.height);
    n.enlarged = n.enlarged | c1.enlarged | c2.enlarged;
}

/// Ties: identical or zero-size boxes make many siblings cost exactly the same, and the first one
/// found (the root) would win every time, stacking each new parent on top of the last: a list. So
/// from the chosen sibling S (reached with total cost `cost`), while one of its children costs the
/// same, go down into the tying child of smaller height: ties fill the shallowest branch.
template <class Cost, class T, std::size_t N>
std::int32_t descend_ties(const Node<T, N>* nodes, std::int32_t s, const Aabb<T, N>& box,
                          Cost cost) {
    while (!nodes[s].is_leaf()) {
        const Node<T, N>& n = nodes[s];
        const Cost inherited = cost - box_area<Cost>(n.box);
        const Cost cost1 = union_area<Cost>(nodes[n.child1].box, box) + inherited;
        const Cost cost2 = union_area<Cost>(nodes[n.child2].box, box) + inherited;
        const bool tie1 = cost1 <= cost, tie2 = cost2 <= cost;
        if (!tie1 && !tie2) break;
        const bool take1 = tie1 && (!tie2 || nodes[n.child1].height <= nodes[n.child2].height);
        s = take1 ? n.child1 : n.child2;
        cost = take1 ? cost1 : cost2;
    }
    return s;
}

/// The greedy descent of the classic dynamic AABB tree (as in Box2D). At internal node X with
/// children C1, C2:
///   stay here (X becomes L's sibling):  area(X u L)
///   go into child Ci:                   area(Ci u L) + (area(X u L) - area(X))
/// the second term being what X grows by whatever happens below it. Take the cheapest (on a tie, go
/// down, into the shorter child); stop at a leaf. The descent costs only the height of the tree but
/// can miss the best sibling on another path.
template <class Cost = double, class T, std::size_t N>
std::int32_t find_sibling_greedy(const Node<T, N>* nodes, std::int32_t root,
                                 const Aabb<T, N>& box) {
    std::int32_t i = root;
    while (!nodes[i].is_leaf()) {
        const Node<T, N>& n = nodes[i];
        const Cost stay = union_area<Cost>(n.box, box);
        const Cost grow = stay - box_area<Cost>(n.box);
        const Cost cost1 = union_area<Cost>(nodes[n.child1].box, box) + grow;
        const Cost cost2 = union_area<Cost>(nodes[n.child2].box, box) + grow;
        if (stay < cost1 && stay < cost2) break;
        const bool take1 =
            cost1 < cost2 || (cost1 == cost2 && nodes[n.child1].height <= nodes[n.child2].height);
        i = take1 ? n.child1 : n.child2;
    }
    return i;
}

/// One path from the root guided by lower bounds (the descent of Catto, GDC 2019): at each
/// internal node both children are priced as siblings (keeping the best seen so far) and bounded
/// from below as places to descend into (area(L) + what they and their ancestors grow by); the walk
/// goes into the child of smaller bound and stops when neither bound can beat the best. It costs
/// the height of the tree, like the greedy descent, yet it does not stop at the first node where
/// staying looks cheapest, so its trees come close to the exact search's.
template <class Cost = double, class T, std::size_t N>
std::int32_t find_sibling_guided(const Node<T, N>* nodes, std::int32_t root,
                                 const Aabb<T, N>& box) {
    const Cost leaf_area = box_area<Cost>(box);
    std::int32_t best = root;
    Cost best_cost = union_area<Cost>(nodes[root].box, box);
    Cost inherited = 0;  // what node i and its ancestors grow by when L goes below i
    for (std::int32_t i = root; !nodes[i].is_leaf();) {
        const Node<T, N>& n = nodes[i];
        inherited += union_area<Cost>(n.box, box) - box_area<Cost>(n.box);
        Cost lower[2];
        const std::int32_t child[2] = {n.child1, n.child2};
        for (int k = 0; k < 2; ++k) {
            const Node<T, N>& c = nodes[child[k]];
            const Cost direct = union_area<Cost>(c.box, box);
            const Cost cost = direct + inherited;
            if (cost < best_cost) best_cost = cost, best = child[k];
            lower[k] = c.is_leaf() ? std::numeric_limits<Cost>::infinity()
                                   : inherited + (direct - box_area<Cost>(c.box)) + leaf_area;
        }
        const int k = lower[1] < lower[0] ? 1 : 0;
        if (!(lower[k] < best_cost)) break;
        i = child[k];
    }
    return descend_ties<Cost>(nodes, best, box, best_cost);
}

/// An internal node waiting to be expanded by the branch and bound search, with the inherited cost
/// of inserting anywhere below it: sum of area(A u L) - area(A) over the node and its ancestors.
template <class Cost>
struct SiblingCandidate {
    std::int32_t node;
    Cost inherited;
};

/// Exact best sibling by branch and bound (Bittner, Hapala, Havran 2013; Catto, GDC 2019).
///
/// For a node C whose ancestors give inherited cost I:
///   cost(C)                 = area(C u L) + I
///   inherited below C       = I + area(C u L) - area(C)  = cost(C) - area(C)
///   lower bound below C     = area(L) + inherited below C
/// since any node X below C has a direct cost area(X u L) >= area(L) and inherited costs only grow
/// on the way down. The search keeps the best cost found so far and a min-heap of internal nodes
/// keyed by their inherited-below cost:
///   - expanding node X evaluates both children's costs at once (so leaves never enter the heap)
///   and
///     pushes a child only when its lower bound beats the best cost;
///   - the node with the smallest inherited cost is expanded first, so good regions come early and
///   the
///     best cost drops fast;
///   - as soon as the smallest key + area(L) is no better than the best cost, nothing left in the
///   heap
///     (nor anything below it) can win and the search stops.
/// `heap` is scratch storage owned by the tree, so a steady stream of inserts allocates nothing.
/// After `max_expansions` expanded nodes the best sibling found so far is taken (heavily
/// overlapping boxes make the bound weak and the exact search visit most of the tree).
template <class Cost = double, class T, std::size_t N>
std::int32_t find_sibling_branch_and_bound(
    const Node<T, N>* nodes, std::int32_t root, const Aabb<T, N>& box,
    std::vector<SiblingCandidate<Cost>>& heap,
    std::size_t max_expansions = std::numeric_limits<std::size_t>::max()) {
    const Cost leaf_area = box_area<Cost>(box);
    const auto later = [](const SiblingCandidate<Cost>& a, const SiblingCandidate<Cost>& b) {
        return a.inherited >
               b.inherited;  // std heap functions build a max-heap: invert for a min-heap
    };
    // The root as sibling: a new root above it, no ancestors to grow.
    std::int32_t best = root;
    Cost best_cost = union_area<Cost>(nodes[root].box, box);
    heap.clear();
    if (!nodes[root].is_leaf()) heap.push_back({root, best_cost - box_area<Cost>(nodes[root].box)});
    while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end(), later);
        const SiblingCandidate<Cost> c = heap.back();
        heap.pop_back();
        const Cost inherited = Cost(c.inherited);       // a Cost stored in double: exact
        if (inherited + leaf_area >= best_cost) break;  // nothing left can beat the best
        if (max_expansions-- == 0) break;
        const Node<T, N>& n = nodes[c.node];
        for (const std::int32_t child : {n.child1, n.child2}) {
            const Node<T, N>& cn = nodes[child];
            const Cost cost = union_area<Cost>(cn.box, box) + inherited;
            if (cost < best_cost) {
                best_cost = cost;
                best = child;
            }
            if (cn.is_leaf()) continue;
            const Cost below = cost - box_area<Cost>(cn.box);
            if (below + leaf_area < best_cost) {
                heap.push_back({child, below});
                std::push_heap(heap.begin(), heap.end(), later);
            }
        }
    }
    return descend_ties<Cost>(nodes, best, box, best_cost);
}

/// One rotation at node a: its child in `slot` (1 or 2) trades places with the child in
/// `nephew_slot` of a's other child, which is then refitted.
template <class T, std::size_t N>
void swap_with_nephew(Node<T, N>* nodes, std::int32_t a, int slot, int nephew_slot) {
    Node<T, N>& na = nodes[a];
    std::int32_t& down = slot == 1 ? na.child1 : na.child2;
    const std::int32_t other = slot == 1 ? na.child2 : na.child1;
    Node<T, N>& no = nodes[other];
    std::int32_t& up = nephew_slot == 1 ? no.child1 : no.child2;
    std::swap(down, up);
    nodes[down].parent = a;
    nodes[up].parent = other;
    refit(nodes, other);
}

/// The four rotations at node A (Kopta et al. 2012 "Fast, effective BVH updates for
/// animated scenes"). A has children B and C. If B is internal with children D and E, swapping C
/// with one of B's children changes only B's box:
///     1. swap C and D:  B becomes C u E,  cost change area(C u E) - area(B)
///     2. swap C and E:  B becomes D u C,  cost change area(D u C) - area(B)
/// and symmetrically, if C is internal with children F and G, swapping B with one of C's children
/// changes only C's box:
///     3. swap B and F:  C becomes B u G,  cost change area(B u G) - area(C)
///     4. swap B and G:  C becomes F u B,  cost change area(F u B) - area(C)
/// A's own box is unchanged (it holds the same leaves). The rotation that lowers the cost the most
/// is applied; none if none lowers it. A's children must be up to date; A is refitted afterwards.
template <class Cost = double, class T, std::size_t N>
void rotate(Node<T, N>* nodes, std::int32_t a) {
    Node<T, N>& na = nodes[a];
    const std::int32_t b = na.child1, c = na.child2;
    Node<T, N>& nb = nodes[b];
    Node<T, N>& nc = nodes[c];
    if (nb.height < 1 && nc.height < 1) return;  // both leaves: nothing to rotate

    int best = 0;
    Cost best_delta = 0;
    if (!nb.is_leaf()) {
        const Cost area_b = box_area<Cost>(nb.box);
        const Cost d1 = union_area<Cost>(nc.box, nodes[nb.child2].box) - area_b;
        const Cost d2 = union_area<Cost>(nodes[nb.child1].box, nc.box) - area_b;
        if (d1 < best_delta) best_delta = d1, best = 1;
        if (d2 < best_delta) best_delta = d2, best = 2;
    }
    if (!nc.is_leaf()) {
        const Cost area_c = box_area<Cost>(nc.box);
        const Cost d3 = union_area<Cost>(nb.box, nodes[nc.child2].box) - area_c;
        const Cost d4 = union_area<Cost>(nodes[nc.child1].box, nb.box) - area_c;
        if (d3 < best_delta) best_delta = d3, best = 3;
        if (d4 < best_delta) best_delta = d4, best = 4;
    }
    if (best == 0) return;
    // 1: C <-> D, 2: C <-> E (C is a's child 2); 3: B <-> F, 4: B <-> G (B is a's child 1).
    swap_with_nephew(nodes, a, best <= 2 ? 2 : 1, best % 2 == 1 ? 1 : 2);
    refit(nodes, a);
}

}  // namespace bvhkit::linked

#pragma once
// Tree-vs-tree traversal: every pair of leaves of A and B whose volumes overlap when B is placed in
// A's frame by `pose_of_b_in_a`. The pose is applied to B's volumes as they are tested (a volume
// test under a pose, volumes/*.hpp); nothing of B is copied or transformed ahead of time.
//
// Iterative with an explicit stack of node pairs, each pushed only after its volumes were found to
// overlap. Its own loop, not walk_pairs (walk/walks.hpp): on that skeleton it took more
// instructions on OBB and RSS (docs/benchmarks.md, "Walk skeletons"). Which node of a pair to open
// is the descent rule (the usual choices of tree-vs-tree collision):
//   Larger        open the node with the larger volume (default; keeps the pair balanced)
//   A / B         open A's node (B's node) until it is a leaf, then the other
//   Simultaneous  open both: four child pairs
//   ByOverlap     test both nodes' children against the other node and open the side where fewer
//                 children overlap (the tests are reused for the pushes)
// A leaf is never opened; two leaves are handed to the callback one primitive slot pair at a time.
#include <array>
#include <cstdint>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/traversal_stack.hpp"
#include "bvhkit/query/stats.hpp"
#include "bvhkit/volumes/bounding_volume.hpp"

namespace bvhkit {

enum class DescentRule { Larger, A, B, Simultaneous, ByOverlap };

inline const char* to_string(DescentRule r) {
    switch (r) {
        case DescentRule::Larger:
            return "larger";
        case DescentRule::A:
            return "a";
        case DescentRule::B:
            return "b";
        case DescentRule::Simultaneous:
            return "simultaneous";
        case DescentRule::ByOverlap:
            return "by-overlap";
    }
    return "?";
}

/// Per-query counts of a pair query: volume tests (node()) and primitive-pair tests (primitive()).
struct PairStats {
    std::uint64_t volume_tests = 0;
    std::uint64_t primitive_tests = 0;
    void node() { ++volume_tests; }
    void primitive() { ++primitive_tests; }
};

namespace detail {

struct NodePair {
    std::uint32_t a, b;
};

/// Room for any traversal of trees within max_bvh_depth: each step pops one pair and pushes at
/// most four, one level deeper on at least one side.
inline constexpr std::size_t pair_stack_size = 8 * max_bvh_depth + 8;

enum class Open { A, B, Both };

template <class V>
Open choose(DescentRule rule, const BvhNode<V>& na, const BvhNode<V>& nb) {
    if (na.is_leaf()) return Open::B;
    if (nb.is_leaf()) return Open::A;
    switch (rule) {
        case DescentRule::A:
            return Open::A;
        case DescentRule::B:
            return Open::B;
        case DescentRule::Simultaneous:
            return Open::Both;
        default:
            return VolumeTraits<V>::size(na.bounds) >= VolumeTraits<V>::size(nb.bounds) ? Open::A
                                                                                        : Open::B;
    }
}

/// Volumes that can be carried into the other tree's frame once per traversal step (obb.hpp,
/// rss.hpp): opening one node tests both its children against the other node, so that node is
/// placed once (B's into A's frame with the pose, A's into B's with its inverse) and each test
/// saves a 3x3 product.
/// They have a centre, which orders the children to search (nearer first).
template <class V>
concept Placeable = requires(const V& v, const typename VolumeTraits<V>::Prepared& p,
                             typename V::Scalar slack) {
    { VolumeTraits<V>::place(v, p) } -> std::same_as<V>;
    {v.center - v.center};
    { VolumeTraits<V>::overlaps_placed(v, v, slack) } -> std::same_as<bool>;
};

}  // namespace detail

/// Calls on_pair(slot_a, slot_b) -> bool for every pair of primitive slots in two leaves whose
/// volumes overlap under the pose (slots index primitive_indices; false from the callback stops the
/// query). Returns false when stopped early. `slack` widens every volume test by that absolute
/// amount (see volumes/bounding_volume.hpp; CollisionModel picks it from the models' scale).
// One function of some 100 lines on purpose: it is the collide walk's hot loop, and its child
// opening moved into a function (shared with distance.hpp) cost it instructions on Rss
// (docs/benchmarks.md, "Figures behind code comments").
template <BoundingVolume V, class OnPair, class Stats = NoStats>
bool for_each_overlapping_pair(const Bvh<V>& a, const Bvh<V>& b,
                               const Transform<typename V::Scalar>& pose_of_b_in_a,
                               OnPair&& on_pair, DescentRule rule = DescentRule::Larger,
                               Stats&& stats = {}, typename V::Scalar slack = 0) {
    using Traits = VolumeTraits<V>;
    if (a.empty() || b.empty()) return true;
    const auto pose = Traits::prepare(pose_of_b_in_a, slack);
    const auto inverse = Traits::prepare(pose_of_b_in_a.inverse(), slack);
    const auto overlap = [&](std::uint32_t x, std::uint32_t y) {
        stats.node();
        return Traits::overlaps(a.nodes[x].bounds, b.nodes[y].bounds, pose);
    };
    FixedStack<detail::NodePair, detail::pair_stack_size> stack;
    // Of two children that both overlap, the one whose centre is nearer the other node's is
    // searched first: its subtree is likelier to hold a touching pair, which ends a yes/no query.
    const auto nearer_on_top = [](const auto& nodes, const auto& w, std::uint32_t lower,
                                  std::uint32_t upper, detail::NodePair& pl, detail::NodePair& pu) {
        if (length_squared(nodes[lower].bounds.center - w.center) <
            length_squared(nodes[upper].bounds.center - w.center))
            std::swap(pl, pu);
    };
    if (!overlap(0, 0)) return true;
    stack.push({0, 0});
    while (!stack.empty()) {
        const detail::NodePair p = stack.pop();
        const auto& na = a.nodes[p.a];
        const auto& nb = b.nodes[p.b];
        if (na.is_leaf() && nb.is_leaf()) {
            for (std::uint32_t sa = na.first; sa < na.first + na.count; ++sa)
                for (std::uint32_t sb = nb.first; sb < nb.first + nb.count; ++sb) {
                    stats.primitive();
                    if (!on_pair(sa, sb)) return false;
                }
            continue;
        }
        if (rule == DescentRule::ByOverlap && !na.is_leaf() && !nb.is_leaf()) {
            const bool al = overlap(na.left(), p.b), ar = overlap(na.right(), p.b);
            const bool bl = overlap(p.a, nb.left()), br = overlap(p.a, nb.right());
            const int open_a = int(al) + int(ar), open_b = int(bl) + int(br);
            const bool pick_a =
                open_a < open_b ||
                (open_a == open_b && Traits::size(na.bounds) >= Traits::size(nb.bounds));
            if (pick_a) {
                if (ar) stack.push({na.right(), p.b});
                if (al) stack.push({na.left(), p.b});
            } else {
                if (br) stack.push({p.a, nb.right()});
                if (bl) stack.push({p.a, nb.left()});
            }
            continue;
        }
        switch (detail::choose(rule, na, nb)) {
            case detail::Open::A:
                if constexpr (detail::Placeable<V>) {
                    const V w = Traits::place(nb.bounds, pose);
                    const std::size_t before = stack.size();
                    for (const std::uint32_t x : {na.right(), na.left()}) {
                        stats.node();
                        if (Traits::overlaps_placed(a.nodes[x].bounds, w, slack))
                            stack.push({x, p.b});
                    }
                    if (stack.size() == before + 2)
                        nearer_on_top(a.nodes, w, stack.from_top(1).a, stack.from_top(0).a,
                                      stack.from_top(1), stack.from_top(0));
                } else {
                    if (overlap(na.right(), p.b)) stack.push({na.right(), p.b});
                    if (overlap(na.left(), p.b)) stack.push({na.left(), p.b});
                }
                break;
            case detail::Open::B:
                if constexpr (detail::Placeable<V>) {
                    const V w = Traits::place(na.bounds, inverse);
                    const std::size_t before = stack.size();
                    for (const std::uint32_t y : {nb.right(), nb.left()}) {
                        stats.node();
                        if (Traits::overlaps_placed(b.nodes[y].bounds, w, slack))
                            stack.push({p.a, y});
                    }
                    if (stack.size() == before + 2)
                        nearer_on_top(b.nodes, w, stack.from_top(1).b, stack.from_top(0).b,
                                      stack.from_top(1), stack.from_top(0));
                } else {
                    if (overlap(p.a, nb.right())) stack.push({p.a, nb.right()});
                    if (overlap(p.a, nb.left())) stack.push({p.a, nb.left()});
                }
                break;
            case detail::Open::Both:
                for (std::uint32_t x : {na.right(), na.left()})
                    for (std::uint32_t y : {nb.right(), nb.left()})
                        if (overlap(x, y)) stack.push({x, y});
                break;
        }
    }
    return true;
}

}  // namespace bvhkit

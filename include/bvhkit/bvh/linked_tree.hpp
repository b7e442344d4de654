#pragma once
// LinkedTree<T, N>: a binary tree of boxes whose nodes link to their parent and children by index,
// in one pool with a free list, so that it can change one leaf at a time: insert a leaf (or a
// whole subtree) next to the sibling that raises the SAH cost least, detach it again, grow a leaf
// in place, rotate the ancestors on the way up (the algorithms are in linked_tree_sah.hpp). A leaf
// holds a box and a number chosen by the owner, nothing else.
//
// DynamicTree keeps its proxies' fat boxes in one; the insertion builder and the reinsertion
// optimizer (build/) use one as their working form and lay the result out as a Bvh.
//
// Indices stay valid while the pool grows. The free list is last in, first out: a node freed by
// detach() is the one the next insert() takes, which the reinsertion optimizer relies on to keep
// the pool full.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/linked_rebuild.hpp"
#include "bvhkit/bvh/linked_tree_sah.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit {

namespace serial_detail {
struct DynamicTreeAccess;  // io/dynamic_tree_file.hpp: saves and loads the pool as it is
}

/// How insert() picks the sibling of a new leaf.
enum class InsertionStrategy : std::uint8_t {
    /// The classic descent: at each node go to the child whose union with the new box is smaller,
    /// and stop where staying is cheapest. Fast, but it only ever looks at one path and stops
    /// early.
    Greedy,
    /// Exact best sibling for the SAH insertion cost, found by branch and bound over the whole tree
    /// (Bittner, Hapala, Havran 2013). The cheapest trees; each insertion may visit many nodes.
    BranchAndBound,
    /// One path guided by lower bounds on the insertion cost (Catto, GDC 2019): the cost of the
    /// greedy descent, trees within a few percent of BranchAndBound's (figures in
    /// docs/dynamic.md).
    Guided,
};

/// How LinkedTree::insert() places a leaf or subtree.
struct InsertionOptions {
    InsertionStrategy strategy = InsertionStrategy::Guided;
    /// Try the four rotations while walking up after an insert or a detach (Kopta et al. 2012).
    bool rotate = true;
    /// A float tree computes its costs in float where they provably stay finite and ordered
    /// (linked::float_costs_fit); false keeps them in double always.
    bool float_costs = true;
    /// Branch and bound: nodes expanded at most; past it the best sibling so far is taken.
    std::size_t max_expansions = std::numeric_limits<std::size_t>::max();
};

template <class T, std::size_t N>
class LinkedTree {
  public:
    using Node = linked::Node<T, N>;
    using Box = Aabb<T, N>;
    static constexpr std::int32_t null = linked::null;

    // ---------------------------------------------------------------- the pool

    std::int32_t root() const { return root_; }
    const Node& node(std::int32_t i) const { return nodes_[std::size_t(i)]; }
    const Node* nodes() const { return nodes_.data(); }
    /// Nodes in the pool, free ones included.
    std::size_t capacity() const { return nodes_.size(); }
    /// Nodes in use: leaves (in the tree or detached) and internal nodes.
    std::size_t node_count() const { return node_count_; }
    int height() const { return root_ == null ? 0 : nodes_[std::size_t(root_)].height; }
    /// Makes room for `n` nodes in all, so that no insert() grows (moves) the pool before then.
    void reserve(std::size_t n) {
        if (n > nodes_.size()) grow_pool(n);
    }

    /// Replaces the tree by the structure of `bvh`, node for node at the same indices; a leaf's
    /// value is its own index (the caller maps it back to the Bvh leaf's primitives).
    void assign(const Bvh<Box>& bvh) {
        clear();
        if (bvh.nodes.size() > std::size_t(INT32_MAX))
            throw Error("LinkedTree: more than 2^31 nodes");
        nodes_.resize(bvh.nodes.size());
        for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
            const auto& b = bvh.nodes[i];
            Node& n = nodes_[i];
            n.box = b.bounds;
            if (b.is_leaf()) {
                n.child2 = static_cast<std::int32_t>(i);
            } else {
                n.child1 = static_cast<std::int32_t>(b.left());
                n.child2 = static_cast<std::int32_t>(b.right());
                nodes_[b.left()].parent = nodes_[b.right()].parent = static_cast<std::int32_t>(i);
            }
        }
        for (std::size_t i = nodes_.size(); i-- > 0;)  // children after parents: heights bottom-up
            if (!nodes_[i].is_leaf()) linked::refit(nodes_.data(), std::int32_t(i));
        root_ = nodes_.empty() ? null : 0;
        node_count_ = nodes_.size();
    }

    /// A new leaf, not in the tree yet (insert() puts it there).
    std::int32_t make_leaf(const Box& box, std::int32_t value) {
        const std::int32_t i = alloc_node();
        Node& n = nodes_[std::size_t(i)];
        n.box = box;
        n.parent = n.child1 = null;
        n.child2 = value;
        n.height = 0;
        n.enlarged = 0;
        return i;
    }
    /// Gives a detached leaf a new box (and clears its enlarged mark).
    void set_leaf_box(std::int32_t leaf, const Box& box) {
        nodes_[std::size_t(leaf)].box = box;
        nodes_[std::size_t(leaf)].enlarged = 0;
    }
    /// Returns a detached leaf to the pool.
    void free_leaf(std::int32_t leaf) { free_node(leaf); }

    // ---------------------------------------------------------------- structure

    /// Puts the detached leaf or subtree `x` into the tree as the sibling of the node the strategy
    /// picks, under a new parent, then refits (and rotates) the ancestors.
    void insert(std::int32_t x, const InsertionOptions& options) {
        if (root_ == null) {
            root_ = x;
            nodes_[std::size_t(x)].parent = null;
            return;
        }
        const std::int32_t parent = alloc_node();  // first: it may grow (move) the pool
        const Box box = nodes_[std::size_t(x)].box;
        const bool float_costs =
            options.float_costs && linked::float_costs_fit(unite(nodes_[root_].box, box));
        const std::int32_t sibling =
            float_costs ? find_sibling<float>(box, options) : find_sibling<double>(box, options);
        const std::int32_t old_parent = nodes_[std::size_t(sibling)].parent;
        Node& p = nodes_[std::size_t(parent)];
        p.parent = old_parent;
        p.child1 = sibling;
        p.child2 = x;
        p.enlarged = 0;
        nodes_[std::size_t(sibling)].parent = parent;
        nodes_[std::size_t(x)].parent = parent;
        linked::refit(nodes_.data(), parent);
        if (old_parent == null) {
            root_ = parent;
            return;
        }
        replace_child(old_parent, sibling, parent);
        walk_up(old_parent, options.rotate, float_costs);
    }

    /// Takes the leaf or subtree `x` out of the tree (its nodes stay allocated): its parent goes
    /// back to the pool and x's sibling takes the parent's place; the ancestors are refitted (and
    /// rotated).
    void detach(std::int32_t x, bool rotate) {
        if (x == root_) {
            root_ = null;
            return;
        }
        const std::int32_t parent = nodes_[std::size_t(x)].parent;
        const std::int32_t grand = nodes_[std::size_t(parent)].parent;
        const Node& p = nodes_[std::size_t(parent)];
        const std::int32_t sibling = p.child1 == x ? p.child2 : p.child1;
        free_node(parent);
        nodes_[std::size_t(x)].parent = null;
        nodes_[std::size_t(sibling)].parent = grand;
        if (grand == null) {
            root_ = sibling;
            return;
        }
        replace_child(grand, parent, sibling);
        walk_up(grand, rotate, linked::float_costs_fit(nodes_[root_].box));
    }

    /// Grows `leaf`'s box to `box` and its ancestors' boxes to contain it, in place, marking them
    /// enlarged: no restructuring, so cheap, and the tree's quality suffers until rebuild().
    /// Invariant: the parent of an enlarged node is enlarged, so the walk stops at the first
    /// ancestor that was enlarged already and contains the box.
    void enlarge(std::int32_t leaf, const Box& box) {
        nodes_[std::size_t(leaf)].box = box;
        nodes_[std::size_t(leaf)].enlarged = 1;
        for (std::int32_t i = nodes_[std::size_t(leaf)].parent; i != null;
             i = nodes_[std::size_t(i)].parent) {
            Node& n = nodes_[std::size_t(i)];
            if (n.enlarged && n.box.contains(box)) break;
            n.box.grow(box);
            n.enlarged = 1;
        }
    }

    /// Rebuilds the internal nodes above a set of kept subtrees: the leaves when `full`, otherwise
    /// every subtree that enlarge() did not touch, kept as it is. The new nodes come from
    /// linked::build_binned (binned SAH, in place), made directly in the pool.
    void rebuild(bool full) {
        if (root_ == null) return;
        std::vector<linked::RebuildItem<T, N>>& items = rebuild_items_;
        std::vector<std::int32_t>& spare = rebuild_kept_;
        items.clear();
        spare.clear();
        // Walked down from the root, the kept subtrees come in the old tree's order, which is
        // spatial: the builder's partitions then find most of them on their side already (a scan
        // of the pool in index order would hand them over shuffled, and cost more than it saves).
        collect_kept(
            full,
            [&items](std::int32_t i, const Box& box) {
                items.push_back({box, i});
            },
            [&spare](std::int32_t i) { spare.push_back(i); });
        // The old internal nodes are exactly as many as the new ones: each new one takes the next
        // of them, which spares the pool's free list (a chain of dependent loads) both ways.
        std::size_t next = 0;
        Node* nodes = nodes_.data();
        root_ = linked::build_binned(
            std::span(items), rebuild_bins_,
            [nodes, &spare, &next](std::int32_t a, std::int32_t b, const Box& box,
                                   std::int32_t height) {
                const std::int32_t p = spare[next++];
                Node& n = nodes[p];
                n.box = box;
                n.parent = null;
                n.child1 = a;
                n.child2 = b;
                n.height = height;
                n.enlarged = 0;
                nodes[a].parent = nodes[b].parent = p;
                return p;
            },
            [nodes](std::int32_t i) { return std::int32_t(nodes[i].height); });
    }

    /// Applies f(Box&) to every node's box in use (an internal node's must stay the union of its
    /// children's, a leaf's as its owner needs: DynamicTree shifts them all by one vector).
    template <class F>
    void update_boxes(F&& f) {
        for (Node& n : nodes_)
            if (!n.is_free()) f(n.box);
    }

    /// Removes every node and returns all memory.
    void clear() {
        release(nodes_);
        release_scratch();
        root_ = free_ = null;
        node_count_ = 0;
    }
    /// Repacks the pool depth first to exactly the nodes of the tree (no detached leaf may exist)
    /// and frees the scratch storage; relink(value, new index) is called for every leaf.
    template <class Relink>
    void shrink_to_fit(Relink&& relink) {
        std::vector<Node> packed;
        packed.reserve(node_count_);
        struct Item {
            std::int32_t old, parent, slot;
        };
        std::vector<Item> stack;
        if (root_ != null) stack.push_back({root_, null, 0});
        while (!stack.empty()) {
            const Item it = stack.back();
            stack.pop_back();
            const auto i = static_cast<std::int32_t>(packed.size());
            packed.push_back(nodes_[std::size_t(it.old)]);
            packed.back().parent = it.parent;
            if (it.slot == 1) packed[std::size_t(it.parent)].child1 = i;
            if (it.slot == 2) packed[std::size_t(it.parent)].child2 = i;
            if (packed.back().is_leaf()) {
                relink(packed.back().value(), i);
            } else {
                stack.push_back({nodes_[std::size_t(it.old)].child2, i, 2});
                stack.push_back({nodes_[std::size_t(it.old)].child1, i, 1});
            }
        }
        nodes_.swap(packed);
        root_ = nodes_.empty() ? null : 0;
        free_ = null;
        node_count_ = nodes_.size();
        release_scratch();
    }
    void release_scratch() {
        release(heap_);
        release(float_heap_);
        release(rebuild_kept_);
        release(rebuild_stack_);
        release(rebuild_items_);
        release(rebuild_bins_);
    }

    // ---------------------------------------------------------------- checks and measures

    /// Checks every invariant of the tree and the pool; throws bvhkit::Error starting with `who`
    /// and naming the first one broken. check_leaf(index, node) may add the owner's checks for
    /// each leaf in the tree. Returns the number of leaves in the tree.
    template <class LeafCheck>
    std::size_t validate(const std::string& who, LeafCheck&& check_leaf) const;
    std::size_t validate(const std::string& who) const {
        return validate(who, [](std::int32_t, const Node&) {});
    }

    /// Sum of the areas (perimeters in 2D) of the internal nodes: the SAH cost.
    double sah_cost() const {
        double s = 0;
        for (const Node& n : nodes_)
            if (n.height > 0) s += linked::box_area(n.box);
        return s;
    }
    std::size_t memory_bytes() const {
        return nodes_.capacity() * sizeof(Node) + heap_.capacity() * sizeof(heap_[0]) +
               float_heap_.capacity() * sizeof(float_heap_[0]) +
               (rebuild_kept_.capacity() + rebuild_stack_.capacity()) * sizeof(std::int32_t) +
               rebuild_items_.capacity() * sizeof(rebuild_items_[0]) + rebuild_bins_.capacity();
    }

  private:
    friend struct serial_detail::DynamicTreeAccess;

    template <class V>
    static void release(V& v) {
        V().swap(v);
    }

    void grow_pool(std::size_t cap) {
        if (cap > std::size_t(INT32_MAX)) throw Error("LinkedTree: more than 2^31 nodes");
        const std::size_t old = nodes_.size();
        nodes_.resize(cap);
        // Chain the new nodes in front of the free list, lowest index first.
        for (std::size_t i = cap; i-- > old;) {
            nodes_[i].height = -1;
            nodes_[i].parent = free_;
            free_ = std::int32_t(i);
        }
    }
    std::int32_t alloc_node() {
        if (free_ == null) grow_pool(std::max<std::size_t>(16, nodes_.size() * 2));
        const std::int32_t i = free_;
        free_ = nodes_[std::size_t(i)].parent;
        ++node_count_;
        return i;
    }
    void free_node(std::int32_t i) {
        Node& n = nodes_[std::size_t(i)];
        n.height = -1;
        n.enlarged = 0;
        n.parent = free_;
        free_ = i;
        --node_count_;
    }

    void replace_child(std::int32_t parent, std::int32_t old_child, std::int32_t new_child) {
        Node& p = nodes_[std::size_t(parent)];
        (p.child1 == old_child ? p.child1 : p.child2) = new_child;
    }

    template <class Cost>
    std::int32_t find_sibling(const Box& box, const InsertionOptions& o) {
        if (o.strategy == InsertionStrategy::Greedy)
            return linked::find_sibling_greedy<Cost>(nodes_.data(), root_, box);
        if (o.strategy == InsertionStrategy::Guided)
            return linked::find_sibling_guided<Cost>(nodes_.data(), root_, box);
        if constexpr (std::is_same_v<Cost, float>) {
            return linked::find_sibling_branch_and_bound<Cost>(nodes_.data(), root_, box,
                                                               float_heap_, o.max_expansions);
        } else {
            return linked::find_sibling_branch_and_bound<Cost>(nodes_.data(), root_, box, heap_,
                                                               o.max_expansions);
        }
    }

    /// Refits (and rotates, when asked) the nodes from i up: to the root, or to the first node
    /// above i whose box, height, children and enlarged mark stay, since nothing above it changes
    /// then but the rotations its unchanged subtree would offer (a heuristic either way; stopping
    /// there halves the cost of a move in a crowd). Without rotations the stop is exact.
    /// `float_costs`: every box on the way lies in bounds for which float_costs_fit() holds.
    void walk_up(std::int32_t i, bool rotate, bool float_costs) {
        Node* nodes = nodes_.data();
        for (const std::int32_t first = i; i != null; i = nodes[i].parent) {
            Node& n = nodes[i];
            const Box before = n.box;
            const std::int32_t child1 = n.child1, child2 = n.child2;
            const std::int32_t height = n.height;
            const std::uint32_t enlarged = n.enlarged;
            linked::refit(nodes, i);
            if (rotate) {
                if (float_costs) {
                    linked::rotate<float>(nodes, i);
                } else {
                    linked::rotate<double>(nodes, i);
                }
            }
            if (i != first && n.child1 == child1 && n.child2 == child2 && n.height == height &&
                n.enlarged == enlarged && n.box == before)
                break;
        }
    }

    /// Hands keep(node, box) every subtree a rebuild keeps, detached (no parent, enlarged mark
    /// cleared), and drop(node) every internal node above them, which it replaces.
    template <class Keep, class Drop>
    void collect_kept(bool full, Keep&& keep, Drop&& drop) {
        std::vector<std::int32_t>& stack = rebuild_stack_;
        stack.assign(1, root_);
        while (!stack.empty()) {
            const std::int32_t i = stack.back();
            stack.pop_back();
            Node& n = nodes_[std::size_t(i)];
            if (n.is_leaf() || (!full && !n.enlarged)) {
                n.enlarged = 0;
                n.parent = null;
                keep(i, n.box);
            } else {
                // The children are fetched together: the second is on its way while the first
                // (often a leaf, anywhere in the pool) is read.
                __builtin_prefetch(&nodes_[std::size_t(n.child1)]);
                __builtin_prefetch(&nodes_[std::size_t(n.child2)]);
                stack.push_back(n.child2);
                stack.push_back(n.child1);
                drop(i);
            }
        }
    }

    std::vector<Node> nodes_;
    std::int32_t root_ = null;
    std::int32_t free_ = null;
    std::size_t node_count_ = 0;
    // Scratch kept between calls so that steady use allocates nothing.
    std::vector<linked::SiblingCandidate<double>> heap_;
    std::vector<linked::SiblingCandidate<float>> float_heap_;
    std::vector<std::int32_t> rebuild_kept_, rebuild_stack_;
    std::vector<linked::RebuildItem<T, N>> rebuild_items_;
    std::vector<std::uint8_t> rebuild_bins_;
};

template <class T, std::size_t N>
template <class LeafCheck>
std::size_t LinkedTree<T, N>::validate(const std::string& who, LeafCheck&& check_leaf) const {
    const auto broken = [&who](const std::string& what) { throw Error(who + ": " + what); };
    const auto cap = static_cast<std::int64_t>(nodes_.size());
    const auto name = [](std::int64_t i) { return "node " + std::to_string(i); };
    // Structure: walk down from the root; every reached node is in range, in use, reached once.
    std::vector<std::uint8_t> seen(nodes_.size(), 0);
    std::size_t reached = 0, leaves = 0;
    std::vector<std::int32_t> stack;
    if (root_ != null) {
        if (root_ < 0 || root_ >= cap)
            broken("root index " + std::to_string(root_) + " out of range");
        if (nodes_[std::size_t(root_)].parent != null)
            broken("root " + name(root_) + " has a parent");
        stack.push_back(root_);
    }
    while (!stack.empty()) {
        const std::int32_t i = stack.back();
        stack.pop_back();
        if (seen[std::size_t(i)])
            broken(name(i) + " is reached twice (the structure is not a tree)");
        seen[std::size_t(i)] = 1;
        ++reached;
        const Node& n = nodes_[std::size_t(i)];
        if (n.is_free()) broken(name(i) + " is in the tree but marked free");
        if (n.is_leaf()) {
            ++leaves;
            if (n.height != 0)
                broken("leaf " + name(i) + " has height " + std::to_string(n.height));
            check_leaf(i, n);
            continue;
        }
        if (n.child1 == n.child2) broken(name(i) + " has the same child twice");
        for (const std::int32_t c : {n.child1, n.child2}) {
            if (c < 0 || c >= cap)
                broken(name(i) + " has child index " + std::to_string(c) + " out of range");
            const Node& cn = nodes_[std::size_t(c)];
            if (cn.parent != i)
                broken("parent link: " + name(c) + " is a child of " + std::to_string(i) +
                       " but its parent is " + std::to_string(cn.parent));
            if (!n.box.contains(cn.box))
                broken("box of internal " + name(i) + " does not enclose its child " +
                       std::to_string(c));
            if (cn.enlarged && !n.enlarged)
                broken(name(c) + " is marked enlarged but its parent " + std::to_string(i) +
                       " is not");
            stack.push_back(c);
        }
        const int h = 1 + std::max<int>(nodes_[std::size_t(n.child1)].height,
                                        nodes_[std::size_t(n.child2)].height);
        if (n.height != h)
            broken(name(i) + " has height " + std::to_string(n.height) + ", expected " +
                   std::to_string(h));
    }
    // Free list: every node on it is marked free and listed once; with the tree and the detached
    // leaves it accounts for the whole pool.
    std::size_t free_nodes = 0;
    for (std::int32_t i = free_; i != null; i = nodes_[std::size_t(i)].parent) {
        if (i < 0 || i >= cap) broken("free list: index " + std::to_string(i) + " out of range");
        if (seen[std::size_t(i)])
            broken("free list: " + name(i) + " is also in the tree or listed twice");
        seen[std::size_t(i)] = 1;
        if (!nodes_[std::size_t(i)].is_free())
            broken("free list: " + name(i) + " is not marked free");
        ++free_nodes;
    }
    if (free_nodes + node_count_ != nodes_.size())
        broken("free list: " + std::to_string(free_nodes) + " free + " +
               std::to_string(node_count_) + " used != pool size " + std::to_string(nodes_.size()));
    std::size_t detached = 0;
    for (std::size_t i = 0; i < nodes_.size(); ++i)
        if (!seen[i]) {
            if (!nodes_[i].is_leaf() || nodes_[i].is_free() || nodes_[i].parent != null)
                broken(name(std::int64_t(i)) +
                       " is neither in the tree, nor free, nor a detached leaf");
            ++detached;
        }
    if (reached + detached != node_count_)
        broken("node count: " + std::to_string(reached) + " in the tree + " +
               std::to_string(detached) + " detached, " + std::to_string(node_count_) + " in use");
    return leaves;
}

}  // namespace bvhkit

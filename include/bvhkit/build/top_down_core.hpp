#pragma once
// The partition core every top-down builder shares. A builder only says how to split one node (a
// SplitRule); this driver does the rest: it drops non-finite primitives, keeps the work stack,
// computes node bounds, partitions the primitive indices, enforces the halting rules, and falls
// back to a median split when a rule's split would leave one side empty, so no input makes it
// recurse forever. The partition itself (Split, RangeBounds, partition_primitives) is in
// build/partition.hpp.
//
// Halting: a node becomes a leaf when it holds one primitive, when it reaches max_depth, or when
// the rule asks for a leaf and it holds no more than max_leaf_size primitives.
//
// Threads (an Executor of more than one thread, with oneTBB): the usual two phases of a parallel
// binned build. The nodes above a size cutoff are split one task each, both children of a node at
// the same time, and the largest of them bin and partition in parallel chunks too (all threads on
// the few large top nodes); every node below the cutoff becomes a subtree built by the serial
// driver into its own node array (one subtree per task), and a last pass lays those out exactly
// where the serial driver puts them. Every decision depends on a node's primitives and size only,
// never on the thread count, so the tree is the same bit for bit.
#include <algorithm>
#include <cassert>
#include <memory>
#include <numeric>
#include <span>
#include <string>
#include <type_traits>

#include "bvhkit/build/box_accumulator.hpp"
#include "bvhkit/build/options.hpp"
#include "bvhkit/build/partition.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// The node a SplitRule is asked about: its primitives (a range of the index array, which the rule
/// may reorder), its box and the box of its primitives' centroids.
template <class T, std::size_t N>
struct SplitTask {
    std::span<std::uint32_t> indices;
    Aabb<T, N> bounds;
    Aabb<T, N> centroid_bounds;
    std::uint32_t depth;
};

/// The centre of a finite box, inside it even where min + max overflows (extents beyond the
/// largest float) or halving a denormal rounds away.
template <class T, std::size_t N>
Vec<T, N> safe_centroid(const Aabb<T, N>& box) {
    Vec<T, N> c;
    for (std::size_t a = 0; a < N; ++a)
        c[a] = std::clamp(box.min[a] * T(0.5) + box.max[a] * T(0.5), box.min[a], box.max[a]);
    return c;
}

/// The builders' rule for bad input: a primitive whose box is non-finite or empty is left out (or
/// rejected, per options); validate() checks the same rule. A centroid that is not finite (or lies
/// outside its box) is replaced by the box's centre, so the centroid never decides.
template <class T, std::size_t N>
std::vector<std::uint32_t> usable_primitives(BuildInput<T, N>& in, std::vector<Vec<T, N>>& fixed,
                                             const BuildOptions& options, const Executor& exec,
                                             BuildReport* report) {
    using top_down_detail::chunk;
    if (in.boxes.size() != in.centroids.size())
        throw Error("build: " + std::to_string(in.boxes.size()) + " boxes but " +
                    std::to_string(in.centroids.size()) + " centroids");
    if (in.boxes.size() >= std::size_t(0xFFFFFFFFu))
        throw Error("build: " + std::to_string(in.boxes.size()) + " primitives; at most 2^32 - 2");
    std::vector<std::uint32_t> indices;
    const std::size_t n = in.boxes.size();
    if (exec.is_parallel() && n >= 4 * chunk) {
        // The usual case, every primitive usable as it is, checked in parallel: then the indices
        // are 0..n-1. Anything else takes the serial loop below, which says what to skip or fix.
        indices.resize(n);
        std::vector<char> clean((n + chunk - 1) / chunk);
        exec.parallel_for(n, chunk, [&](std::size_t b, std::size_t e) {
            bool ok = true;
            for (std::size_t i = b; i < e; ++i) {
                const Aabb<T, N>& box = in.boxes[i];
                ok &= box.is_finite() && !box.is_empty() && box.contains(in.centroids[i]);
                indices[i] = static_cast<std::uint32_t>(i);
            }
            clean[b / chunk] = ok;
        });
        if (std::find(clean.begin(), clean.end(), char(0)) == clean.end()) return indices;
        indices.clear();
    }
    indices.reserve(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        if (in.boxes[i].is_finite() && !in.boxes[i].is_empty()) {
            indices.push_back(i);
            if (!in.boxes[i].contains(in.centroids[i])) {
                if (fixed.empty()) fixed.assign(in.centroids.begin(), in.centroids.end());
                fixed[i] = safe_centroid(in.boxes[i]);
            }
        } else if (options.non_finite == NonFinitePolicy::Reject) {
            throw Error("build: primitive " + std::to_string(i) +
                        " has a non-finite or empty box; NonFinitePolicy::Skip leaves such "
                        "primitives out");
        } else if (report) {
            report->skipped.push_back(i);
        }
    }
    if (!fixed.empty()) in.centroids = fixed;
    return indices;
}

/// Levels of halving that bring `count` primitives down to leaves of at most `max_leaf`.
inline std::uint32_t levels_to_halve(std::uint64_t count, std::uint64_t max_leaf) {
    std::uint32_t levels = 0;
    for (std::uint64_t c = count; c > max_leaf; c = (c + 1) / 2) ++levels;
    return levels;
}

/// Whether a node of `count` primitives at `depth` must be halved: the depth left only just
/// suffices for halving down to `max_leaf` primitives a leaf. A rule peeling off a few primitives
/// per level (extents spanning many decades) would otherwise reach max_depth with a huge leaf.
inline bool must_halve(std::uint64_t count, std::uint32_t depth, std::uint64_t max_leaf,
                       std::uint32_t max_depth) {
    return count > max_leaf && levels_to_halve(count, max_leaf) + 1 >= max_depth - depth;
}

namespace top_down_detail {

/// A node waiting to be split: its slot in the node array, its range of the index array, its
/// depth, and the bounds of that range (gathered by the parent's partition).
template <class T, std::size_t N>
struct Work {
    std::uint32_t node, begin, end, depth;
    RangeBounds<T, N> bounds;
};

/// What every step of one build shares.
template <class T, std::size_t N>
struct Context {
    const BuildInput<T, N>& in;
    std::uint32_t* indices;  // the whole index array
    std::uint32_t* scratch;  // as long; a large node partitions through its own part of it
    std::uint32_t max_depth, max_leaf;
};

/// Asks `rule` to split `task`: with the executor where the rule takes one (to bin or sweep a large
/// node in parallel), else without.
template <class T, std::size_t N, class SplitRule>
Split<T> ask_rule(SplitRule& rule, const SplitTask<T, N>& task, const Executor& exec) {
    if constexpr (std::is_invocable_v<SplitRule&, const SplitTask<T, N>&, const Executor&>)
        return rule(task, exec);
    else
        return rule(task);
}

/// One step of every driver: 0 when the node of `w` is a leaf, else partitions its range and
/// returns how many of it go left, with both sides' bounds.
template <class T, std::size_t N, class SplitRule>
std::uint32_t split_node(const Context<T, N>& cx, const Work<T, N>& w, SplitRule& rule,
                         const Executor& exec, RangeBounds<T, N>& left, RangeBounds<T, N>& right) {
    const std::uint32_t count = w.end - w.begin;
    if (count == 1 || w.depth >= cx.max_depth) return 0;
    const Aabb<T, N> centroid_bounds = w.bounds.centroids.box();
    const std::span<std::uint32_t> range(cx.indices + w.begin, count);
    const std::span<std::uint32_t> scratch(cx.scratch ? cx.scratch + w.begin : nullptr,
                                           cx.scratch ? count : 0);
    const bool halve = must_halve(count, w.depth, cx.max_leaf, cx.max_depth);
    const Split<T> split =
        halve
            ? Split<T>::leaf()
            : ask_rule(rule, SplitTask<T, N>{range, w.bounds.boxes.box(), centroid_bounds, w.depth},
                       exec);
    if (split.kind == Split<T>::Kind::Leaf && count <= cx.max_leaf) return 0;
    std::uint32_t left_count =
        halve ? 0 : partition_primitives(cx.in, range, split, left, right, scratch, exec);
    if (left_count == 0 || left_count == count) {
        // The rule gave no split (or could not split). Fall back to the object median on the
        // centroids' longest axis; if all centroids coincide the order is arbitrary, so halve.
        left = right = RangeBounds<T, N>{};
        left_count = partition_primitives(
            cx.in, range,
            Split<T>::at_count(static_cast<std::uint32_t>(centroid_bounds.largest_axis()),
                               count / 2),
            left, right, scratch, exec);
    }
    return left_count;
}

/// The serial driver: builds the subtree of `root` into `nodes` (where root.node already is),
/// appending each sibling pair when its parent is split, depth first, left before right.
template <class T, std::size_t N, class SplitRule, class Nodes>
void build_serial(const Context<T, N>& cx, const Work<T, N>& root, SplitRule& rule, Nodes& nodes) {
    const Executor serial = Executor::serial();
    std::vector<Work<T, N>> stack{root};
    while (!stack.empty()) {
        const Work<T, N> w = stack.back();
        stack.pop_back();
        nodes[w.node].bounds = w.bounds.boxes.box();
        RangeBounds<T, N> left, right;
        const std::uint32_t left_count = split_node(cx, w, rule, serial, left, right);
        if (left_count == 0) {
            nodes[w.node].first = w.begin;
            nodes[w.node].count = w.end - w.begin;
            continue;
        }
        const auto first_child = static_cast<std::uint32_t>(nodes.size());
        nodes[w.node].first = first_child;
        nodes[w.node].count = 0;
        nodes.emplace_back();
        nodes.emplace_back();
        // Right pushed first so the left subtree is laid out first (depth-first order).
        stack.push_back({first_child + 1, w.begin + left_count, w.end, w.depth + 1, right});
        stack.push_back({first_child, w.begin, w.begin + left_count, w.depth + 1, left});
    }
}

/// Nodes of more primitives than this are split one task each by the parallel driver; a smaller
/// node becomes one task building its whole subtree serially (to balance many such tasks over the
/// threads, it is small against the large meshes; to pay for a task's few allocations, not tiny).
inline constexpr std::uint32_t parallel_subtree_cutoff = tuning::parallel_subtree_cutoff;

/// A node of the parallel driver's top tree: split there (children), or the root of a subtree the
/// serial driver built into `subtree` (node 0 its root, child indices local to it).
template <class T, std::size_t N>
struct TopNode {
    Aabb<T, N> bounds;
    std::unique_ptr<TopNode[]> children;
    std::vector<BvhNode<Aabb<T, N>>> subtree;
    std::uint32_t self = 0, at = 0;  // final index; of its children pair or its subtree's pairs
};

template <class T, std::size_t N, class SplitRule>
void build_top_node(const Context<T, N>& cx, const Work<T, N>& w, const BuildOptions& options,
                    const Executor& exec, TopNode<T, N>& t) {
    t.bounds = w.bounds.boxes.box();
    const std::uint32_t count = w.end - w.begin;
    if (count > parallel_subtree_cutoff) {
        // A rule per node: rules keep scratch, and the two children run at the same time. It
        // bins in parallel (in this build's arena) when the node is large.
        SplitRule rule(cx.in, options);
        RangeBounds<T, N> lb, rb;
        if (const std::uint32_t k = split_node(cx, w, rule, exec, lb, rb)) {
            const Work<T, N> left{0, w.begin, w.begin + k, w.depth + 1, lb};
            const Work<T, N> right{0, w.begin + k, w.end, w.depth + 1, rb};
            t.children = std::make_unique<TopNode<T, N>[]>(2);
            exec.parallel_invoke(
                [&] { build_top_node<T, N, SplitRule>(cx, left, options, exec, t.children[0]); },
                [&] { build_top_node<T, N, SplitRule>(cx, right, options, exec, t.children[1]); });
            return;
        }
        t.subtree.resize(1);
        t.subtree[0] = {t.bounds, w.begin, count};
        return;
    }
    SplitRule rule(cx.in, options);
    t.subtree.reserve(2 * count - 1);
    t.subtree.emplace_back();
    Work<T, N> root = w;
    root.node = 0;
    build_serial(cx, root, rule, t.subtree);
}

/// Gives the top tree its final indices as the serial driver allocates them: a node's children
/// pair when it is split, then all of its left subtree's pairs, then its right one's.
template <class T, std::size_t N>
void place_top_node(TopNode<T, N>& t, std::uint32_t self, std::uint32_t& next,
                    std::vector<TopNode<T, N>*>& all) {
    t.self = self;
    t.at = next;
    all.push_back(&t);
    if (t.children) {
        next += 2;
        place_top_node(t.children[0], t.at, next, all);
        place_top_node(t.children[1], t.at + 1, next, all);
    } else {
        next += static_cast<std::uint32_t>(t.subtree.size() - 1);
    }
}

/// The parallel driver (run inside the executor's arena): the top tree in parallel, then one
/// parallel copy of every subtree to its place, local child indices shifted.
template <class T, std::size_t N, class SplitRule, class Nodes>
void build_parallel(const Context<T, N>& cx, const Work<T, N>& root, const BuildOptions& options,
                    const Executor& exec, Nodes& nodes) {
    TopNode<T, N> top;
    build_top_node<T, N, SplitRule>(cx, root, options, exec, top);
    std::vector<TopNode<T, N>*> all;
    std::uint32_t next = 1;
    place_top_node(top, 0, next, all);
    nodes.resize(next);
    exec.parallel_for(all.size(), 1, [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) {
            TopNode<T, N>& t = *all[k];
            if (t.children) {
                nodes[t.self] = {t.bounds, t.at, 0};
                continue;
            }
            const auto place = [&](std::uint32_t local) {
                return local ? t.at + local - 1 : t.self;
            };
            for (std::uint32_t local = 0; local < t.subtree.size(); ++local) {
                auto node = t.subtree[local];
                if (!node.is_leaf()) node.first = place(node.first);
                nodes[place(local)] = node;
            }
            std::vector<BvhNode<Aabb<T, N>>>().swap(t.subtree);  // freed by the thread that copied
        }
    });
}

}  // namespace top_down_detail

/// Builds over `indices` (from usable_primitives) with `rule` deciding each split. In parallel
/// when `exec` is and oneTBB is there, for rules made from (BuildInput, BuildOptions): each task
/// makes its own.
template <class T, std::size_t N, class SplitRule>
Bvh<Aabb<T, N>> build_top_down(const BuildInput<T, N>& in, std::vector<std::uint32_t> indices,
                               const BuildOptions& options, SplitRule& rule, const Executor& exec) {
    using namespace top_down_detail;
    Bvh<Aabb<T, N>> bvh;
    bvh.primitive_indices = std::move(indices);
    std::vector<std::uint32_t>& idx = bvh.primitive_indices;
    if (idx.empty()) return bvh;
    const auto n = static_cast<std::uint32_t>(idx.size());
    // Scratch only where a node is large enough to partition through it; left uninitialized.
    std::unique_ptr<std::uint32_t[]> scratch;
    if (n >= stable_partition_from) scratch.reset(new std::uint32_t[n]);
    const Context<T, N> cx{in, idx.data(), scratch.get(),
                           std::min(options.max_depth, max_bvh_depth),
                           std::max<std::uint32_t>(1, options.max_leaf_size)};

    constexpr bool remakeable =
        std::is_constructible_v<SplitRule, const BuildInput<T, N>&, const BuildOptions&>;
    if constexpr (remakeable) {
        if (exec.is_parallel() && n > parallel_subtree_cutoff) {
            exec.run([&] {
                const Work<T, N> root{0, 0, n, 0, range_bounds<T, N>(in, idx, exec)};
                build_parallel<T, N, SplitRule>(cx, root, options, exec, bvh.nodes);
            });
            return bvh;
        }
    }
    bvh.nodes.reserve(2 * idx.size() - 1);
    bvh.nodes.emplace_back();
    build_serial(cx, Work<T, N>{0, 0, n, 0, range_bounds<T, N>(in, idx, Executor::serial())}, rule,
                 bvh.nodes);
    return bvh;
}

}  // namespace bvhkit

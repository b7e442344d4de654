#pragma once
// From a binary tree built in any order (bottom-up clustering, Morton-code hierarchy, insertion)
// to the Bvh layout: sibling pairs adjacent, depth-first, children after parents.
//
// The builders that make such trees (bottom_up, lbvh, insertion, reinsertion) give one primitive
// (or one run of primitives) per leaf and no depth limit. Flattening does the two things they
// share:
//   - collapse: a subtree becomes one leaf when that is cheaper by the SAH (leaf cost C_isect * n,
//     n counted in blocks of SahCosts::leaf_block,
//     against C_trav + the children's best costs, all weighted by area) and it holds no more than
//     max_leaf_size primitives; the usual post-pass of bottom-up builders (Karras 2012, Meister and
//     Bittner 2018);
//   - depth: no tree is deeper than max_depth (at most the fixed traversal stack, max_bvh_depth),
//     whatever the builder did: a subtree too tall for the depth left is laid out balanced from the
//     depth where halving its primitives down to max_leaf_size just fits (so leaves stay within
//     max_leaf_size unless max_depth is too small even for that).
// Boxes are recomputed from the leaves, so the builders need not keep internal boxes exact.
#include <algorithm>
#include <span>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/statistics.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

inline constexpr std::uint32_t no_child = 0xFFFFFFFFu;

/// A binary tree as the builders make it: node i is internal when left[i] != no_child (then
/// right[i] is its other child), else a leaf holding the run [first[i], first[i] + count[i]) of
/// `order` (the primitive indices in any order the builder likes).
struct BinaryTree {
    std::vector<std::uint32_t> left, right, first, count;
    std::vector<std::uint32_t> order;
    std::uint32_t root = no_child;

    std::uint32_t add_leaf(std::uint32_t run_first, std::uint32_t run_count) {
        left.push_back(no_child);
        right.push_back(no_child);
        first.push_back(run_first);
        count.push_back(run_count);
        return static_cast<std::uint32_t>(left.size() - 1);
    }
    std::uint32_t add_internal(std::uint32_t l, std::uint32_t r) {
        left.push_back(l);
        right.push_back(r);
        first.push_back(0);
        count.push_back(0);
        return static_cast<std::uint32_t>(left.size() - 1);
    }
    std::size_t size() const { return left.size(); }
    void reserve(std::size_t n) {
        left.reserve(n), right.reserve(n), first.reserve(n), count.reserve(n);
    }
};

struct FlattenOptions {
    // Collapse only subtrees at most this large (1: never).
    std::uint32_t max_leaf_size = tuning::max_leaf_size;
    std::uint32_t max_depth = max_bvh_depth;
    SahCosts costs{};
};

namespace flatten_detail {

/// Per node of a BinaryTree: its box, primitive count, height, and whether the subtree is
/// cheapest as one leaf (by the SAH costs, within max_leaf_size).
template <class T, std::size_t N>
struct SubtreeMeasures {
    std::vector<Aabb<T, N>> box;
    std::vector<std::uint32_t> prims, height;
    std::vector<std::uint8_t> collapse;
};

/// One post-order pass (children before parents, from an explicit pre-order list reversed).
template <class T, std::size_t N>
SubtreeMeasures<T, N> measure_subtrees(const BinaryTree& tree, std::span<const Aabb<T, N>> boxes,
                                       const FlattenOptions& options) {
    const std::size_t n = tree.size();
    std::vector<std::uint32_t> preorder;
    preorder.reserve(n);
    preorder.push_back(tree.root);
    for (std::size_t i = 0; i < preorder.size(); ++i) {
        const std::uint32_t v = preorder[i];
        if (tree.left[v] != no_child) {
            preorder.push_back(tree.left[v]);
            preorder.push_back(tree.right[v]);
        }
    }
    SubtreeMeasures<T, N> m;
    m.box.resize(n);
    m.prims.resize(n);
    m.height.assign(n, 0);
    m.collapse.assign(n, 0);
    std::vector<double> cost(n);  // best SAH cost of the subtree, in area units
    for (std::size_t k = preorder.size(); k-- > 0;) {
        const std::uint32_t v = preorder[k];
        if (tree.left[v] == no_child) {
            Aabb<T, N> b;
            for (std::uint32_t s = tree.first[v]; s < tree.first[v] + tree.count[v]; ++s)
                b.grow(boxes[tree.order[s]]);
            m.box[v] = b;
            m.prims[v] = tree.count[v];
            cost[v] = options.costs.intersection * options.costs.leaf_tests(m.prims[v]) *
                      double(b.area());
            m.collapse[v] = 1;
            continue;
        }
        const std::uint32_t l = tree.left[v], r = tree.right[v];
        m.height[v] = 1 + std::max(m.height[l], m.height[r]);
        m.box[v] = unite(m.box[l], m.box[r]);
        m.prims[v] = m.prims[l] + m.prims[r];
        const double area = double(m.box[v].area());
        const double split = options.costs.traversal * area + cost[l] + cost[r];
        const double leaf =
            options.costs.intersection * options.costs.leaf_tests(m.prims[v]) * area;
        if (m.prims[v] <= options.max_leaf_size && leaf <= split) {
            m.collapse[v] = 1;
            cost[v] = leaf;
        } else {
            cost[v] = split;
        }
    }
    return m;
}

/// Appends the primitives of the subtree of `v` to `out`, left to right; `gather` is scratch.
inline void append_primitives(const BinaryTree& tree, std::uint32_t v,
                              std::vector<std::uint32_t>& out, std::vector<std::uint32_t>& gather) {
    gather.assign(1, v);
    while (!gather.empty()) {
        const std::uint32_t u = gather.back();
        gather.pop_back();
        if (tree.left[u] == no_child) {
            for (std::uint32_t s = tree.first[u]; s < tree.first[u] + tree.count[u]; ++s)
                out.push_back(tree.order[s]);
        } else {
            gather.push_back(tree.right[u]);
            gather.push_back(tree.left[u]);
        }
    }
}

}  // namespace flatten_detail

/// Lays `tree` out as a Bvh; `boxes` are the primitive boxes, indexed by the entries of `order`.
// The layout walk stays one function of some 80 lines: its three cases (a run laid out in halves,
// a subtree too tall for the depth left, an ordinary node) share the work stack and the node array
// it appends to.
template <class T, std::size_t N>
Bvh<Aabb<T, N>> flatten(const BinaryTree& tree, std::span<const Aabb<T, N>> boxes,
                        const FlattenOptions& options = {}) {
    Bvh<Aabb<T, N>> bvh;
    if (tree.root == no_child) return bvh;
    const flatten_detail::SubtreeMeasures<T, N> measures =
        flatten_detail::measure_subtrees(tree, boxes, options);
    const auto& box = measures.box;
    const auto& prims = measures.prims;
    const auto& height = measures.height;
    const auto& collapse = measures.collapse;

    const std::uint32_t max_depth = std::min(options.max_depth, max_bvh_depth);
    const std::uint32_t max_leaf = std::max<std::uint32_t>(1, options.max_leaf_size);
    bvh.nodes.reserve(2 * std::size_t(prims[tree.root]));
    bvh.primitive_indices.reserve(prims[tree.root]);
    std::vector<std::uint32_t> gather;  // reused stack for collecting a collapsed subtree's leaves
    const auto collect = [&](std::uint32_t v, std::vector<std::uint32_t>& out) {
        flatten_detail::append_primitives(tree, v, out, gather);
    };
    // A subtree too tall for the depth left is laid out balanced instead, halving the run of its
    // primitives (left to right, so still grouped as the builder grouped them) from the depth where
    // halving just fits: a leaf of more than max_leaf_size only when even halving cannot fit.
    std::vector<std::uint32_t> runs;  // the primitives of such subtrees; Work::source = no_child
    struct Work {
        std::uint32_t source, target, depth, begin = 0, end = 0;
    };
    std::vector<Work> stack{{tree.root, 0, 0}};
    bvh.nodes.emplace_back();
    while (!stack.empty()) {
        const Work w = stack.back();
        stack.pop_back();
        if (w.source == no_child) {
            auto& node = bvh.nodes[w.target];
            Aabb<T, N> b;
            for (std::uint32_t k = w.begin; k < w.end; ++k) b.grow(boxes[runs[k]]);
            node.bounds = b;
            if (w.end - w.begin <= max_leaf || w.depth >= max_depth) {
                node.first = static_cast<std::uint32_t>(bvh.primitive_indices.size());
                node.count = w.end - w.begin;
                bvh.primitive_indices.insert(bvh.primitive_indices.end(), runs.begin() + w.begin,
                                             runs.begin() + w.end);
                continue;
            }
            const auto child = static_cast<std::uint32_t>(bvh.nodes.size());
            node.first = child;
            node.count = 0;
            bvh.nodes.emplace_back();
            bvh.nodes.emplace_back();
            const std::uint32_t mid = w.begin + (w.end - w.begin) / 2;
            stack.push_back({no_child, child + 1, w.depth + 1, mid, w.end});
            stack.push_back({no_child, child, w.depth + 1, w.begin, mid});
            continue;
        }
        auto& node = bvh.nodes[w.target];
        node.bounds = box[w.source];
        const std::uint32_t left_depth = max_depth - std::min(max_depth, w.depth);
        if (!collapse[w.source] && height[w.source] > left_depth && prims[w.source] > max_leaf) {
            std::uint32_t levels = 0;  // halvings down to max_leaf
            for (std::uint32_t c = prims[w.source]; c > max_leaf; c = (c + 1) / 2) ++levels;
            if (levels + 1 >= left_depth) {
                const auto begin = static_cast<std::uint32_t>(runs.size());
                collect(w.source, runs);
                stack.push_back(
                    {no_child, w.target, w.depth, begin, static_cast<std::uint32_t>(runs.size())});
                continue;
            }
        }
        if (collapse[w.source] || w.depth >= max_depth) {
            node.first = static_cast<std::uint32_t>(bvh.primitive_indices.size());
            node.count = prims[w.source];
            collect(w.source, bvh.primitive_indices);
            continue;
        }
        const auto child = static_cast<std::uint32_t>(bvh.nodes.size());
        node.first = child;
        node.count = 0;
        bvh.nodes.emplace_back();
        bvh.nodes.emplace_back();
        stack.push_back({tree.right[w.source], child + 1, w.depth + 1});
        stack.push_back({tree.left[w.source], child, w.depth + 1});
    }
    return bvh;
}

}  // namespace bvhkit

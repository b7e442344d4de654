#pragma once
// LBVH: the hierarchy of the Morton-sorted primitives, every internal node found independently
// (Karras 2012, "Maximizing parallelism in the construction of BVHs, octrees, and k-d trees").
// The fastest builder here: a sort and a linear pass, no surface areas; its trees are some 10 to
// 30% worse by SAH than binned SAH's (the split is always at the highest differing Morton bit, not
// where the geometry asks). flatten() then collapses small subtrees into leaves by the SAH and
// caps the depth, which equal codes (ties broken by index) can push past max_bvh_depth.
//
// Internal node i of the n - 1 covers a range of sorted leaves with i at one end; the range and
// its split follow from the common prefix lengths delta(i, j) of the codes, and no node depends on
// another, so the loop runs in parallel with the serial result.
#include <bit>

#include "bvhkit/build/flatten.hpp"
#include "bvhkit/build/morton.hpp"
#include "bvhkit/build/options.hpp"

namespace bvhkit {

namespace lbvh_detail {

/// Length of the common prefix of the keys at sorted positions i and j (code, then index), or -1
/// when j is out of range.
inline int delta(const std::vector<MortonItem>& items, std::int64_t i, std::int64_t j) {
    if (j < 0 || j >= std::int64_t(items.size())) return -1;
    const std::uint64_t a = items[std::size_t(i)].code, b = items[std::size_t(j)].code;
    if (a != b) return std::countl_zero(a ^ b);
    return 64 + std::countl_zero(std::uint32_t(i) ^ std::uint32_t(j));
}

}  // namespace lbvh_detail

/// The unflattened LBVH of `indices`: internal nodes 0 .. n-2 (root 0), leaf k at n - 1 + k.
template <class T, std::size_t N>
BinaryTree build_lbvh_tree(std::span<const Vec<T, N>> centroids,
                           std::span<const std::uint32_t> indices, const Executor& exec) {
    using lbvh_detail::delta;
    BinaryTree tree;
    const std::size_t n = indices.size();
    if (n == 0) return tree;
    const std::vector<MortonItem> items = morton_order(centroids, indices, exec);
    tree.left.assign(2 * n - 1, no_child);
    tree.right.assign(2 * n - 1, no_child);
    tree.first.assign(2 * n - 1, 0);
    tree.count.assign(2 * n - 1, 0);
    tree.order.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        tree.order[k] = items[k].index;
        tree.first[n - 1 + k] = static_cast<std::uint32_t>(k);
        tree.count[n - 1 + k] = 1;
    }
    tree.root = 0;
    exec.parallel_for(n - 1, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t node = b; node < e; ++node) {
            const auto i = std::int64_t(node);
            const int d = delta(items, i, i + 1) > delta(items, i, i - 1) ? 1 : -1;
            const int delta_min = delta(items, i, i - d);
            std::int64_t lmax = 2;
            while (delta(items, i, i + lmax * d) > delta_min) lmax *= 2;
            std::int64_t l = 0;
            for (std::int64_t t = lmax / 2; t >= 1; t /= 2)
                if (delta(items, i, i + (l + t) * d) > delta_min) l += t;
            const std::int64_t j = i + l * d;
            const int delta_node = delta(items, i, j);
            std::int64_t s = 0;
            for (std::int64_t div = 2;; div *= 2) {
                const std::int64_t t = (l + div - 1) / div;
                if (delta(items, i, i + (s + t) * d) > delta_node) s += t;
                if (t <= 1) break;
            }
            const std::int64_t gamma = i + s * d + std::min(d, 0);
            const std::int64_t lo = std::min(i, j), hi = std::max(i, j);
            tree.left[node] = std::uint32_t(lo == gamma ? std::int64_t(n) - 1 + gamma : gamma);
            tree.right[node] =
                std::uint32_t(hi == gamma + 1 ? std::int64_t(n) - 1 + gamma + 1 : gamma + 1);
        }
    });
    return tree;
}

template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_lbvh(std::span<const Aabb<T, N>> boxes, std::span<const Vec<T, N>> centroids,
                           std::span<const std::uint32_t> indices, const BuildOptions& options,
                           const Executor& exec) {
    const BinaryTree tree = build_lbvh_tree(centroids, indices, exec);
    return flatten(tree, boxes, {options.max_leaf_size, options.max_depth, options.costs});
}

/// As above, on an executor of options.threads.
template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_lbvh(std::span<const Aabb<T, N>> boxes, std::span<const Vec<T, N>> centroids,
                           std::span<const std::uint32_t> indices, const BuildOptions& options) {
    return build_lbvh(boxes, centroids, indices, options, Executor(options.threads));
}

}  // namespace bvhkit

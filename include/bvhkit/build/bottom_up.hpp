#pragma once
// Bottom-up agglomerative clustering: PLOC (Meister and Bittner 2018, "Parallel locally-ordered
// clustering for bounding volume hierarchy construction"). Start with one cluster per primitive in
// Morton order; each round, every cluster finds its nearest neighbour (the one whose union box has
// the smallest area) among the `radius` clusters on either side in that order, mutual nearest
// neighbours merge, and the survivors are compacted in order. The order keeps the search local;
// merging the closest pairs first gives trees close to Walter et al.'s exact agglomerative
// clustering, usually a little better than binned SAH by SAH cost, at several times its build time.
//
// Ties: pairs are compared by (area, distance in the order, the smaller position being odd, the
// smaller position), a total order on unordered pairs, so the globally smallest pair is always
// mutual and every round merges at least one pair. Among equal areas (copies of one primitive,
// coincident boxes) it pairs neighbours 2k and 2k + 1, so such clusters all merge in one round.
//
// Progress: mutual pairs alone can be few per round (nested boxes make every cluster choose the
// next smaller one: one merge a round, a quadratic build and a list-like tree). A round that merges
// fewer than an eighth of the clusters also merges each unpaired cluster with its unpaired nearest
// neighbour, in order, then pairs up the clusters left over, neighbours in the order. So every
// round removes at least a sixteenth of the clusters: O(n radius) work in all, depth O(log n) on
// such input. Ordinary input almost never takes this path.
//
// The neighbour search runs in parallel (it only reads); merging and compaction are serial and in
// order, so the tree is the same with any number of threads.
#include "bvhkit/build/flatten.hpp"
#include "bvhkit/build/morton.hpp"
#include "bvhkit/build/options.hpp"

namespace bvhkit {

namespace bottom_up_detail {

inline constexpr std::uint32_t unpaired = 0xFFFFFFFFu;

/// Rank of the pair (i, j) among pairs of equal area (see the tie rule above); equal for (j, i).
inline std::uint64_t tie_rank(std::size_t i, std::size_t j) {
    const std::uint64_t d = i > j ? i - j : j - i, lo = std::min(i, j);
    return d << 33 | (lo & 1) << 32 | lo;
}

/// The cluster within `radius` positions of i whose union with i has the smallest area (ties by
/// tie_rank). With areas that overflow to inf no area is smaller than another, so the search never
/// starts from i itself (it would name itself and be dropped).
template <class T, std::size_t N>
std::uint32_t nearest(const std::vector<Aabb<T, N>>& box, std::size_t i, std::size_t radius) {
    const std::size_t m = box.size();
    const std::size_t lo = i > radius ? i - radius : 0;
    const std::size_t hi = std::min(m - 1, i + radius);
    std::size_t best_j = lo == i ? lo + 1 : lo;
    T best = unite(box[i], box[best_j]).area();
    for (std::size_t j = best_j + 1; j <= hi; ++j) {
        if (j == i) continue;
        const T a = unite(box[i], box[j]).area();
        if (a < best || (a == best && tie_rank(i, j) < tie_rank(i, best_j))) best = a, best_j = j;
    }
    return static_cast<std::uint32_t>(best_j);
}

/// Sets partner[i] (of the m clusters) to the cluster i merges with this round, or `unpaired`:
/// mutual nearest neighbours, and when they are fewer than m / 8 clusters, the progress rule
/// above. Returns the number of clusters merged.
inline std::size_t pair_up(const std::vector<std::uint32_t>& nearest,
                           std::vector<std::uint32_t>& partner, std::size_t m) {
    std::size_t merged = 0;
    for (std::size_t i = 0; i < m; ++i) {
        partner[i] = nearest[nearest[i]] == i ? nearest[i] : unpaired;
        merged += partner[i] != unpaired;
    }
    if (merged >= m / 8) return merged;
    for (std::size_t i = 0; i < m; ++i) {  // each with its nearest neighbour while both are free
        const std::uint32_t j = nearest[i];
        if (partner[i] == unpaired && partner[j] == unpaired) {
            partner[i] = j;
            partner[j] = static_cast<std::uint32_t>(i);
            merged += 2;
        }
    }
    std::size_t waiting = unpaired;
    for (std::size_t i = 0; i < m; ++i) {  // the rest with each other, neighbours in the order
        if (partner[i] != unpaired) continue;
        if (waiting == unpaired) {
            waiting = i;
            continue;
        }
        partner[i] = static_cast<std::uint32_t>(waiting);
        partner[waiting] = static_cast<std::uint32_t>(i);
        merged += 2;
        waiting = unpaired;
    }
    return merged;
}

}  // namespace bottom_up_detail

template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_bottom_up(std::span<const Aabb<T, N>> boxes,
                                std::span<const Vec<T, N>> centroids,
                                std::span<const std::uint32_t> indices, const BuildOptions& options,
                                const Executor& exec) {
    BinaryTree tree;
    const std::size_t n = indices.size();
    if (n == 0) return {};
    const std::vector<MortonItem> items = morton_order(centroids, indices, exec);
    tree.reserve(2 * n - 1);
    tree.order.resize(n);
    std::vector<std::uint32_t> cluster(n);  // tree node of each live cluster, in order
    std::vector<Aabb<T, N>> box(n);
    for (std::size_t k = 0; k < n; ++k) {
        tree.order[k] = items[k].index;
        cluster[k] = tree.add_leaf(static_cast<std::uint32_t>(k), 1);
        box[k] = boxes[items[k].index];
    }
    const std::size_t radius = std::clamp<std::size_t>(options.ploc_radius, 1, max_ploc_radius);
    std::vector<std::uint32_t> nearest(n), partner(n);
    while (cluster.size() > 1) {
        const std::size_t m = cluster.size();
        exec.parallel_for(m, 1024, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i)
                nearest[i] = bottom_up_detail::nearest(box, i, radius);
        });
        bottom_up_detail::pair_up(nearest, partner, m);
        std::size_t out = 0;
        for (std::size_t i = 0; i < m; ++i) {
            const std::size_t j = partner[i];
            if (j == bottom_up_detail::unpaired) {
                cluster[out] = cluster[i];
                box[out] = box[i];
                ++out;
            } else if (i < j) {  // the pair's first member makes the parent, in its place
                cluster[out] = tree.add_internal(cluster[i], cluster[j]);
                box[out] = unite(box[i], box[j]);
                ++out;
            }
        }
        cluster.resize(out);
        box.resize(out);
    }
    tree.root = cluster[0];
    return flatten(tree, boxes, {options.max_leaf_size, options.max_depth, options.costs});
}

/// As above, on an executor of options.threads.
template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_bottom_up(std::span<const Aabb<T, N>> boxes,
                                std::span<const Vec<T, N>> centroids,
                                std::span<const std::uint32_t> indices,
                                const BuildOptions& options) {
    return build_bottom_up(boxes, centroids, indices, options, Executor(options.threads));
}

}  // namespace bvhkit

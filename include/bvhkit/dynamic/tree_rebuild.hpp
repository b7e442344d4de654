#pragma once
// Top-down binned SAH build over the dynamic tree's nodes, used by DynamicTree::rebuild(). Its
// inputs are "items": leaves, or whole subtrees kept as they are (a partial rebuild keeps every
// subtree that enlarge() did not touch). The build makes new internal nodes above the items and
// returns the root.
//
// At each range of items: bin the item centroids into kBins bins along each axis, sweep the bins
// from both ends to get the SAH cost  area(left) * count(left) + area(right) * count(right)  of
// each of the kBins - 1 planes, and split at the cheapest plane of the three axes; when all
// centroids coincide (or no plane separates them) split the range in halves. The ranges wait on an
// explicit stack.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "bvhkit/dynamic/tree_insertion.hpp"
#include "bvhkit/dynamic/tree_types.hpp"

namespace bvhkit::dynamic_detail {

/// A box's centre computed from halves, so that boxes reaching +-FLT_MAX do not overflow to inf.
template <class T, std::size_t N>
Vec<T, N> safe_centroid(const Aabb<T, N>& b) {
    return b.min * T(0.5) + b.max * T(0.5);
}

/// Bin of centroid coordinate c in [lo, hi] (lo < hi), out of `bins`. Uses halves and a ratio in
/// [0, 1] so that neither the range nor its inverse can overflow (a range of 2 * FLT_MAX, or one of
/// a few subnormals), which would give a NaN bin.
template <class T>
int bin_of(T c, T lo, T hi, int bins) {
    const T r = (c * T(0.5) - lo * T(0.5)) / (hi * T(0.5) - lo * T(0.5));
    return std::min(bins - 1, static_cast<int>(std::clamp(r, T(0), T(1)) * T(bins)));
}

template <class T, std::size_t N>
struct BuildItem {
    Vec<T, N> centroid;
    std::int32_t node;
};

struct BuildTask {
    std::int32_t begin, end;  // item range
    std::int32_t parent;      // node to hang the result under (kNullNode for the root)
    std::int32_t slot;        // 1 or 2: which child of parent
};

/// Scratch storage for the build, owned by the tree so repeated rebuilds do not allocate.
template <class T, std::size_t N>
struct BuildScratch {
    std::vector<BuildItem<T, N>> items;
    std::vector<BuildTask> tasks;
    std::vector<std::int32_t>
        created;  // internal nodes in creation order (parents before children)
};

/// Builds a tree over scratch.items (at least one). `alloc()` returns a fresh node index and must
/// not move the node array (the caller reserves enough free nodes first). Returns the root.
template <class T, std::size_t N, class Alloc>
std::int32_t build_binned_sah(Node<T, N>* nodes, BuildScratch<T, N>& s, Alloc&& alloc) {
    constexpr int kBins = 16;
    auto& items = s.items;
    s.tasks.clear();
    s.created.clear();
    std::int32_t root = kNullNode;
    s.tasks.push_back({0, static_cast<std::int32_t>(items.size()), kNullNode, 0});

    while (!s.tasks.empty()) {
        const BuildTask task = s.tasks.back();
        s.tasks.pop_back();
        std::int32_t node;
        if (task.end - task.begin == 1) {
            node = items[task.begin].node;
        } else {
            // Bounds of the items and of their centroids.
            Aabb<T, N> bounds, cbounds;
            for (std::int32_t i = task.begin; i < task.end; ++i) {
                bounds.grow(nodes[items[i].node].box);
                cbounds.grow(items[i].centroid);
            }
            std::int32_t mid = task.begin + (task.end - task.begin) / 2;
            bool spread = false;
            for (std::size_t axis = 0; axis < N; ++axis)
                spread = spread || cbounds.max[axis] > cbounds.min[axis];
            if (spread) {
                int best_axis = -1, best_split = 0;
                Cost best_cost = std::numeric_limits<Cost>::infinity();
                for (std::size_t axis = 0; axis < N; ++axis) {
                    const T lo = cbounds.min[axis], hi = cbounds.max[axis];
                    if (!(hi > lo)) continue;
                    Aabb<T, N> bin_box[kBins];
                    int bin_count[kBins] = {};
                    for (std::int32_t i = task.begin; i < task.end; ++i) {
                        const int b = bin_of(items[i].centroid[axis], lo, hi, kBins);
                        bin_box[b].grow(nodes[items[i].node].box);
                        ++bin_count[b];
                    }
                    // Right-to-left sweep stores the cost of everything right of each plane.
                    Cost right_cost[kBins];
                    Aabb<T, N> acc;
                    int count = 0;
                    for (int b = kBins - 1; b > 0; --b) {
                        acc.grow(bin_box[b]);
                        count += bin_count[b];
                        right_cost[b] = count ? box_area(acc) * Cost(count) : Cost(0);
                    }
                    acc = Aabb<T, N>();
                    count = 0;
                    for (int b = 0; b < kBins - 1; ++b) {  // plane between bin b and bin b + 1
                        acc.grow(bin_box[b]);
                        count += bin_count[b];
                        if (count == 0 || count == task.end - task.begin) continue;
                        const Cost cost = box_area(acc) * Cost(count) + right_cost[b + 1];
                        if (cost < best_cost)
                            best_cost = cost, best_axis = int(axis), best_split = b;
                    }
                }
                if (best_axis >= 0) {
                    const T lo = cbounds.min[best_axis], hi = cbounds.max[best_axis];
                    auto* split = std::partition(
                        items.data() + task.begin, items.data() + task.end, [&](const auto& it) {
                            return bin_of(it.centroid[best_axis], lo, hi, kBins) <= best_split;
                        });
                    mid = static_cast<std::int32_t>(split - items.data());
                    if (mid == task.begin || mid == task.end) {
                        mid = task.begin + (task.end - task.begin) / 2;
                    }
                }
            }
            node = alloc();
            Node<T, N>& n = nodes[node];
            n.box = bounds;
            n.child1 = n.child2 = kNullNode;
            n.height = 0;
            n.enlarged = 0;
            s.created.push_back(node);
            s.tasks.push_back({task.begin, mid, node, 1});
            s.tasks.push_back({mid, task.end, node, 2});
        }
        nodes[node].parent = task.parent;
        if (task.parent == kNullNode) {
            root = node;
        } else if (task.slot == 1) {
            nodes[task.parent].child1 = node;
        } else {
            nodes[task.parent].child2 = node;
        }
    }
    // Heights bottom-up: children were created after their parents.
    for (auto it = s.created.rbegin(); it != s.created.rend(); ++it) {
        Node<T, N>& n = nodes[*it];
        n.height = 1 + std::max<std::int32_t>(nodes[n.child1].height, nodes[n.child2].height);
    }
    return root;
}

/// Copies the tree under `root` into `out` (cleared), depth first, so that the pool holds exactly
/// the nodes in use; calls relink(proxy, new leaf index) for every leaf. Returns the new root.
template <class T, std::size_t N, class Relink>
std::int32_t compact_nodes(const std::vector<Node<T, N>>& nodes, std::int32_t root,
                           std::vector<Node<T, N>>& out, Relink&& relink) {
    out.clear();
    if (root == kNullNode) return kNullNode;
    struct Item {
        std::int32_t old, parent, slot;
    };
    std::vector<Item> stack{{root, kNullNode, 0}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        const auto i = static_cast<std::int32_t>(out.size());
        out.push_back(nodes[it.old]);
        out[i].parent = it.parent;
        if (it.slot == 1) out[it.parent].child1 = i;
        if (it.slot == 2) out[it.parent].child2 = i;
        if (out[i].is_leaf()) {
            relink(out[i].proxy(), i);
        } else {
            stack.push_back({nodes[it.old].child2, i, 2});
            stack.push_back({nodes[it.old].child1, i, 1});
        }
    }
    return 0;
}

}  // namespace bvhkit::dynamic_detail

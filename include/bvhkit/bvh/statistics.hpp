#pragma once
// Tree statistics: the figures that tell a good tree from a bad one.
//
// SAH cost (Goldsmith and Salmon 1987; MacDonald and Booth 1990): the expected cost of a random
// ray,
//   sum over internal nodes n of  A(n)/A(root) * traversal_cost
// + sum over leaves l of          A(l)/A(root) * count(l) * intersection_cost,
// A being surface area in 3D and perimeter in 2D. Lower is better; it is comparable across builders
// of the same input.
#include <algorithm>

#include "bvhkit/bvh/iterate.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

struct SahCosts {
    double traversal = tuning::sah_traversal_cost;
    double intersection = tuning::sah_intersection_cost;
    /// Primitives a leaf tests at once: a leaf of n costs intersection * ceil(n / leaf_block)
    /// (Embree's SAH block size), so a builder stops splitting where the halves would cost a test
    /// each. 1..64, or 0 for the tree's own choice: 8 or 4 for TriangleBvh's eight- or four-wide
    /// ray layouts, whose leaves test that many triangles abreast, 1 everywhere else.
    std::uint32_t leaf_block = 0;

    std::uint32_t block() const { return leaf_block ? leaf_block : 1; }
    /// ceil(count / block()): the tests a leaf of `count` primitives takes.
    std::uint32_t leaf_tests(std::uint32_t count) const {
        return count / block() + (count % block() != 0);  // no overflow near 2^32
    }
};

struct BvhStatistics {
    std::size_t node_count = 0;
    std::size_t leaf_count = 0;
    std::size_t primitive_count = 0;  // primitive slots in leaves
    std::uint32_t depth = 0;          // of the deepest leaf; a lone root leaf has depth 0
    std::vector<std::size_t> leaf_size_histogram;  // [k] = number of leaves holding k primitives
    double sah_cost = 0.0;
    double average_leaf_size() const {
        return leaf_count ? double(primitive_count) / leaf_count : 0.0;
    }
};

template <class Volume>
double sah_cost(const Bvh<Volume>& bvh, SahCosts costs = {}) {
    if (bvh.empty()) return 0.0;
    const double root_area = double(bvh.root().bounds.area());
    double cost = 0.0;
    for (const auto& node : bvh.nodes) {
        // A flat (zero-area) root makes every ratio 0/0; count every node at full weight then.
        const double ratio = root_area > 0 ? double(node.bounds.area()) / root_area : 1.0;
        cost += ratio * (node.is_leaf() ? costs.intersection * costs.leaf_tests(node.count)
                                        : costs.traversal);
    }
    return cost;
}

template <class Volume>
BvhStatistics statistics(const Bvh<Volume>& bvh, SahCosts costs = {}) {
    BvhStatistics s;
    s.node_count = bvh.nodes.size();
    for_each_node_depth_first(bvh, [&](std::uint32_t index, std::uint32_t depth) {
        const auto& node = bvh.nodes[index];
        s.depth = std::max(s.depth, depth);
        if (!node.is_leaf()) return;
        ++s.leaf_count;
        s.primitive_count += node.count;
        if (s.leaf_size_histogram.size() <= node.count)
            s.leaf_size_histogram.resize(node.count + 1);
        ++s.leaf_size_histogram[node.count];
    });
    s.sah_cost = sah_cost(bvh, costs);
    return s;
}

}  // namespace bvhkit

#pragma once
// The four-wide top level of SceneRayTop (scene/rays.hpp) for float scenes: the binary tree over
// the instances' world boxes collapsed into nodes of four children, whose boxes are held one array
// per axis and bound, so one SSE pass clips the ray against all four (Wald, Benthin and Boulos,
// "Getting rid of packets", 2008; Dammertz et al., "Shallow bounding volume hierarchies", 2008).
// A top level has one instance a leaf and its leaves cost a whole bottom-level walk each, so
// its nodes are few and the walk is the simple one, on walk_depth_first (walk/walks.hpp): the
// children hit are sorted by entry distance, the nearest gone on with and the others pushed
// farthest first; an entry beyond the closest hit so far is dropped when popped.
//
// The slab test is RaySlabData's (math/ray.hpp) lane by lane: the near and far planes chosen by
// the direction's signs, the far distance scaled up by 1 + 2 gamma(3) (so rounding never loses a
// box the ray meets), and a NaN distance (a zero or subnormal direction component on a plane)
// leaving the interval as it was. An empty lane is marked in the node's mask, not by its box, so
// a ray that ignores an axis (a subnormal component: NaN distances) cannot enter it.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/traversal_stack.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/simd/simd.hpp"
#include "bvhkit/walk/walks.hpp"

namespace bvhkit::scene_detail {

#if BVHKIT_SIMD

/// A node or leaf of the top level (child >= 0: a node; < 0: ~ the leaf's index) and the entry
/// distance of the ray into its box.
struct TopRef {
    std::int32_t child;
    float entry;
};

/// The top level as a NodeView: the walk opens the nodes itself (four children clipped at once).
struct TopNodes {
    using Ref = TopRef;
    Ref root() const { return {0, -std::numeric_limits<float>::infinity()}; }
    bool is_leaf(const Ref& r) const { return r.child < 0; }
};

class WideTop4 {
  public:
    WideTop4() = default;
    /// From a binary tree: each wide node takes a binary node's two children and opens the
    /// largest internal one among them until it has four; a leaf keeps its run of primitives.
    explicit WideTop4(const Bvh<Aabb<float, 3>>& bvh) : primitives_(bvh.primitive_indices) {
        if (bvh.nodes.empty()) return;
        nodes_.reserve(bvh.nodes.size() / 2 + 1);
        nodes_.emplace_back();
        fill(bvh, 0, 0);
    }
    bool empty() const { return nodes_.empty(); }

    /// Walks the leaves the ray meets within [ray.tmin, tmax], for a traceable ray:
    /// on_leaf(primitive) -> bool for each primitive of each, true stops the walk; it may lower
    /// tmax (a closest hit), and with NearestFirst the leaves are reached in order of their boxes'
    /// entry distance.
    template <bool NearestFirst, class OnLeaf>
    void walk(const Ray<float, 3>& ray, float& tmax, OnLeaf&& on_leaf) const {
        if (nodes_.empty()) return;
        constexpr float far_scale = 1.0f + 2.0f * rounding_gamma<float>(3);
        const RaySlabData<float, 3> slab(ray);
        using F = simd::Float<4>;
        F origin[3], inv[3];
        std::uint32_t near_row[3];
        for (std::size_t a = 0; a < 3; ++a) {
            origin[a] = F(slab.origin[a]);
            inv[a] = F(slab.inv_direction[a]);
            near_row[a] = (slab.octant >> a) & 1u;  // 1: the near plane is the box's max
        }
        const F scale(far_scale);
        // Each node pushes at most three besides the one gone on with: depth of the collapsed
        // tree times three, with room to spare (a binary top level is at most max_bvh_depth deep).
        FixedStack<TopRef, 3 * max_bvh_depth + 4> stack;
        // A subtree or leaf entered beyond the closest hit so far is dropped.
        const auto enter = [&](const TopRef& r) { return !(r.entry > tmax); };
        const auto leaf_walk = [&](const TopRef& r) {
            const Leaf leaf = leaves_[std::size_t(~r.child)];
            for (std::uint32_t i = leaf.first; i < leaf.first + leaf.count; ++i)
                if (on_leaf(primitives_[i])) return false;
            return true;
        };
        const auto open = [&](TopRef& r, decltype(stack)& pending) -> bool {
            const Node& n = nodes_[std::size_t(r.child)];
            F t0(ray.tmin), t1(tmax);
            for (std::size_t a = 0; a < 3; ++a) {
                const F lo = F::load(n.bound[near_row[a]][a]);
                const F hi = F::load(n.bound[1 - near_row[a]][a]);
                const F tn = (lo - origin[a]) * inv[a];
                const F tf = (hi - origin[a]) * inv[a] * scale;
                // max and min return their second operand when either is NaN: a NaN
                // distance leaves the interval as it was.
                t0 = max(tn, t0);
                t1 = min(tf, t1);
            }
            unsigned hits = (t0 <= t1).bits() & n.mask;
            if (!hits) return false;
            alignas(16) float entry[4];
            t0.store(entry);
            TopRef found[4];
            int k = 0;
            for (; hits; hits &= hits - 1) {
                const int lane = __builtin_ctz(hits);
                found[k++] = {n.child[lane], entry[lane]};
            }
            if (NearestFirst)  // insertion sort, farthest first
                for (int i = 1; i < k; ++i)
                    for (int j = i; j > 0 && found[j - 1].entry < found[j].entry; --j)
                        std::swap(found[j - 1], found[j]);
            for (int i = 0; i < k - 1; ++i) pending.push(found[i]);
            r = found[k - 1];
            return true;
        };
        walk_depth_first(TopNodes{}, stack, enter, leaf_walk, open);
    }

  private:
    struct alignas(16) Node {
        float bound[2][3][4];   // [min or max][axis][lane]
        std::int32_t child[4];  // >= 0: a node; < 0: ~ the leaf's index in leaves_
        unsigned mask = 0;      // the lanes in use
    };
    struct Leaf {
        std::uint32_t first, count;  // a run of primitives_
    };

    void fill(const Bvh<Aabb<float, 3>>& bvh, std::size_t wide, std::uint32_t binary) {
        std::uint32_t open[4];
        int k = 0;
        const auto& b = bvh.nodes[binary];
        if (b.is_leaf()) {
            open[k++] = binary;
        } else {
            open[k++] = b.left();
            open[k++] = b.right();
            while (k < 4) {  // open the internal child with the largest box
                int pick = -1;
                float area = -1;
                for (int i = 0; i < k; ++i) {
                    const auto& c = bvh.nodes[open[i]];
                    if (!c.is_leaf() && c.bounds.area() > area) pick = i, area = c.bounds.area();
                }
                if (pick < 0) break;
                const auto& c = bvh.nodes[open[pick]];
                open[pick] = c.left();
                open[k++] = c.right();
            }
        }
        for (int lane = 0; lane < 4; ++lane) {
            Node& n = nodes_[wide];
            if (lane >= k) {
                for (int s = 0; s < 2; ++s)
                    for (int a = 0; a < 3; ++a) n.bound[s][a][lane] = 0;
                n.child[lane] = -1;
                continue;
            }
            const auto& c = bvh.nodes[open[lane]];
            for (int a = 0; a < 3; ++a)
                n.bound[0][a][lane] = c.bounds.min[a], n.bound[1][a][lane] = c.bounds.max[a];
            n.mask |= 1u << lane;
            if (c.is_leaf()) {
                n.child[lane] = ~std::int32_t(leaves_.size());
                leaves_.push_back({c.first, c.count});
            } else {
                const std::size_t child = nodes_.size();
                n.child[lane] = std::int32_t(child);
                nodes_.emplace_back();  // may move nodes_: n is not used below
                fill(bvh, child, open[lane]);
            }
        }
    }

    std::vector<Node> nodes_;
    std::vector<Leaf> leaves_;
    std::vector<std::uint32_t> primitives_;
};

#endif

}  // namespace bvhkit::scene_detail

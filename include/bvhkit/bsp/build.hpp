#pragma once
// Building a BSP tree over convex polygons (Fuchs, Kedem and Naylor 1980: pick a polygon's plane,
// put the others in front, behind or split them, repeat on each side).
//
// Each node scores candidate planes by split_weight * spanning + (1 - split_weight) * |front -
// back| (counted over at most count_sample of its polygons) and takes the lowest (first on ties,
// so builds are deterministic). Polygons in the
// splitter's thick plane stay at the node, those facing along its normal first. The build is
// iterative: a stack of pending nodes, each with its list of polygon indices.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "bvhkit/bsp/node.hpp"
#include "bvhkit/bsp/options.hpp"
#include "bvhkit/bsp/polygon.hpp"
#include "bvhkit/bsp/split.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit {

template <class T, std::size_t N = 3>
struct BspBuildResult {
    std::vector<BspNode<T, N>> nodes;
    PolygonPool<T, N> polygons;  // ordered by node: a node's polygons are one run
    BspStatistics stats;
};

namespace bsp_detail {

struct Counts {
    std::size_t front = 0, back = 0, spanning = 0, coplanar = 0;
};

template <class T, std::size_t N>
struct Candidate {
    Plane<T, N> plane;
    bool axis = false;
};

template <class T, std::size_t N>
class Builder {
  public:
    Builder(PolygonPool<T, N> pool, const BspOptions& options, T epsilon)
        : pool_(std::move(pool)), options_(options), eps_(epsilon) {}

    BspBuildResult<T, N> run(std::size_t input_triangles, std::size_t dropped) {
        BspBuildResult<T, N> out;
        out.polygons.source_planes = pool_.source_planes;
        out.nodes.emplace_back();
        std::vector<std::uint32_t> all(pool_.size());
        for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
        std::vector<Task> stack;
        stack.push_back({0, 0, BspCell::Outside, std::move(all)});
        BspStatistics& s = out.stats;
        s.input_triangles = input_triangles;
        s.dropped_degenerate = dropped;
        s.epsilon = double(eps_);
        while (!stack.empty()) {
            Task task = std::move(stack.back());
            stack.pop_back();
            s.depth = std::max<std::size_t>(s.depth, task.depth);
            BspNode<T, N> node;
            node.first = std::uint32_t(out.polygons.size());
            const bool halt =
                task.list.size() <= options_.leaf_size || task.depth >= options_.max_depth;
            Candidate<T, N> best;
            if (!task.list.empty() && !halt && choose(task.list, best))
                split(task, best, node, out, stack);
            else
                make_leaf(task, node, out);
            out.nodes[task.node] = node;
        }
        finish_statistics(out);
        return out;
    }

  private:
    /// A node waiting to be built, with the polygons that reach it.
    struct Task {
        std::uint32_t node;
        std::uint32_t depth;
        BspCell cell_if_empty;
        std::vector<std::uint32_t> list;
    };

    /// Makes `node` an interior node on `best`: its coplanar polygons stay at the node (those
    /// facing the plane's way first), the others go to the front or back child (spanning ones
    /// split in two), and both children are pushed, front on top.
    void split(Task& task, const Candidate<T, N>& best, BspNode<T, N>& node,
               BspBuildResult<T, N>& out, std::vector<Task>& stack) {
        BspStatistics& s = out.stats;
        std::vector<std::uint32_t> front, back, facing_back;
        for (const std::uint32_t i : task.list) {
            const auto v = pool_.vertices_of(i);
            switch (classify_polygon(v, best.plane, eps_)) {
                case Side::Front:
                    front.push_back(i);
                    break;
                case Side::Back:
                    back.push_back(i);
                    break;
                case Side::Coplanar:
                    if (dot(pool_.plane_of(i).normal, best.plane.normal) >= T(0))
                        emit(out.polygons, i), ++node.front_facing;
                    else
                        facing_back.push_back(i);
                    break;
                case Side::Spanning: {
                    split_polygon(v, best.plane, eps_, f_part_, b_part_);
                    const std::uint32_t src = pool_.polygons[i].source;
                    front.push_back(pool_.add(f_part_, src));
                    back.push_back(pool_.add(b_part_, src));
                    ++s.splits;
                    break;
                }
            }
        }
        for (const std::uint32_t i : facing_back) emit(out.polygons, i);
        node.count = std::uint32_t(out.polygons.size()) - node.first;
        node.plane = best.plane;
        node.axis_aligned = best.axis;
        s.polygons_at_nodes += node.count;
        ++s.interior_nodes;
        node.front = std::uint32_t(out.nodes.size());
        node.back = node.front + 1;
        out.nodes.emplace_back();
        out.nodes.emplace_back();
        // The cells beside an axis-aligned plane are not known to be in or out.
        const BspCell fc = best.axis ? BspCell::Unknown : BspCell::Outside;
        const BspCell bc = best.axis ? BspCell::Unknown : BspCell::Inside;
        task.list.clear();
        task.list.shrink_to_fit();
        stack.push_back({node.back, task.depth + 1, bc, std::move(back)});
        stack.push_back({node.front, task.depth + 1, fc, std::move(front)});
    }

    /// Makes `node` a leaf holding the task's polygons; an empty one takes the cell its side of
    /// the parent's plane says.
    void make_leaf(const Task& task, BspNode<T, N>& node, BspBuildResult<T, N>& out) {
        BspStatistics& s = out.stats;
        for (const std::uint32_t i : task.list) emit(out.polygons, i);
        node.count = std::uint32_t(task.list.size());
        node.cell = node.count == 0 ? task.cell_if_empty : BspCell::Unknown;
        s.polygons_in_leaves += node.count;
        ++s.leaves;
        if (node.count == 0) ++s.empty_leaves;
    }

    /// The totals of a finished tree, and whether it is solid (every leaf a known empty cell).
    static void finish_statistics(BspBuildResult<T, N>& out) {
        BspStatistics& s = out.stats;
        s.nodes = out.nodes.size();
        s.polygons = out.polygons.size();
        s.vertices = out.polygons.vertices.size();
        s.solid = true;
        for (const auto& n : out.nodes)
            if (n.is_leaf() && (n.count != 0 || n.cell == BspCell::Unknown)) s.solid = false;
        s.memory_bytes = out.nodes.size() * sizeof(BspNode<T, N>) +
                         out.polygons.polygons.size() * sizeof(BspPolygon) +
                         out.polygons.vertices.size() * sizeof(Vec<T, N>) +
                         out.polygons.source_planes.size() * sizeof(Plane<T, N>);
    }

    void emit(PolygonPool<T, N>& to, std::uint32_t i) {
        to.add(pool_.vertices_of(i), pool_.polygons[i].source);
    }

    Counts count(const std::vector<std::uint32_t>& list, const Plane<T, N>& plane,
                 double bound) const {
        Counts c;
        const double w = options_.split_weight;
        const std::size_t n = list.size();
        const std::size_t m = std::min<std::size_t>(n, options_.count_sample);
        for (std::size_t j = 0; j < m; ++j) {
            switch (classify_polygon(pool_.vertices_of(list[j * n / m]), plane, eps_)) {
                case Side::Front:
                    ++c.front;
                    break;
                case Side::Back:
                    ++c.back;
                    break;
                case Side::Coplanar:
                    ++c.coplanar;
                    break;
                case Side::Spanning:
                    ++c.spanning;
                    break;
            }
            // The least score the polygons still to count could leave: stop when it cannot win.
            const double gap = std::abs(double(c.front) - double(c.back)) - double(m - 1 - j);
            if (w * double(c.spanning) + (1 - w) * std::max(0.0, gap) >= bound) {
                c.spanning = std::numeric_limits<std::size_t>::max();
                return c;
            }
        }
        return c;
    }

    // The best candidate for `list`, false when none makes progress.
    bool choose(const std::vector<std::uint32_t>& list, Candidate<T, N>& best) const {
        const std::size_t n = list.size();
        const std::size_t k = std::min<std::size_t>(n, options_.candidate_count);
        double best_score = std::numeric_limits<double>::infinity();
        bool found = false;
        const double w = options_.split_weight;
        auto consider = [&](const Candidate<T, N>& c) {
            const Counts r = count(list, c.plane, best_score);
            if (r.spanning == std::numeric_limits<std::size_t>::max()) return;
            // An axis-aligned plane must leave each side fewer polygons than the node has (in the
            // sample, hence in the list), or splitting could go on forever; a polygon plane always
            // keeps its own polygon at the node.
            const std::size_t m = r.front + r.back + r.spanning + r.coplanar;
            if (c.axis && (r.front + r.spanning >= m || r.back + r.spanning >= m)) return;
            const double score =
                w * double(r.spanning) + (1 - w) * std::abs(double(r.front) - double(r.back));
            if (score < best_score) {
                best_score = score;
                best = c;
                found = true;
            }
        };
        const bool polygons = options_.candidates != BspCandidates::AxisAligned;
        const bool axes = options_.candidates != BspCandidates::PolygonPlanes;
        for (std::size_t j = 0; j < k; ++j) {
            const std::uint32_t i = list[j * n / k];
            if (polygons) consider({pool_.plane_of(i), false});
            if (axes) {
                const auto v = pool_.vertices_of(i);
                Vec<T, N> c{};
                for (const auto& p : v) c += p;
                c = c / T(v.size());
                for (int a = 0; a < int(N); ++a)
                    consider({Plane<T, N>::axis_aligned(a, c[std::size_t(a)]), true});
            }
        }
        if (!found && !polygons) {
            // No axis plane makes progress (a node of few polygons, or all at one coordinate).
            for (std::size_t j = 0; j < k; ++j) consider({pool_.plane_of(list[j * n / k]), false});
        }
        return found;
    }

    PolygonPool<T, N> pool_;
    BspOptions options_;
    T eps_;
    std::vector<Vec<T, N>> f_part_, b_part_;  // split_polygon's output, reused by every split
};

}  // namespace bsp_detail

/// Builds a BSP over `pool` (polygons with their source planes set) with thick-plane `epsilon`
/// (absolute). `input_triangles` and `dropped` are passed through to the statistics.
template <class T, std::size_t N>
BspBuildResult<T, N> build_bsp(PolygonPool<T, N> pool, const BspOptions& options, T epsilon,
                               std::size_t input_triangles, std::size_t dropped) {
    options.validate();
    return bsp_detail::Builder<T, N>(std::move(pool), options, epsilon)
        .run(input_triangles, dropped);
}

}  // namespace bvhkit

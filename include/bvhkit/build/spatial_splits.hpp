#pragma once
// Spatial splits: the SBVH of Stich, Friedrich and Dietrich 2009 ("Spatial splits in bounding
// volume hierarchies"), TriangleBvh's high-quality build (TriangleBvhOptions::spatial_splits).
//
// The tree is built over references: a triangle and a box around a part of it. Each node is offered
// the binned SAH object split (BinnedSahRule, the default builder's rule, run on the references'
// boxes) and, where that split's children overlap by more than `alpha` of the root's area (the
// paper's restriction: elsewhere a spatial split seldom wins, and its binning is most of the cost),
// a spatial split: the node's box is cut into equal bins on each axis, each reference is clipped
// into every bin it spans ("chopped binning"), and the SAH is evaluated at the bin planes with the
// references that cross a plane counted on both sides. The cheapest of leaf, object split and
// spatial split wins. A spatial split clips a reference that crosses its plane into two, unless
// putting it whole on one side is cheaper (the paper's reference unsplitting). A clipped triangle
// lies in several leaves, so primitive_indices names it more than once; every point of a triangle
// lies in the box of at least one leaf that names it.
//
// Exactness: the references' boxes are kept in double, and clip_to_slab pads each crossing point
// it computes by a bound on that point's rounding, so a box always holds the true part of its
// triangle. The node boxes are those boxes rounded outward to T. Memory is bounded: at most
// `budget` times the triangle count of extra references are made, shared out down the tree in
// proportion to each node's references. The build is serial. Areas are measured in double: a
// double mesh whose root box has an area beyond double's range (extents past about 1e154 or below
// 1e-154) gets object splits only.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/build/binned_sah.hpp"
#include "bvhkit/build/sah.hpp"
#include "bvhkit/build/top_down_core.hpp"
#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/primitives/triangle.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// The spatial-split build's own parameters; TriangleBvhOptions::spatial carries them.
struct SpatialSplitOptions {
    /// Spatial splits are tried where the object split's children overlap by more than alpha of
    /// the root's surface area: 0 tries them everywhere; finite, >= 0. Smaller values build
    /// slower for the same rays on the meshes measured (tuning.hpp).
    double alpha = tuning::spatial_split_alpha;
    /// Extra references allowed, as a fraction of the triangles: 0..4. Bounds the memory.
    double budget = 1.0;
    /// Bins of a spatial split on each axis: 2..256 (tuning.hpp).
    std::uint32_t bins = tuning::spatial_split_bins;
};

/// Throws bvhkit::Error naming the first field outside its range.
inline void validate_spatial_options(const SpatialSplitOptions& s) {
    if (!(s.alpha >= 0) || !std::isfinite(s.alpha))
        throw Error("SpatialSplitOptions::alpha must be finite and >= 0");
    if (!(s.budget >= 0 && s.budget <= 4))
        throw Error("SpatialSplitOptions::budget must be in [0, 4]");
    if (s.bins < 2 || s.bins > 256) throw Error("SpatialSplitOptions::bins must be in [2, 256]");
}

namespace spatial_detail {

using Box = Aabb<double, 3>;
using Point = Vec<double, 3>;

/// Whether edge a-b crosses the plane x[axis] = q strictly between its ends (an end on the plane
/// is a corner; an infinite plane crosses nothing), and where: x = a + t (b - a), x[axis] = q.
inline bool crossing(const Point& a, const Point& b, std::size_t axis, double q, Point& x) {
    if (!((a[axis] < q && q < b[axis]) || (b[axis] < q && q < a[axis]))) return false;
    const double t = (q - a[axis]) / (b[axis] - a[axis]);
    for (std::size_t c = 0; c < 3; ++c) x[c] = a[c] + t * (b[c] - a[c]);
    x[axis] = q;
    return true;
}

/// A box that holds the part of triangle `v` that lies in `ref` and in lo <= x[axis] <= hi (lo, hi
/// may be infinite); empty when the triangle has no part there. The corners are exact in double;
/// a crossing of an edge with a plane, a + t (b - a), is off by at most 6 units of roundoff
/// (3 epsilon) of |a| + |b| per coordinate when rounding to nearest, twice that under a directed
/// rounding mode, so it is padded by 16 epsilon (plus a few least denormals).
inline Box clip_to_slab(const Point (&v)[3], const Box& ref, std::size_t axis, double lo,
                        double hi) {
    constexpr double u = std::numeric_limits<double>::epsilon();
    constexpr double tiny = 4 * std::numeric_limits<double>::denorm_min();
    Box out;
    for (int k = 0; k < 3; ++k) {
        const Point& a = v[k];
        const Point& b = v[(k + 1) % 3];
        if (a[axis] >= lo && a[axis] <= hi) out.grow(a);
        for (const double plane : {lo, hi}) {
            Point x;
            if (!crossing(a, b, axis, plane, x)) continue;
            Point low = x, high = x;
            for (std::size_t c = 0; c < 3; ++c) {
                if (c == axis) continue;
                const double pad = 16 * u * (std::fabs(a[c]) + std::fabs(b[c])) + tiny;
                low[c] = x[c] - pad;
                high[c] = x[c] + pad;
            }
            out.grow(low);
            out.grow(high);
        }
    }
    out = intersect(out, ref);
    out.min[axis] = std::max(out.min[axis], lo);
    out.max[axis] = std::min(out.max[axis], hi);
    return out.is_empty() ? Box{} : out;
}

/// `b` rounded outward to T: the least box of T that holds it.
template <class T>
Aabb<T, 3> round_out(const Box& b) {
    if constexpr (std::is_same_v<T, double>) {
        return b;
    } else {
        Aabb<T, 3> out;
        for (std::size_t a = 0; a < 3; ++a) {
            T lo = T(b.min[a]), hi = T(b.max[a]);
            if (double(lo) > b.min[a]) lo = std::nextafter(lo, -std::numeric_limits<T>::infinity());
            if (double(hi) < b.max[a]) hi = std::nextafter(hi, std::numeric_limits<T>::infinity());
            out.min[a] = lo;
            out.max[a] = hi;
        }
        return out;
    }
}

/// The best spatial split of a node, as evaluated on its bins.
struct SpatialCandidate {
    double cost = std::numeric_limits<double>::infinity();  // sah_partial_cost's units
    std::uint32_t axis = 0;
    double plane = 0;
};

template <class T, class TriangleAt>
class Builder {
  public:
    Builder(TriangleAt& triangle_at, std::size_t count, const BuildOptions& options,
            const SpatialSplitOptions& spatial, BuildReport* report)
        : triangle_at_(triangle_at), options_(options), spatial_(spatial) {
        std::vector<Box> boxes(count);
        std::vector<Point> centroids(count);
        for (std::size_t i = 0; i < count; ++i) {
            // The triangle's own box, as every other build takes it (a NaN corner makes it
            // non-finite; grown point by point in double, the NaN would drop out).
            const Aabb<T, 3> box = triangle_at_(i).bounds();
            for (std::size_t a = 0; a < 3; ++a) {
                boxes[i].min[a] = double(box.min[a]);
                boxes[i].max[a] = double(box.max[a]);
            }
            centroids[i] = safe_centroid(boxes[i]);
        }
        // Zero area (misjudged either way, a triangle is still covered: "flat" only means never
        // split).
        flat_.resize(count);
        for (std::size_t i = 0; i < count; ++i) {
            Point v[3];
            corners(triangle_at_(i), v);
            const Point n = cross(v[1] - v[0], v[2] - v[0]);
            flat_[i] = n[0] == 0 && n[1] == 0 && n[2] == 0;
        }
        BuildInput<double, 3> in{boxes, centroids};
        std::vector<Point> fixed;
        const std::vector<std::uint32_t> usable =
            usable_primitives(in, fixed, options, Executor::serial(), report);
        const std::size_t n = usable.size();
        const std::size_t capacity =
            n + std::size_t(spatial.budget * double(n));  // at most 5n: fits 2^32 - 2 below
        if (capacity >= std::size_t(0xFFFFFFFFu))
            throw Error("spatial splits: " + std::to_string(n) + " triangles with budget " +
                        std::to_string(spatial.budget) + " need more than 2^32 - 2 references");
        ref_box_.resize(capacity);
        ref_centroid_.resize(capacity);
        ref_triangle_.resize(capacity);
        for (std::size_t k = 0; k < n; ++k) {
            ref_box_[k] = boxes[usable[k]];
            ref_centroid_[k] = in.centroids[usable[k]];
            ref_triangle_[k] = usable[k];
        }
        ref_count_ = n;
        ids_.resize(n);
        for (std::uint32_t k = 0; k < n; ++k) ids_[k] = k;
        bins_.resize(spatial.bins);
        parts_.resize(spatial.bins);
        planes_.resize(spatial.bins + 1);
        right_area_.resize(spatial.bins);
        right_count_.resize(spatial.bins);
    }

    Bvh<Aabb<T, 3>> build() {
        Bvh<Aabb<T, 3>> out;
        if (ids_.empty()) return out;
        const BuildInput<double, 3> refs{ref_box_, ref_centroid_};
        BinnedSahRule<double, 3> rule(refs, options_);
        const std::uint32_t max_depth = std::min(options_.max_depth, max_bvh_depth);
        const std::uint32_t max_leaf = std::max<std::uint32_t>(1, options_.max_leaf_size);
        Box root;
        for (std::uint32_t id : ids_) root.grow(ref_box_[id]);
        root_area_ = root.area();
        out.nodes.emplace_back();
        // The work of a node: its references are ids_[begin, end), always the end of ids_, so a
        // spatial split can grow them in place. The child pushed last is split next.
        // A node's budget is its share of the extra references: what it does not spend goes to its
        // children in proportion to their references (depth first, the budget would otherwise go
        // to whichever subtree is built first).
        struct Work {
            std::uint32_t node, begin, end, depth;
            Box bounds;
            std::size_t budget;
        };
        std::vector<Work> stack{
            {0, 0, std::uint32_t(ids_.size()), 0, root, ref_box_.size() - ref_count_}};
        while (!stack.empty()) {
            const Work w = stack.back();
            stack.pop_back();
            const std::uint32_t count = w.end - w.begin;
            Box left_box, right_box;
            const std::size_t refs_before = ref_count_;
            budget_ = w.budget;
            const std::uint32_t left_count = split(rule, w.begin, count, w.depth, w.bounds,
                                                   max_depth, max_leaf, left_box, right_box);
            if (left_count == 0) {
                Aabb<T, 3> box;
                for (std::uint32_t k = w.begin; k < w.end; ++k) {
                    box.grow(round_out<T>(ref_box_[ids_[k]]));
                    out.primitive_indices.push_back(ref_triangle_[ids_[k]]);
                }
                out.nodes[w.node].bounds = box;
                out.nodes[w.node].first = std::uint32_t(out.primitive_indices.size() - count);
                out.nodes[w.node].count = count;
                ids_.resize(w.begin);
                continue;
            }
            const auto first = std::uint32_t(out.nodes.size());
            out.nodes.resize(out.nodes.size() + 2);
            out.nodes[w.node].first = first;
            out.nodes[w.node].count = 0;
            const auto end = std::uint32_t(ids_.size());
            const std::size_t left_over = w.budget - (ref_count_ - refs_before);
            const auto left_share =
                std::size_t(double(left_over) * double(left_count) / double(end - w.begin));
            stack.push_back(
                {first, w.begin, w.begin + left_count, w.depth + 1, left_box, left_share});
            stack.push_back({first + 1, w.begin + left_count, end, w.depth + 1, right_box,
                             left_over - left_share});
        }
        // Children come after their parents: one reverse pass makes each box its children's union.
        for (std::size_t i = out.nodes.size(); i-- > 0;) {
            auto& node = out.nodes[i];
            if (!node.is_leaf())
                node.bounds = unite(out.nodes[node.left()].bounds, out.nodes[node.right()].bounds);
        }
        return out;
    }

  private:
    static void corners(const Triangle<T>& t, Point (&v)[3]) {
        const Vec<T, 3>* p[3] = {&t.p0, &t.p1, &t.p2};
        for (int k = 0; k < 3; ++k)
            for (std::size_t a = 0; a < 3; ++a) v[k][a] = double((*p[k])[a]);
    }

    /// Splits the node of ids_[begin, begin + count) and returns how many references go left
    /// (ids_[begin, begin + left)), the rest after them to the end of ids_; 0 for a leaf.
    std::uint32_t split(BinnedSahRule<double, 3>& rule, std::uint32_t begin, std::uint32_t count,
                        std::uint32_t depth, const Box& bounds, std::uint32_t max_depth,
                        std::uint32_t max_leaf, Box& left_box, Box& right_box) {
        // The object split is the top-down driver's own step (the rule, the halting rules, the
        // median fallback); a spatial split may then replace it.
        const BuildInput<double, 3> refs{ref_box_, ref_centroid_};
        const top_down_detail::Context<double, 3> cx{refs, ids_.data(), nullptr, max_depth,
                                                     max_leaf};
        top_down_detail::Work<double, 3> work{0, begin, begin + count, depth, {}};
        work.bounds.boxes.grow(bounds);
        for (std::uint32_t k = begin; k < begin + count; ++k)
            work.bounds.centroids.grow_point(ref_centroid_[ids_[k]]);
        RangeBounds<double, 3> left, right;
        const std::uint32_t left_count =
            top_down_detail::split_node(cx, work, rule, Executor::serial(), left, right);
        if (left_count == 0) return 0;
        left_box = left.boxes.box();
        right_box = right.boxes.box();
        // Where the depth left only just suffices, the driver halved: no spatial split there.
        if (must_halve(count, depth, max_leaf, max_depth) || budget_ == 0 ||
            count <= min_spatial_count || !(root_area_ > 0))
            return left_count;
        const Box overlap = intersect(left_box, right_box);
        if (overlap.is_empty() || !(overlap.area() > spatial_.alpha * root_area_))
            return left_count;
        const double object_cost = sah_partial_cost(options_.costs, left_box.area(), left_count,
                                                    right_box.area(), count - left_count);
        const SpatialCandidate best = best_spatial(begin, count, bounds);
        if (!(best.cost < object_cost)) return left_count;
        if (!sah_split_beats_leaf(options_.costs, best.cost, bounds.area(), count) &&
            count <= max_leaf)
            return 0;
        const std::uint32_t spatial_left = spatial_split(begin, count, best, left_box, right_box);
        if (spatial_left == 0) {  // it would leave a side empty: keep the object split
            left_box = left.boxes.box();
            right_box = right.boxes.box();
            return left_count;
        }
        return spatial_left;
    }

    double plane(const Box& bounds, std::size_t axis, std::uint32_t k) const {
        const double lo = bounds.min[axis], hi = bounds.max[axis];
        return k >= spatial_.bins ? hi : lo + (hi - lo) * double(k) / double(spatial_.bins);
    }

    /// Chopped binning on every axis of the node's box, then the SAH at each bin plane.
    SpatialCandidate best_spatial(std::uint32_t begin, std::uint32_t count, const Box& bounds) {
        SpatialCandidate best;
        const std::uint32_t bin_count = spatial_.bins;
        const std::size_t budget_left = budget_;
        for (std::size_t axis = 0; axis < 3; ++axis) {
            const double lo = bounds.min[axis], extent = bounds.max[axis] - lo;
            if (!(extent > 0)) continue;
            const double scale = double(bin_count) / extent;
            for (std::uint32_t k = 0; k <= bin_count; ++k) planes_[k] = plane(bounds, axis, k);
            const auto bin = [&](double x) {
                const double b = (x - lo) * scale;
                return b > 0 ? std::min(bin_count - 1, std::uint32_t(std::min(b, 1e9))) : 0u;
            };
            std::fill(bins_.begin(), bins_.end(), Bin{});
            for (std::uint32_t k = begin; k < begin + count; ++k) {
                const std::uint32_t id = ids_[k];
                const Box& box = ref_box_[id];
                const std::uint32_t first = bin(box.min[axis]), last = bin(box.max[axis]);
                ++bins_[first].enter;
                ++bins_[last].exit;
                if (first == last) {
                    bins_[first].box.grow(box);
                    continue;
                }
                chop(ref_triangle_[id], box, axis, first, last, bin);
            }
            Box acc;
            std::uint32_t n = 0;
            for (std::uint32_t b = bin_count; b-- > 1;) {
                acc.grow(bins_[b].box);
                n += bins_[b].exit;
                right_area_[b] = acc.area();
                right_count_[b] = n;
            }
            acc = Box{};
            std::uint32_t left_n = 0;
            for (std::uint32_t b = 1; b < bin_count; ++b) {  // the plane between bins b - 1 and b
                acc.grow(bins_[b - 1].box);
                left_n += bins_[b - 1].enter;
                const std::uint32_t right_n = right_count_[b];
                if (left_n == 0 || right_n == 0 || (left_n == count && right_n == count)) continue;
                if (left_n + right_n - count > budget_left) continue;
                const double cost =
                    sah_partial_cost(options_.costs, acc.area(), left_n, right_area_[b], right_n);
                if (cost < best.cost) best = {cost, std::uint32_t(axis), planes_[b]};
            }
        }
        return best;
    }

    /// Grows bins first..last (first < last) of `axis` by the parts of the triangle in each: its
    /// corners and its edges' crossings with the planes between them (each crossing serves the
    /// bins on both sides of its plane), within the reference's box. An estimate: the split
    /// itself clips with clip_to_slab's padding.
    template <class BinOf>
    void chop(std::uint32_t triangle, const Box& box, std::size_t axis, std::uint32_t first,
              std::uint32_t last, const BinOf& bin) {
        Point v[3];
        corners(triangle_at_(triangle), v);
        Box* const parts = parts_.data();  // parts[b - first]: bin b
        for (std::uint32_t b = first; b <= last; ++b) parts[b - first] = Box{};
        for (const Point& p : v) parts[std::clamp(bin(p[axis]), first, last) - first].grow(p);
        for (std::uint32_t b = first + 1; b <= last; ++b) {
            for (int k = 0; k < 3; ++k) {
                Point x;
                if (!crossing(v[k], v[(k + 1) % 3], axis, planes_[b], x)) continue;
                parts[b - 1 - first].grow(x);
                parts[b - first].grow(x);
            }
        }
        for (std::uint32_t b = first; b <= last; ++b) {
            Box part = intersect(parts[b - first], box);
            if (b > first) part.min[axis] = std::max(part.min[axis], planes_[b]);
            if (b < last) part.max[axis] = std::min(part.max[axis], planes_[b + 1]);
            if (!part.is_empty()) bins_[b].box.grow(part);
        }
    }

    /// Performs `s` on ids_[begin, begin + count): the left references, then the right ones, from
    /// `begin` to the new end of ids_; returns how many go left, or 0 (and changes nothing) when a
    /// side would be empty.
    std::uint32_t spatial_split(std::uint32_t begin, std::uint32_t count, const SpatialCandidate& s,
                                Box& left_box, Box& right_box) {
        constexpr double inf = std::numeric_limits<double>::infinity();
        const std::size_t axis = s.axis;
        left_ids_.clear();
        right_ids_.clear();
        straddling_.clear();
        Box left, right;
        for (std::uint32_t k = begin; k < begin + count; ++k) {
            const std::uint32_t id = ids_[k];
            const Box& box = ref_box_[id];
            if (box.max[axis] <= s.plane) {
                left_ids_.push_back(id);
                left.grow(box);
            } else if (box.min[axis] >= s.plane) {
                right_ids_.push_back(id);
                right.grow(box);
            } else {
                Point v[3];
                corners(triangle_at_(ref_triangle_[id]), v);
                Straddle st{id, clip_to_slab(v, box, axis, -inf, s.plane),
                            clip_to_slab(v, box, axis, s.plane, inf)};
                // An empty part can have some finite bounds: never grown by.
                if (!st.left.is_empty()) left.grow(st.left);
                if (!st.right.is_empty()) right.grow(st.right);
                straddling_.push_back(st);
            }
        }
        // Reference unsplitting: a crossing reference goes whole to one side when that costs less
        // than its two halves (areas times counts, the sides' boxes as they grow), and always once
        // the budget is spent.
        auto left_n = std::uint32_t(left_ids_.size() + straddling_.size());
        auto right_n = std::uint32_t(right_ids_.size() + straddling_.size());
        std::size_t budget_left = budget_;
        for (Straddle& st : straddling_) {
            // A triangle with no part on one side (its reference's box crossed the plane, the
            // triangle does not) goes to the other, with that side's box.
            if (st.left.is_empty() || st.right.is_empty()) {
                st.side = st.left.is_empty() ? Side::RightPart : Side::LeftPart;
                (st.left.is_empty() ? left_n : right_n) -= 1;
                continue;
            }
            const Box& whole = ref_box_[st.id];
            // A triangle of zero area is never hit: no reference is spent on it.
            const bool splits = budget_left > 0 && !flat_[ref_triangle_[st.id]];
            const double split_cost = left.area() * left_n + right.area() * right_n;
            const double to_left =
                unite(left, whole).area() * left_n + right.area() * (right_n - 1);
            const double to_right =
                left.area() * (left_n - 1) + unite(right, whole).area() * right_n;
            if (splits && split_cost <= std::min(to_left, to_right)) {
                st.side = Side::Both;
                --budget_left;
            } else if (to_left <= to_right) {
                st.side = Side::Left;
                left.grow(whole);
                --right_n;
            } else {
                st.side = Side::Right;
                right.grow(whole);
                --left_n;
            }
        }
        if (left_n == 0 || right_n == 0) return 0;
        left_box = Box{};
        right_box = Box{};
        for (std::uint32_t id : left_ids_) left_box.grow(ref_box_[id]);
        for (std::uint32_t id : right_ids_) right_box.grow(ref_box_[id]);
        for (const Straddle& st : straddling_) {
            if (st.side == Side::LeftPart) set_box(st.id, st.left);
            if (st.side == Side::RightPart) set_box(st.id, st.right);
            if (st.side == Side::Left || st.side == Side::LeftPart) {
                left_ids_.push_back(st.id);
                left_box.grow(ref_box_[st.id]);
            } else if (st.side == Side::Right || st.side == Side::RightPart) {
                right_ids_.push_back(st.id);
                right_box.grow(ref_box_[st.id]);
            } else {
                const auto twin = std::uint32_t(ref_count_++);
                ref_triangle_[twin] = ref_triangle_[st.id];
                set_box(st.id, st.left);
                set_box(twin, st.right);
                left_ids_.push_back(st.id);
                right_ids_.push_back(twin);
                left_box.grow(st.left);
                right_box.grow(st.right);
            }
        }
        ids_.resize(begin);
        ids_.insert(ids_.end(), left_ids_.begin(), left_ids_.end());
        ids_.insert(ids_.end(), right_ids_.begin(), right_ids_.end());
        return std::uint32_t(left_ids_.size());
    }

    void set_box(std::uint32_t id, const Box& box) {
        ref_box_[id] = box;
        ref_centroid_[id] = safe_centroid(box);
    }

    struct Bin {
        Box box;
        std::uint32_t enter = 0, exit = 0;
    };
    // Left / Right: whole, with its box; LeftPart / RightPart: only that side holds a part of it.
    enum class Side { Left, Right, LeftPart, RightPart, Both };
    struct Straddle {
        std::uint32_t id;
        Box left, right;  // the parts on each side of the plane
        Side side = Side::Both;
    };

    TriangleAt& triangle_at_;
    BuildOptions options_;
    SpatialSplitOptions spatial_;
    std::vector<Box> ref_box_;  // sized to the budget up front, so spans over them stay valid
    std::vector<Point> ref_centroid_;
    std::vector<std::uint32_t> ref_triangle_;
    std::size_t ref_count_ = 0;
    std::vector<std::uint32_t> ids_;  // the references of the nodes still to split, a stack
    double root_area_ = 0;
    std::vector<Bin> bins_;
    std::vector<Box> parts_;      // chop's, one per bin
    std::vector<double> planes_;  // best_spatial's bin planes on the axis it bins
    std::vector<char> flat_;      // per triangle: zero area (never hit, never split)
    std::size_t budget_ = 0;      // extra references the node being split may make
    // Nodes of at most this many references try object splits only (spatial binning is most of
    // the build's time, and few of its splits win in small nodes).
    static constexpr std::uint32_t min_spatial_count = tuning::spatial_split_min_count;
    std::vector<double> right_area_;
    std::vector<std::uint32_t> right_count_;
    std::vector<std::uint32_t> left_ids_, right_ids_;
    std::vector<Straddle> straddling_;
};

}  // namespace spatial_detail

/// A tree over `count` triangles (triangle_at(i) returns triangle i as a Triangle<T>) with spatial
/// splits; its leaves may name a triangle more than once. `options` as for build_bvh, with the
/// binned SAH's bins and costs; non-finite triangles are skipped or rejected as there.
template <class T, class TriangleAt>
Bvh<Aabb<T, 3>> build_spatial_split_bvh(TriangleAt&& triangle_at, std::size_t count,
                                        const BuildOptions& options,
                                        const SpatialSplitOptions& spatial = {},
                                        BuildReport* report = nullptr) {
    validate_options(options);
    validate_spatial_options(spatial);
    if (report) report->skipped.clear();
    spatial_detail::Builder<T, std::remove_reference_t<TriangleAt>> builder(
        triangle_at, count, options, spatial, report);
    return builder.build();
}

}  // namespace bvhkit

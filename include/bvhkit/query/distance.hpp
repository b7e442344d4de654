#pragma once
// Minimum distance between two models at a pose, with a closest pair of points and the triangle
// pair. Best first over node pairs: each pair carries the lower bound of its volumes' distance
// (VolumeTraits<V>::distance_lower_bound), the pending pair with the least bound is opened next,
// and the query ends when that bound shows nothing left can beat the best distance found (the
// branch and bound of Larsen, Gottschalk, Lin, Manocha 1999, "Fast proximity queries with swept
// sphere volumes"; Rss is their volume, the others work too).
//
// Tolerance: with absolute tolerance a and relative tolerance r, a pair is dropped once its bound
// is within max(a, r * best) of the best, so the answer is at most that much above the true
// distance. Both are 0 by default: the exact minimum (up to rounding).
//
// A zero-area triangle counts as the segment or point it is (triangle_triangle.hpp's rule).
// B's corners are carried into A's frame in double; triangle pairs that meet for the pose as given
// (exactly, as collide() decides: primitives/posed_triangles.hpp) are at distance 0 (the points
// then lie on an intersection segment), the others are measured in double (a pair beyond
// 2^+-150 at a power-of-two scale: triangle_distance.hpp). An empty model gives +infinity.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "bvhkit/math/wide_length.hpp"
#include "bvhkit/primitives/triangle_distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "bvhkit/walk/walks.hpp"

namespace bvhkit {

template <class T>
struct DistanceOptions {
    T absolute_tolerance = 0;
    T relative_tolerance = 0;
    DescentRule rule = DescentRule::Larger;  // Larger, A, B or Simultaneous (ByOverlap = Larger)
    /// Node pairs whose lower bound reaches this are not opened: a caller that keeps a running
    /// minimum over many pairs of meshes (a scene's closest pair) passes it, so a mesh pair that
    /// cannot beat it ends early. When the meshes' distance is below it, the result is the same as
    /// without it; otherwise it is some distance at or above it, or +inf (nothing measured).
    T upper_bound = std::numeric_limits<T>::infinity();
};

template <class T>
struct DistanceResult {
    T distance = std::numeric_limits<T>::infinity();
    Vec<T, 3> point_a{}, point_b{};  // closest points, both in A's frame
    std::uint32_t triangle_a = 0, triangle_b = 0;
    PairStats stats;  // volume bounds computed, triangle pairs measured
};

namespace detail {

/// Whether triangle `u` lies wholly on one side of triangle t's plane, at least `gap` from it
/// (then the triangles are at least `gap` apart). In double, comparing sixth powers of the
/// coordinates: only a normal, finite `reach` and |n|^2 are trusted (two sides overflowing to
/// inf >= inf, or sunk to 0 >= 0, would reject pairs that are not beyond; a subnormal one has lost
/// its bits), and anything else rejects nothing. distance() scales the pairs whose coordinates
/// leave 2^+-150 (triangle_distance.hpp), where it would reject nothing.
template <class T>
bool beyond_plane(const Triangle<T>& t, const Triangle<T>& u, T gap) {
    using V = Vec<double, 3>;
    if (!(double(gap) < std::numeric_limits<double>::infinity())) return false;
    const V t0(t.p0), n = cross(V(t.p1) - t0, V(t.p2) - t0);
    const double d0 = dot(n, V(u.p0) - t0), d1 = dot(n, V(u.p1) - t0), d2 = dot(n, V(u.p2) - t0);
    const double nn = length_squared(n), reach = double(gap) * double(gap) * nn;
    const double lo = std::min({d0, d1, d2}), hi = std::max({d0, d1, d2});
    return ((lo > 0 && lo * lo >= reach) || (hi < 0 && hi * hi >= reach)) &&
           std::min(nn, reach) >= std::numeric_limits<double>::min() &&
           reach <= std::numeric_limits<double>::max();
}

/// For a triangle pair outside triangle_distance.hpp's window: whether distance()'s sphere or
/// plane rejection drops it, both taken at scale 2^-k (`gap`, the best distance so far, scaled
/// alike). Out of line: such pairs are rare, and the common loop stays as small as before.
[[gnu::noinline]] inline bool rejected_at_scale(const Triangle<double>& a,
                                                const Triangle<double>& b, int k, double gap) {
    const Triangle<double> u = scaled_by(a, -k), v = scaled_by(b, -k);
    const double g = std::ldexp(gap, -k);
    const double ru = std::sqrt(std::max(length_squared(u.p1 - u.p0), length_squared(u.p2 - u.p0)));
    const double rv = std::sqrt(std::max(length_squared(v.p1 - v.p0), length_squared(v.p2 - v.p0)));
    const double reach = g + ru + rv;
    return length_squared(u.p0 - v.p0) > reach * reach || beyond_plane(u, v, g) ||
           beyond_plane(v, u, g);
}

/// feature_distance() of a pair at scale 2^-k: the squared distance at that scale (the true one
/// times 4^-k), the points scaled back.
[[gnu::noinline]] inline FeatureDistance feature_distance_at_scale(const Triangle<double>& a,
                                                                   const Triangle<double>& b,
                                                                   int k) {
    const Triangle<double> u = scaled_by(a, -k), v = scaled_by(b, -k);
    const Vec<double, 3> pu[3] = {u.p0, u.p1, u.p2}, pv[3] = {v.p0, v.p1, v.p2};
    const FeatureDistance f = feature_distance(pu, pv);
    return {f.distance_squared, scaled_by(f.p, k), scaled_by(f.q, k)};
}

/// A squared distance as s2 * 4^e: a pair measured at scale 2^-e (triangle_distance.hpp) keeps
/// its square there, which double holds where the square itself would overflow or sink to zero.
/// Pairs measured as given have e = 0 and compare as plain squares.
struct ScaledSquare {
    double s2 = std::numeric_limits<double>::infinity();
    int e = 0;
    /// Whether c2 * 4^ce is below this (any finite value is below the initial inf; an exponent
    /// far apart settles it by the scaling's overflow to inf or underflow to 0).
    bool exceeds(double c2, int ce) const {
        if (ce == e) return c2 < s2;
        if (!(s2 < std::numeric_limits<double>::infinity())) return c2 < s2;
        return std::ldexp(c2, 2 * (ce - e)) < s2;
    }
    /// The distance, rounded to T (inf beyond T's range).
    template <class T>
    T root() const {
        const double r = std::sqrt(s2);
        return narrow_or_inf<T>(e == 0 ? r : std::ldexp(r, e));
    }
};

/// A query's limits from the models' scales and the pose: `slack`, by which the volumes' bounds are
/// widened (infinite, turning pruning off, where their squares would leave T's range), and
/// `window_top`, whether every coordinate in A's frame stays within 2^150.
template <class T>
struct DistanceLimits {
    T slack;
    bool window_top;
};

template <class T>
DistanceLimits<T> distance_limits(T scale_a, T scale_b, const Transform<T>& pose_of_b_in_a) {
    // The volumes' distance bounds square lengths of the scene in T: where those squares leave
    // T's range (float models near 1e19 and beyond) a bound can overflow to inf and drop the
    // closest pair. Such models are measured without pruning (an infinite slack makes every
    // bound -inf): every pair, exactly; slow, but right.
    const T extent =
        scale_a + scale_b +
        max_component(bvhkit::max(pose_of_b_in_a.translation, -pose_of_b_in_a.translation));
    // At the other end the squares sink below T's normal range (models near 1e-154 in double,
    // 1e-19 in float), and a length rooted from them may be off by up to sqrt(2.5 denorm_min):
    // 16 sqrt(denorm_min) more slack keeps any bound made of a few such lengths below the true
    // distance (at ordinary scales it vanishes in the slack's rounding; models far below, it
    // turns pruning off as above).
    const T slack = std::isfinite(T(16) * extent * extent)
                        ? pose_slack(scale_a, scale_b, pose_of_b_in_a) +
                              T(16) * std::sqrt(std::numeric_limits<T>::denorm_min())
                        : std::numeric_limits<T>::infinity();
    // Whether every coordinate in A's frame is within 2^150: |R x + t| <= sqrt(3) |x| + |t| in
    // the largest component, so twice the extent (rounding included) bounds them.
    return {slack, 2 * double(extent) <= 0x1p150};
}

/// A pending node pair of distance()'s search and its volumes' distance lower bound.
template <class T>
struct DistancePair {
    std::uint32_t a, b;
    T bound;
};

/// Measures every triangle pair of leaves `na` (of A) and `nb` (of B), handing each one not
/// rejected to take(d2, exponent, p, q, slot_a, slot_b), which lowers `best` when it is closer.
/// Inlined: the search loop stays one piece of code, as it was measured.
template <class T, class Node, class Take>
[[gnu::always_inline]] inline void measure_leaf_pair(std::span<const Triangle<T>> ta,
                                                     std::span<const Triangle<T>> tb,
                                                     const Node& na, const Node& nb,
                                                     const PosedTriangles<T>& posed,
                                                     bool window_top, const T& best,
                                                     PairStats& stats, Take&& take) {
    // B's triangle outside: carried into A's frame (in double) once for all of A's.
    for (std::uint32_t sb = nb.first; sb < nb.first + nb.count; ++sb) {
        using D = Vec<double, 3>;
        const D vb[3] = {posed.apply(tb[sb].p0), posed.apply(tb[sb].p1), posed.apply(tb[sb].p2)};
        const Triangle<double> tri_b{vb[0], vb[1], vb[2]};
        // Every pair with this triangle inside the window of triangle_distance.hpp
        // (coordinates up to `window_top`, one of B's at least 2^-150): measured as
        // given, with no per-pair look at the magnitudes.
        const bool inside = window_top && max_component(abs(vb[0])) >= 0x1p-150;
        const double rb =
            std::sqrt(std::max(length_squared(vb[1] - vb[0]), length_squared(vb[2] - vb[0])));
        for (std::uint32_t sa = na.first; sa < na.first + na.count; ++sa) {
            const Triangle<double> tri_a{D(ta[sa].p0), D(ta[sa].p1), D(ta[sa].p2)};
            // Outside the window the pair is tested and measured at scale 2^-k (best
            // scaled alike), where its powers stay finite and normal.
            const int k =
                inside
                    ? 0
                    : pair_exponent(std::max(largest_coordinate(tri_b), largest_coordinate(tri_a)));
            if (k != 0) [[unlikely]] {
                if (rejected_at_scale(tri_a, tri_b, k, double(best))) continue;
                stats.primitive();
                const TriangleIntersection<T> x = posed.intersect(ta[sa], tb[sb], vb);
                if (x.hit) {
                    take(0.0, 0, D(x.p), D(x.p), sa, sb);
                } else {
                    const FeatureDistance f = feature_distance_at_scale(tri_a, tri_b, k);
                    take(f.distance_squared, k, f.p, f.q, sa, sb);
                }
                continue;
            }
            // Cheap rejection by the triangles' spheres about their first corners.
            const double ra = std::sqrt(
                std::max(length_squared(tri_a.p1 - tri_a.p0), length_squared(tri_a.p2 - tri_a.p0)));
            const double reach = double(best) + ra + rb;
            if (length_squared(tri_a.p0 - tri_b.p0) > reach * reach) continue;
            // Then by either triangle's plane: the other wholly at least `best` beyond
            // it (facing triangles of two surfaces, which the spheres keep).
            if (beyond_plane(tri_a, tri_b, double(best)) ||
                beyond_plane(tri_b, tri_a, double(best)))
                continue;
            stats.primitive();
            const TriangleIntersection<T> x = posed.intersect(ta[sa], tb[sb], vb);
            if (x.hit) {
                take(0.0, 0, D(x.p), D(x.p), sa, sb);
            } else {
                const D u[3] = {tri_a.p0, tri_a.p1, tri_a.p2};
                const FeatureDistance f = feature_distance(u, vb);
                take(f.distance_squared, 0, f.p, f.q, sa, sb);
            }
        }
    }
}

/// The child pairs of the inner pair `e` (nodes `na`, `nb`) that the descent rule opens, with
/// their bounds: bound(x, y) for a node of A against one of B, placed_bound(node, placed) for a
/// node against the other side's node placed in its frame (pairs.hpp, Placeable). The opening is
/// pairs.hpp's rule (choose picks the side, left child measured first here where that walk
/// pushes the right one first): keep the two in step. Returns how many of `kids` it filled.
template <BoundingVolume V, class Node, class Prepared, class Bound, class PlacedBound>
[[gnu::always_inline]] inline int open_pair(std::span<const Node> na_, std::span<const Node> nb_,
                                            const DistancePair<typename V::Scalar>& e,
                                            const Node& na, const Node& nb, DescentRule rule,
                                            const Prepared& pose, const Prepared& inverse,
                                            Bound&& bound, PlacedBound&& placed_bound,
                                            DistancePair<typename V::Scalar> (&kids)[4]) {
    using Traits = VolumeTraits<V>;
    int n = 0;
    switch (choose(rule, na, nb)) {
        case Open::A:
            if constexpr (Placeable<V>) {
                const V w = Traits::place(nb.bounds, pose);
                for (const std::uint32_t x : {na.left(), na.right()})
                    kids[n++] = {x, e.b, placed_bound(na_[x].bounds, w)};
            } else {
                kids[n++] = {na.left(), e.b, bound(na.left(), e.b)};
                kids[n++] = {na.right(), e.b, bound(na.right(), e.b)};
            }
            break;
        case Open::B:
            if constexpr (Placeable<V>) {
                const V w = Traits::place(na.bounds, inverse);
                for (const std::uint32_t y : {nb.left(), nb.right()})
                    kids[n++] = {e.a, y, placed_bound(nb_[y].bounds, w)};
            } else {
                kids[n++] = {e.a, nb.left(), bound(e.a, nb.left())};
                kids[n++] = {e.a, nb.right(), bound(e.a, nb.right())};
            }
            break;
        case Open::Both:
            for (std::uint32_t x : {na.left(), na.right()})
                for (std::uint32_t y : {nb.left(), nb.right()}) kids[n++] = {x, y, bound(x, y)};
            break;
    }
    return n;
}

/// Queues the child pairs that can still beat the best: the least of them goes on as `next`
/// without a trip through the heap when no pending pair is below it (the usual case while
/// refining toward a leaf), the others into the heap.
template <class T, class Heap, class Hopeless>
[[gnu::always_inline]] inline void queue_children(const DistancePair<T> (&kids)[4], int n,
                                                  Hopeless&& hopeless, Heap& heap,
                                                  DistancePair<T>& next, bool& have_next) {
    int least = -1;
    for (int k = 0; k < n; ++k)
        if (!hopeless(kids[k].bound) && (least < 0 || kids[k].bound < kids[least].bound)) least = k;
    for (int k = 0; k < n; ++k) {
        if (hopeless(kids[k].bound)) continue;
        if (k == least && (heap.empty() || kids[k].bound <= heap.top().bound)) {
            next = kids[k];
            have_next = true;
        } else {
            heap.push(kids[k]);
        }
    }
}

}  // namespace detail

// The search loop, its bounds and the best so far stay in this function; its steps (the limits,
// a leaf pair's measurement, a pair's opening, the children's queueing) are detail functions
// forced inline: the steps as members of a query class, or out of line, took more instructions
// on the placeable volumes (docs/benchmarks.md, "distance() in one piece").
template <BoundingVolume V>
DistanceResult<typename V::Scalar> distance(
    const CollisionModel<V>& a, const CollisionModel<V>& b,
    const Transform<typename V::Scalar>& pose_of_b_in_a,
    const DistanceOptions<typename V::Scalar>& options = {}) {
    using T = typename V::Scalar;
    using Traits = VolumeTraits<V>;
    check_rigid_pose(pose_of_b_in_a, "distance", "pose_of_b_in_a");
    if (std::isnan(options.upper_bound)) throw Error("distance: options.upper_bound is NaN");
    DistanceResult<T> result;
    if (a.bvh().empty() || b.bvh().empty()) return result;
    const auto& na_ = a.bvh().nodes;
    const auto& nb_ = b.bvh().nodes;
    const auto ta = a.slot_triangles();
    const auto tb = b.slot_triangles();
    const PosedTriangles<T> posed(pose_of_b_in_a, b.scale());
    const detail::DistanceLimits<T> limits =
        detail::distance_limits(a.scale(), b.scale(), pose_of_b_in_a);
    const T slack = limits.slack;
    const auto pose = Traits::prepare(pose_of_b_in_a, slack);
    const auto inverse = Traits::prepare(pose_of_b_in_a.inverse(), slack);
    // The best squared distance, kept in double (finite for any finite float input: a float
    // square overflows past 1.8e19) and scaled with its pair (detail::ScaledSquare); `best`, its
    // root in T, feeds the volumes' bounds.
    detail::ScaledSquare best2;
    T best = std::numeric_limits<T>::infinity();
    const T cap = options.upper_bound;
    const auto hopeless = [&](T lb) {
        if (lb >= cap) return true;
        if (!(best2.s2 < std::numeric_limits<double>::infinity())) return false;
        const T tol = std::max(options.absolute_tolerance, options.relative_tolerance * best);
        return lb >= best - tol;
    };
    const auto bound = [&](std::uint32_t x, std::uint32_t y) {
        result.stats.node();
        // A volume that can stop early once the pair is sure to be dropped (rss.hpp) is told
        // where that is: the best so far less the tolerance.
        if constexpr (requires {
                          Traits::distance_lower_bound(na_[x].bounds, nb_[y].bounds, pose, best);
                      }) {
            const T tol = std::max(options.absolute_tolerance, options.relative_tolerance * best);
            return Traits::distance_lower_bound(na_[x].bounds, nb_[y].bounds, pose,
                                                std::min(best - tol, cap));
        } else {
            return Traits::distance_lower_bound(na_[x].bounds, nb_[y].bounds, pose);
        }
    };
    // A node against the other node placed in its frame (pairs.hpp, detail::Placeable).
    const auto placed_bound = [&](const V& x, const V& w) {
        result.stats.node();
        if constexpr (requires { Traits::distance_lower_bound_placed(x, w, slack, best); }) {
            const T tol = std::max(options.absolute_tolerance, options.relative_tolerance * best);
            return Traits::distance_lower_bound_placed(x, w, slack, std::min(best - tol, cap));
        } else if constexpr (detail::Placeable<V>) {
            return Traits::distance_lower_bound_placed(x, w, slack);
        } else {
            return T(0);  // not called: only placeable volumes are placed
        }
    };
    const auto take = [&](double d2, int exponent, const Vec<double, 3>& p, const Vec<double, 3>& q,
                          std::uint32_t sa, std::uint32_t sb) {
        if (!best2.exceeds(d2, exponent)) return;
        best2 = {d2, exponent};
        best = best2.root<T>();
        result.distance = best;
        result.point_a = Vec<T, 3>(p);
        result.point_b = Vec<T, 3>(q);
        result.triangle_a = a.triangle_id(sa);
        result.triangle_b = b.triangle_id(sb);
    };
    using Entry = detail::DistancePair<T>;
    // Best first: the pending pair with the least bound is opened next, so the query ends as
    // soon as that bound cannot beat the best, having opened (nearly) only pairs whose bound is
    // below the answer; depth first with near-first children opened about twice as many on the
    // C2 workload, refining near pairs before a good best was known. The heap lives on for the
    // thread's next query, so a query allocates only when it needs more room than any before.
    thread_local std::vector<Entry> heap_storage;
    MinHeap4 heap(heap_storage, [](const Entry& x) { return x.bound; });
    const DescentRule rule =
        options.rule == DescentRule::ByOverlap ? DescentRule::Larger : options.rule;
    heap.push(Entry{0, 0, bound(0, 0)});
    // The step is forced inline: out of line it read the query's state through its closure.
    walk_best_first(
        heap, hopeless, [&](Entry & e, auto& queue) __attribute__((always_inline)) {
            const auto& na = na_[e.a];
            const auto& nb = nb_[e.b];
            if (na.is_leaf() && nb.is_leaf()) {
                detail::measure_leaf_pair<T>(ta, tb, na, nb, posed, limits.window_top, best,
                                             result.stats, take);
                return best2.s2 == 0 ? Step::Stop : Step::Pop;
            }
            Entry kids[4];
            const int n = detail::open_pair<V>(std::span(na_), std::span(nb_), e, na, nb, rule,
                                               pose, inverse, bound, placed_bound, kids);
            // A child that is already the least pending pair goes on without a trip through the
            // heap (the usual case while refining toward a leaf); it is not hopeless, or it would
            // not have been chosen.
            bool have_next = false;
            detail::queue_children(kids, n, hopeless, queue, e, have_next);
            return have_next ? Step::Continue : Step::Pop;
        });
    return result;
}

}  // namespace bvhkit

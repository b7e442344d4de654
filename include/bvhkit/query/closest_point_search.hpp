#pragma once
// The walk of one ClosestPointMesh::closest_point query (query/closest_point_mesh.hpp): its
// search limit (ClosestPointLimit) and its state and steps (ClosestPointSearch), which read the
// mesh's arrays as its friend.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "bvhkit/math/select.hpp"
#include "bvhkit/math/wide_length.hpp"
#include "bvhkit/primitives/closest_point.hpp"
#include "bvhkit/primitives/triangle_pack.hpp"
#include "bvhkit/query/nearest.hpp"

namespace bvhkit::detail {

/// A closest point's search limit: a squared distance in T, judged on the squared distance
/// rounded to T (closest_point's), or a distance, judged in W (closest_point_within's).
template <class T>
struct ClosestPointLimit {
    using W = AccurateScalar<T>;
    bool by_distance = false;
    T squared_limit = std::numeric_limits<T>::infinity();
    W distance_limit = 0, distance_limit2 = 0;  // by distance: the limit and its square in W
    static ClosestPointLimit squared(T max2) { return {false, max2, 0, 0}; }
    static ClosestPointLimit distance(W max) { return {true, 0, max, max * max}; }
    bool none() const { return by_distance ? !(distance_limit >= W(0)) : !(squared_limit >= T(0)); }
    /// The limit squared and times scale^2, rounded up to T (inf past its range), to prune.
    T scaled2(T scale) const {
        if (!by_distance) return squared_limit * scale * scale;
        const W s = distance_limit * W(scale);
        return nearest_detail::round_up_key<T>(s * s);
    }
    bool admits(W d2) const {
        if (!by_distance)  // (rounding to T: inf past its range)
            return (d2 > W(std::numeric_limits<T>::max()) ? std::numeric_limits<T>::infinity()
                                                          : T(d2)) <= squared_limit;
        // Where the square leaves W's normal range (W is double: a double limit past 1e154),
        // the distances are compared instead.
        if (distance_limit2 >= std::numeric_limits<W>::min() &&
            distance_limit2 < std::numeric_limits<W>::infinity())
            return d2 <= distance_limit2;
        return std::sqrt(d2) <= distance_limit;
    }
};

// One closest-point walk: the best triangle so far and the search radius, with the steps
// that change them (start_from, open_leaf, measure, tighten, finish).
//
// Candidates are measured accurately, in W (closest_point_accurate), and compared there: a
// squared distance past T's range (a point 1e19 from a float mesh) still ranks. The walk
// ranks by the packs' float distances and measures accurately only at the end, and only the
// candidates that rounding leaves in the running: a pack's distance is within the slack of
// widened() of the true one, so a candidate can still win while its estimate is within twice
// that slack of the best estimate. Slivers (a pack's exact_lanes) and points too far for the
// pack's formula are measured at once. The packs hold the mesh scaled to unit magnitude (see
// build): p likewise, and the estimates and the search radius are kept in those units, where
// the squared distances of a mesh 1e-36 across (float) do not sink below T's least normal.
// The node walk gets the radius unscaled.
template <class T, class Mesh, class Stats>
struct ClosestPointSearch {
    using W = AccurateScalar<T>;
    const Mesh& mesh;
    const Vec<T, 3>& p;
    const ClosestPointLimit<T>& limit;
    Stats& stats;
    std::vector<std::pair<T, std::uint32_t>>& candidates;
    NearestSlot<T> best;
    W best2 = std::numeric_limits<W>::infinity();          // accurate, unscaled
    T best_estimate = std::numeric_limits<T>::infinity();  // scaled
    T limit2;
    T search2;  // scaled
    Vec<T, 3> ps;
    // The pack formula squares lengths twice over: beyond 2^(max_exponent / 4) from the
    // (unit) mesh it would overflow, and every lane is measured.
    bool scaled_ok;
    T unscale;  // exact: a power of two (its square may not be)
    T box_radius2;
    // The best triangle's answer is kept, not measured again at the end: the triangle
    // measured is tris_[s] bit for bit (a pack's copy only when it unscales exactly).
    AccurateClosestPoint<T> best_point;
    // Candidates are ranked by their squared distance, which rounds by eps_W d^2: from a
    // point far off (d beyond twice the mesh's extent) that is more than the gaps between
    // its triangles' distances (1e16 from a float unit sphere, double's ulp there is 2). The
    // ranking then uses far_key (see there), which rounds in proportion to the mesh's
    // extent and coordinates, not to d.
    typename Mesh::FarFrame far;
    W best_key = std::numeric_limits<W>::infinity();

    ClosestPointSearch(const Mesh& m, const Vec<T, 3>& point, const ClosestPointLimit<T>& lim,
                       Stats& st, NearestScratch<T>& scratch)
        : mesh(m),
          p(point),
          limit(lim),
          stats(st),
          candidates(scratch.candidates),
          limit2(m.widened_scaled(lim.scaled2(m.pack_scale_))),
          search2(limit2),
          ps(point * m.pack_scale_),
          scaled_ok(max_component(abs(ps)) <
                    std::ldexp(T(1), std::numeric_limits<T>::max_exponent / 4)),
          unscale(T(1) / m.pack_scale_),
          box_radius2(box_radius()),
          far(m.far_frame(point)) {
        candidates.clear();
    }

    // The radius for the node walk's unscaled boxes: search2 unscaled, exactly, unless that
    // falls below 4 least normals, where rounding could drop a box within reach.
    [[gnu::always_inline]] T box_radius() const {
        return std::max(search2 * unscale * unscale, T(4) * std::numeric_limits<T>::min());
    }

    [[gnu::always_inline]] void measure(std::uint32_t s, const Triangle<T>& t) {
        const AccurateClosestPoint<T> c = mesh.frames_.empty()
                                              ? closest_point_accurate(t, p)
                                              : closest_point_accurate(t, mesh.frames_[s], p);
        const W d2 = c.distance_squared;
        const W key = far.far ? mesh.far_key(far, t, c) : d2;
        // The limit is judged as Limit::admits says. Of triangles with the same key the one
        // in the lowest slot wins, whatever the order they were measured in: every triangle
        // that ties with the best is measured (its estimate is within the slack), so the
        // answer does not depend on where the walk started.
        if ((key < best_key || (key == best_key && s < best.slot)) && limit.admits(d2))
            best = {s, T(d2)}, best2 = d2, best_key = key, best_point = c;
    }

    [[gnu::always_inline]] void tighten() {
        T bound = std::min(limit2, mesh.widened_scaled(mesh.widened_scaled(best_estimate)));
        if (best)
            bound = std::min(bound,
                             mesh.widened_scaled(T(best2 * mesh.pack_scale_ * mesh.pack_scale_)));
        search2 = bound;
        box_radius2 = box_radius();
    }

    // The nearest corner of the starting triangle bounds the distance from above, cheaply
    // (measuring the triangle itself bounds it tighter but cost more than it saved). The
    // bound is widened twice, as a pack's estimate is: its rounding is a few ulps of the
    // distance, far inside one widening.
    [[gnu::always_inline]] void start_from(std::uint32_t start) {
        const Triangle<T>& t = mesh.tris_[start];
        const auto scaled2 = [&](const Vec<T, 3>& corner) {
            return length_squared((p - corner) * mesh.pack_scale_);
        };
        const T corner2 = std::min({scaled2(t.p0), scaled2(t.p1), scaled2(t.p2)});
        search2 = std::min(search2, mesh.widened_scaled(mesh.widened_scaled(corner2)));
        box_radius2 = box_radius();
    }

    // A leaf child of the wide walk: its slivers measured at once, the other lanes within
    // the radius kept as candidates by their estimates.
    [[gnu::always_inline]] void open_leaf(std::uint32_t first, std::uint32_t groups) {
        for (std::uint32_t g = first; g < first + groups; ++g) {
            const TrianglePack4<T>& pack = mesh.packs_[g];
            for (int l = 0; l < 4; ++l)
                if (pack.slot[l] != invalid_index) stats.primitive();
            T d[4];
            const unsigned lanes =
                scaled_ok ? pack.lanes_within(ps, search2, d) : pack.used_lanes();
            const unsigned now = scaled_ok ? lanes & pack.exact_lanes : lanes;
            bool changed = false;
            for (unsigned m = now; m; m &= m - 1) {
                const int l = __builtin_ctz(m);
                const std::uint32_t s = pack.slot[l];
                // The pack's own copy, in cache already, when it unscales exactly.
                measure(s, mesh.packs_unscale_exactly_ ? pack.triangle(l, unscale) : mesh.tris_[s]);
                changed = true;
            }
            for (unsigned m = lanes & ~now; m; m &= m - 1) {
                const int l = __builtin_ctz(m);
                const T estimate = d[l];
                candidates.push_back({estimate, pack.slot[l]});
                if (estimate < best_estimate) best_estimate = estimate, changed = true;
            }
            if (changed) tighten();
        }
    }

    // Nearest estimate first; stop at the first whose estimate rounding cannot bring below
    // the best measured so far. Whether a triangle was found (best, best_point).
    [[gnu::always_inline]] bool finish() {
        std::sort(candidates.begin(), candidates.end());
        for (const auto& [estimate, s] : candidates) {
            if (best &&
                estimate > mesh.widened_scaled(T(best2 * mesh.pack_scale_ * mesh.pack_scale_)))
                break;
            if (estimate > search2) break;
            measure(s, mesh.tris_[s]);
        }
        return bool(best);
    }
};

}  // namespace bvhkit::detail

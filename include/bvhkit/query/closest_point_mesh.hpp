#pragma once
// ClosestPointMesh<T>: closest point on a triangle mesh, what geometry processing asks most. Build
// it from a mesh, then ask closest_point(p): the point on the surface, its squared distance, the
// triangle's index in the mesh and the barycentrics (u, v) of the point in that triangle
// (point = (1 - u - v) p0 + u p1 + v p2). Also the k nearest triangles, all triangles within a
// radius, and a batch of points (in parallel with oneTBB, the same answers as serial).
//
// It owns a Bvh (binned SAH by default) and a copy of the triangles in leaf order, so a leaf's
// triangles are contiguous. A triangle's distance is closest_point_accurate's
// (primitives/closest_point.hpp): computed in double for float meshes, long double for double
// ones, without cancellation, so the distance returned is the true distance from the point to the
// mesh within |d - d_true| <= 2 eps_T d + 96 eps_W (d + L) (L the longest edge; docs/accuracy.md),
// on slivers and far from the origin alike. The float boxes and packs only cull, against the
// search radius widened by their rounding. Triangles with a NaN or infinite coordinate are left
// out. Candidates are ranked in the wider type, so a point whose squared distance is past T's
// range (1e19 from a float mesh) still gets its closest triangle (distance_squared is then inf).
//
// closest_point walks a second form of the same tree, built from it: the binary tree collapsed
// to four children a node (bvh/wide_bvh.hpp), its leaves' triangles four abreast
// (primitives/triangle_pack.hpp). A pack's SIMD distances only pick which triangles to measure
// accurately, with a margin for rounding, so the answers are those of measuring every triangle;
// it opens fewer nodes and measures fewer triangles than the binary walk (docs/proximity.md).
// k_nearest and within_radius walk the binary tree.
#include <span>

#include "bvhkit/build/build.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/math/select.hpp"
#include "bvhkit/math/wide_length.hpp"
#include "bvhkit/primitives/closest_point.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/primitives/triangle_pack.hpp"
#include "bvhkit/query/closest_point_search.hpp"
#include "bvhkit/query/nearest.hpp"
#include "bvhkit/query/nearest_wide.hpp"
#include "bvhkit/query/point_order.hpp"
#include "bvhkit/simd/simd.hpp"

namespace bvhkit {

namespace serial_detail {
struct ClosestPointMeshAccess;  // io/closest_point_mesh_file.hpp: saves and loads the arrays
}

/// A point on the mesh: triangle == invalid_index when there is none (an empty mesh, or nothing
/// within the search radius).
template <class T>
struct MeshPoint {
    Vec<T, 3> point{};
    T distance_squared = std::numeric_limits<T>::infinity();
    /// The distance itself, rounded from the wider type the triangle was measured in: finite and
    /// non-zero where distance_squared over- or underflows T (a point 1e20 from a float mesh, a
    /// mesh 1e-25 across).
    T distance = std::numeric_limits<T>::infinity();
    std::uint32_t triangle = invalid_index;
    T u = 0, v = 0;
    explicit operator bool() const { return triangle != invalid_index; }
};

template <class T>
class ClosestPointMesh {
  public:
    ClosestPointMesh() = default;

    template <IndexedTriangleMesh M>
    explicit ClosestPointMesh(const M& mesh, const BuildOptions& options = {}) {
        const std::vector<Triangle<T>> tris = mesh_triangles<T>(mesh);
        build(tris, options);
    }
    explicit ClosestPointMesh(const std::vector<Triangle<T>>& triangles,
                              const BuildOptions& options = {}) {
        build(triangles, options);
    }

    /// The closest point of the mesh to p within sqrt(max_distance_squared); none for a point
    /// with a NaN or infinite coordinate.
    template <class Stats = NoStats>
    MeshPoint<T> closest_point(const Vec<T, 3>& p, NearestScratch<T>& scratch,
                               T max_distance_squared = std::numeric_limits<T>::infinity(),
                               Stats&& stats = {}) const {
        return closest_point_from(p, invalid_index, scratch, Limit::squared(max_distance_squared),
                                  stats);
    }
    /// The same answer as closest_point(p, scratch, max_distance_squared), found sooner when
    /// `near` is the answer for a point close to p (the previous point of a grid, or of a batch
    /// in spatial_order): the walk starts with the radius to the nearest corner of near's
    /// triangle instead of none. Any `near` gives the same answer (an invalid one, none; of
    /// triangles at the same distance the answer is always the one in the lowest leaf slot).
    MeshPoint<T> closest_point(const Vec<T, 3>& p, const MeshPoint<T>& near,
                               NearestScratch<T>& scratch,
                               T max_distance_squared = std::numeric_limits<T>::infinity()) const {
        const std::uint32_t start = near.triangle < slot_of_triangle_.size()
                                        ? slot_of_triangle_[near.triangle]
                                        : invalid_index;
        NoStats stats;
        return closest_point_from(p, start, scratch, Limit::squared(max_distance_squared), stats);
    }
    /// closest_point(p, near, scratch) within `max_distance` itself, not its square, given in the
    /// wider type W (double for a float mesh: a limit from Python or a double computation is
    /// taken as it is, not rounded to float). Judged on the squared distance in W against
    /// max_distance^2 taken there, so any finite limit holds at any scale (its square in T would
    /// be inf past 1.8e19 in float and 0 below 1e-23). Inclusive; a negative or NaN limit finds
    /// nothing.
    MeshPoint<T> closest_point_within(const Vec<T, 3>& p, AccurateScalar<T> max_distance,
                                      const MeshPoint<T>& near, NearestScratch<T>& scratch) const {
        const std::uint32_t start = near.triangle < slot_of_triangle_.size()
                                        ? slot_of_triangle_[near.triangle]
                                        : invalid_index;
        NoStats stats;
        return closest_point_from(p, start, scratch, Limit::distance(max_distance), stats);
    }
    MeshPoint<T> closest_point(const Vec<T, 3>& p) const {
        thread_local NearestScratch<T> scratch;
        return closest_point(p, scratch);
    }

    /// The k nearest triangles (nearest first), each with its closest point. They are ranked as
    /// closest_point ranks its candidates (in the wider type, far points by far_key), so the
    /// order holds for squared distances past T's range (a point 2e19 from a float mesh, a mesh
    /// 1e-25 across); of triangles with the same key the one in the lower leaf slot comes first.
    void k_nearest(const Vec<T, 3>& p, std::size_t k, std::vector<MeshPoint<T>>& out,
                   NearestScratch<T>& scratch) const {
        thread_local std::vector<std::pair<AccurateScalar<T>, std::uint32_t>> slots;
        bvhkit::k_nearest(bvh_, p, k, ranked_distance(p, true), scratch, slots);
        out.clear();
        for (const auto& [key, s] : slots) out.push_back(point_of(s, p));
    }

    /// Every triangle within `radius` of p (inclusive: the squared distance, measured in the
    /// wider type, against radius^2 taken there, exactly for float), in no particular order. A
    /// negative or NaN radius finds nothing.
    void within_radius(const Vec<T, 3>& p, T radius, std::vector<MeshPoint<T>>& out) const {
        out.clear();
        bvhkit::within_radius(bvh_, p, radius, ranked_distance(p, false),
                              [&](LeafSlot s, AccurateScalar<T>) {
                                  out.push_back(point_of(s.value, p));
                                  return true;
                              });
    }

    /// closest_point for every point, on `threads` threads (0 = all; see exec/executor.hpp).
    void closest_points(std::span<const Vec<T, 3>> points, std::span<MeshPoint<T>> out,
                        unsigned threads = 0) const {
        closest_points(points, out, Executor(threads));
    }
    /// closest_point for every point, on `exec`.
    void closest_points(std::span<const Vec<T, 3>> points, std::span<MeshPoint<T>> out,
                        const Executor& exec) const {
        if (out.size() < points.size())
            throw Error("ClosestPointMesh::closest_points: " + std::to_string(points.size()) +
                        " points but room for " + std::to_string(out.size()));
        // In spatial order (query/point_order.hpp): neighbours find the same nodes in cache.
        for_point_chunks(points, exec, 1024, [&](std::span<const std::uint32_t> chunk) {
            NearestScratch<T> scratch;
            MeshPoint<T> previous;  // each walk starts from its neighbour's answer
            for (const std::uint32_t i : chunk)
                previous = out[i] = closest_point(points[i], previous, scratch);
        });
    }

    const AabbBvh<T, 3>& bvh() const { return bvh_; }
    /// The triangle in leaf slot `slot` (slots are the order of bvh().primitive_indices).
    const Triangle<T>& triangle_in_slot(std::uint32_t slot) const { return tris_[slot]; }
    std::size_t triangle_count() const { return triangle_count_; }

  private:
    friend struct serial_detail::ClosestPointMeshAccess;

    template <class, class, class>
    friend struct detail::ClosestPointSearch;
    using Limit = detail::ClosestPointLimit<T>;

    // closest_point, its walk started from the triangle in leaf slot `start` when that is one.
    template <class Stats>
    MeshPoint<T> closest_point_from(const Vec<T, 3>& p, std::uint32_t start,
                                    NearestScratch<T>& scratch, const Limit& limit,
                                    Stats&& stats) const {
        // No distance is within a negative or NaN limit (and the walk would still measure).
        if (!is_finite(p) || limit.none()) return {};
        using Search =
            detail::ClosestPointSearch<T, ClosestPointMesh, std::remove_reference_t<Stats>>;
        Search search(*this, p, limit, stats, scratch);
        struct OpenLeaf {
            Search& search;
            const TrianglePack4<T>* packs;
            void operator()(std::uint32_t first, std::uint32_t groups) {
                search.open_leaf(first, groups);
            }
            std::uintptr_t address(std::uint32_t first) const {
                return reinterpret_cast<std::uintptr_t>(packs) + first * sizeof(*packs);
            }
        };
        if (start < triangle_slots_) search.start_from(start);
        nearest_wide(wide_, p, scratch, search.box_radius2, OpenLeaf{search, packs_.data()}, stats);
        return search.finish() ? point_of(search.best.slot, search.best_point) : MeshPoint<T>{};
    }

    void build(const std::vector<Triangle<T>>& tris, const BuildOptions& options) {
        std::vector<Aabb<T, 3>> boxes(tris.size());
        std::vector<Vec<T, 3>> centroids(tris.size());
        for (std::size_t i = 0; i < tris.size(); ++i) {
            boxes[i] = tris[i].bounds();
            centroids[i] = boxes[i].centroid();
        }
        bvh_ = build_bvh<T, 3>(boxes, centroids, options);
        tris_.clear();
        tris_.reserve(bvh_.primitive_indices.size() + 1);
        for (std::uint32_t i : bvh_.primitive_indices) tris_.push_back(tris[i]);
        // One triangle of padding: the SSE box test loads 4 floats from each corner, the last
        // slot's third corner reaching one float past its triangle.
        tris_.push_back(Triangle<T>{});
        triangle_count_ = tris.size();

        // The longest edge, rounded up, for widened(); triangles with a NaN or infinite
        // coordinate are left out of the tree and of this.
        double longest = 0;
        for (const Triangle<T>& t : tris) longest = std::max(longest, longest_edge_of(t));
        longest_edge_ = narrow_or_inf<T>(longest * (1 + 1e-6));
        derive_walk_data();
    }
    /// The longest edge of a triangle with finite corners (0 for one with a NaN or an infinity),
    /// in double without squaring (wide_length): the squares of a double mesh's edges overflow
    /// at 1e155 and sink at 1e-155. Inf only for an edge longer than double holds; a float mesh's
    /// longest edge past FLT_MAX makes longest_edge_ inf (widened() then prunes nothing).
    static double longest_edge_of(const Triangle<T>& t) {
        if (!t.bounds().is_finite()) return 0;
        const Vec<double, 3> a(t.p0), b(t.p1), c(t.p2);
        return std::max({wide_length(b - a), wide_length(c - b), wide_length(a - c)});
    }
    // The wide tree and the packs, from bvh_ and tris_ alone (a loaded file rebuilds them so).
    void derive_walk_data() {
        wide_ = collapse_to_wide(bvh_);
        // Where each triangle sits, for a walk that starts from a given triangle.
        triangle_slots_ = std::uint32_t(bvh_.primitive_indices.size());
        slot_of_triangle_.assign(triangle_count_, invalid_index);
        for (std::uint32_t s = 0; s < triangle_slots_; ++s)
            if (bvh_.primitive_indices[s] < triangle_count_)
                slot_of_triangle_[bvh_.primitive_indices[s]] = s;
        // A float mesh keeps each triangle's accurate frame (80 bytes; a double mesh's, in long
        // double, would take 144, so it keeps them only where long double is double): a query
        // measures ~3 triangles in full, and the frame is two square roots and six divisions of
        // each (the timings are in docs/benchmarks.md, "Figures behind code comments").
        frames_.clear();
        if constexpr (sizeof(AccurateScalar<T>) == sizeof(double)) {
            frames_.reserve(triangle_slots_);
            for (std::uint32_t s = 0; s < triangle_slots_; ++s)
                frames_.push_back(accurate_frame(tris_[s]));
        }
        // The packs hold the triangles scaled by a power of two (exact, barring denormals) that
        // brings the largest coordinate to [1, 2) (for all but meshes within a few binades of
        // T's range): the pack formula's products of four lengths then neither overflow nor
        // sink into denormals, for meshes in any unit.
        const T magnitude =
            bvh_.empty()
                ? T(0)
                : max_component(max(abs(bvh_.root().bounds.min), abs(bvh_.root().bounds.max)));
        constexpr int max_shift = std::numeric_limits<T>::max_exponent - 8;
        pack_scale_ =
            magnitude > T(0) && std::isfinite(magnitude)
                ? std::ldexp(T(1), std::clamp(-std::ilogb(magnitude), -max_shift, max_shift))
                : T(1);
        scaled_longest_edge_ = longest_edge_ * pack_scale_;
        // The far points' frame (far_key): the box's centre and squared diagonal, in W.
        far_origin_ = {};
        far_extent2_ = 0;
        if (!bvh_.empty()) {
            using W = AccurateScalar<T>;
            const Aabb<T, 3>& box = bvh_.root().bounds;
            for (int k = 0; k < 3; ++k) {
                const W lo = W(box.min[k]), hi = W(box.max[k]);
                far_origin_[k] = lo / 2 + hi / 2;  // halves first: no overflow
                far_extent2_ += (hi - lo) * (hi - lo);
            }
        }
        // A power of two scales exactly unless a coordinate falls into denormals; then the walk
        // measures from tris_ instead.
        packs_.assign(wide_.group_count(), TrianglePack4<T>{});
        packs_unscale_exactly_ = true;
        for (std::size_t i = 0; i < wide_.group_slots.size(); ++i) {
            const std::uint32_t s = wide_.group_slots[i];
            if (s == invalid_index) continue;
            const Triangle<T>& t = tris_[s];
            TrianglePack4<T>& pack = packs_[i / 4];
            pack.set(int(i % 4), {t.p0 * pack_scale_, t.p1 * pack_scale_, t.p2 * pack_scale_}, s);
            const Triangle<T> back = pack.triangle(int(i % 4), T(1) / pack_scale_);
            if (!(back.p0 == t.p0 && back.p1 == t.p1 && back.p2 == t.p2))
                packs_unscale_exactly_ = false;
        }
    }
    /// What far_key needs of a query point: whether it is far (its distance to the mesh's box
    /// above twice the box's diagonal), and p - o in W, o the box's centre.
    struct FarFrame {
        bool far = false;
        Vec<AccurateScalar<T>, 3> from_origin;
    };
    FarFrame far_frame(const Vec<T, 3>& p) const {
        using W = AccurateScalar<T>;
        FarFrame f;
        if (bvh_.empty()) return f;
        const Aabb<T, 3>& box = bvh_.root().bounds;
        W gap2 = 0;
        for (int k = 0; k < 3; ++k) {
            const W g = std::max({W(box.min[k]) - W(p[k]), W(p[k]) - W(box.max[k]), W(0)});
            gap2 += g * g;
        }
        f.far = gap2 > W(4) * far_extent2_;
        f.from_origin = Vec<W, 3>(p) - far_origin_;
        return f;
    }
    /// The rank of a candidate for a far point p: |p - x|^2 - |p - o|^2 = |y|^2 - 2 (p - o).y
    /// with x the candidate's closest point and y = x - o, o the mesh box's centre. The common
    /// |p - o|^2, whose rounding (eps_W d^2) hides the differences, is never formed: y is a
    /// corner's offset from o (one rounding, of a length within the box) plus the barycentric
    /// offset (nothing for a corner, so that the triangles around a closest vertex tie exactly
    /// and the lowest slot wins), and the products round by eps_W d |y|. The closest point is
    /// the exact one for p moved by rounding (eps_W d), which costs a few eps_W L in distance
    /// at most: the point found stays within the triangle, and a far point's distance changes
    /// to first order only along the direction to p. Divided by 2d, the key's error in distance
    /// is within 128 eps_W (E + L), E the box's diagonal, whatever d (docs/accuracy.md).
    AccurateScalar<T> far_key(const FarFrame& f, const Triangle<T>& t,
                              const AccurateClosestPoint<T>& c) const {
        using W = AccurateScalar<T>;
        using V = Vec<W, 3>;
        V y;
        if (c.u == W(0) && c.v == W(0)) {
            y = V(t.p0) - far_origin_;
        } else if (c.u == W(1)) {
            y = V(t.p1) - far_origin_;
        } else if (c.v == W(1)) {
            y = V(t.p2) - far_origin_;
        } else {
            const V a(t.p0);
            y = (a - far_origin_) + (V(t.p1) - a) * c.u + (V(t.p2) - a) * c.v;
        }
        return dot(y, y) - W(2) * dot(f.from_origin, y);
    }
    /// `radius2` widened by what rounding can put between a triangle's true distance and the
    /// float bounds on it: the pack's distance, the triangle's box, a node's box. Each is computed
    /// from differences of the (exact) coordinates, so its error scales with the lengths between
    /// the point and the triangle's corners, at most r + the longest edge for a triangle that can
    /// still be within r; tests/proximity/triangle_pack_test.cpp bounds a pack's distance error by
    /// 560 ulps of that length on triangles not flagged as slivers (slivers are always measured).
    /// The slack is 1024 ulps of it.
    T widened(T radius2) const { return widen(radius2, longest_edge_); }
    /// widened() in the packs' units (the mesh times pack_scale_): the same value times
    /// pack_scale_^2, bit for bit, where neither under- nor overflows; and never below 8 least
    /// normals, where the slack itself would have sunk (a mesh 1e25 across whose nearest
    /// triangles are 1e-25 of that: its scaled squared distances underflow).
    T widened_scaled(T radius2) const {
        const T w = widen(radius2, scaled_longest_edge_);
        return w >= T(0) ? std::max(w, T(8) * std::numeric_limits<T>::min()) : w;
    }
    static T widen(T radius2, T longest_edge) {
        if (!(radius2 >= T(0) && radius2 < std::numeric_limits<T>::infinity())) return radius2;
        const T r = std::sqrt(radius2);
        const T slack = T(1024) * std::numeric_limits<T>::epsilon() * (r + longest_edge);
        return (r + slack) * (r + slack);
    }
    /// The key of the triangle in a leaf slot, for k_nearest() and within_radius(): its squared
    /// distance measured in W, or for a far point (ranking only) far_key, which keeps the order
    /// where the squared distance's rounding would not.
    struct RankedDistance {
        using W = AccurateScalar<T>;
        const ClosestPointMesh* mesh;
        FarFrame far;
        W from_origin2 = 0;  // |p - o|^2, to turn a far key back into a squared distance
        // The last bound widened: k_nearest asks again with the same bound for every triangle.
        mutable W last_bound = std::numeric_limits<W>::quiet_NaN();
        mutable T last_prune = 0;
        W operator()(std::uint32_t slot, const Vec<T, 3>& p, W bound) const {
            const Triangle<T>& t = mesh->tris_[slot];
            // The triangle's box is a cheap lower bound: most triangles of a leaf fail it.
            if (box_distance_squared(t, p) > widen(p, bound))
                return std::numeric_limits<W>::infinity();
            const AccurateClosestPoint<T> c = mesh->measure(slot, p);
            return far.far ? mesh->far_key(far, t, c) : c.distance_squared;
        }
        /// The squared radius in T to prune boxes with (see widened_key), for a key.
        T widen(const Vec<T, 3>& /*p*/, W bound) const {
            if (bound == last_bound) return last_prune;
            last_bound = bound;
            // (A far key plus |p - o|^2 is the squared distance again, to its rounding, which
            // the widening covers; rounding can take it below 0.)
            return last_prune =
                       mesh->widened_key(far.far ? std::max(bound + from_origin2, W(0)) : bound);
        }
        void prefetch(std::uint32_t slot) const { __builtin_prefetch(mesh->tris_.data() + slot); }
    };
    RankedDistance ranked_distance(const Vec<T, 3>& p, bool rank_far) const {
        RankedDistance d{this, {}};
        if (rank_far) d.far = far_frame(p);
        if (d.far.far) d.from_origin2 = dot(d.far.from_origin, d.far.from_origin);
        return d;
    }
    /// A triangle measured accurately, with its frame where there is one.
    AccurateClosestPoint<T> measure(std::uint32_t slot, const Vec<T, 3>& p) const {
        return frames_.empty() ? closest_point_accurate(tris_[slot], p)
                               : closest_point_accurate(tris_[slot], frames_[slot], p);
    }
    /// widened() for a squared radius in W: computed there and rounded up to T, so it is inf
    /// past T's range (no box is pruned: they are all within reach of a radius T cannot hold)
    /// and never below 4 least normals, where the boxes' own rounding could drop one within
    /// reach (a radius 1e-25 in float squares to 0).
    T widened_key(AccurateScalar<T> radius2) const {
        using W = AccurateScalar<T>;
        if (radius2 != radius2) return std::numeric_limits<T>::quiet_NaN();
        if (radius2 < W(0)) return T(-1);
        const W r = std::sqrt(radius2);
        const W slack = W(1024) * W(std::numeric_limits<T>::epsilon()) * (r + W(longest_edge_));
        return std::max(nearest_detail::round_up_key<T>((r + slack) * (r + slack)),
                        T(4) * std::numeric_limits<T>::min());
    }
    /// Squared distance from p to the triangle's box. For float on x86 in four lanes: each corner
    /// is one 4-float load (the fourth lane, the next coordinate, masked off), a fraction of the
    /// scalar form's instructions on a path every N1 query takes often.
    static T box_distance_squared(const Triangle<T>& t, const Vec<T, 3>& p) {
#if BVHKIT_SIMD
        if constexpr (std::is_same_v<T, float>) {
            using F = simd::Float<4>;
            static_assert(sizeof(Triangle<float>) == 9 * sizeof(float), "corners are contiguous");
            const float* f = &t.p0[0];
            const F a = F::load_unaligned(f), b = F::load_unaligned(f + 3),
                    c = F::load_unaligned(f + 6);
            const F q = F::lanes(p[0], p[1], p[2], 0.0f);
            const F lo = min(a, min(b, c)), hi = max(a, max(b, c));
            const simd::Mask<4> xyz = simd::Mask<4>::lanes(true, true, true, false);
            F g = max(max(lo - q, q - hi), F::zero());
            g = where(xyz, g);
            g = g * g;
            const F s = g + g.high_half();
            return add_first(s, s.shuffle<1, 1, 1, 1>()).first();
        }
#endif
        T d2 = 0;
        for (std::size_t a = 0; a < 3; ++a) {
            const T lo = min_of(t.p0[a], min_of(t.p1[a], t.p2[a]));
            const T hi = max_of(t.p0[a], max_of(t.p1[a], t.p2[a]));
            const T g = max_of(max_of(lo - p[a], p[a] - hi), T(0));
            d2 += g * g;
        }
        return d2;
    }
    MeshPoint<T> point_of(std::uint32_t slot, const Vec<T, 3>& p) const {
        return point_of(slot, measure(slot, p));
    }
    MeshPoint<T> point_of(std::uint32_t slot, const AccurateClosestPoint<T>& c) const {
        return {Vec<T, 3>(c.point),
                T(c.distance_squared),
                T(std::sqrt(c.distance_squared)),
                bvh_.primitive_indices[slot],
                T(c.u),
                T(c.v)};
    }

    AabbBvh<T, 3> bvh_;
    std::vector<Triangle<T>> tris_;         // leaf-slot order, then one of padding
    WideSlotBvh<T> wide_;                   // bvh_ collapsed, for closest_point
    std::vector<TrianglePack4<T>> packs_;   // wide_'s leaf groups: triangles four abreast
    std::vector<AccurateFrame<T>> frames_;  // leaf-slot order, where W is double (see above)
    T longest_edge_ = 0;                    // the mesh's longest edge (finite triangles)
    T pack_scale_ = 1;                      // packs_ hold the triangles times this (a power of 2)
    T scaled_longest_edge_ = 0;             // longest_edge_ * pack_scale_
    bool packs_unscale_exactly_ = true;     // and dividing by it gives tris_ back, bit for bit
    Vec<AccurateScalar<T>, 3> far_origin_;  // the box's centre, for far_key
    AccurateScalar<T> far_extent2_ = 0;     // the box's squared diagonal
    std::vector<std::uint32_t> slot_of_triangle_;  // mesh triangle -> leaf slot (or invalid)
    std::uint32_t triangle_slots_ = 0;             // bvh_.primitive_indices.size()
    std::size_t triangle_count_ = 0;
};

}  // namespace bvhkit

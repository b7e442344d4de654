#pragma once
// Distance over a Scene (scene.hpp): the closest pair of instances, every pair within a threshold,
// and the instance nearest to one more posed mesh.
//
// The distance of two instances is their meshes' distance (distance(), query/distance.hpp, on the
// geometries' shared collision models under the relative pose inverse(pose_a) * pose_b taken in
// the wider type, as collision.hpp's test) less margin_a + margin_b. So it is <= 0 exactly when
// collision.hpp says the pair collides (for pairs with a margin; with both margins zero, 0 for
// meshes that touch or cross), and it goes down to -(margin_a + margin_b) for meshes that touch.
// The witness points are on the meshes themselves (not moved out by the margins), in world space.
// The filters are collision's: the group/mask test (may_collide) and the caller's ignore list;
// an instance whose geometry has no finite triangle is never measured.
//
// Pruning: the world boxes bound the meshes, so a pair's box gap less its margins is a lower bound
// of its distance, and a pair whose bound exceeds the best so far is dropped unmeasured (the
// running minimum of FCL's manager). Each instance a walks the top-level tree best first from its
// box's centre c (DynamicTree::query_nearest): a box at distance d from c is at least d - r from
// a's box (r: the farthest corner of a's box from c) and its instance at least d - r - m_a - M
// from a by the distance above (M: the largest margin in the scene), so the walk ends once that
// exceeds the best. The candidates it reaches are checked by the exact box gap first.
//
// Ties: of pairs at the same distance the first in InstancePair's order (a's slot, then b's) wins,
// so the answer does not depend on the walk's order.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "bvhkit/query/distance.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/scene.hpp"

namespace bvhkit {

/// Two instances (or a posed mesh and an instance) and their distance.
template <class T>
struct SceneDistance {
    /// The pair, a.index() < b.index(); for the distance of a posed mesh to the scene
    /// (closest_instance) a is null (the posed mesh) and b the instance. Both null: nothing found.
    InstanceId a, b;
    /// The meshes' distance less margin_a + margin_b (+inf when nothing was found).
    T distance = std::numeric_limits<T>::infinity();
    Vec<T, 3> point_a{}, point_b{};  // the closest points, on a's mesh and on b's, in world space
    std::uint32_t face_a = invalid_index, face_b = invalid_index;  // their triangles
    explicit operator bool() const { return !b.is_null(); }
};

namespace scene_detail {

/// The Euclidean gap between two boxes in W (0 when they touch or overlap). The boxes' bounds are
/// exact in W; each difference and the sum round, so the result is within a few eps_W of the gap.
template <class T>
AccurateScalar<T> box_gap(const Aabb<T, 3>& a, const Aabb<T, 3>& b) {
    using W = AccurateScalar<T>;
    W sum = 0;
    for (std::size_t i = 0; i < 3; ++i) {
        const W s = std::max({W(a.min[i]) - W(b.max[i]), W(b.min[i]) - W(a.max[i]), W(0)});
        sum += s * s;
    }
    return std::sqrt(sum);
}

/// Whether a pair whose box gap is `gap` and margins sum to `margins` may still be within `best`
/// (inclusive): its distance as measure() reports it is narrow<T>(W(d) - W(margins)) with d >= the
/// gap, and narrowing is monotone, so the pair is dropped only when the gap less the margins
/// (shrunk by a relative 64 eps_W for the gap's own rounding) narrows to more than `best`.
template <class T>
bool may_beat(AccurateScalar<T> gap, T margins, T best) {
    using W = AccurateScalar<T>;
    const W lower = gap * (W(1) - W(64) * std::numeric_limits<W>::epsilon()) - W(margins);
    return !(narrow<T>(lower) > best);
}

/// The largest margin of any live instance (0 for an empty scene).
template <class T>
T largest_margin(const Scene<T>& scene) {
    T m = 0;
    scene.for_each_instance([&](InstanceId id) { m = std::max(m, scene.options(id).margin); });
    return m;
}

/// The centre of a box (rounded to T) and a bound on the distance from it to any point of the box.
template <class T>
struct BoxReach {
    Vec<T, 3> centre;
    AccurateScalar<T> radius;
};
template <class T>
BoxReach<T> box_reach(const Aabb<T, 3>& box) {
    using W = AccurateScalar<T>;
    BoxReach<T> r;
    W sum = 0;
    for (std::size_t i = 0; i < 3; ++i) {
        r.centre[i] = narrow<T>((W(box.min[i]) + W(box.max[i])) / W(2));
        const W h = std::max(W(r.centre[i]) - W(box.min[i]), W(box.max[i]) - W(r.centre[i]));
        sum += h * h;
    }
    r.radius = std::sqrt(sum) * (W(1) + W(16) * std::numeric_limits<W>::epsilon());
    return r;
}

/// The squared bound for DynamicTree::query_nearest from a box's centre: a box farther than
/// best + reach + margins cannot hold a pair within best. `margins` is the largest margin sum, in
/// W; the pair's own sum is rounded to T (up to eps_T / 2 more) and so is its distance, which
/// 4 eps_T of the three terms covers, and the walk's own rounding a relative 64 eps_W more. +inf
/// while best is.
template <class T>
NearestWalkScalar<T> walk_bound(T best, AccurateScalar<T> reach, AccurateScalar<T> margins) {
    using W = NearestWalkScalar<T>;
    if (!(best < std::numeric_limits<T>::infinity())) return std::numeric_limits<W>::infinity();
    const W sum = W(best) + W(reach) + W(margins);
    const W slack =
        W(4) * W(std::numeric_limits<T>::epsilon()) * (W(std::fabs(best)) + W(reach) + W(margins));
    const W b = (std::max(sum, W(0)) + slack) * (W(1) + W(64) * std::numeric_limits<W>::epsilon());
    return b * b;
}

/// The distance of geometry ga at pose_a and gb at pose_b less `margins`, with world witnesses
/// (into `out`, a and b left to the caller). False, out unchanged, when either has no extent, or
/// when the pair's distance (less the margins) is sure to exceed `best`: the mesh walk is cut
/// there (DistanceOptions::upper_bound, set just above best + margins so that a pair at exactly
/// best, a tie, is still measured).
template <class T>
bool measure(const SceneGeometry<T>& ga, const Transform<T>& pose_a, const SceneGeometry<T>& gb,
             const Transform<T>& pose_b, T margins, SceneDistance<T>& out,
             T best = std::numeric_limits<T>::infinity()) {
    using W = AccurateScalar<T>;
    if (!ga.has_extent() || !gb.has_extent()) return false;
    const Transform<T> b_in_a = relative_pose<W>(pose_a, pose_b);
    DistanceOptions<T> options;
    if (best < std::numeric_limits<T>::infinity()) {
        // The pair is kept when narrow(W(d) - W(margins)) <= best, so d up to best + margins and
        // the two roundings; 4 eps_T of the sum's size covers them.
        const W sum = W(best) + W(margins);
        const W room =
            W(4) * W(std::numeric_limits<T>::epsilon()) * (std::fabs(W(best)) + W(margins));
        options.upper_bound =
            std::nextafter(narrow<T>(sum + room), std::numeric_limits<T>::infinity());
    }
    const DistanceResult<T> d =
        distance(ga.collision_model(), gb.collision_model(), b_in_a, options);
    if (!(d.distance < std::numeric_limits<T>::infinity())) return false;
    out.distance = margins == T(0) ? d.distance : narrow<T>(W(d.distance) - W(margins));
    // Both points are in a's frame (distance()'s convention).
    const Vec<W, 3> pa = apply_wide<W>(pose_a, d.point_a), pb = apply_wide<W>(pose_a, d.point_b);
    for (std::size_t i = 0; i < 3; ++i)
        out.point_a[i] = narrow<T>(pa[i]), out.point_b[i] = narrow<T>(pb[i]);
    out.face_a = d.triangle_a;
    out.face_b = d.triangle_b;
    return true;
}

/// Whether (a, b) comes before (c, d) in InstancePair's order.
inline bool pair_before(InstanceId a, InstanceId b, InstanceId c, InstanceId d) {
    return a.index() != c.index() ? a.index() < c.index() : b.index() < d.index();
}

}  // namespace scene_detail

namespace scene_detail {

/// The closest pair (a of `first`, b of `second`) with wanted(a, b) and may_collide: each
/// instance of `first` walks `second`'s top level nearest first, pruned by the running best; ties
/// go to the lower (a's slot, b's slot).
template <class T, class Wanted>
SceneDistance<T> closest_of(const Scene<T>& first, const Scene<T>& second, Wanted&& wanted) {
    using W = NearestWalkScalar<T>;
    SceneDistance<T> best;
    const T largest = largest_margin(second);
    first.for_each_instance([&](InstanceId a) {
        const SceneInstance<T>& ra = first.instance_at(a.proxy());
        const SceneGeometry<T>& ga = first.geometry_at(ra.geometry);
        if (!ga.has_extent()) return;
        const BoxReach<T> reach = box_reach(ra.box);
        const AccurateScalar<T> margins = AccurateScalar<T>(ra.options.margin) + largest;
        second.top_level().query_nearest(reach.centre, [&](ProxyId proxy, W) -> W {
            const InstanceId b(proxy);
            const SceneInstance<T>& rb = second.instance_at(proxy);
            const T m = ra.options.margin + rb.options.margin;
            SceneDistance<T> d;
            if (wanted(a, b) && may_collide(ra.options, rb.options) &&
                may_beat(box_gap(ra.box, rb.box), m, best.distance) &&
                measure(ga, ra.pose, second.geometry_at(rb.geometry), rb.pose, m, d,
                        best.distance) &&
                (d.distance < best.distance ||
                 (d.distance == best.distance && pair_before(a, b, best.a, best.b)))) {
                d.a = a, d.b = b;
                best = d;
            }
            return walk_bound(best.distance, reach.radius, margins);
        });
    });
    return best;
}

}  // namespace scene_detail

/// The closest pair of instances that the filters let collide (group/mask, not in `ignore`),
/// a.index() < b.index(), with its distance (less the margins) and world witness points; nothing
/// (both ids null, distance +inf) when no such pair has finite triangles on both sides.
template <class T>
SceneDistance<T> closest_pair(const Scene<T>& scene, std::span<const InstancePair> ignore = {}) {
    const auto skip = scene_detail::ignore_set(ignore);
    return scene_detail::closest_of(scene, scene, [&](InstanceId a, InstanceId b) {
        return b.index() > a.index() && !scene_detail::ignored(skip, a, b);
    });
}

/// The closest pair (a of `first`, b of `second`) that the filters let collide and that is not in
/// `ignore` (given in the same (first, second) order), with its distance (less the margins) and
/// world witnesses; ties go to the lower (a's slot, b's slot). Nothing (both null, +inf) when no
/// such pair has finite triangles on both sides. The scenes share no ids; one scene passed as both
/// measures every instance against every other and against itself (distance 0).
template <class T>
SceneDistance<T> closest_pair(const Scene<T>& first, const Scene<T>& second,
                              std::span<const InstancePair> ignore = {}) {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> skip;
    for (const InstancePair& p : ignore) skip.emplace_back(p.a.bits(), p.b.bits());
    std::sort(skip.begin(), skip.end());
    return scene_detail::closest_of(first, second, [&](InstanceId a, InstanceId b) {
        return !std::binary_search(skip.begin(), skip.end(), std::pair(a.bits(), b.bits()));
    });
}

namespace scene_detail {

/// Every pair (a of `first`, b of `second`) with wanted(a, b), may_collide and distance (less the
/// margins) at most `threshold`, appended to `out` in (a's slot, b's slot) order: each instance
/// of `first` walks `second`'s top level nearest first, out to the threshold's bound.
template <class T, class Wanted>
void within_of(const Scene<T>& first, const Scene<T>& second, T threshold, Wanted&& wanted,
               std::vector<SceneDistance<T>>& out) {
    using W = NearestWalkScalar<T>;
    const T largest = largest_margin(second);
    first.for_each_instance([&](InstanceId a) {
        const SceneInstance<T>& ra = first.instance_at(a.proxy());
        const SceneGeometry<T>& ga = first.geometry_at(ra.geometry);
        if (!ga.has_extent()) return;
        const std::size_t begin = out.size();
        const BoxReach<T> reach = box_reach(ra.box);
        const W bound =
            walk_bound(threshold, reach.radius, AccurateScalar<T>(ra.options.margin) + largest);
        second.top_level().query_nearest(reach.centre, [&](ProxyId proxy, W) -> W {
            const InstanceId b(proxy);
            const SceneInstance<T>& rb = second.instance_at(proxy);
            const T m = ra.options.margin + rb.options.margin;
            SceneDistance<T> d;
            if (wanted(a, b) && may_collide(ra.options, rb.options) &&
                may_beat(box_gap(ra.box, rb.box), m, threshold) &&
                measure(ga, ra.pose, second.geometry_at(rb.geometry), rb.pose, m, d, threshold) &&
                d.distance <= threshold) {
                d.a = a, d.b = b;
                out.push_back(d);
            }
            return bound;
        });
        std::sort(out.begin() + std::ptrdiff_t(begin), out.end(),
                  [](const SceneDistance<T>& x, const SceneDistance<T>& y) {
                      return x.b.index() < y.b.index();
                  });
    });
}

}  // namespace scene_detail

/// Every pair of instances that the filters let collide and whose distance (less the margins) is
/// at most `threshold`, sorted by (a's slot, b's slot), each with its witnesses: `out` is cleared,
/// then filled. Error on a NaN threshold (+inf gives every pair with finite triangles).
template <class T>
void pairs_within(const Scene<T>& scene, T threshold, std::vector<SceneDistance<T>>& out,
                  std::span<const InstancePair> ignore = {}) {
    if (std::isnan(threshold)) throw Error("pairs_within(Scene): threshold is NaN");
    out.clear();
    const auto skip = scene_detail::ignore_set(ignore);
    scene_detail::within_of(
        scene, scene, threshold,
        [&](InstanceId a, InstanceId b) {
            return b.index() > a.index() && !scene_detail::ignored(skip, a, b);
        },
        out);
}

/// Every pair (a of `first`, b of `second`) that the filters let collide, not in `ignore` (given in
/// the same (first, second) order), whose distance (less the margins) is at most `threshold`,
/// sorted by (a's slot, b's slot): `out` is cleared, then filled. Error on a NaN threshold.
template <class T>
void pairs_within(const Scene<T>& first, const Scene<T>& second, T threshold,
                  std::vector<SceneDistance<T>>& out, std::span<const InstancePair> ignore = {}) {
    if (std::isnan(threshold)) throw Error("pairs_within(Scene, Scene): threshold is NaN");
    out.clear();
    std::vector<std::pair<std::uint64_t, std::uint64_t>> skip;
    for (const InstancePair& p : ignore) skip.emplace_back(p.a.bits(), p.b.bits());
    std::sort(skip.begin(), skip.end());
    scene_detail::within_of(
        first, second, threshold,
        [&](InstanceId a, InstanceId b) {
            return !std::binary_search(skip.begin(), skip.end(), std::pair(a.bits(), b.bits()));
        },
        out);
}

/// The instance nearest to the scene's geometry `geometry` placed at `pose` with `options` (its
/// group, mask and margin, as an instance's; user_data unused): b the instance, a null, point_a
/// on the posed mesh, distance less both margins. Ties go to the lower slot. Nothing found (b
/// null, +inf) for an empty scene or when no instance passes the filter. Error on a bad geometry
/// id, pose or margin.
template <class T>
SceneDistance<T> closest_instance(const Scene<T>& scene, GeometryId geometry,
                                  const Transform<T>& caller_pose,
                                  const InstanceOptions<T>& options = {}) {
    using W = NearestWalkScalar<T>;
    const SceneGeometry<T>& g = scene.geometry(geometry);
    check_rigid_pose(caller_pose, "closest_instance(Scene)", "pose");
    if (!(std::isfinite(options.margin) && options.margin >= T(0)))
        throw Error("closest_instance(Scene): margin " + std::to_string(double(options.margin)) +
                    " must be finite and >= 0");
    SceneDistance<T> best;
    if (!g.has_extent()) return best;
    const Transform<T> pose = scene_detail::rigid_pose(caller_pose);
    const Aabb<T, 3> box = g.world_box(pose, g.pose_pad(pose));
    const scene_detail::BoxReach<T> reach = scene_detail::box_reach(box);
    const AccurateScalar<T> margins =
        AccurateScalar<T>(options.margin) + scene_detail::largest_margin(scene);
    scene.top_level().query_nearest(reach.centre, [&](ProxyId proxy, W) -> W {
        const InstanceId b(proxy);
        const SceneInstance<T>& rb = scene.instance_at(proxy);
        const T m = options.margin + rb.options.margin;
        SceneDistance<T> d;
        if (may_collide(options, rb.options) &&
            scene_detail::may_beat(scene_detail::box_gap(box, rb.box), m, best.distance) &&
            scene_detail::measure(g, pose, scene.geometry_at(rb.geometry), rb.pose, m, d,
                                  best.distance) &&
            (d.distance < best.distance ||
             (d.distance == best.distance && b.index() < best.b.index()))) {
            d.b = b;
            best = d;
        }
        return scene_detail::walk_bound(best.distance, reach.radius, margins);
    });
    return best;
}

}  // namespace bvhkit

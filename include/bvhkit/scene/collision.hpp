#pragma once
// Collision within a Scene (scene.hpp): the pairs of instances that collide, whether any pair
// does, the instances that collide with one more posed mesh, and the pairs of two scenes that
// collide (an instance of one against an instance of the other).
//
// Two instances collide when the group/mask filter lets them (may_collide, instance.hpp), the pair
// is not in the caller's ignore list, and their meshes come within margin_a + margin_b of each
// other: with both margins zero, when a triangle of one meets a triangle of the other (collides,
// query/pairs_model.hpp, exact for the pose given); else when the meshes' distance (distance,
// query/distance.hpp) is at most the sum. The exact test runs under the relative pose
// inverse(pose_a) * pose_b (taken in the wider type and rounded once), on the geometries' shared
// collision models: no mesh is moved.
//
// The candidates come from the top-level tree, whose boxes are the world boxes grown by each
// instance's own margin: for each instance a, a box query with a's grown box finds the instances
// b whose world boxes lie within margin_a + margin_b of a's (then the exact box gap with the
// pair's own margins). A large margin on one instance widens only the queries that involve it.
//
// Collision is surface contact, as in FCL: a mesh wholly inside another, with no triangle of one
// meeting a triangle of the other and the margins not covering the gap between the surfaces, does
// not collide.
#include <algorithm>
#include <span>
#include <vector>

#include "bvhkit/query/distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "bvhkit/scene/scene.hpp"

namespace bvhkit {

namespace scene_detail {

/// Whether two boxes come within `gap` of each other (each axis' separation at most gap; the
/// boxes already bound the meshes, so this only culls).
template <class T>
bool boxes_within(const Aabb<T, 3>& a, const Aabb<T, 3>& b, T gap) {
    using W = AccurateScalar<T>;
    for (std::size_t i = 0; i < 3; ++i)
        if (W(a.min[i]) - W(b.max[i]) > W(gap) || W(b.min[i]) - W(a.max[i]) > W(gap)) return false;
    return true;
}

/// Whether geometry ga at pose_a and geometry gb at pose_b come within `margin` of each other.
template <class T>
bool meshes_collide(const SceneGeometry<T>& ga, const Transform<T>& pose_a,
                    const SceneGeometry<T>& gb, const Transform<T>& pose_b, T margin) {
    if (!ga.has_extent() || !gb.has_extent()) return false;
    const Transform<T> b_in_a = relative_pose<AccurateScalar<T>>(pose_a, pose_b);
    if (margin == T(0)) return collides(ga.collision_model(), gb.collision_model(), b_in_a);
    return distance(ga.collision_model(), gb.collision_model(), b_in_a).distance <= margin;
}

/// The ignore list as sorted (smaller bits, larger bits) pairs, for binary search.
inline std::vector<std::pair<std::uint64_t, std::uint64_t>> ignore_set(
    std::span<const InstancePair> ignore) {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> s;
    s.reserve(ignore.size());
    for (const InstancePair& p : ignore)
        s.emplace_back(std::min(p.a.bits(), p.b.bits()), std::max(p.a.bits(), p.b.bits()));
    std::sort(s.begin(), s.end());
    return s;
}
inline bool ignored(const std::vector<std::pair<std::uint64_t, std::uint64_t>>& s, InstanceId a,
                    InstanceId b) {
    return std::binary_search(
        s.begin(), s.end(), std::pair(std::min(a.bits(), b.bits()), std::max(a.bits(), b.bits())));
}

/// on_pair(InstanceId a, InstanceId b) -> bool (false stops) for every colliding pair, a's slot
/// below b's, in increasing order of a's slot.
template <class T, class F>
void for_each_colliding_pair(const Scene<T>& scene, std::span<const InstancePair> ignore,
                             F&& on_pair) {
    const auto skip = ignore_set(ignore);
    std::vector<InstanceId> candidates;
    bool go_on = true;
    scene.for_each_instance([&](InstanceId a) {
        if (!go_on) return;
        const SceneInstance<T>& ra = scene.instance(a);
        const Aabb<T, 3>& box_a = ra.box;
        candidates.clear();
        // a's top-level box is its world box grown by margin_a, b's by margin_b: they overlap iff
        // the world boxes' gap is within margin_a + margin_b on every axis (rounded outward, so
        // never less), and no other instance's margin widens a's query.
        scene.top_level().query(scene.top_level().box(a.proxy()), [&](ProxyId proxy) {
            if (proxy.index() > a.index()) candidates.push_back(InstanceId(proxy));
            return true;
        });
        std::sort(candidates.begin(), candidates.end(),
                  [](InstanceId x, InstanceId y) { return x.index() < y.index(); });
        for (const InstanceId b : candidates) {
            const SceneInstance<T>& rb = scene.instance_at(b.proxy());
            if (!may_collide(ra.options, rb.options) || ignored(skip, a, b)) continue;
            const T margin = ra.options.margin + rb.options.margin;
            if (!boxes_within(box_a, rb.box, margin)) continue;
            if (!meshes_collide(scene.geometry_at(ra.geometry), ra.pose,
                                scene.geometry_at(rb.geometry), rb.pose, margin))
                continue;
            if (!on_pair(a, b)) {
                go_on = false;
                return;
            }
        }
    });
}

}  // namespace scene_detail

/// Every pair of instances that collide, (a, b) with a.index() < b.index(), sorted by
/// InstancePair's order (a's slot, then b's: live ids differ in their slots): `out` is cleared,
/// then filled. Pairs in `ignore` (either order) are left out.
template <class T>
void colliding_pairs(const Scene<T>& scene, std::vector<InstancePair>& out,
                     std::span<const InstancePair> ignore = {}) {
    out.clear();
    scene_detail::for_each_colliding_pair(scene, ignore, [&](InstanceId a, InstanceId b) {
        out.push_back({a, b});
        return true;
    });
}

/// Whether any pair of instances collides (stops at the first).
template <class T>
bool any_collision(const Scene<T>& scene, std::span<const InstancePair> ignore = {}) {
    bool found = false;
    scene_detail::for_each_colliding_pair(scene, ignore, [&](InstanceId, InstanceId) {
        found = true;
        return false;
    });
    return found;
}

/// The instances that collide with the scene's geometry `geometry` placed at `pose` with
/// `options` (its group, mask and margin; user_data unused), in slot order: `out` is cleared,
/// then filled. With stop_at_first, at most one. Error on a bad geometry id, pose or margin.
template <class T>
void colliding_instances(const Scene<T>& scene, GeometryId geometry,
                         const Transform<T>& caller_pose, const InstanceOptions<T>& options,
                         std::vector<InstanceId>& out, bool stop_at_first = false) {
    out.clear();
    const SceneGeometry<T>& g = scene.geometry(geometry);
    check_rigid_pose(caller_pose, "colliding_instances(Scene)", "pose");
    if (!(std::isfinite(options.margin) && options.margin >= T(0)))
        throw Error("colliding_instances(Scene): margin " + std::to_string(double(options.margin)) +
                    " must be finite and >= 0");
    // As an instance's pose is stored: the nearest rotation, so that the relative poses are rigid.
    const Transform<T> pose = scene_detail::rigid_pose(caller_pose);
    const Aabb<T, 3> box = g.world_box(pose, g.pose_pad(pose));
    scene.top_level().query(scene_detail::grown(box, options.margin), [&](ProxyId proxy) {
        out.push_back(InstanceId(proxy));
        return true;
    });
    std::sort(out.begin(), out.end(),
              [](InstanceId x, InstanceId y) { return x.index() < y.index(); });
    std::size_t kept = 0;
    for (const InstanceId b : out) {
        if (stop_at_first && kept == 1) break;
        const SceneInstance<T>& rb = scene.instance_at(b.proxy());
        const T margin = options.margin + rb.options.margin;
        if (!may_collide(options, rb.options) || !scene_detail::boxes_within(box, rb.box, margin) ||
            !scene_detail::meshes_collide(g, pose, scene.geometry_at(rb.geometry), rb.pose, margin))
            continue;
        out[kept++] = b;
    }
    out.resize(kept);
}

/// Whether the geometry at `pose` collides with any instance.
template <class T>
bool collides_with(const Scene<T>& scene, GeometryId geometry, const Transform<T>& pose,
                   const InstanceOptions<T>& options = {}) {
    thread_local std::vector<InstanceId> found;
    colliding_instances(scene, geometry, pose, options, found, true);
    return !found.empty();
}

/// Every pair (a of `first`, b of `second`) that collides, by the rule above (the group/mask
/// filter, the margins, the exact test), sorted by a's slot then b's: `out` is cleared, then
/// filled. The two scenes share no ids: a pair's a is an id of `first`, its b one of `second`
/// (InstancePair's a.index() < b.index() does not hold here). Pairs in `ignore`, given in the same
/// (first, second) order, are left out. The candidates come from one walk over both top-level
/// trees at once (DynamicTree::query_tree: boxes grown by each instance's margin overlap iff the
/// world boxes come within the margins' sum on every axis). Passing one scene as both compares
/// every instance with every instance, itself included.
template <class T>
void colliding_pairs(const Scene<T>& first, const Scene<T>& second, std::vector<InstancePair>& out,
                     std::span<const InstancePair> ignore = {}) {
    out.clear();
    std::vector<std::pair<std::uint64_t, std::uint64_t>> skip;
    for (const InstancePair& p : ignore) skip.emplace_back(p.a.bits(), p.b.bits());
    std::sort(skip.begin(), skip.end());
    first.top_level().query_tree(second.top_level(), [&](ProxyId pa, ProxyId pb) {
        out.push_back({InstanceId(pa), InstanceId(pb)});
        return true;
    });
    std::sort(out.begin(), out.end());
    std::size_t kept = 0;
    for (const InstancePair& p : out) {
        const SceneInstance<T>& ra = first.instance_at(p.a.proxy());
        const SceneInstance<T>& rb = second.instance_at(p.b.proxy());
        const T margin = ra.options.margin + rb.options.margin;
        if (!may_collide(ra.options, rb.options) ||
            std::binary_search(skip.begin(), skip.end(), std::pair(p.a.bits(), p.b.bits())) ||
            !scene_detail::boxes_within(ra.box, rb.box, margin) ||
            !scene_detail::meshes_collide(first.geometry_at(ra.geometry), ra.pose,
                                          second.geometry_at(rb.geometry), rb.pose, margin))
            continue;
        out[kept++] = p;
    }
    out.resize(kept);
}

/// Whether any pair (a of `first`, b of `second`) collides: stops at the first found, in the
/// walk's order. `ignore` as for colliding_pairs(first, second, ...).
template <class T>
bool any_collision(const Scene<T>& first, const Scene<T>& second,
                   std::span<const InstancePair> ignore = {}) {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> skip;
    for (const InstancePair& p : ignore) skip.emplace_back(p.a.bits(), p.b.bits());
    std::sort(skip.begin(), skip.end());
    bool found = false;
    first.top_level().query_tree(second.top_level(), [&](ProxyId pa, ProxyId pb) {
        const SceneInstance<T>& ra = first.instance_at(pa);
        const SceneInstance<T>& rb = second.instance_at(pb);
        const T margin = ra.options.margin + rb.options.margin;
        found = may_collide(ra.options, rb.options) &&
                !std::binary_search(skip.begin(), skip.end(), std::pair(pa.bits(), pb.bits())) &&
                scene_detail::boxes_within(ra.box, rb.box, margin) &&
                scene_detail::meshes_collide(first.geometry_at(ra.geometry), ra.pose,
                                             second.geometry_at(rb.geometry), rb.pose, margin);
        return !found;
    });
    return found;
}

}  // namespace bvhkit

#pragma once
// Collision of a Scene (scene.hpp) at other poses of some of its instances, without changing it:
// a planner's configurations. For the instances `ids` at `poses` (the links of an arm at one
// configuration) and every other instance where it is, the pairs with at least one moved instance
// that collide by collision.hpp's rule (the group/mask filter, the ignore list, the margins, the
// exact test). The answer is the one set_poses(ids, poses) followed by colliding_pairs would give
// for those pairs; pairs of two unmoved instances (the environment against itself) do not depend
// on the configuration and are not looked at.
//
// The scene is only read, so configurations may be checked from many threads at once, and the
// batch any_collisions_at spreads them over the library's threads: the "batched" mode of a
// collision manager, which FCL's and Coal's managers (one mutable tree each) cannot offer.
//
// The moved instances' world boxes are computed as set_pose computes them (the stored pose, the
// hull's extent, the pad); a moved instance is tested against the unmoved ones the top-level tree
// finds around its new box (its own proxy, at its old pose, is skipped), and against the other
// moved instances directly (a configuration moves few).
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "bvhkit/exec/executor.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/scene.hpp"

namespace bvhkit {

namespace scene_detail {

/// One moved instance: its id, record, stored pose and world box at the configuration.
template <class T>
struct MovedInstance {
    InstanceId id;
    const SceneInstance<T>* record;
    Transform<T> pose;
    Aabb<T, 3> box;
};

/// Checks the configuration (lengths, live and distinct ids, rigid poses) and fills `moved`.
template <class T>
void place_moved(const Scene<T>& scene, std::span<const InstanceId> ids,
                 std::type_identity_t<std::span<const Transform<T>>> poses, const char* where,
                 std::vector<MovedInstance<T>>& moved) {
    if (ids.size() != poses.size())
        throw Error(std::string(where) + ": " + std::to_string(ids.size()) + " ids but " +
                    std::to_string(poses.size()) + " poses");
    moved.resize(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) {
        if (!scene.contains(ids[i]))
            throw Error(std::string(where) + ": ids[" + std::to_string(i) + "] = " + ids[i].text() +
                        " names no live instance (removed, stale or never added)");
        for (std::size_t j = 0; j < i; ++j)
            if (ids[j] == ids[i])
                throw Error(std::string(where) + ": ids[" + std::to_string(i) + "] repeats ids[" +
                            std::to_string(j) + "]: a configuration gives each instance one pose");
        check_rigid_pose(poses[i], where, "pose");
        MovedInstance<T>& m = moved[i];
        m.id = ids[i];
        m.record = &scene.instance(ids[i]);
        const SceneGeometry<T>& g = scene.geometry_at(m.record->geometry);
        m.pose = rigid_pose(poses[i]);
        m.box = g.world_box(m.pose, g.pose_pad(m.pose));
        dynamic_detail::check_box(grown(m.box, m.record->options.margin), where);
    }
}

/// on_pair(InstanceId a, InstanceId b) -> bool (false stops) for each colliding pair with a moved
/// instance, (a, b) with a's slot below b's, in no particular order.
template <class T, class F>
void for_each_pair_at(const Scene<T>& scene, const std::vector<MovedInstance<T>>& moved,
                      const std::vector<std::pair<std::uint64_t, std::uint64_t>>& skip,
                      std::vector<InstanceId>& candidates, F&& on_pair) {
    const auto is_moved = [&](InstanceId id) {
        for (const MovedInstance<T>& m : moved)
            if (m.id == id) return true;
        return false;
    };
    const auto report = [&](InstanceId a, InstanceId b) {
        return a.index() < b.index() ? on_pair(a, b) : on_pair(b, a);
    };
    // The exact test in slot order, as colliding_pairs runs it: it decides for the relative pose
    // of the second in the first's frame as rounded, so the other order could differ at contact.
    const auto meet = [&](InstanceId a, const SceneGeometry<T>& ga, const Transform<T>& pa,
                          InstanceId b, const SceneGeometry<T>& gb, const Transform<T>& pb,
                          T margin) {
        return a.index() < b.index() ? meshes_collide(ga, pa, gb, pb, margin)
                                     : meshes_collide(gb, pb, ga, pa, margin);
    };
    for (std::size_t i = 0; i < moved.size(); ++i) {
        const MovedInstance<T>& a = moved[i];
        const InstanceOptions<T>& oa = a.record->options;
        const SceneGeometry<T>& ga = scene.geometry_at(a.record->geometry);
        for (std::size_t j = i + 1; j < moved.size(); ++j) {
            const MovedInstance<T>& b = moved[j];
            const InstanceOptions<T>& ob = b.record->options;
            const T margin = oa.margin + ob.margin;
            if (may_collide(oa, ob) && !ignored(skip, a.id, b.id) &&
                boxes_within(a.box, b.box, margin) &&
                meet(a.id, ga, a.pose, b.id, scene.geometry_at(b.record->geometry), b.pose,
                     margin) &&
                !report(a.id, b.id))
                return;
        }
        candidates.clear();
        scene.top_level().query(grown(a.box, oa.margin), [&](ProxyId proxy) {
            candidates.push_back(InstanceId(proxy));
            return true;
        });
        for (const InstanceId b : candidates) {
            if (is_moved(b)) continue;
            const SceneInstance<T>& rb = scene.instance_at(b.proxy());
            const T margin = oa.margin + rb.options.margin;
            if (may_collide(oa, rb.options) && !ignored(skip, a.id, b) &&
                boxes_within(a.box, rb.box, margin) &&
                meet(a.id, ga, a.pose, b, scene.geometry_at(rb.geometry), rb.pose, margin) &&
                !report(a.id, b))
                return;
        }
    }
}

}  // namespace scene_detail

/// The colliding pairs with at least one of `ids` moved to `poses` (each other instance where it
/// is), as colliding_pairs gives them: (a, b) with a.index() < b.index(), sorted; `out` is
/// cleared, then filled. The scene is not changed. Error on differing lengths, a stale or
/// repeated id, or a bad pose.
template <class T>
void colliding_pairs_at(const Scene<T>& scene, std::span<const InstanceId> ids,
                        std::type_identity_t<std::span<const Transform<T>>> poses,
                        std::vector<InstancePair>& out, std::span<const InstancePair> ignore = {}) {
    out.clear();
    std::vector<scene_detail::MovedInstance<T>> moved;
    scene_detail::place_moved(scene, ids, poses, "colliding_pairs_at(Scene)", moved);
    std::vector<InstanceId> candidates;
    scene_detail::for_each_pair_at(scene, moved, scene_detail::ignore_set(ignore), candidates,
                                   [&](InstanceId a, InstanceId b) {
                                       out.push_back({a, b});
                                       return true;
                                   });
    std::sort(out.begin(), out.end());
}

/// Whether any pair with at least one of `ids` moved to `poses` collides (stops at the first).
template <class T>
bool any_collision_at(const Scene<T>& scene, std::span<const InstanceId> ids,
                      std::type_identity_t<std::span<const Transform<T>>> poses,
                      std::span<const InstancePair> ignore = {}) {
    thread_local std::vector<scene_detail::MovedInstance<T>> moved;
    thread_local std::vector<InstanceId> candidates;
    scene_detail::place_moved(scene, ids, poses, "any_collision_at(Scene)", moved);
    bool found = false;
    scene_detail::for_each_pair_at(scene, moved, scene_detail::ignore_set(ignore), candidates,
                                   [&](InstanceId, InstanceId) {
                                       found = true;
                                       return false;
                                   });
    return found;
}

/// Many configurations of the same instances: configuration k puts ids[i] at
/// poses[k * ids.size() + i]; collides[k] = any_collision_at for it (1 or 0). On `threads`
/// threads (0 = every core, 1 = the calling thread) or an Executor (or anything with its
/// parallel_for(count, grain, body)); each answer is its configuration's alone, the same for any
/// thread count. Each configuration is checked as it is placed; an Error (lengths, ids, a bad
/// pose) names the lowest bad configuration and leaves `collides` unwritten (the others are still
/// tested: the check saves no time).
template <class T, class Exec>
requires(!std::is_arithmetic_v<Exec>) void any_collisions_at(
    const Scene<T>& scene, std::span<const InstanceId> ids,
    std::type_identity_t<std::span<const Transform<T>>> poses, std::span<std::uint8_t> collides,
    std::span<const InstancePair> ignore, const Exec& exec) {
    const std::size_t n = ids.size();
    if (poses.size() != n * collides.size())
        throw Error("any_collisions_at(Scene): " + std::to_string(poses.size()) + " poses for " +
                    std::to_string(collides.size()) + " configurations of " + std::to_string(n) +
                    " instances");
    const auto skip = scene_detail::ignore_set(ignore);
    // One pass: each configuration is placed (checked) and tested in its chunk; a configuration
    // that fails its checks is marked, and the lowest marked one is placed again below to throw
    // its Error, so `collides` stays unwritten and the message does not depend on the threads.
    std::vector<std::uint8_t> result(collides.size()), failed(collides.size());
    exec.parallel_for(collides.size(), 4, [&](std::size_t b, std::size_t e) {
        std::vector<scene_detail::MovedInstance<T>> moved;
        std::vector<InstanceId> candidates;
        for (std::size_t k = b; k < e; ++k) {
            try {
                scene_detail::place_moved(scene, ids, poses.subspan(k * n, n),
                                          "any_collisions_at(Scene)", moved);
            } catch (const Error&) {
                failed[k] = 1;
                continue;
            }
            bool found = false;
            scene_detail::for_each_pair_at(scene, moved, skip, candidates,
                                           [&](InstanceId, InstanceId) {
                                               found = true;
                                               return false;
                                           });
            result[k] = std::uint8_t(found);
        }
    });
    if (const auto bad = std::find(failed.begin(), failed.end(), std::uint8_t(1));
        bad != failed.end()) {
        const std::size_t k = std::size_t(bad - failed.begin());
        const std::string where = "any_collisions_at(Scene): configuration " + std::to_string(k);
        std::vector<scene_detail::MovedInstance<T>> moved;
        scene_detail::place_moved(scene, ids, poses.subspan(k * n, n), where.c_str(), moved);
    }
    std::copy(result.begin(), result.end(), collides.begin());
}
template <class T>
void any_collisions_at(const Scene<T>& scene, std::span<const InstanceId> ids,
                       std::type_identity_t<std::span<const Transform<T>>> poses,
                       std::span<std::uint8_t> collides, std::span<const InstancePair> ignore = {},
                       unsigned threads = 0) {
    any_collisions_at(scene, ids, poses, collides, ignore, Executor(threads));
}

}  // namespace bvhkit

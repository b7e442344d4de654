#pragma once
// Scene<T>: many posed instances of shared triangle meshes, for rays, closest points and collision
// (docs/scenes.md). Two levels: geometry is added once (add_mesh) and shared by any number of
// instances, each a rigid pose (stored with the nearest rotation), an id, user data, a collision
// group and mask and a margin; the top level is a DynamicTree over the instances' world boxes,
// each grown by the instance's own margin (fat boxes: a small pose change only updates the tight
// box), the bottom level the per-geometry trees (scene/geometry.hpp), built the first time a query
// family needs them and shared by all instances.
//
//   bvhkit::Scene<float> scene;
//   GeometryId g = scene.add_mesh(mesh);
//   InstanceId a = scene.add_instance(g, pose, {.user_data = 7});
//   scene.set_pose(a, new_pose);
//   SceneHit<float> hit = closest_hit(scene, ray);        // scene/rays.hpp
//   ScenePoint<float> q = closest_point(scene, p);        // scene/closest_point.hpp
//   colliding_pairs(scene, pairs);                        // scene/collision.hpp
//
// Threads: the const calls and the queries may run on many threads at once while nothing changes
// the scene; add_mesh, add_instance, set_pose(s), set_options and remove need the scene to
// themselves (the caller's lock), as the dynamic tree does.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/scene/geometry.hpp"
#include "bvhkit/scene/instance.hpp"

namespace bvhkit {

namespace serial_detail {
struct SceneAccess;  // scene/scene_file.hpp
}

template <class T>
struct SceneOptions {
    /// The top-level tree's fat boxes: each instance's box grown by a tenth of its largest extent,
    /// and stretched along a pose change's translation, so small motions keep the tree as it is.
    DynamicTreeOptions<T> top_level = [] {
        DynamicTreeOptions<T> o;
        o.margin_absolute = T(0);
        o.margin_relative = T(0.1);
        return o;
    }();
};

/// What the scene keeps per instance (in the slot of its id).
template <class T>
struct SceneInstance {
    GeometryId geometry;
    /// The pose as stored: the caller's translation, and the rotation nearest to the caller's
    /// (scene_detail::rigid_pose), so every query works with a pose as rigid as T can hold.
    Transform<T> pose;
    InstanceOptions<T> options;
    /// The world box (tight: the hull's extent under the pose, padded for the queries' rounding).
    /// The top-level tree holds it grown by options.margin.
    Aabb<T, 3> box;
};

template <class T>
class Scene {
    static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>,
                  "Scene is for float and double geometry");

  public:
    using Scalar = T;
    using Pose = Transform<T>;
    using Box = Aabb<T, 3>;
    using TopLevel = DynamicTree<T, 3>;

    explicit Scene(const SceneOptions<T>& options = {}) : tree_(options.top_level) {}
    Scene(Scene&&) noexcept = default;
    Scene& operator=(Scene&&) noexcept = default;

    // ---------------------------------------------------------------- geometry

    /// Adds a triangle mesh (copied; indices checked: Error when out of range). Triangles with a
    /// NaN or infinite corner are never hit, found or collided with.
    template <IndexedTriangleMesh M>
    GeometryId add_mesh(const M& mesh) {
        if (geometry_.size() >= 0xFFFFFFFEu) throw Error("Scene::add_mesh: too many meshes");
        geometry_.push_back(std::make_unique<SceneGeometry<T>>(mesh));
        return GeometryId(std::uint32_t(geometry_.size() - 1));
    }
    std::size_t geometry_count() const { return geometry_.size(); }
    const SceneGeometry<T>& geometry(GeometryId id) const {
        return *geometry_[checked(id, "Scene::geometry")];
    }

    // ---------------------------------------------------------------- instances

    /// Adds an instance of `geometry` at `pose` (finite and rigid: check_rigid_pose). The pose is
    /// stored with its rotation replaced by the nearest rotation (pose(id) returns that). Error on
    /// a bad geometry id, pose or options (a negative or non-finite margin), or when the world box
    /// leaves T's finite range.
    InstanceId add_instance(GeometryId geometry, const Pose& pose,
                            const InstanceOptions<T>& options = {}) {
        const SceneGeometry<T>& g = *geometry_[checked(geometry, "Scene::add_instance")];
        check_rigid_pose(pose, "Scene::add_instance", "pose");
        check_options(options, "Scene::add_instance");
        const Pose stored = scene_detail::rigid_pose(pose);
        const Box box = g.world_box(stored, g.pose_pad(stored));
        const Box top = scene_detail::grown(box, options.margin);
        // The record's slot exists before the tree hands the slot out: the tree's next slot is a
        // free one below id_bound() or id_bound() itself, and a bad_alloc here leaves no live id
        // without a record.
        if (instances_.size() <= std::size_t(tree_.id_bound()))
            instances_.resize(std::size_t(tree_.id_bound()) + 1);
        const ProxyId proxy = tree_.create(top);
        instances_[std::size_t(proxy.index())] = {geometry, stored, options, box};
        return InstanceId(proxy);
    }

    /// Moves an instance (the pose stored as add_instance stores it). Its world box is
    /// recomputed from the hull; the top-level tree changes only when the box leaves its fat box
    /// (stretched along the translation's change). Error, and no change, on a stale id, a bad
    /// pose, or a world box beyond T's finite range.
    void set_pose(InstanceId id, const Pose& pose) {
        check_id(id, "Scene::set_pose");
        check_rigid_pose(pose, "Scene::set_pose", "pose");
        apply(id, plan_move(id, pose, "Scene::set_pose"));
    }
    /// set_pose for each (ids[i], poses[i]), in order. Every id, pose and new box is computed and
    /// checked first, so an Error leaves the scene as it was. Serial.
    void set_poses(std::span<const InstanceId> ids, std::span<const Pose> poses) {
        if (ids.size() != poses.size())
            throw Error("Scene::set_poses: " + std::to_string(ids.size()) + " ids but " +
                        std::to_string(poses.size()) + " poses");
        std::vector<Move> moves(ids.size());
        for (std::size_t i = 0; i < ids.size(); ++i) {
            check_id(ids[i], "Scene::set_poses");
            check_rigid_pose(poses[i], "Scene::set_poses", "pose");
            moves[i] = plan_move(ids[i], poses[i], "Scene::set_poses");
        }
        // No Error below: the boxes and displacements are the ones checked above.
        for (std::size_t i = 0; i < ids.size(); ++i) apply(ids[i], moves[i]);
    }
    /// New options; a new margin regrows the instance's top-level box. Error, and no change, on a
    /// stale id, a bad margin, or a grown box beyond T's finite range.
    void set_options(InstanceId id, const InstanceOptions<T>& options) {
        check_id(id, "Scene::set_options");
        check_options(options, "Scene::set_options");
        SceneInstance<T>& r = instances_[std::size_t(id.index())];
        if (options.margin != r.options.margin)
            tree_.move(id.proxy(), scene_detail::grown(r.box, options.margin));  // checks first
        r.options = options;
    }
    /// Removes the instance; `id` is stale from now on (calls given it throw Error).
    void remove(InstanceId id) {
        check_id(id, "Scene::remove");
        tree_.destroy(id.proxy());
        instances_[std::size_t(id.index())] = {};
    }

    /// Whether `id` names a live instance (false once removed, also after its slot is reused).
    bool contains(InstanceId id) const { return tree_.contains(id.proxy()); }
    std::size_t instance_count() const { return tree_.size(); }
    bool empty() const { return tree_.empty(); }
    const SceneInstance<T>& instance(InstanceId id) const {
        check_id(id, "Scene::instance");
        return instances_[std::size_t(id.index())];
    }
    GeometryId geometry_of(InstanceId id) const { return instance(id).geometry; }
    const Pose& pose(InstanceId id) const { return instance(id).pose; }
    const InstanceOptions<T>& options(InstanceId id) const { return instance(id).options; }
    std::uint64_t user_data(InstanceId id) const { return instance(id).options.user_data; }
    /// The instance's world box (tight: the hull's extent under the pose, padded by the rounding
    /// pad of scene/geometry.hpp; not grown by the margin, which top_level()'s box is).
    const Box& world_box(InstanceId id) const {
        check_id(id, "Scene::world_box");
        return instances_[std::size_t(id.index())].box;
    }
    /// The union of the instances' world boxes (empty for an empty scene). O(instances).
    Box bounds() const {
        Box b;
        for_each_instance([&](InstanceId id) { b.grow(instances_[std::size_t(id.index())].box); });
        return b;
    }
    /// visitor(InstanceId) for every live instance, in slot order.
    template <class F>
    void for_each_instance(F&& visitor) const {
        for (std::int32_t i = 0; i < tree_.id_bound(); ++i)
            if (const ProxyId p = tree_.proxy_at(i); !p.is_null() && tree_.contains(p))
                visitor(InstanceId(p));
    }

    /// The top-level tree (read only): its boxes are the instances' world boxes, each grown by
    /// the instance's margin (two grown boxes overlap iff the world boxes' gap is within the sum
    /// of the margins); its proxy ids are the instances' (InstanceId::proxy()).
    const TopLevel& top_level() const { return tree_; }
    /// The record of a live instance by its proxy, unchecked: for the query walks, which get the
    /// proxy from the tree itself.
    const SceneInstance<T>& instance_at(ProxyId proxy) const {
        return instances_[std::size_t(proxy.index())];
    }
    const SceneGeometry<T>& geometry_at(GeometryId id) const { return *geometry_[id.index()]; }

    /// Builds every geometry's bottom-level trees now (they are otherwise built at the first
    /// query that needs each).
    void prepare() const {
        for (const auto& g : geometry_) g->prepare();
    }

    /// Checks every invariant: the top-level tree's (DynamicTree::validate), each live instance's
    /// geometry id, pose and options, and that its box is the one its pose gives. Error naming the
    /// first broken one.
    void validate() const {
        tree_.validate();
        for_each_instance([&](InstanceId id) {
            const SceneInstance<T>& r = instances_[std::size_t(id.index())];
            const std::string who = "Scene::validate: instance " + id.text();
            if (r.geometry.index() >= geometry_.size())
                throw Error(who + " names geometry " + std::to_string(r.geometry.index()) + " of " +
                            std::to_string(geometry_.size()));
            check_rigid_pose(r.pose, who.c_str(), "pose");
            check_options(r.options, who.c_str());
            const SceneGeometry<T>& g = *geometry_[r.geometry.index()];
            if (rigid_deviation(r.pose.rotation) > 64 * double(std::numeric_limits<T>::epsilon()))
                throw Error(who + ": its stored rotation is not orthonormalised");
            const Box expected = g.world_box(r.pose, g.pose_pad(r.pose));
            if (!(r.box.min == expected.min && r.box.max == expected.max))
                throw Error(who + ": its world box is not the one its pose gives");
            const Box top = scene_detail::grown(expected, r.options.margin);
            const Box& box = tree_.box(id.proxy());
            if (!(box.min == top.min && box.max == top.max))
                throw Error(who + ": its top-level box is not its world box grown by its margin");
        });
    }

  private:
    friend struct serial_detail::SceneAccess;
    struct Move {
        Pose pose;
        Box box, top;
        Vec<T, 3> displacement;
    };
    /// The stored pose, world box, top-level box and displacement of a pose change, checked as
    /// the tree will check them. The displacement is only the fat box's prediction of the next
    /// motion: taken from the pose before the call, in W, and clamped to T's finite range (a jump
    /// from -3e38 to 3e38 is a legal pose change, not an overflow).
    /// Stores a planned move: the tree's move() checks only what plan_move() checked, so it
    /// throws no Error here (an allocation failure inside the tree aside).
    void apply(InstanceId id, const Move& m) {
        SceneInstance<T>& r = instances_[std::size_t(id.index())];
        tree_.move(id.proxy(), m.top, m.displacement);
        r.pose = m.pose;
        r.box = m.box;
    }
    Move plan_move(InstanceId id, const Pose& pose, const char* where) const {
        using W = AccurateScalar<T>;
        const SceneInstance<T>& r = instances_[std::size_t(id.index())];
        const SceneGeometry<T>& g = *geometry_[r.geometry.index()];
        Move m;
        m.pose = scene_detail::rigid_pose(pose);
        m.box = g.world_box(m.pose, g.pose_pad(m.pose));
        m.top = scene_detail::grown(m.box, r.options.margin);
        dynamic_detail::check_box(m.top, where);
        constexpr W big = W(std::numeric_limits<T>::max());
        for (std::size_t a = 0; a < 3; ++a)
            m.displacement[a] =
                T(std::clamp(W(m.pose.translation[a]) - W(r.pose.translation[a]), -big, big));
        return m;
    }
    std::size_t checked(GeometryId id, const char* where) const {
        if (id.index() >= geometry_.size())
            throw Error(std::string(where) + ": geometry id " +
                        (id.is_null() ? std::string("null") : std::to_string(id.index())) +
                        " is not one of the scene's " + std::to_string(geometry_.size()) +
                        " meshes");
        return id.index();
    }
    void check_id(InstanceId id, const char* where) const {
        if (!tree_.contains(id.proxy()))
            throw Error(std::string(where) + ": instance id " + id.text() +
                        " names no live instance (removed, stale or never added)");
    }
    static void check_options(const InstanceOptions<T>& o, const char* where) {
        if (!(std::isfinite(o.margin) && o.margin >= T(0)))
            throw Error(std::string(where) + ": margin " + std::to_string(double(o.margin)) +
                        " must be finite and >= 0");
    }

    std::vector<std::unique_ptr<SceneGeometry<T>>> geometry_;
    std::vector<SceneInstance<T>> instances_;  // by the instance's slot
    TopLevel tree_;
};

}  // namespace bvhkit

#pragma once
// Scene<T>: many posed instances of shared triangle meshes, for rays, closest points and collision
// (docs/scenes.md). Two levels: geometry is added once (add_mesh) and shared by any number of
// instances, each a rigid pose, an id, user data, a collision group and mask and a margin; the top
// level is a DynamicTree over the instances' world boxes (fat boxes: a small pose change only
// updates the tight box), the bottom level the per-geometry trees (scene/geometry.hpp), built the
// first time a query family needs them and shared by all instances.
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
#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/scene/geometry.hpp"
#include "bvhkit/scene/instance.hpp"

namespace bvhkit {

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
    Transform<T> pose;
    InstanceOptions<T> options;
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

    /// Adds an instance of `geometry` at `pose` (finite and rigid: check_rigid_pose). Error on a
    /// bad geometry id, pose or options (a negative or non-finite margin).
    InstanceId add_instance(GeometryId geometry, const Pose& pose,
                            const InstanceOptions<T>& options = {}) {
        const SceneGeometry<T>& g = *geometry_[checked(geometry, "Scene::add_instance")];
        check_rigid_pose(pose, "Scene::add_instance", "pose");
        check_options(options, "Scene::add_instance");
        const ProxyId proxy = tree_.create(g.world_box(pose, g.pose_pad(pose)));
        const std::size_t slot = std::size_t(proxy.index());
        if (slot >= instances_.size()) instances_.resize(slot + 1);
        instances_[slot] = {geometry, pose, options};
        return InstanceId(proxy);
    }

    /// Moves an instance. Its world box is recomputed from the hull; the top-level tree changes
    /// only when the box leaves its fat box (stretched along the translation's change).
    void set_pose(InstanceId id, const Pose& pose) {
        check_id(id, "Scene::set_pose");
        check_rigid_pose(pose, "Scene::set_pose", "pose");
        move(id, pose);
    }
    /// set_pose for each (ids[i], poses[i]), in order. Every id and pose is checked first, so an
    /// Error leaves the scene as it was. Serial.
    void set_poses(std::span<const InstanceId> ids, std::span<const Pose> poses) {
        if (ids.size() != poses.size())
            throw Error("Scene::set_poses: " + std::to_string(ids.size()) + " ids but " +
                        std::to_string(poses.size()) + " poses");
        for (std::size_t i = 0; i < ids.size(); ++i) {
            check_id(ids[i], "Scene::set_poses");
            check_rigid_pose(poses[i], "Scene::set_poses", "pose");
        }
        for (std::size_t i = 0; i < ids.size(); ++i) move(ids[i], poses[i]);
    }
    void set_options(InstanceId id, const InstanceOptions<T>& options) {
        check_id(id, "Scene::set_options");
        check_options(options, "Scene::set_options");
        instances_[std::size_t(id.index())].options = options;
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
    /// pad of scene/geometry.hpp).
    const Box& world_box(InstanceId id) const {
        check_id(id, "Scene::world_box");
        return tree_.box(id.proxy());
    }
    /// The union of the instances' world boxes (empty for an empty scene). O(instances).
    Box bounds() const {
        Box b;
        for_each_instance([&](InstanceId id) { b.grow(tree_.box(id.proxy())); });
        return b;
    }
    /// visitor(InstanceId) for every live instance, in slot order.
    template <class F>
    void for_each_instance(F&& visitor) const {
        for (std::int32_t i = 0; i < tree_.id_bound(); ++i)
            if (const ProxyId p = tree_.proxy_at(i); !p.is_null() && tree_.contains(p))
                visitor(InstanceId(p));
    }

    /// The top-level tree (read only): its boxes are the instances' world boxes, its proxy ids
    /// the instances' (InstanceId::proxy()).
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
            const Box expected = g.world_box(r.pose, g.pose_pad(r.pose));
            const Box& box = tree_.box(id.proxy());
            if (!(box.min == expected.min && box.max == expected.max))
                throw Error(who + ": its world box is not the one its pose gives");
        });
    }

  private:
    void move(InstanceId id, const Pose& pose) {
        SceneInstance<T>& r = instances_[std::size_t(id.index())];
        const SceneGeometry<T>& g = *geometry_[r.geometry.index()];
        const Box box = g.world_box(pose, g.pose_pad(pose));
        tree_.move(id.proxy(), box, pose.translation - r.pose.translation);
        r.pose = pose;
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

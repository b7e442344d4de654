#pragma once
// Rays over a Scene (scene.hpp): the closest hit, any hit, all hits and a batch of closest hits.
//
// The walk: the top-level tree's ray cast (DynamicTree::ray_cast) visits the instances' world
// boxes nearest entry first; each instance's geometry is traced with the ray moved into its frame,
// origin' = R^T (o - t) and direction' = R^T d (taken in the wider type and rounded once), with the
// same [tmin, tmax]; a hit shortens the cast to its t, which drops every box entered beyond it.
// The ray parameter carries over unchanged: x -> R^T (x - t) is affine, so o + s d maps to
// origin' + s direction' for every s, and t in the instance's frame is t in the world (no
// normalisation of the direction is needed, and a rigid R keeps |d| too). Rounding aside: the
// local ray is the world ray up to one rounding of each coordinate.
//
// Hits report the instance, its geometry, the triangle's index in the mesh, t, the barycentrics
// (u, v) in that triangle, and the world-space geometric normal R n (n = (p1 - p0) x (p2 - p0) in
// the mesh's frame: not normalised, its length twice the triangle's area). Rays that cannot be
// traced (is_traceable: a NaN or infinite component, a zero direction, tmin > tmax) miss; a
// negative tmin is an Error (the cast starts at the origin). A ray whose origin or direction
// leaves T's finite range in an instance's frame (a direction of 3e38 rotated 45 degrees, an
// origin 3e38 from an instance at -3e38) misses that instance.
#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/build/build.hpp"
#include "bvhkit/query/ray.hpp"
#include "bvhkit/scene/ray_top_wide.hpp"
#include "bvhkit/scene/scene.hpp"

namespace bvhkit {

template <class T>
struct SceneHit {
    InstanceId instance;  // null on a miss
    GeometryId geometry;
    std::uint32_t face = invalid_index;  // the triangle's index in the geometry's mesh
    T t = std::numeric_limits<T>::infinity();
    T u = 0, v = 0;
    Vec<T, 3> normal{};  // world space, not normalised
    explicit operator bool() const { return face != invalid_index; }
};

namespace scene_detail {

template <class T>
bool check_scene_ray(const Ray<T, 3>& ray, const char* where) {
    if (!is_traceable(ray)) return false;
    if (ray.tmin < T(0))
        throw Error(std::string(where) + ": tmin " + std::to_string(double(ray.tmin)) +
                    " is negative; scene rays start at tmin >= 0");
    return true;
}

/// The ray in the instance's frame. A coordinate beyond T's range there comes out infinite (the
/// conversion is checked: scene_detail::narrow), and the callers treat such a ray as a miss of
/// that instance (is_traceable) rather than trace it.
template <class T>
Ray<T, 3> local_ray(const Transform<T>& pose, const Ray<T, 3>& ray, T tmax) {
    using W = AccurateScalar<T>;
    return Ray<T, 3>(to_local_point<W>(pose, ray.origin), to_local_vector<W>(pose, ray.direction),
                     ray.tmin, tmax);
}

template <class T>
SceneHit<T> scene_hit(const Scene<T>& scene, ProxyId proxy, const Hit<T>& h) {
    const SceneInstance<T>& r = scene.instance_at(proxy);
    SceneHit<T> out;
    out.instance = InstanceId(proxy);
    out.geometry = r.geometry;
    out.face = h.primitive;
    out.t = h.t;
    out.u = h.u;
    out.v = h.v;
    out.normal = to_world_vector<AccurateScalar<T>>(r.pose, h.normal);
    return out;
}

}  // namespace scene_detail

/// The nearest hit of the ray over all instances (a miss: !hit). Of hits at the same t, the first
/// instance the walk reaches wins.
template <class T>
SceneHit<T> closest_hit(const Scene<T>& scene, const Ray<T, 3>& ray) {
    SceneHit<T> best;
    if (!scene_detail::check_scene_ray(ray, "closest_hit(Scene)")) return best;
    Hit<T> best_local;
    ProxyId best_proxy;
    scene.top_level().ray_cast(ray.origin, ray.direction, ray.tmax, [&](ProxyId proxy, T max_t) {
        const SceneInstance<T>& r = scene.instance_at(proxy);
        const SceneGeometry<T>& g = scene.geometry_at(r.geometry);
        if (!g.has_extent()) return T(-1);
        const Ray<T, 3> local = scene_detail::local_ray(r.pose, ray, max_t);
        if (!is_traceable(local)) return T(-1);  // overflowed in the instance's frame: a miss
        const Hit<T> h = g.ray_tree().closest_hit(local);
        if (!h || !(h.t < best_local.t)) return T(-1);
        best_local = h;
        best_proxy = proxy;
        return h.t;  // 0 (a hit at the origin) stops the walk: nothing can be nearer
    });
    if (best_local) best = scene_detail::scene_hit(scene, best_proxy, best_local);
    return best;
}

/// Whether the ray hits any instance within [tmin, tmax] (stops at the first hit found).
template <class T>
bool any_hit(const Scene<T>& scene, const Ray<T, 3>& ray) {
    if (!scene_detail::check_scene_ray(ray, "any_hit(Scene)")) return false;
    bool hit = false;
    scene.top_level().ray_cast(ray.origin, ray.direction, ray.tmax, [&](ProxyId proxy, T) {
        const SceneInstance<T>& r = scene.instance_at(proxy);
        const SceneGeometry<T>& g = scene.geometry_at(r.geometry);
        if (!g.has_extent()) return T(-1);
        const Ray<T, 3> local = scene_detail::local_ray(r.pose, ray, ray.tmax);
        if (!is_traceable(local) || !g.ray_tree().any_hit(local)) return T(-1);
        hit = true;
        return T(0);
    });
    return hit;
}

/// Every hit of the ray within [tmin, tmax], sorted by t (ties by instance slot, then face):
/// `out` is cleared, then filled.
template <class T>
void all_hits(const Scene<T>& scene, const Ray<T, 3>& ray, std::vector<SceneHit<T>>& out) {
    out.clear();
    if (!scene_detail::check_scene_ray(ray, "all_hits(Scene)")) return;
    scene.top_level().ray_cast(ray.origin, ray.direction, ray.tmax, [&](ProxyId proxy, T) {
        const SceneInstance<T>& r = scene.instance_at(proxy);
        const SceneGeometry<T>& g = scene.geometry_at(r.geometry);
        if (!g.has_extent()) return T(-1);
        const Ray<T, 3> local = scene_detail::local_ray(r.pose, ray, ray.tmax);
        if (!is_traceable(local)) return T(-1);
        g.ray_tree().all_hits(local, [&](const Hit<T>& h) {
            out.push_back(scene_detail::scene_hit(scene, proxy, h));
            return true;
        });
        return T(-1);
    });
    std::sort(out.begin(), out.end(), [](const SceneHit<T>& a, const SceneHit<T>& b) {
        if (a.t != b.t) return a.t < b.t;
        if (a.instance.index() != b.instance.index())
            return a.instance.index() < b.instance.index();
        return a.face < b.face;
    });
}

/// The scene's top level flattened for rays: a static binned-SAH tree over the instances' world
/// boxes, one instance per leaf, each leaf holding what its ray needs (the pose, the geometry's
/// ray tree) beside it. The dynamic top level is made for change (its nodes linked, its cast
/// general enough for boxes); a batch of rays through a scene that stands still walks this one
/// instead: flat nodes, and the ray's octant chosen once per ray rather than once per box
/// (query/ray.hpp's walk).
///
/// A snapshot: it answers for the scene as it was when made (its poses copied, its geometry's
/// trees referenced, so it must not outlive the scene), and changing the scene afterwards leaves
/// it stale; make a new one. Making it costs a build over the instances (O(n log n)), so it pays
/// for itself over many rays: closest_hits and any_hits make one per call when the batch is large
/// enough (ray_top_min_rays).
template <class T>
class SceneRayTop {
  public:
    explicit SceneRayTop(const Scene<T>& scene) {
        std::vector<Aabb<T, 3>> boxes;
        std::vector<Vec<T, 3>> centres;
        scene.for_each_instance([&](InstanceId id) {
            const SceneInstance<T>& r = scene.instance_at(id.proxy());
            const SceneGeometry<T>& g = scene.geometry_at(r.geometry);
            if (!g.has_extent()) return;
            boxes.push_back(r.box);
            centres.push_back(safe_centroid(r.box));
            entries_.push_back({r.pose, &g.ray_tree(), id.proxy(), r.geometry});
        });
        BuildOptions options;
        options.max_leaf_size = 1;  // an instance costs a whole tree walk: never two per leaf
        options.threads = 1;
        bvh_ = build_bvh<T, 3>(boxes, centres, options);
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>) wide_ = scene_detail::WideTop4(bvh_);
#endif
    }

    /// As closest_hit(scene, ray) for the scene when this was made (of hits at the same t, the
    /// one this walk reaches first wins, which may be another instance than closest_hit's).
    SceneHit<T> closest_hit(const Ray<T, 3>& ray) const {
        SceneHit<T> best;
        if (!scene_detail::check_scene_ray(ray, "SceneRayTop::closest_hit") || bvh_.nodes.empty())
            return best;
        Hit<T> best_local;
        const Entry* best_entry = nullptr;
        T tmax = ray.tmax;
        walk<true>(ray, tmax, [&](std::uint32_t i) {
            const Entry& e = entries_[i];
            const Ray<T, 3> local = scene_detail::local_ray(e.pose, ray, tmax);
            if (!is_traceable(local)) return false;  // overflowed in the instance's frame
            const Hit<T> h = e.tree->closest_hit(local);
            if (!h || !(h.t < best_local.t)) return false;
            best_local = h;
            best_entry = &e;
            tmax = h.t;
            return h.t == T(0);  // a hit at the origin: nothing can be nearer
        });
        if (best_entry) {
            best.instance = InstanceId(best_entry->proxy);
            best.geometry = best_entry->geometry;
            best.face = best_local.primitive;
            best.t = best_local.t;
            best.u = best_local.u;
            best.v = best_local.v;
            best.normal = scene_detail::to_world_vector<AccurateScalar<T>>(best_entry->pose,
                                                                           best_local.normal);
        }
        return best;
    }

    /// As any_hit(scene, ray) for the scene when this was made.
    bool any_hit(const Ray<T, 3>& ray) const {
        if (!scene_detail::check_scene_ray(ray, "SceneRayTop::any_hit") || bvh_.nodes.empty())
            return false;
        bool hit = false;
        T tmax = ray.tmax;
        walk<false>(ray, tmax, [&](std::uint32_t i) {
            const Entry& e = entries_[i];
            const Ray<T, 3> local = scene_detail::local_ray(e.pose, ray, ray.tmax);
            hit = is_traceable(local) && e.tree->any_hit(local);
            return hit;
        });
        return hit;
    }

  private:
    struct Entry {
        Transform<T> pose;
        const TriangleBvh<T>* tree;
        ProxyId proxy;
        GeometryId geometry;
    };
    /// on_instance(index in entries_) -> bool (true stops) for each instance whose box the ray
    /// meets within [tmin, tmax], which on_instance may lower; a checked ray, a tree not empty.
    template <bool NearestFirst, class F>
    void walk(const Ray<T, 3>& ray, T& tmax, F&& on_instance) const {
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>) {
            wide_.template walk<NearestFirst>(ray, tmax, on_instance);
            return;
        }
#endif
        Ray<T, 3> narrowed = ray;
        // The ray was checked by the caller and the tree is not empty: the walk's own checks are
        // skipped.
        traverse_ray(
            bvh_view(bvh_), narrowed, RaySlabData<T, 3>(ray),
            [&](const BvhNode<Aabb<T, 3>>& leaf) {
                for (std::uint32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
                    const bool stop = on_instance(bvh_.primitive_indices[s]);
                    narrowed.tmax = tmax;
                    if (stop) return true;
                }
                return false;
            },
            NoStats{});
    }

    Bvh<Aabb<T, 3>> bvh_;
#if defined(__SSE2__)
    scene_detail::WideTop4 wide_;  // float scenes: the same tree, four children a node
#endif
    std::vector<Entry> entries_;  // by the tree's primitive index
};

/// The batch size from which closest_hits and any_hits trace through a SceneRayTop made for the
/// call: below it, making one costs more than it saves.
template <class T>
std::size_t ray_top_min_rays(const Scene<T>& scene) {
    return 64 + 4 * scene.instance_count();
}

/// hits[i] = closest_hit(scene, rays[i]) for every ray, on the calling thread (serial: call it
/// from several threads on parts of a batch to use more cores); a large batch goes through a
/// SceneRayTop made for the call (so a tie between instances at the same t may go to another of
/// them than closest_hit's). Error when the spans' lengths differ.
template <class T>
void closest_hits(const Scene<T>& scene, std::span<const Ray<T, 3>> rays,
                  std::span<SceneHit<T>> hits) {
    if (rays.size() != hits.size())
        throw Error("closest_hits(Scene): " + std::to_string(rays.size()) + " rays but " +
                    std::to_string(hits.size()) + " hits");
    if (rays.size() >= ray_top_min_rays(scene)) {
        const SceneRayTop<T> top(scene);
        for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = top.closest_hit(rays[i]);
        return;
    }
    for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = closest_hit(scene, rays[i]);
}

/// hit[i] = any_hit(scene, rays[i]) for every ray, as closest_hits goes (serial; a large batch
/// through a SceneRayTop). Error when the spans' lengths differ.
template <class T>
void any_hits(const Scene<T>& scene, std::span<const Ray<T, 3>> rays, std::span<bool> hit) {
    if (rays.size() != hit.size())
        throw Error("any_hits(Scene): " + std::to_string(rays.size()) + " rays but " +
                    std::to_string(hit.size()) + " answers");
    if (rays.size() >= ray_top_min_rays(scene)) {
        const SceneRayTop<T> top(scene);
        for (std::size_t i = 0; i < rays.size(); ++i) hit[i] = top.any_hit(rays[i]);
        return;
    }
    for (std::size_t i = 0; i < rays.size(); ++i) hit[i] = any_hit(scene, rays[i]);
}

}  // namespace bvhkit

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

inline void check_batch(std::size_t rays, std::size_t out, const char* what) {
    if (rays != out)
        throw Error(std::string(what) + " holds " + std::to_string(out) + " entries for " +
                    std::to_string(rays) + " rays");
}

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

}  // namespace bvhkit

#pragma once
// Signed distance and inside/outside over a Scene (scene.hpp): the answers the one-mesh queries
// (query/signed_distance.hpp, query/winding_number.hpp) would give on the scene as one
// world-space mesh, each instance a solid of its own:
// - |distance| is the distance to the nearest surface of any instance, closest_point()'s;
// - p is inside the scene when it is inside ANY instance (overlapping instances: their union),
//   and the distance is then negative. A point inside one instance and near another's surface
//   is inside, at the distance of that nearest surface.
// contains() is "inside any instance" alone. A point on one instance's surface and inside
// another is at distance -0 (std::signbit tells it; contains() says so plainly).
//
// Inside one instance, by the sign option (SceneSign), each as the one-mesh query decides it:
// - pseudonormal: the angle-weighted pseudonormal at the instance's own closest point to p
//   (Baerentzen and Aanaes 2005); exact for closed, consistently oriented meshes.
// - winding_number, and contains(): the generalized winding number above 1/2 (Jacobson et al.
//   2013); on a closed oriented surface one ray's signed crossings give it exactly
//   (query/crossings.hpp), elsewhere (and where the ray meets an edge) the fast winding number
//   decides (Barill et al. 2018, beta = 2). Robust for meshes with holes.
// The candidates for "inside" are the instances whose world box contains p (one top-level box
// query): a point inside a closed mesh is inside its hull, so inside its box. A point far from
// everything costs the nearest walk and one empty box query; a point inside k boxes costs up to k
// more per-instance tests (the nearest instance's pseudonormal sign comes with the walk). For
// an open mesh, a winding number above 1/2 outside its hull (a surface wrapped over itself) is
// not found.
//
// As closest_point(): p goes into each instance's frame in the wider type and is rounded once,
// so instances far from the origin keep their detail. Points with a NaN or infinite coordinate,
// and every point of a scene with no triangles, are outside at distance +inf with no closest
// point. The structures are per geometry and built at their first use (scene/geometry_solid.hpp).
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>

#include "bvhkit/error.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/query/crossings.hpp"
#include "bvhkit/query/point_order.hpp"
#include "bvhkit/scene/closest_point.hpp"

namespace bvhkit {

enum class SceneSign : std::uint8_t { pseudonormal, winding_number };

template <class T>
struct SceneSignedDistance {
    T distance = std::numeric_limits<T>::infinity();  // negative inside
    ScenePoint<T> closest;                            // the nearest surface point (world)
    explicit operator bool() const { return bool(closest); }
};

namespace scene_detail {

/// Whether p is inside some instance other than `skip` whose world box contains p, by
/// inside(geometry, p in the instance's frame).
template <class T, class Inside>
bool inside_any(const Scene<T>& scene, const Vec<T, 3>& p, ProxyId skip, Inside&& inside) {
    using W = AccurateScalar<T>;
    bool found = false;
    scene.top_level().query_point(p, [&](ProxyId proxy) {
        if (proxy == skip) return true;
        const SceneInstance<T>& r = scene.instance_at(proxy);
        if (!r.box.contains(p)) return true;  // within the instance's margin only
        const SceneGeometry<T>& g = scene.geometry_at(r.geometry);
        if (!g.has_extent()) return true;
        const Vec<T, 3> local = to_local_point<W>(r.pose, p);
        if (!is_finite(local)) return true;
        found = inside(g, local);
        return !found;
    });
    return found;
}

/// The winding number rule of contains() for one geometry, at a point of its frame.
template <class T>
bool inside_by_winding(const SceneGeometry<T>& g, const Vec<T, 3>& local) {
    if (g.is_closed())
        if (const std::optional<int> w = crossing_winding_number<T>(g.ray_tree(), local))
            return *w >= 1;
    return g.winding_number_mesh().inside(local);
}

}  // namespace scene_detail

/// Whether p is inside any instance (see above): the winding number rule. False for a point
/// with a NaN or infinite coordinate.
template <class T>
bool contains(const Scene<T>& scene, const Vec<T, 3>& p) {
    if (!is_finite(p)) return false;
    return scene_detail::inside_any(scene, p, ProxyId{},
                                    [](const SceneGeometry<T>& g, const Vec<T, 3>& local) {
                                        return scene_detail::inside_by_winding(g, local);
                                    });
}

/// The signed distance from p to the scene (see above): negative inside any instance, with the
/// nearest surface point, its instance, geometry and face.
template <class T>
SceneSignedDistance<T> signed_distance(const Scene<T>& scene, const Vec<T, 3>& p,
                                       SceneSign sign = SceneSign::pseudonormal) {
    using W = AccurateScalar<T>;
    SceneSignedDistance<T> r;
    if (!is_finite(p)) return r;
    if (sign == SceneSign::winding_number) {
        r.closest = closest_point(scene, p);
        if (!r.closest) return r;
        r.distance = contains(scene, p) ? -r.closest.distance : r.closest.distance;
        return r;
    }
    if (sign != SceneSign::pseudonormal)
        throw Error("signed_distance(Scene): sign " + std::to_string(int(sign)) +
                    " is not a SceneSign");
    // The walk over the SignedDistanceMeshes' own closest point trees: the winner's closest
    // point is the one its pseudonormal sign needs.
    const scene_detail::NearestFound<T> found = scene_detail::nearest_over(
        scene, p, [](const SceneGeometry<T>& g) -> const ClosestPointMesh<T>& {
            return g.signed_distance_mesh().closest_point_mesh();
        });
    r.closest = found.point;
    if (!r.closest) return r;
    const SceneInstance<T>& nearest = scene.instance_at(found.proxy);
    const SceneGeometry<T>& g = scene.geometry_at(nearest.geometry);
    const Vec<T, 3> local = scene_detail::to_local_point<W>(nearest.pose, p);
    bool inside = g.signed_distance_mesh().signed_distance_at(local, found.local).distance < T(0);
    if (!inside)
        inside = scene_detail::inside_any(
            scene, p, found.proxy, [](const SceneGeometry<T>& other, const Vec<T, 3>& q) {
                thread_local NearestScratch<T> scratch;
                return other.signed_distance_mesh().signed_distance(q, scratch).distance < T(0);
            });
    r.distance = inside ? -r.closest.distance : r.closest.distance;
    return r;
}

/// out[i] = signed_distance(scene, points[i], sign) for every point, on `exec` (threads: 0 =
/// every core, 1 = the calling thread): the same answers as one at a time, for any thread
/// count. Error when `out` has fewer rows than `points`.
template <class T>
void signed_distances(const Scene<T>& scene, std::span<const Vec<T, 3>> points,
                      std::span<SceneSignedDistance<T>> out,
                      SceneSign sign = SceneSign::pseudonormal, const Executor& exec = Executor()) {
    if (out.size() < points.size())
        throw Error("signed_distances(Scene): " + std::to_string(points.size()) +
                    " points but room for " + std::to_string(out.size()));
    for_point_chunks(points, exec, 256, [&](std::span<const std::uint32_t> chunk) {
        for (const std::uint32_t i : chunk) out[i] = signed_distance(scene, points[i], sign);
    });
}

/// out[i] = contains(scene, points[i]) for every point, on `exec`. Error when `out` has fewer
/// rows than `points`.
template <class T>
void contains(const Scene<T>& scene, std::span<const Vec<T, 3>> points, std::span<bool> out,
              const Executor& exec = Executor()) {
    if (out.size() < points.size())
        throw Error("contains(Scene): " + std::to_string(points.size()) + " points but room for " +
                    std::to_string(out.size()));
    for_point_chunks(points, exec, 256, [&](std::span<const std::uint32_t> chunk) {
        for (const std::uint32_t i : chunk) out[i] = contains(scene, points[i]);
    });
}

}  // namespace bvhkit

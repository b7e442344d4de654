#pragma once
// The closest point of a Scene (scene.hpp) to a point: over every instance's mesh, the nearest
// point, its instance, geometry, triangle and distance.
//
// The walk: best first over the top-level boxes (DynamicTree::query_nearest), nearest box first,
// with the distance of the best point so far as the bound: a box farther than it ends the walk.
// Each instance's geometry is asked for its closest point within the bound
// (ClosestPointMesh::closest_point_within), with the point moved into the instance's frame,
// p' = R^T (p - t), taken in the wider type and rounded once; for a rigid pose the distance from
// p' to the mesh is the distance from p to the posed mesh, so it is not transformed back. The
// point found is carried to the world as R q + t, in the wider type and rounded once.
#include <cmath>

#include "bvhkit/scene/scene.hpp"

namespace bvhkit {

template <class T>
struct ScenePoint {
    InstanceId instance;  // null when the scene has no triangle
    GeometryId geometry;
    std::uint32_t face = invalid_index;  // the triangle's index in the geometry's mesh
    Vec<T, 3> point{};                   // world space
    T distance = std::numeric_limits<T>::infinity();
    T u = 0, v = 0;  // barycentrics of the point in the triangle (as MeshPoint's)
    explicit operator bool() const { return face != invalid_index; }
};

namespace scene_detail {

/// What the nearest walk found: the answer in the world, and the winner's proxy and answer in
/// its own frame (for a caller that signs it: scene/signed_distance.hpp).
template <class T>
struct NearestFound {
    ScenePoint<T> point;
    ProxyId proxy;
    MeshPoint<T> local;
};

/// closest_point()'s walk over the closest point trees that tree_of(const SceneGeometry<T>&)
/// gives: each geometry's own, or the one inside its SignedDistanceMesh.
template <class T, class TreeOf>
NearestFound<T> nearest_over(const Scene<T>& scene, const Vec<T, 3>& p, TreeOf&& tree_of) {
    using W = AccurateScalar<T>;
    NearestFound<T> found;
    if (!is_finite(p)) return found;
    thread_local NearestScratch<T> scratch;
    MeshPoint<T>& best_local = found.local;
    ProxyId& best_proxy = found.proxy;
    W best_distance = std::numeric_limits<W>::infinity();
    scene.top_level().query_nearest(p, [&](ProxyId proxy, W) -> W {
        const SceneInstance<T>& r = scene.instance_at(proxy);
        const SceneGeometry<T>& g = scene.geometry_at(r.geometry);
        if (!g.has_extent()) return std::numeric_limits<W>::infinity();
        const Vec<T, 3> local = to_local_point<W>(r.pose, p);
        // Beyond T's range in the instance's frame (p 3e38 from an instance at -3e38): the
        // instance is farther than any distance T holds, so it is skipped, not measured.
        if (!is_finite(local)) return best_distance * best_distance;
        const ClosestPointMesh<T>& tree = tree_of(g);
        const MeshPoint<T> m =
            tree.closest_point_within(local, best_distance, MeshPoint<T>{}, scratch);
        if (m && W(m.distance) < best_distance) {
            best_local = m;
            best_proxy = proxy;
            best_distance = W(m.distance);
        }
        return best_distance * best_distance;
    });
    if (!best_local) return found;
    const SceneInstance<T>& r = scene.instance_at(best_proxy);
    const Vec<W, 3> q = apply_wide<W>(r.pose, best_local.point);
    ScenePoint<T>& best = found.point;
    best.instance = InstanceId(best_proxy);
    best.geometry = r.geometry;
    best.face = best_local.triangle;
    best.point = Vec<T, 3>(T(q[0]), T(q[1]), T(q[2]));
    best.distance = best_local.distance;
    best.u = best_local.u;
    best.v = best_local.v;
    return found;
}

}  // namespace scene_detail

/// The point of the scene nearest to p (none for an empty scene or a point with a NaN or
/// infinite coordinate). Of points at the same distance, the first instance the walk reaches
/// wins. An instance from which p is beyond T's range in the instance's frame is skipped.
template <class T>
ScenePoint<T> closest_point(const Scene<T>& scene, const Vec<T, 3>& p) {
    return scene_detail::nearest_over(scene, p,
                                      [](const SceneGeometry<T>& g) -> const ClosestPointMesh<T>& {
                                          return g.closest_point_tree();
                                      })
        .point;
}

}  // namespace bvhkit

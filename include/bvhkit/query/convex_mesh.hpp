#pragma once
// A convex shape (convex/: sphere, box, capsule, cylinder, cone, hull) against a triangle mesh's
// CollisionModel, each under its own world pose: whether they meet, and their distance with the
// closest points and the mesh's triangle. The mesh's tree is walked with a volume of the mesh's
// own kind fitted around the shape (its box in its own frame, from six supports), placed in the
// mesh's frame by the relative pose: a node whose volume misses the shape's is skipped (collision),
// a node whose volume is farther than the best distance so far ends the walk (distance, best
// first). At the leaves, GJK (convex/distance.hpp) runs between the shape and each triangle.
//
// Each shape-triangle GJK works in a frame of its own: the shape's position at the origin, scaled
// by the power of two that brings the pair to unit size, so a shape far from the mesh's origin or
// at a tiny or huge scale keeps its digits (as convex_distance does for two shapes). Spheres and
// capsules run on their cores (centre, segment) with the radius subtracted after, so their answers
// are exact to rounding. Touching counts as meeting, within GJK's tolerance of 64 epsilons of the
// pair's size.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "bvhkit/bvh/traverse.hpp"
#include "bvhkit/convex/distance.hpp"
#include "bvhkit/primitives/closest_point.hpp"
#include "bvhkit/query/collision_model.hpp"
#include "bvhkit/query/pose_slack.hpp"

namespace bvhkit {

/// The answer of convex_mesh_distance (world frame).
template <class T>
struct ConvexMeshDistance {
    /// The distance between the shape and the mesh's triangles; 0 when they meet; +inf for a mesh
    /// without triangles.
    T distance = std::numeric_limits<T>::infinity();
    bool overlap = false;
    /// The closest points, on the shape and on the mesh (meeting: one point of the contact).
    Vec<T, 3> point_shape{}, point_mesh{};
    /// The mesh's triangle that point_mesh lies on (its index in the mesh).
    std::uint32_t face = std::numeric_limits<std::uint32_t>::max();
};

namespace convex_mesh_detail {

/// The shape and one triangle for run_gjk: D = shape - triangle, in a frame with the shape's
/// position at the origin, scaled by `factor`.
template <class T>
struct ShapeTrianglePair {
    using Scalar = T;
    convex_detail::PosedSupport<T> a;
    Vec<T, 3> p[3];
    T abs_tolerance;

    std::pair<Vec<T, 3>, Vec<T, 3>> support(const Vec<T, 3>& d) const {
        const Vec<T, 3> pa = a(d);
        // The triangle's support along -d: the corner with the least d . p.
        const T d0 = dot(d, p[0]), d1 = dot(d, p[1]), d2 = dot(d, p[2]);
        const Vec<T, 3>& q = d0 <= d1 ? (d0 <= d2 ? p[0] : p[2]) : (d1 <= d2 ? p[1] : p[2]);
        return {pa - q, pa};
    }
    Vec<T, 3> initial_direction() const { return (p[0] + p[1] + p[2]) * T(-1); }
};

/// The shape placed in the mesh's frame, and the volume of kind V around it (shape-local).
template <BoundingVolume V>
struct PlacedShape {
    using T = typename V::Scalar;
    const ConvexShape<T>* shape;
    Transform<T> in_mesh;  // the shape's pose in the mesh's frame
    V volume;
    T reach;  // the shape's largest |local coordinate|
    typename VolumeTraits<V>::Prepared prepared;
};

template <BoundingVolume V>
PlacedShape<V> place(const ConvexShape<typename V::Scalar>& shape,
                     const Transform<typename V::Scalar>& shape_pose, const CollisionModel<V>& mesh,
                     const Transform<typename V::Scalar>& mesh_pose, const char* where) {
    using T = typename V::Scalar;
    using W = AccurateScalar<T>;
    check_rigid_pose(shape_pose, where, "shape_pose");
    check_rigid_pose(mesh_pose, where, "mesh_pose");
    struct {
        Transform<T> in_mesh;
        T reach = 0;
    } s;
    // inverse(mesh_pose) * shape_pose in the wider type, rounded once: R_m^T R_s and
    // R_m^T (t_s - t_m), so two poses far out and near each other lose nothing.
    for (std::size_t i = 0; i < 3; ++i) {
        W t = 0;
        for (std::size_t k = 0; k < 3; ++k)
            t += W(mesh_pose.rotation[k][i]) *
                 (W(shape_pose.translation[k]) - W(mesh_pose.translation[k]));
        s.in_mesh.translation[i] = T(t);
        for (std::size_t j = 0; j < 3; ++j)
            s.in_mesh.rotation[i][j] =
                T(W(mesh_pose.rotation[0][i]) * W(shape_pose.rotation[0][j]) +
                  W(mesh_pose.rotation[1][i]) * W(shape_pose.rotation[1][j]) +
                  W(mesh_pose.rotation[2][i]) * W(shape_pose.rotation[2][j]));
    }
    // The shape's box in its own frame (supports include the margin), as a volume of kind V.
    Aabb<T, 3> box;
    for (std::size_t i = 0; i < 3; ++i) {
        Vec<T, 3> d{};
        d[i] = T(1);
        box.max[i] = shape.support(d)[i];
        d[i] = T(-1);
        box.min[i] = shape.support(d)[i];
        s.reach = std::max({s.reach, std::fabs(box.min[i]), std::fabs(box.max[i])});
    }
    std::vector<Triangle<T>> faces;
    for (int f = 0; f < 6; ++f) {  // the box's faces as two triangles each
        const std::size_t a = std::size_t(f / 2), b = (a + 1) % 3, c = (a + 2) % 3;
        const T x = f % 2 ? box.max[a] : box.min[a];
        Vec<T, 3> q[4];
        for (int k = 0; k < 4; ++k) {
            q[k][a] = x;
            q[k][b] = k & 1 ? box.max[b] : box.min[b];
            q[k][c] = k & 2 ? box.max[c] : box.min[c];
        }
        faces.push_back({q[0], q[1], q[3]});
        faces.push_back({q[0], q[3], q[2]});
    }
    const V volume = VolumeTraits<V>::fit(std::span<const Triangle<T>>(faces));
    return {
        &shape, s.in_mesh, volume, s.reach,
        VolumeTraits<V>::prepare(s.in_mesh, pose_slack(mesh.scale(), T(2) * s.reach, s.in_mesh))};
}

/// GJK between the placed shape and triangle `tri` (mesh frame): the distance (0 when they
/// meet), and the closest points on the shape and on the triangle (mesh frame).
template <class T>
struct TriangleAnswer {
    T distance;
    bool overlap;
    Vec<T, 3> on_shape, on_triangle;
};

template <BoundingVolume V>
TriangleAnswer<typename V::Scalar> shape_triangle(const PlacedShape<V>& s,
                                                  const Triangle<typename V::Scalar>& tri) {
    using T = typename V::Scalar;
    const Vec<T, 3>& origin = s.in_mesh.translation;
    const Vec<T, 3> rel[3] = {tri.p0 - origin, tri.p1 - origin, tri.p2 - origin};
    T scale = s.reach;
    for (const Vec<T, 3>& r : rel) scale = std::max(scale, max_component(bvhkit::max(r, -r)));
    const int e = convex_detail::unit_exponent<T>(scale);
    const T factor = std::ldexp(T(1), -e), unscale = std::ldexp(T(1), e);
    ShapeTrianglePair<T> pair{
        {s.shape, s.in_mesh.rotation, Vec<T, 3>{}, true, HullSupport<T>::none, factor},
        {rel[0] * factor, rel[1] * factor, rel[2] * factor},
        T(64) * std::numeric_limits<T>::epsilon() * scale * factor};
    const convex_detail::GjkRun<T> g = convex_detail::run_gjk(pair);
    const T margin = s.shape->margin();
    TriangleAnswer<T> r{T(0), true, {}, {}};
    if (g.overlap) {
        r.on_shape = r.on_triangle = convex_detail::simplex_witness_a(g.simplex) * unscale + origin;
        return r;
    }
    const T v_length = length(g.v);
    const T core = v_length * unscale;
    const Vec<T, 3> n = g.v * (T(-1) / v_length);  // from the shape's core to the triangle
    const Vec<T, 3> core_a = g.simplex.witness_a() * unscale + origin;
    r.on_triangle = core_a + n * core;
    if (core > margin) {
        r.distance = core - margin;
        r.overlap = false;
        r.on_shape = core_a + n * margin;
    } else {
        r.on_shape = r.on_triangle;  // the margin reaches the triangle: they meet there
    }
    return r;
}

}  // namespace convex_mesh_detail

/// Whether `shape` at `shape_pose` meets the triangles of `mesh` at `mesh_pose` (world poses,
/// finite and rigid: Error otherwise). Stops at the first triangle met.
template <BoundingVolume V>
bool convex_mesh_collides(const ConvexShape<typename V::Scalar>& shape,
                          const Transform<typename V::Scalar>& shape_pose,
                          const CollisionModel<V>& mesh,
                          const Transform<typename V::Scalar>& mesh_pose) {
    const auto s =
        convex_mesh_detail::place(shape, shape_pose, mesh, mesh_pose, "convex_mesh_collides");
    const auto& bvh = mesh.bvh();
    if (bvh.empty() || !is_finite(s.in_mesh.translation)) return false;
    const auto tris = mesh.slot_triangles();
    const auto enter = [&](std::uint32_t, const BvhNode<V>& node) {
        return VolumeTraits<V>::overlaps(node.bounds, s.volume, s.prepared);
    };
    const auto on_leaf = [&](const BvhNode<V>& node) {
        for (std::uint32_t k = node.first; k < node.first + node.count; ++k)
            if (convex_mesh_detail::shape_triangle(s, tris[k]).overlap) return false;
        return true;
    };
    return !traverse_depth_first<FirstChild::Right>(bvh, enter, on_leaf);
}

/// The distance between `shape` at `shape_pose` and the triangles of `mesh` at `mesh_pose` (world
/// poses, finite and rigid: Error otherwise), with the closest points and the mesh's triangle.
/// Of triangles at the same distance, the first the walk reaches wins. A shape placed beyond T's
/// range from the mesh (poses at -3e38 and 3e38 in float) gets +inf and no face.
template <BoundingVolume V>
ConvexMeshDistance<typename V::Scalar> convex_mesh_distance(
    const ConvexShape<typename V::Scalar>& shape, const Transform<typename V::Scalar>& shape_pose,
    const CollisionModel<V>& mesh, const Transform<typename V::Scalar>& mesh_pose) {
    using T = typename V::Scalar;
    const auto s =
        convex_mesh_detail::place(shape, shape_pose, mesh, mesh_pose, "convex_mesh_distance");
    ConvexMeshDistance<T> best;
    const auto& bvh = mesh.bvh();
    // A shape whose position in the mesh's frame is beyond T's range is farther than any
    // distance T holds: +inf, no face.
    if (bvh.empty() || !is_finite(s.in_mesh.translation)) return best;
    const auto tris = mesh.slot_triangles();
    struct Entry {
        T bound;
        std::uint32_t node;
    };
    thread_local std::vector<Entry> storage;
    MinHeap4 heap(storage, [](const Entry& e) { return e.bound; });
    heap.push({T(0), 0});
    convex_mesh_detail::TriangleAnswer<T> found{};
    const auto hopeless = [&](T bound) { return !(bound < best.distance); };  // nor any left
    walk_best_first(heap, hopeless, [&](const Entry& e, auto& queue) {
        const auto& node = bvh.nodes[e.node];
        if (!node.is_leaf()) {
            for (const std::uint32_t c : {node.left(), node.right()}) {
                const T bound = VolumeTraits<V>::distance_lower_bound(bvh.nodes[c].bounds, s.volume,
                                                                      s.prepared);
                if (bound < best.distance) queue.push({bound, c});
            }
            return Step::Pop;
        }
        for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
            const auto a = convex_mesh_detail::shape_triangle(s, tris[k]);
            if (a.distance < best.distance) {
                best.distance = a.distance;
                best.overlap = a.overlap;
                best.face = mesh.triangle_id(k);
                found = a;
            }
        }
        return best.overlap ? Step::Stop : Step::Pop;  // 0: nothing is nearer
    });
    if (best.face != ConvexMeshDistance<T>{}.face) {
        best.point_shape = mesh_pose.apply(found.on_shape);
        best.point_mesh = mesh_pose.apply(found.on_triangle);
    }
    return best;
}

}  // namespace bvhkit

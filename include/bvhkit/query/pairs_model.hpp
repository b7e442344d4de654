#pragma once
// CollisionModel<V>: a triangle mesh ready for collision and distance queries with any bounding
// volume type V (Aabb<T, 3>, Sphere<T>, Obb<T>, Kdop<T, K>). The tree's shape comes from the AABB
// builders (build_bvh); its volumes are fitted per node (build/fit_volumes.hpp). The triangles are
// kept in leaf-slot order, so a leaf's triangles are contiguous.
//
// collide(A, B, pose_of_b_in_a, ...) reports the intersecting triangle pairs (or only whether one
// exists) with the intersection segment in A's frame. B's triangles are carried into A's frame one
// at a time, at the leaf pairs the traversal reaches; neither mesh is copied per query.
#include <span>
#include <string>
#include <vector>

#include "bvhkit/build/build.hpp"
#include "bvhkit/build/fit_volumes.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/primitives/triangle_triangle.hpp"
#include "bvhkit/query/pairs.hpp"

namespace bvhkit {

/// Build options for collision trees: small leaves, as a leaf pair costs count_a * count_b
/// triangle tests.
inline BuildOptions collision_build_options() {
    BuildOptions o;
    o.max_leaf_size = 2;
    return o;
}

template <BoundingVolume V>
class CollisionModel {
  public:
    using T = typename V::Scalar;
    using Volume = V;

    CollisionModel() = default;
    template <IndexedTriangleMesh M>
    explicit CollisionModel(const M& mesh,
                            const BuildOptions& options = collision_build_options()) {
        check_triangle_indices(mesh);
        std::vector<Aabb<T, 3>> boxes(mesh.triangle_count());
        std::vector<Vec<T, 3>> centroids(mesh.triangle_count());
        for (std::size_t i = 0; i < boxes.size(); ++i) {
            boxes[i] = triangle_at<T>(mesh, i).bounds();
            centroids[i] = boxes[i].centroid();
        }
        const AabbBvh<T, 3> topology = build_bvh<T, 3>(boxes, centroids, options, &report_);
        triangle_count_ = mesh.triangle_count();
        lay_out(mesh, topology.primitive_indices);
        bvh_ = fit_volumes<V>(topology, std::span<const Triangle<T>>(slot_triangles_));
    }

    /// After the mesh's vertices moved (same triangles in the same order): new triangles, every
    /// volume refitted in one pass, same tree shape.
    template <IndexedTriangleMesh M>
    void refit(const M& mesh) {
        if (mesh.triangle_count() != triangle_count_)
            throw Error("CollisionModel::refit: the mesh has " +
                        std::to_string(mesh.triangle_count()) +
                        " triangles, the model was built over " + std::to_string(triangle_count_));
        check_triangle_indices(mesh);
        lay_out(mesh, bvh_.primitive_indices);
        refit_volumes(bvh_, std::span<const Triangle<T>>(slot_triangles_));
    }

    const Bvh<V>& bvh() const { return bvh_; }
    /// Triangle in leaf slot s; its index in the mesh is bvh().primitive_indices[s].
    std::span<const Triangle<T>> slot_triangles() const { return slot_triangles_; }
    std::span<const std::array<std::uint32_t, 3>> slot_vertex_ids() const {
        return slot_vertex_ids_;
    }
    std::uint32_t triangle_id(std::uint32_t slot) const { return bvh_.primitive_indices[slot]; }
    std::size_t triangle_count() const { return triangle_count_; }
    /// Triangles left out for non-finite coordinates.
    const std::vector<std::uint32_t>& skipped() const { return report_.skipped; }
    /// Largest |coordinate| of the model plus its box diagonal: the scale of its rounding errors.
    T scale() const { return scale_; }

  private:
    template <IndexedTriangleMesh M>
    void lay_out(const M& mesh, const std::vector<std::uint32_t>& order) {
        slot_triangles_.resize(order.size());
        slot_vertex_ids_.resize(order.size());
        Aabb<T, 3> box;
        for (std::size_t s = 0; s < order.size(); ++s) {
            slot_triangles_[s] = triangle_at<T>(mesh, order[s]);
            slot_vertex_ids_[s] = mesh.triangle(order[s]);
            box.grow(slot_triangles_[s].p0).grow(slot_triangles_[s].p1).grow(slot_triangles_[s].p2);
        }
        scale_ = box.is_empty()
                     ? T(0)
                     : max_component(bvhkit::max(box.max, -box.min)) + length(box.max - box.min);
    }

    Bvh<V> bvh_;
    std::vector<Triangle<T>> slot_triangles_;
    std::vector<std::array<std::uint32_t, 3>> slot_vertex_ids_;
    BuildReport report_;
    std::size_t triangle_count_ = 0;
    T scale_ = 0;
};

/// The absolute widening of volume tests under `pose` that covers the rounding of carrying B's
/// triangles into A's frame (a few ulps of the largest coordinate involved).
template <class T>
T pose_slack(T scale_a, T scale_b, const Transform<T>& pose) {
    return std::numeric_limits<T>::epsilon() * T(64) *
           (scale_a + scale_b + max_component(bvhkit::max(pose.translation, -pose.translation)));
}

template <class T>
Triangle<T> transformed(const Triangle<T>& t, const Transform<T>& pose) {
    return {pose.apply(t.p0), pose.apply(t.p1), pose.apply(t.p2)};
}

template <class T>
struct Contact {
    std::uint32_t triangle_a = 0, triangle_b = 0;  // indices in the meshes
    Vec<T, 3> p{}, q{};  // intersection segment in A's frame (triangle_triangle.hpp's rules)
    bool coplanar = false;
};

enum class CollideMode {
    FirstContact,  // stop at the first intersecting pair
    AllPairs,      // every intersecting triangle pair
};

struct CollideOptions {
    CollideMode mode = CollideMode::AllPairs;
    DescentRule rule = DescentRule::Larger;
    bool segments = true;  // compute each contact's segment (else only the triangle pair)
};

template <class T>
struct CollideResult {
    bool colliding = false;
    std::vector<Contact<T>> contacts;  // cleared, then filled (reuse one result across queries)
    PairStats stats;
};

/// Whether A and B (B placed in A's frame by pose_of_b_in_a) intersect, and where. The pose must
/// be finite and rigid (check_rigid_pose, math/transform.hpp: Error otherwise). What is decided:
/// each of B's corners is carried into A's frame in T (R x + t, each product and sum rounded to
/// T, transformed() below), and the triangle pairs are then decided exactly on those rounded
/// coordinates (triangle_triangle.hpp).
template <BoundingVolume V>
bool collide(const CollisionModel<V>& a, const CollisionModel<V>& b,
             const Transform<typename V::Scalar>& pose_of_b_in_a, const CollideOptions& options,
             CollideResult<typename V::Scalar>& result) {
    using T = typename V::Scalar;
    check_rigid_pose(pose_of_b_in_a, "collide", "pose_of_b_in_a");
    result.colliding = false;
    result.contacts.clear();
    result.stats = {};
    const auto ta = a.slot_triangles();
    const auto tb = b.slot_triangles();
    const bool first = options.mode == CollideMode::FirstContact;
    for_each_overlapping_pair(
        a.bvh(), b.bvh(), pose_of_b_in_a,
        [&](std::uint32_t sa, std::uint32_t sb) {
            const Triangle<T> tri_b = transformed(tb[sb], pose_of_b_in_a);
            Contact<T> c{a.triangle_id(sa), b.triangle_id(sb)};
            if (options.segments) {
                const TriangleIntersection<T> x = intersect_triangles(ta[sa], tri_b);
                if (!x.hit) return true;
                c.p = x.p;
                c.q = x.q;
                c.coplanar = x.coplanar;
            } else if (!triangles_intersect(ta[sa], tri_b)) {
                return true;
            }
            result.colliding = true;
            result.contacts.push_back(c);
            return !first;
        },
        options.rule, result.stats, pose_slack(a.scale(), b.scale(), pose_of_b_in_a));
    return result.colliding;
}

/// The yes/no query alone.
template <BoundingVolume V>
bool collides(const CollisionModel<V>& a, const CollisionModel<V>& b,
              const Transform<typename V::Scalar>& pose_of_b_in_a,
              DescentRule rule = DescentRule::Larger) {
    check_rigid_pose(pose_of_b_in_a, "collides", "pose_of_b_in_a");
    const auto ta = a.slot_triangles();
    const auto tb = b.slot_triangles();
    return !for_each_overlapping_pair(
        a.bvh(), b.bvh(), pose_of_b_in_a,
        [&](std::uint32_t sa, std::uint32_t sb) {
            return !triangles_intersect(ta[sa], transformed(tb[sb], pose_of_b_in_a));
        },
        rule, NoStats{}, pose_slack(a.scale(), b.scale(), pose_of_b_in_a));
}

}  // namespace bvhkit

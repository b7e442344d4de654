#pragma once
// collide(A, B, pose_of_b_in_a, ...) reports the intersecting triangle pairs of two
// CollisionModels (query/collision_model.hpp), or only whether one exists, with the intersection
// segment in A's frame. B's triangles are carried into A's frame one at a time, at the leaf pairs
// the traversal reaches; neither mesh is copied per query.
#include <cstdint>
#include <vector>

#include "bvhkit/primitives/triangle_triangle.hpp"
#include "bvhkit/query/collision_model.hpp"
#include "bvhkit/query/pairs.hpp"
#include "bvhkit/query/pose_slack.hpp"

namespace bvhkit {

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

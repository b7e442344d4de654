#pragma once
// collide(A, B, pose_of_b_in_a, ...) reports the intersecting triangle pairs of two
// CollisionModels (query/collision_model.hpp), or only whether one exists, with the intersection
// segment in A's frame. B's triangles are carried into A's frame one at a time, at the leaf pairs
// the traversal reaches (primitives/posed_triangles.hpp, exactly for the pose as given); neither
// mesh is copied per query.
#include <cstdint>
#include <vector>

#include "bvhkit/primitives/posed_triangles.hpp"
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
/// whether A's triangles meet B's carried by the pose as given, R x + t in exact arithmetic (no
/// rounding of B's corners, primitives/posed_triangles.hpp). The segments are computed in double
/// and rounded to T.
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
    const PosedTriangles<T> posed(pose_of_b_in_a, b.scale());
    for_each_overlapping_pair(
        a.bvh(), b.bvh(), pose_of_b_in_a,
        [&](std::uint32_t sa, std::uint32_t sb) {
            Contact<T> c{a.triangle_id(sa), b.triangle_id(sb)};
            if (options.segments) {
                const TriangleIntersection<T> x = posed.intersect(ta[sa], tb[sb]);
                if (!x.hit) return true;
                c.p = x.p;
                c.q = x.q;
                c.coplanar = x.coplanar;
            } else if (!posed.intersects(ta[sa], tb[sb])) {
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
    const PosedTriangles<typename V::Scalar> posed(pose_of_b_in_a, b.scale());
    return !for_each_overlapping_pair(
        a.bvh(), b.bvh(), pose_of_b_in_a,
        [&](std::uint32_t sa, std::uint32_t sb) { return !posed.intersects(ta[sa], tb[sb]); }, rule,
        NoStats{}, pose_slack(a.scale(), b.scale(), pose_of_b_in_a));
}

}  // namespace bvhkit

#pragma once
// Face contacts over a Scene (scene.hpp): for each pair of instances that collide (collision.hpp's
// rule: the group/mask filter, the ignore list, the margins, the exact test), the triangle pairs
// where they touch, in world space.
//
// A pair whose triangles meet gives one SceneFaceContact per intersecting triangle pair, with the
// intersection segment [p, q] (collide(), query/pairs_model.hpp: decided exactly for the relative
// pose, the segment computed in double in a's frame, then carried to the world as R x + t in the
// wider type and rounded once). A pair that collides only through its margins (its meshes apart
// by at most margin_a + margin_b) has no intersecting triangles: it gives one entry, `separated`,
// holding the closest triangles with p on a's mesh and q on b's (distance(), as closest_pair's
// witnesses). So every colliding pair appears at least once, and a caller that only wants where
// the surfaces cross reads the entries that are not `separated`.
#include <algorithm>
#include <span>
#include <vector>

#include "bvhkit/query/distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/scene.hpp"

namespace bvhkit {

template <class T>
struct SceneFaceContact {
    InstanceId a, b;  // the pair, as colliding_pairs reports it
    std::uint32_t face_a = invalid_index, face_b = invalid_index;  // triangles of a's and b's mesh
    Vec<T, 3> p{}, q{};     // the segment where the triangles cross (or the closest points), world
    bool coplanar = false;  // the triangles are coplanar and overlap (p, q: collide()'s rule)
    bool separated =
        false;  // a pair within its margins whose triangles do not meet: p on a, q on b
};

namespace scene_detail {

/// Appends the face contacts of instance a (of `sa`) with instance b (of `sb`), a pair known to
/// collide; `hits` is reusable scratch.
template <class T>
void append_face_contacts(const Scene<T>& sa, InstanceId a, const Scene<T>& sb, InstanceId b,
                          CollideResult<T>& hits, std::vector<SceneFaceContact<T>>& out) {
    using W = AccurateScalar<T>;
    const SceneInstance<T>& ra = sa.instance_at(a.proxy());
    const SceneInstance<T>& rb = sb.instance_at(b.proxy());
    const SceneGeometry<T>& ga = sa.geometry_at(ra.geometry);
    const SceneGeometry<T>& gb = sb.geometry_at(rb.geometry);
    const Transform<T> b_in_a = relative_pose<W>(ra.pose, rb.pose);
    const auto world = [&](const Vec<T, 3>& x) {
        const Vec<W, 3> w = apply_wide<W>(ra.pose, x);
        return Vec<T, 3>(narrow<T>(w[0]), narrow<T>(w[1]), narrow<T>(w[2]));
    };
    collide(ga.collision_model(), gb.collision_model(), b_in_a, CollideOptions{}, hits);
    if (hits.colliding) {
        for (const Contact<T>& c : hits.contacts)
            out.push_back(
                {a, b, c.triangle_a, c.triangle_b, world(c.p), world(c.q), c.coplanar, false});
        return;
    }
    // Colliding through the margins alone: the closest triangles stand for the pair.
    const DistanceResult<T> d = distance(ga.collision_model(), gb.collision_model(), b_in_a);
    out.push_back(
        {a, b, d.triangle_a, d.triangle_b, world(d.point_a), world(d.point_b), false, true});
}

}  // namespace scene_detail

/// The face contacts of every colliding pair of the scene (colliding_pairs' pairs, in its order;
/// each pair's triangle pairs in the order collide() finds them): `out` is cleared, then filled.
template <class T>
void colliding_faces(const Scene<T>& scene, std::vector<SceneFaceContact<T>>& out,
                     std::span<const InstancePair> ignore = {}) {
    out.clear();
    std::vector<InstancePair> pairs;
    colliding_pairs(scene, pairs, ignore);
    CollideResult<T> hits;
    for (const InstancePair& p : pairs)
        scene_detail::append_face_contacts(scene, p.a, scene, p.b, hits, out);
}

/// The face contacts of every colliding pair (a of `first`, b of `second`), in the order of
/// colliding_pairs(first, second, ...); `ignore` as there.
template <class T>
void colliding_faces(const Scene<T>& first, const Scene<T>& second,
                     std::vector<SceneFaceContact<T>>& out,
                     std::span<const InstancePair> ignore = {}) {
    out.clear();
    std::vector<InstancePair> pairs;
    colliding_pairs(first, second, pairs, ignore);
    CollideResult<T> hits;
    for (const InstancePair& p : pairs)
        scene_detail::append_face_contacts(first, p.a, second, p.b, hits, out);
}

}  // namespace bvhkit

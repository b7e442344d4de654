#pragma once
// InstancedScene<T>'s collision, face contact and distance calls (scene/collision.hpp,
// scene/face_contacts.hpp, scene/distance.hpp):
// within one scene, between two scenes, and against one more posed mesh. Each reads the ignore
// list and the pose before it releases the GIL, then checks the ids under the scene's shared lock.
#include <string>
#include <vector>

#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/configurations.hpp"
#include "bvhkit/scene/distance.hpp"
#include "bvhkit/scene/face_contacts.hpp"
#include "instanced_scene.hpp"

namespace bvhkit::python::instance_pairs {

template <class T>
using Scene = InstancedScene<T>;

inline std::vector<InstancePair> pairs_of(const IdPairs& pairs) {
    std::vector<InstancePair> out(pairs.shape(0));
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = {InstanceId::from_bits(std::uint64_t(pairs.data()[2 * i])),
                  InstanceId::from_bits(std::uint64_t(pairs.data()[2 * i + 1]))};
    return out;
}

/// Throws naming the first entry of `pairs` that is no live instance: column 0 of `first`,
/// column 1 of `second` (the same scene for pairs within one).
template <class T>
void check_pairs(const Scene<T>& first, const Scene<T>& second, const IdPairs& pairs) {
    for (std::size_t i = 0; i < 2 * pairs.shape(0); ++i) {
        const bool in_first = i % 2 == 0;
        if (!(in_first ? first : second)
                 .scene()
                 .contains(InstanceId::from_bits(std::uint64_t(pairs.data()[i]))))
            throw Error("ignore[" + std::to_string(i / 2) + ", " + std::to_string(i % 2) +
                        "] = " + std::to_string(pairs.data()[i]) + " names no live instance of " +
                        (&first == &second || in_first ? "this scene" : "the other scene") +
                        " (removed, stale or never added)");
    }
}

/// Both scenes' shared locks (one when they are the same object: a shared_mutex is not to be
/// locked twice by one thread), taken in address order so that two calls with the scenes in
/// either order cannot wait for each other behind a writer.
template <class T>
struct BothLocks {
    std::shared_lock<std::shared_mutex> first, second;
    BothLocks(const Scene<T>& x, const Scene<T>& y) {
        const Scene<T>* lo = &x < &y ? &x : &y;
        const Scene<T>* hi = &x < &y ? &y : &x;
        first = std::shared_lock<std::shared_mutex>(lo->mutex());
        if (hi != lo) second = std::shared_lock<std::shared_mutex>(hi->mutex());
    }
};

/// (p, 2) ids of the pairs.
inline nb::ndarray<nb::numpy, std::int64_t> id_pairs(const std::vector<InstancePair>& pairs) {
    std::vector<std::int64_t> flat;
    flat.reserve(2 * pairs.size());
    for (const InstancePair& p : pairs)
        flat.insert(flat.end(), {std::int64_t(p.a.bits()), std::int64_t(p.b.bits())});
    return owned_array(std::move(flat), pairs.size(), 2);
}

/// (distance (p,), ids (p, 2), point_a (p, 3), point_b (p, 3), faces (p, 2)); a null id -1.
template <class T>
nb::tuple pack(const std::vector<SceneDistance<T>>& v) {
    const std::size_t n = v.size();
    std::vector<T> d(n), pa(3 * n), pb(3 * n);
    std::vector<std::int64_t> ids(2 * n), faces(2 * n);
    for (std::size_t i = 0; i < n; ++i) {
        d[i] = v[i].distance;
        ids[2 * i] = v[i].a.is_null() ? -1 : std::int64_t(v[i].a.bits());
        ids[2 * i + 1] = std::int64_t(v[i].b.bits());
        faces[2 * i] = std::int64_t(v[i].face_a);
        faces[2 * i + 1] = std::int64_t(v[i].face_b);
        for (std::size_t a = 0; a < 3; ++a)
            pa[3 * i + a] = v[i].point_a[a], pb[3 * i + a] = v[i].point_b[a];
    }
    return nb::make_tuple(owned_array(std::move(d), n, 0), owned_array(std::move(ids), n, 2),
                          owned_array(std::move(pa), n, 3), owned_array(std::move(pb), n, 3),
                          owned_array(std::move(faces), n, 2));
}

/// One more posed mesh of the scene's: its geometry id, pose and options as an instance's.
template <class T>
struct PosedGeometry {
    std::int64_t geometry;
    Transform<T> pose;
    InstanceOptions<T> options;

    PosedGeometry(std::int64_t g, const Mats<T>& rotation, const Rows<T, 3>& translation,
                  std::uint32_t group, std::uint32_t mask, T margin)
        : geometry(g) {
        expect_rows(rotation, 1, "rotation");
        expect_rows(translation, 1, "translation");
        pose = Scene<T>::pose_at(rotation, translation, 0);
        options.group = group;
        options.mask = mask;
        options.margin = margin;
    }
    /// The geometry's id once checked against the scene (the caller holds its lock).
    GeometryId id(const bvhkit::Scene<T>& scene) const {
        if (geometry < 0 || std::size_t(geometry) >= scene.geometry_count())
            throw Error("geometry: " + std::to_string(geometry) + " is not one of the scene's " +
                        std::to_string(scene.geometry_count()) + " meshes");
        return GeometryId(std::uint32_t(geometry));
    }
};

// ---------------------------------------------------------------- collision

template <class T>
nb::ndarray<nb::numpy, std::int64_t> colliding_pairs(const Scene<T>& s, const IdPairs& ignore) {
    std::vector<InstancePair> out;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(s.mutex());
        check_pairs(s, s, ignore);
        bvhkit::colliding_pairs(s.scene(), out, skip);
    }
    return id_pairs(out);
}

template <class T>
bool any_collision(const Scene<T>& s, const IdPairs& ignore) {
    const std::vector<InstancePair> skip = pairs_of(ignore);
    nb::gil_scoped_release release;
    const std::shared_lock<std::shared_mutex> lock(s.mutex());
    check_pairs(s, s, ignore);
    return bvhkit::any_collision(s.scene(), skip);
}

/// The instances that geometry `geometry` at the one pose given collides with (its group, mask
/// and margin as an instance's), in slot order; at most one with stop_at_first.
template <class T>
nb::ndarray<nb::numpy, std::int64_t> colliding_instances(const Scene<T>& s, std::int64_t geometry,
                                                         const Mats<T>& rotation,
                                                         const Rows<T, 3>& translation,
                                                         std::uint32_t group, std::uint32_t mask,
                                                         T margin, bool stop_at_first) {
    const PosedGeometry<T> posed(geometry, rotation, translation, group, mask, margin);
    std::vector<std::int64_t> flat;
    {
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(s.mutex());
        std::vector<InstanceId> found;
        bvhkit::colliding_instances(s.scene(), posed.id(s.scene()), posed.pose, posed.options,
                                    found, stop_at_first);
        for (const InstanceId id : found) flat.push_back(std::int64_t(id.bits()));
    }
    const std::size_t n = flat.size();
    return owned_array(std::move(flat), n, 0);
}

/// The pairs of scene `s` (a) and `other` (b) that collide, (p, 2) ids sorted by a's slot then
/// b's. `ignore` rows are (id of s, id of other).
template <class T>
nb::ndarray<nb::numpy, std::int64_t> colliding_pairs_with(const Scene<T>& s, const Scene<T>& other,
                                                          const IdPairs& ignore) {
    std::vector<InstancePair> out;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const BothLocks<T> lock(s, other);
        check_pairs(s, other, ignore);
        bvhkit::colliding_pairs(s.scene(), other.scene(), out, skip);
    }
    return id_pairs(out);
}

template <class T>
bool any_collision_with(const Scene<T>& s, const Scene<T>& other, const IdPairs& ignore) {
    const std::vector<InstancePair> skip = pairs_of(ignore);
    nb::gil_scoped_release release;
    const BothLocks<T> lock(s, other);
    check_pairs(s, other, ignore);
    return bvhkit::any_collision(s.scene(), other.scene(), skip);
}

/// (pairs (c, 2), faces (c, 2), p (c, 3), q (c, 3), coplanar (c,), separated (c,)); the flags as
/// 0/1 bytes (the Python side views them as bool).
template <class T>
nb::tuple pack_faces(const std::vector<SceneFaceContact<T>>& v) {
    const std::size_t n = v.size();
    std::vector<std::int64_t> ids(2 * n), faces(2 * n);
    std::vector<T> p(3 * n), q(3 * n);
    std::vector<std::uint8_t> coplanar(n), separated(n);
    for (std::size_t i = 0; i < n; ++i) {
        ids[2 * i] = std::int64_t(v[i].a.bits());
        ids[2 * i + 1] = std::int64_t(v[i].b.bits());
        faces[2 * i] = std::int64_t(v[i].face_a);
        faces[2 * i + 1] = std::int64_t(v[i].face_b);
        for (std::size_t a = 0; a < 3; ++a) p[3 * i + a] = v[i].p[a], q[3 * i + a] = v[i].q[a];
        coplanar[i] = std::uint8_t(v[i].coplanar);
        separated[i] = std::uint8_t(v[i].separated);
    }
    return nb::make_tuple(owned_array(std::move(ids), n, 2), owned_array(std::move(faces), n, 2),
                          owned_array(std::move(p), n, 3), owned_array(std::move(q), n, 3),
                          owned_array(std::move(coplanar), n, 0),
                          owned_array(std::move(separated), n, 0));
}

template <class T>
nb::tuple colliding_faces(const Scene<T>& s, const IdPairs& ignore) {
    std::vector<SceneFaceContact<T>> out;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(s.mutex());
        check_pairs(s, s, ignore);
        bvhkit::colliding_faces(s.scene(), out, skip);
    }
    return pack_faces(out);
}

template <class T>
nb::tuple colliding_faces_with(const Scene<T>& s, const Scene<T>& other, const IdPairs& ignore) {
    std::vector<SceneFaceContact<T>> out;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const BothLocks<T> lock(s, other);
        check_pairs(s, other, ignore);
        bvhkit::colliding_faces(s.scene(), other.scene(), out, skip);
    }
    return pack_faces(out);
}

// ---------------------------------------------------------------- configurations

/// The instances `ids` and their poses at every configuration: rows k * ids.size() + i.
template <class T>
struct Configurations {
    std::vector<InstanceId> ids;
    std::vector<Transform<T>> poses;
    Configurations(const Ids& which, const Mats<T>& rotations, const Rows<T, 3>& translations) {
        for (std::size_t i = 0; i < which.shape(0); ++i)
            ids.push_back(Scene<T>::id_of(which.data()[i]));
        expect_rows(translations, rotations.shape(0), "translations");
        poses.resize(rotations.shape(0));
        for (std::size_t r = 0; r < poses.size(); ++r)
            poses[r] = Scene<T>::pose_at(rotations, translations, r);
    }
};

/// The colliding pairs with a moved instance at one configuration, (p, 2) ids sorted.
template <class T>
nb::ndarray<nb::numpy, std::int64_t> colliding_pairs_at(const Scene<T>& s, const Ids& which,
                                                        const Mats<T>& rotations,
                                                        const Rows<T, 3>& translations,
                                                        const IdPairs& ignore) {
    const Configurations<T> c(which, rotations, translations);
    std::vector<InstancePair> out;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(s.mutex());
        check_pairs(s, s, ignore);
        bvhkit::colliding_pairs_at(s.scene(), c.ids, c.poses, out, skip);
    }
    return id_pairs(out);
}

/// Whether each configuration collides: (K,) 0/1 bytes, over the extension's pool.
template <class T>
nb::ndarray<nb::numpy, std::uint8_t> any_collisions_at(const Scene<T>& s, const Ids& which,
                                                       const Mats<T>& rotations,
                                                       const Rows<T, 3>& translations,
                                                       const IdPairs& ignore, unsigned threads) {
    const Configurations<T> c(which, rotations, translations);
    const std::size_t n = c.ids.size();
    const std::size_t k = n == 0 ? 0 : c.poses.size() / n;
    std::vector<std::uint8_t> out(k);
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(s.mutex());
        check_pairs(s, s, ignore);
        bvhkit::any_collisions_at(s.scene(), c.ids, c.poses, out, skip, BatchExecutor{threads});
    }
    return owned_array(std::move(out), k, 0);
}

// ---------------------------------------------------------------- distance

/// The closest pair: pack() of none or one.
template <class T>
nb::tuple closest_pair(const Scene<T>& s, const IdPairs& ignore) {
    std::vector<SceneDistance<T>> found;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(s.mutex());
        check_pairs(s, s, ignore);
        if (const SceneDistance<T> d = bvhkit::closest_pair(s.scene(), skip)) found.push_back(d);
    }
    return pack(found);
}

/// The closest pair (a of s, b of other): pack() of none or one.
template <class T>
nb::tuple closest_pair_with(const Scene<T>& s, const Scene<T>& other, const IdPairs& ignore) {
    std::vector<SceneDistance<T>> found;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const BothLocks<T> lock(s, other);
        check_pairs(s, other, ignore);
        if (const SceneDistance<T> d = bvhkit::closest_pair(s.scene(), other.scene(), skip))
            found.push_back(d);
    }
    return pack(found);
}

template <class T>
nb::tuple pairs_within(const Scene<T>& s, T threshold, const IdPairs& ignore) {
    std::vector<SceneDistance<T>> found;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(s.mutex());
        check_pairs(s, s, ignore);
        bvhkit::pairs_within(s.scene(), threshold, found, skip);
    }
    return pack(found);
}

template <class T>
nb::tuple pairs_within_with(const Scene<T>& s, const Scene<T>& other, T threshold,
                            const IdPairs& ignore) {
    std::vector<SceneDistance<T>> found;
    {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const BothLocks<T> lock(s, other);
        check_pairs(s, other, ignore);
        bvhkit::pairs_within(s.scene(), other.scene(), threshold, found, skip);
    }
    return pack(found);
}

/// The instance nearest geometry `geometry` at the one pose given: pack() of none or one, its a
/// -1.
template <class T>
nb::tuple closest_instance(const Scene<T>& s, std::int64_t geometry, const Mats<T>& rotation,
                           const Rows<T, 3>& translation, std::uint32_t group, std::uint32_t mask,
                           T margin) {
    const PosedGeometry<T> posed(geometry, rotation, translation, group, mask, margin);
    std::vector<SceneDistance<T>> found;
    {
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(s.mutex());
        if (const SceneDistance<T> d =
                bvhkit::closest_instance(s.scene(), posed.id(s.scene()), posed.pose, posed.options))
            found.push_back(d);
    }
    return pack(found);
}

}  // namespace bvhkit::python::instance_pairs

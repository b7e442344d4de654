// libFuzzer target: the TriangleBvh (copied and in place), ClosestPointMesh, SignedDistanceMesh,
// WindingNumberMesh, DynamicTree, CollisionModel and Scene loaders on arbitrary bytes, as they come
// and again with the checksum recomputed (random bytes almost never carry a valid checksum, and the
// checks behind it are the ones worth fuzzing). A load may throw bvhkit::Error; a structure it
// accepts, with or without validate(), must answer queries with indices in range (ASan and UBSan
// watch the walks).
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "bvhkit/io/closest_point_mesh_file.hpp"
#include "bvhkit/io/collision_model_file.hpp"
#include "bvhkit/io/dynamic_tree_file.hpp"
#include "bvhkit/io/mapped_triangle_bvh.hpp"
#include "bvhkit/io/signed_distance_mesh_file.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/io/winding_number_mesh_file.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "bvhkit/query/self_collision.hpp"
#include "bvhkit/scene/closest_point.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/distance.hpp"
#include "bvhkit/scene/rays.hpp"
#include "bvhkit/scene/scene_file.hpp"

namespace {

// Rays that touch the tree; every index they return must be in range.
template <class T, class Tree>
void query_triangle_tree(const Tree& tree) {
    const bvhkit::Vec<T, 3> origins[] = {{T(-2), T(0.1), T(0.2)}, {T(0.3), T(0.2), T(0.1)}};
    const bvhkit::Vec<T, 3> directions[] = {{T(1), T(0), T(0)}, {T(0.1), T(-1), T(0.3)}};
    for (const auto& o : origins)
        for (const auto& d : directions) {
            const bvhkit::Ray<T, 3> ray(o, d);
            const bvhkit::Hit<T> hit = tree.closest_hit(ray);
            if (hit && hit.primitive >= tree.triangle_count()) std::abort();
            (void)tree.any_hit(ray);
            tree.all_hits(ray, [&](const bvhkit::Hit<T>& h) {
                if (h.primitive >= tree.triangle_count()) std::abort();
                return true;
            });
        }
    for (const std::uint32_t s : tree.skipped())
        if (s >= tree.triangle_count()) std::abort();
}

// Both loaders must accept the same files: the copying one and the in-place one (map_triangle_bvh).
// The queries run outside the try: an Error from a query would be a finding, not a rejection.
template <class T>
void load_and_query(std::span<const std::uint8_t> bytes) {
    for (const bool validate : {true, false}) {
        std::optional<bvhkit::TriangleBvh<T>> copied;
        std::optional<bvhkit::MappedTriangleBvh<T>> in_place;
        try {
            copied.emplace(
                bvhkit::triangle_bvh_from_bytes<T>(bytes, bvhkit::LoadOptions{validate}));
        } catch (const bvhkit::Error&) {
            // Rejected cleanly.
        }
        try {
            in_place.emplace(bvhkit::view_triangle_bvh<T>(bytes, bvhkit::LoadOptions{validate}));
        } catch (const bvhkit::Error&) {
        }
        if (copied) query_triangle_tree<T>(*copied);
        if (in_place) query_triangle_tree<T>(*in_place);
        // Bytes not aligned for the records are refused in place by design.
        const bool aligned = reinterpret_cast<std::uintptr_t>(bytes.data()) % alignof(T) == 0;
        if (aligned && copied.has_value() != in_place.has_value()) std::abort();
    }
}

template <class T>
void load_closest_point_mesh_and_query(std::span<const std::uint8_t> bytes) {
    for (const bool validate : {true, false}) {
        try {
            const bvhkit::ClosestPointMesh<T> mesh =
                bvhkit::closest_point_mesh_from_bytes<T>(bytes, bvhkit::LoadOptions{validate});
            bvhkit::NearestScratch<T> scratch;
            std::vector<bvhkit::MeshPoint<T>> near;
            const bvhkit::Vec<T, 3> points[] = {{T(-2), T(0.1), T(0.2)}, {T(0.3), T(0.2), T(0.1)}};
            for (const auto& p : points) {
                const auto q = mesh.closest_point(p, scratch);
                if (q && q.triangle >= mesh.triangle_count()) std::abort();
                mesh.k_nearest(p, 3, near, scratch);
                mesh.within_radius(p, T(0.5), near);
                for (const auto& n : near)
                    if (n.triangle >= mesh.triangle_count()) std::abort();
            }
        } catch (const bvhkit::Error&) {
        }
    }
}

template <class T>
void load_signed_distance_mesh_and_query(std::span<const std::uint8_t> bytes) {
    for (const bool validate : {true, false}) {
        try {
            const bvhkit::SignedDistanceMesh<T> mesh =
                bvhkit::signed_distance_mesh_from_bytes<T>(bytes, bvhkit::LoadOptions{validate});
            bvhkit::NearestScratch<T> scratch;
            const bvhkit::Vec<T, 3> points[] = {{T(-2), T(0.1), T(0.2)}, {T(0.3), T(0.2), T(0.1)}};
            for (const auto& p : points) (void)mesh.signed_distance(p, scratch);
        } catch (const bvhkit::Error&) {
        }
    }
}

template <class T>
void load_winding_number_mesh_and_query(std::span<const std::uint8_t> bytes) {
    for (const bool validate : {true, false}) {
        try {
            const bvhkit::WindingNumberMesh<T> mesh =
                bvhkit::winding_number_mesh_from_bytes<T>(bytes, bvhkit::LoadOptions{validate});
            const bvhkit::Vec<T, 3> points[] = {{T(-2), T(0.1), T(0.2)}, {T(0.3), T(0.2), T(0.1)}};
            for (const auto& p : points) (void)mesh.fast(p), (void)mesh.exact(p);
        } catch (const bvhkit::Error&) {
        }
    }
}

/// A Scene the loader accepts answers every query family with live ids, and validates.
template <class T>
void load_scene_and_query(std::span<const std::uint8_t> bytes) {
    std::optional<bvhkit::Scene<T>> scene;
    try {
        scene.emplace(bvhkit::scene_from_bytes<T>(bytes));
    } catch (const bvhkit::Error&) {
        return;
    }
    const bvhkit::Scene<T>& s = *scene;
    s.validate();
    const bvhkit::Ray<T, 3> ray({T(-2), T(0.1), T(0.2)}, {T(1), T(0), T(0)});
    const auto hit = bvhkit::closest_hit(s, ray);
    if (hit && !s.contains(hit.instance)) std::abort();
    const auto near = bvhkit::closest_point(s, bvhkit::Vec<T, 3>(T(0.3), T(0.2), T(0.1)));
    if (near && !s.contains(near.instance)) std::abort();
    std::vector<bvhkit::InstancePair> pairs;
    bvhkit::colliding_pairs(s, pairs);
    for (const auto& p : pairs)
        if (!s.contains(p.a) || !s.contains(p.b)) std::abort();
    const auto d = bvhkit::closest_pair(s);
    if (d && (!s.contains(d.a) || !s.contains(d.b))) std::abort();
}

/// A DynamicTree the loader accepts must keep working: queries, moves, a pair step, validate().
template <class T, std::size_t N>
void load_dynamic_tree_and_use(std::span<const std::uint8_t> bytes) {
    try {
        auto tree = bvhkit::dynamic_tree_from_bytes<T, N>(bytes);
        const bvhkit::Aabb<T, N> box(bvhkit::Vec<T, N>(T(-1)), bvhkit::Vec<T, N>(T(1)));
        tree.query(box,
                   [&](bvhkit::ProxyId id) { return tree.contains(id) || (std::abort(), false); });
        for (std::int32_t slot = 0; slot < tree.id_bound() && slot < 8; ++slot)
            if (const bvhkit::ProxyId id = tree.proxy_at(slot); tree.contains(id))
                tree.move(id, box);
        (void)tree.create(box);
        tree.update_pairs([](bvhkit::ProxyId, bvhkit::ProxyId) {},
                          [](bvhkit::ProxyId, bvhkit::ProxyId) {});
        tree.rebuild(false);
        tree.validate();
    } catch (const bvhkit::Error&) {
    }
}

/// A CollisionModel the loader accepts must answer collide, distance and self-collision against
/// itself and a fixed model with triangle indices in range.
template <class V>
void load_collision_model_and_query(std::span<const std::uint8_t> bytes) {
    using T = typename V::Scalar;
    for (const bool validate : {true, false}) {
        try {
            const auto model =
                bvhkit::collision_model_from_bytes<V>(bytes, bvhkit::LoadOptions{validate});
            bvhkit::BasicTriangleMesh<T> two;
            two.vertices = {{T(0), T(0), T(0)},     {T(1), T(0), T(0)},
                            {T(0), T(1), T(0)},     {T(0.2), T(0.2), T(-1)},
                            {T(0.3), T(0.2), T(1)}, {T(0.2), T(0.3), T(1)}};
            two.triangles = {{0, 1, 2}, {3, 4, 5}};
            const bvhkit::CollisionModel<V> other(two);
            const std::size_t n = model.triangle_count();
            bvhkit::Transform<T> pose;
            pose.rotation = bvhkit::rotation_about(bvhkit::Vec<T, 3>(T(0), T(0), T(1)), T(0.3));
            pose.translation = {T(0.1), T(0.2), T(0)};
            bvhkit::CollideResult<T> result;
            for (const auto& p : {bvhkit::Transform<T>{}, pose}) {
                bvhkit::collide(model, other, p, {}, result);
                for (const auto& c : result.contacts)
                    if (c.triangle_a >= n || c.triangle_b >= 2) std::abort();
                bvhkit::collide(model, model, p, {}, result);
                for (const auto& c : result.contacts)
                    if (c.triangle_a >= n || c.triangle_b >= n) std::abort();
                const auto d = bvhkit::distance(model, other, p);
                if (d.distance < std::numeric_limits<T>::infinity() && d.triangle_a >= n)
                    std::abort();
            }
            std::vector<bvhkit::Contact<T>> contacts;
            bvhkit::self_collide(model, contacts);
            for (const auto& c : contacts)
                if (c.triangle_a >= n || c.triangle_b >= n) std::abort();
        } catch (const bvhkit::Error&) {
        }
    }
}

/// Byte 17 is the volume (docs/serialization.md): load as the file says.
template <class T>
void load_collision_model_as_volume(std::span<const std::uint8_t> bytes, std::uint8_t volume) {
    switch (volume) {
        case 1:
            return load_collision_model_and_query<bvhkit::Aabb<T, 3>>(bytes);
        case 3:
            return load_collision_model_and_query<bvhkit::Sphere<T>>(bytes);
        case 4:
            return load_collision_model_and_query<bvhkit::Obb<T>>(bytes);
        case 5:
            return load_collision_model_and_query<bvhkit::Rss<T>>(bytes);
        case 6:
            return load_collision_model_and_query<bvhkit::ObbRss<T>>(bytes);
        case 7:
            return load_collision_model_and_query<bvhkit::Kdop<T, 14>>(bytes);
        case 8:
            return load_collision_model_and_query<bvhkit::Kdop<T, 18>>(bytes);
        case 10:
            return load_collision_model_and_query<bvhkit::ConvexHull<T>>(bytes);
        default:
            return load_collision_model_and_query<bvhkit::Kdop<T, 26>>(bytes);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const std::uint8_t> raw(data, size);
    load_and_query<float>(raw);
    std::vector<std::uint8_t> resealed(raw.begin(), raw.end());
    bvhkit::serial_detail::reseal_tree_file(resealed);
    // Byte 12 is the kind, byte 16 the scalar type: load as the file says, so the fuzzer gets
    // past those checks.
    const bool as_double = size > 16 && data[16] == 2;
    if (size > 16 && data[12] == 2) {
        load_closest_point_mesh_and_query<float>(raw);
        if (as_double)
            load_closest_point_mesh_and_query<double>(resealed);
        else
            load_closest_point_mesh_and_query<float>(resealed);
    } else if (size > 16 && data[12] == 3) {
        load_signed_distance_mesh_and_query<float>(raw);
        if (as_double)
            load_signed_distance_mesh_and_query<double>(resealed);
        else
            load_signed_distance_mesh_and_query<float>(resealed);
    } else if (size > 16 && data[12] == 4) {
        load_winding_number_mesh_and_query<float>(raw);
        if (as_double)
            load_winding_number_mesh_and_query<double>(resealed);
        else
            load_winding_number_mesh_and_query<float>(resealed);
    } else if (size > 17 && data[12] == 5) {
        // Byte 17 is the volume: 2 for a 2D tree.
        const bool flat = data[17] == 2;
        if (flat) load_dynamic_tree_and_use<float, 2>(raw);
        if (flat && as_double) load_dynamic_tree_and_use<double, 2>(resealed);
        if (flat && !as_double) load_dynamic_tree_and_use<float, 2>(resealed);
        if (!flat && as_double) load_dynamic_tree_and_use<double, 3>(resealed);
        if (!flat && !as_double) load_dynamic_tree_and_use<float, 3>(resealed);
    } else if (size > 17 && data[12] == 7) {
        load_scene_and_query<float>(raw);
        if (as_double)
            load_scene_and_query<double>(resealed);
        else
            load_scene_and_query<float>(resealed);
    } else if (size > 17 && data[12] == 6) {
        load_collision_model_and_query<bvhkit::Obb<float>>(raw);
        if (as_double)
            load_collision_model_as_volume<double>(resealed, data[17]);
        else
            load_collision_model_as_volume<float>(resealed, data[17]);
    } else if (as_double) {
        load_and_query<double>(resealed);
    } else {
        load_and_query<float>(resealed);
    }
    return 0;
}

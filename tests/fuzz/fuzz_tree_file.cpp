// libFuzzer target: the TriangleBvh, ClosestPointMesh, SignedDistanceMesh, WindingNumberMesh and
// DynamicTree loaders on arbitrary bytes, as they come and again with the checksum recomputed
// (random bytes almost never carry a valid checksum, and the checks behind it are the ones worth
// fuzzing). A load may throw bvhkit::Error; a structure it accepts, with or without validate(),
// must answer queries with indices in range (ASan and UBSan watch the walks).
#include <cstdlib>
#include <span>
#include <vector>

#include "bvhkit/io/closest_point_mesh_file.hpp"
#include "bvhkit/io/dynamic_tree_file.hpp"
#include "bvhkit/io/signed_distance_mesh_file.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/io/winding_number_mesh_file.hpp"

namespace {

template <class T>
void load_and_query(std::span<const std::uint8_t> bytes) {
    for (const bool validate : {true, false}) {
        try {
            const bvhkit::TriangleBvh<T> tree =
                bvhkit::triangle_bvh_from_bytes<T>(bytes, bvhkit::LoadOptions{validate});
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
        } catch (const bvhkit::Error&) {
            // Rejected cleanly.
        }
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

/// A DynamicTree the loader accepts must keep working: queries, moves, a pair step, validate().
template <class T, std::size_t N>
void load_dynamic_tree_and_use(std::span<const std::uint8_t> bytes) {
    try {
        auto tree = bvhkit::dynamic_tree_from_bytes<T, N>(bytes);
        const bvhkit::Aabb<T, N> box(bvhkit::Vec<T, N>(T(-1)), bvhkit::Vec<T, N>(T(1)));
        tree.query(box,
                   [&](bvhkit::ProxyId id) { return tree.contains(id) || (std::abort(), false); });
        for (bvhkit::ProxyId id = 0; id < tree.id_bound() && id < 8; ++id)
            if (tree.contains(id)) tree.move(id, box);
        (void)tree.create(box);
        tree.update_pairs([](bvhkit::ProxyId, bvhkit::ProxyId) {},
                          [](bvhkit::ProxyId, bvhkit::ProxyId) {});
        tree.rebuild(false);
        tree.validate();
    } catch (const bvhkit::Error&) {
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
    } else if (as_double) {
        load_and_query<double>(resealed);
    } else {
        load_and_query<float>(resealed);
    }
    return 0;
}

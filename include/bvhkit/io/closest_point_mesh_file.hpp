#pragma once
// Saving and loading a ClosestPointMesh (format: docs/serialization.md, kind 2). The file holds the
// binary tree, the slot indices, the triangles' corners in slot order, the triangles left out of
// the tree (so the triangle count is bounded by the file) and the mesh's longest edge (it includes
// finite edges of triangles left out, so it cannot be recomputed from the tree). The wide tree and
// the SIMD packs are rebuilt on load by the code that built them, from the same arrays, so a
// loaded mesh answers bit for bit as the saved one.
//
// Loading checks what a TriangleBvh load checks (envelope, counts before allocation, structure and
// indices always, validate() unless opted out), and that the longest edge is not negative or NaN
// (inf is what a build stores for an edge past T's largest finite value) and not below the
// longest edge of the triangles in the tree.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/io/tree_sections.hpp"
#include "bvhkit/io/tree_structure.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"

namespace bvhkit {

namespace serial_detail {

struct ClosestPointMeshAccess {
    static constexpr const char* file_what = "ClosestPointMesh file";

    // The sections into w; the header to seal them with.
    template <class T>
    static TreeFileHeader put(ByteWriter& w, const ClosestPointMesh<T>& mesh) {
        const auto& bvh = mesh.bvh_;
        const std::size_t slots = bvh.primitive_indices.size();
        // The complement of the slot indices: the triangles left out of the tree.
        std::vector<std::uint8_t> in_tree(mesh.triangle_count_, 0);
        for (const std::uint32_t p : bvh.primitive_indices) in_tree[p] = 1;
        std::vector<std::uint32_t> skipped;
        for (std::size_t i = 0; i < in_tree.size(); ++i)
            if (!in_tree[i]) skipped.push_back(std::uint32_t(i));
        w.reserve(bvh.nodes.size() * node_record_bytes<T> + slots * (4 + 9 * sizeof(T)) + 64);
        put_nodes(w, bvh);
        put_u32s(w, bvh.primitive_indices);
        put_corners(w, std::span<const Triangle<T>>(mesh.tris_.data(), slots));  // no padding
        put_u32s(w, skipped);
        w.scalar(mesh.longest_edge_);
        w.pad(8);
        TreeFileHeader h;
        h.kind = FileKind::ClosestPointMesh;
        h.scalar = scalar_code<T>();
        h.volume = VolumeCode::Aabb3;
        h.layout = 1;  // corners
        h.counts = {bvh.nodes.size(), slots, skipped.size(), mesh.triangle_count_};
        return h;
    }

    template <class T>
    static std::vector<std::uint8_t> save(const ClosestPointMesh<T>& mesh) {
        ByteWriter w;
        const TreeFileHeader h = put(w, mesh);
        return seal_tree_file(h, w.bytes());
    }

    template <class T>
    static ClosestPointMesh<T> load(std::span<const std::uint8_t> file,
                                    const LoadOptions& options) {
        const OpenedTreeFile f = open_tree_file(file, FileKind::ClosestPointMesh, file_what);
        ByteReader r(f.payload, file_what);
        return get<T>(f.header, r, options, true, file_what);
    }

    // Reads the sections put() wrote; `whole` says they fill the payload (else more follow).
    template <class T>
    static ClosestPointMesh<T> get(const TreeFileHeader& h, ByteReader& r,
                                   const LoadOptions& options, bool whole, const char* what) {
        const auto fail = [&](const std::string& m) { throw Error(std::string(what) + ": " + m); };
        check_scalar_and_volume<T>(h, what);
        if (h.layout != 1) fail("unknown triangle layout " + std::to_string(int(h.layout)));
        check_tree_counts(h, node_record_bytes<T>, 9 * sizeof(T), 8, what, whole);
        const auto [node_count, slot_count, skipped_count, triangle_count] = h.counts;

        ClosestPointMesh<T> mesh;
        auto& bvh = mesh.bvh_;
        get_nodes(r, bvh, node_count);
        get_u32s(r, bvh.primitive_indices, slot_count);
        get_corners(r, mesh.tris_, slot_count);
        std::vector<std::uint32_t> skipped;
        get_u32s(r, skipped, skipped_count);
        mesh.longest_edge_ = r.scalar<T>();
        r.skip_padding(8);

        check_tree_structure(bvh, triangle_count, what);
        check_skipped(skipped, triangle_count, what);
        // +inf is what a build stores for an edge longer than T's largest finite value.
        if (!(mesh.longest_edge_ >= T(0))) fail("the longest edge is negative or NaN");
        if (options.validate) {
            validate_loaded(
                bvh_view(bvh), std::size_t(triangle_count), skipped,
                [&](std::uint32_t s, const auto&) { return mesh.tris_[s].bounds(); }, what);
            // As build() measures edges (longest_edge_of, which cannot overflow), over the
            // tree's triangles only: the file's may be longer. The build rounds up by a relative
            // 1e-6, so the stored value is at least the edge itself, whatever the rounding.
            double longest = 0;
            for (const Triangle<T>& t : mesh.tris_)
                longest = std::max(longest, ClosestPointMesh<T>::longest_edge_of(t));
            if (!(double(mesh.longest_edge_) >= longest))
                fail("the longest edge is shorter than an edge in the tree");
        }
        mesh.tris_.push_back(Triangle<T>{});  // the padding the SSE box test reads past
        mesh.triangle_count_ = std::size_t(triangle_count);
        mesh.derive_walk_data();
        return mesh;
    }
};

}  // namespace serial_detail

/// The mesh's search structure as a file's bytes.
template <class T>
std::vector<std::uint8_t> to_bytes(const ClosestPointMesh<T>& mesh) {
    return serial_detail::ClosestPointMeshAccess::save(mesh);
}

template <class T>
void save(const ClosestPointMesh<T>& mesh, const std::filesystem::path& path) {
    serial_detail::write_file_bytes(path, to_bytes(mesh));
}

/// A ClosestPointMesh from bytes written by to_bytes / save; the scalar type must match the file's.
template <class T>
ClosestPointMesh<T> closest_point_mesh_from_bytes(std::span<const std::uint8_t> bytes,
                                                  const LoadOptions& options = {}) {
    return serial_detail::ClosestPointMeshAccess::load<T>(bytes, options);
}

template <class T>
ClosestPointMesh<T> load_closest_point_mesh(const std::filesystem::path& path,
                                            const LoadOptions& options = {}) {
    return serial_detail::load_file(path, [&](std::span<const std::uint8_t> bytes) {
        return closest_point_mesh_from_bytes<T>(bytes, options);
    });
}

}  // namespace bvhkit

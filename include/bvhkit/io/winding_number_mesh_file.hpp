#pragma once
// Saving and loading a WindingNumberMesh (format: docs/serialization.md, kind 4): the binary tree,
// slot indices, corners in slot order and the absent triangles, as in a ClosestPointMesh file
// without the longest edge. The per-node expansions (dipoles and moments) are not stored: the load
// derives them again from the tree and triangles with the code that built them, so they answer
// bit for bit and a file cannot carry forged ones. A WindingNumberMesh keeps no triangle count,
// so the file's triangle count is one past the largest index in the tree and "skipped" lists the
// absent indices below it.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/io/tree_sections.hpp"
#include "bvhkit/io/tree_structure.hpp"
#include "bvhkit/query/winding_number.hpp"

namespace bvhkit {

namespace serial_detail {

struct WindingNumberMeshAccess {
    static constexpr const char* what = "WindingNumberMesh file";

    template <class T>
    static std::vector<std::uint8_t> save(const WindingNumberMesh<T>& mesh) {
        const auto& bvh = mesh.bvh_;
        const auto& ids = bvh.primitive_indices;
        const std::size_t count =
            ids.empty() ? 0 : std::size_t(*std::max_element(ids.begin(), ids.end())) + 1;
        std::vector<std::uint8_t> in_tree(count, 0);
        for (const std::uint32_t p : ids) in_tree[p] = 1;
        std::vector<std::uint32_t> skipped;
        for (std::size_t i = 0; i < count; ++i)
            if (!in_tree[i]) skipped.push_back(std::uint32_t(i));
        ByteWriter w;
        w.reserve(bvh.nodes.size() * node_record_bytes<T> + ids.size() * (4 + 9 * sizeof(T)) + 32);
        put_nodes(w, bvh);
        put_u32s(w, ids);
        put_corners<T>(w, mesh.tris_);
        put_u32s(w, skipped);
        TreeFileHeader h;
        h.kind = FileKind::WindingNumberMesh;
        h.scalar = scalar_code<T>();
        h.volume = VolumeCode::Aabb3;
        h.layout = 1;  // corners
        h.counts = {bvh.nodes.size(), ids.size(), skipped.size(), count};
        return seal_tree_file(h, w.bytes());
    }

    template <class T>
    static WindingNumberMesh<T> load(std::span<const std::uint8_t> file,
                                     const LoadOptions& options) {
        const OpenedTreeFile f = open_tree_file(file, FileKind::WindingNumberMesh, what);
        const TreeFileHeader& h = f.header;
        check_scalar_and_volume<T>(h, what);
        if (h.layout != 1)
            throw Error(std::string(what) + ": unknown triangle layout " +
                        std::to_string(int(h.layout)));
        check_tree_counts(h, node_record_bytes<T>, 9 * sizeof(T), 0, what);
        const auto [node_count, slot_count, skipped_count, triangle_count] = h.counts;
        ByteReader r(f.payload, what);
        WindingNumberMesh<T> mesh;
        get_nodes(r, mesh.bvh_, node_count);
        get_u32s(r, mesh.bvh_.primitive_indices, slot_count);
        get_corners(r, mesh.tris_, slot_count);
        std::vector<std::uint32_t> skipped;
        get_u32s(r, skipped, skipped_count);
        check_tree_structure(mesh.bvh_, triangle_count, what);
        check_skipped(skipped, triangle_count, what);
        if (options.validate)
            validate_loaded(
                bvh_view(mesh.bvh_), std::size_t(triangle_count), skipped,
                [&](std::uint32_t s, const auto&) { return mesh.tris_[s].bounds(); }, what);
        mesh.derive_dipoles();
        return mesh;
    }
};

}  // namespace serial_detail

template <class T>
std::vector<std::uint8_t> to_bytes(const WindingNumberMesh<T>& mesh) {
    return serial_detail::WindingNumberMeshAccess::save(mesh);
}

template <class T>
void save(const WindingNumberMesh<T>& mesh, const std::filesystem::path& path) {
    serial_detail::write_file_bytes(path, to_bytes(mesh));
}

/// A WindingNumberMesh from bytes written by to_bytes / save; the scalar type must match.
template <class T>
WindingNumberMesh<T> winding_number_mesh_from_bytes(std::span<const std::uint8_t> bytes,
                                                    const LoadOptions& options = {}) {
    return serial_detail::WindingNumberMeshAccess::load<T>(bytes, options);
}

template <class T>
WindingNumberMesh<T> load_winding_number_mesh(const std::filesystem::path& path,
                                              const LoadOptions& options = {}) {
    return serial_detail::load_file(path, [&](std::span<const std::uint8_t> bytes) {
        return winding_number_mesh_from_bytes<T>(bytes, options);
    });
}

}  // namespace bvhkit

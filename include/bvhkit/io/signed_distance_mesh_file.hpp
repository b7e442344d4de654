#pragma once
// Saving and loading a SignedDistanceMesh (format: docs/serialization.md, kind 3): the sections of
// a ClosestPointMesh file, then the sign data as built (welded vertex count, unit face normals,
// edge pseudonormals, vertex pseudonormals, welded corner ids), stored as they are, so a loaded
// mesh answers bit for bit as the saved one. Loading checks the ClosestPointMesh part as that
// loader does, every array size against the bytes left before allocating it, and every corner id
// against the vertex count (always: the sign lookup indexes with them).
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/io/closest_point_mesh_file.hpp"
#include "bvhkit/query/signed_distance.hpp"

namespace bvhkit {

namespace serial_detail {

struct SignedDistanceMeshAccess {
    static constexpr const char* what = "SignedDistanceMesh file";

    template <class T>
    static std::vector<std::uint8_t> save(const SignedDistanceMesh<T>& m) {
        ByteWriter w;
        TreeFileHeader h = ClosestPointMeshAccess::put(w, m.closest_);
        h.kind = FileKind::SignedDistanceMesh;
        w.u64(m.vertex_normals_.size());
        for (const auto& n : m.face_normals_) put_vec(w, n);
        w.pad(8);
        for (const auto& e : m.edge_normals_)
            for (const auto& n : e) put_vec(w, n);
        w.pad(8);
        for (const auto& n : m.vertex_normals_) put_vec(w, n);
        w.pad(8);
        for (const auto& c : m.corners_)
            for (const std::uint32_t id : c) w.u32(id);
        w.pad(8);
        return seal_tree_file(h, w.bytes());
    }

    template <class T>
    static SignedDistanceMesh<T> load(std::span<const std::uint8_t> file,
                                      const LoadOptions& options) {
        const OpenedTreeFile f = open_tree_file(file, FileKind::SignedDistanceMesh, what);
        ByteReader r(f.payload, what);
        SignedDistanceMesh<T> m;
        m.closest_ = ClosestPointMeshAccess::get<T>(f.header, r, options, false, what);
        const std::uint64_t nt = f.header.counts[3], nv = r.u64();
        const std::uint64_t left = r.remaining(), S = sizeof(T);
        const std::uint64_t need = section_bytes(nt, 3 * S, left, what, "face normal") +
                                   section_bytes(nt, 9 * S, left, what, "edge normal") +
                                   section_bytes(nv, 3 * S, left, what, "vertex normal") +
                                   section_bytes(nt, 12, left, what, "corner");
        if (need != left)
            throw Error(std::string(what) + ": the sign data needs " + std::to_string(need) +
                        " bytes, the file has " + std::to_string(left));
        m.face_normals_.resize(std::size_t(nt));
        for (auto& n : m.face_normals_) n = get_vec<T>(r);
        r.skip_padding(8);
        m.edge_normals_.resize(std::size_t(nt));
        for (auto& e : m.edge_normals_)
            for (auto& n : e) n = get_vec<T>(r);
        r.skip_padding(8);
        m.vertex_normals_.resize(std::size_t(nv));
        for (auto& n : m.vertex_normals_) n = get_vec<T>(r);
        r.skip_padding(8);
        m.corners_.resize(std::size_t(nt));
        for (auto& c : m.corners_)
            for (std::uint32_t& id : c) {
                id = r.u32();
                if (id >= nv)
                    r.fail("corner names welded vertex " + std::to_string(id) + " of " +
                           std::to_string(nv));
            }
        r.skip_padding(8);
        return m;
    }
};

}  // namespace serial_detail

template <class T>
std::vector<std::uint8_t> to_bytes(const SignedDistanceMesh<T>& mesh) {
    return serial_detail::SignedDistanceMeshAccess::save(mesh);
}

template <class T>
void save(const SignedDistanceMesh<T>& mesh, const std::filesystem::path& path) {
    serial_detail::write_file_bytes(path, to_bytes(mesh));
}

/// A SignedDistanceMesh from bytes written by to_bytes / save; the scalar type must match.
template <class T>
SignedDistanceMesh<T> signed_distance_mesh_from_bytes(std::span<const std::uint8_t> bytes,
                                                      const LoadOptions& options = {}) {
    return serial_detail::SignedDistanceMeshAccess::load<T>(bytes, options);
}

template <class T>
SignedDistanceMesh<T> load_signed_distance_mesh(const std::filesystem::path& path,
                                                const LoadOptions& options = {}) {
    return serial_detail::load_file(path, [&](std::span<const std::uint8_t> bytes) {
        return signed_distance_mesh_from_bytes<T>(bytes, options);
    });
}

}  // namespace bvhkit

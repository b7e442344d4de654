#pragma once
// Stanford PLY reader: ascii, binary_little_endian and binary_big_endian. Vertex x, y, z may have
// any scalar type; triangles come from a `face` element's list property `vertex_indices` (or
// `vertex_index`), polygons split into fans, and/or a `tristrips` element's list `vertex_indices`
// (strips with -1 restarts; odd triangles of a strip swap their first two corners; triangles with a
// repeated corner are dropped). Other properties and elements are skipped. Counts in the header are
// checked against the bytes left before anything is allocated. Malformed input is a bvhkit::Error
// naming the file and the line (ascii) or byte offset (binary).
#include <filesystem>
#include <string_view>

#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit {

TriangleMesh read_ply(const std::filesystem::path& path);
/// Parses PLY bytes held in memory; `name` stands for the file in error messages.
TriangleMesh read_ply(std::string_view bytes, std::string_view name);

}  // namespace bvhkit

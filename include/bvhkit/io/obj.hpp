#pragma once
// Wavefront OBJ reader. Reads `v` and `f` statements (f in the forms v, v/vt, v//vn, v/vt/vn, with
// negative indices relative to the vertices read so far); polygons are split into fans
// (v0,v1,v2), (v0,v2,v3), ... in file order. Texture coordinates, normals, groups, materials, lines
// and points are ignored; an unknown statement, a face with fewer than 3 vertices, an index of 0 or
// out of range, or a file without triangles is a bvhkit::Error naming the file and the line.
// Non-finite vertex coordinates (nan, inf) are kept as data.
#include <filesystem>
#include <string_view>

#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit {

TriangleMesh read_obj(const std::filesystem::path& path);
/// Parses OBJ text held in memory; `name` stands for the file in error messages.
TriangleMesh read_obj(std::string_view bytes, std::string_view name);

}  // namespace bvhkit

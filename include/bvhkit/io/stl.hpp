#pragma once
// STL reader, ascii and binary. Binary is recognised by its size (84 + 50 * count bytes), not by
// the header's first word, since binary headers may also begin with "solid". STL shares no
// vertices: each triangle gets its own 3 vertices, in file order (no welding). Malformed input is a
// bvhkit::Error naming the file and the line (ascii) or byte offset (binary).
#include <filesystem>
#include <string_view>

#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit {

TriangleMesh read_stl(const std::filesystem::path& path);
/// Parses STL bytes held in memory; `name` stands for the file in error messages.
TriangleMesh read_stl(std::string_view bytes, std::string_view name);

}  // namespace bvhkit

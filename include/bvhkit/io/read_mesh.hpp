#pragma once
// read_mesh: reads an .obj, .ply or .stl file, choosing the reader by the extension
// (case-insensitive). Another extension is a bvhkit::Error.
#include <filesystem>
#include <string_view>

#include "bvhkit/io/obj.hpp"
#include "bvhkit/io/ply.hpp"
#include "bvhkit/io/stl.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit {

TriangleMesh read_mesh(const std::filesystem::path& path);
/// Parses bytes held in memory, choosing the format by the extension of `name`.
TriangleMesh read_mesh(std::string_view bytes, std::string_view name);

/// True for the extensions read_mesh knows (".obj", ".ply", ".stl", any case).
bool is_mesh_file_extension(std::string_view extension);

}  // namespace bvhkit

#include "bvhkit/mesh/load_mesh.hpp"

#include <filesystem>
#include <string>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"

namespace bvhkit {

TriangleMesh load_mesh(std::string_view file_or_spec) {
    const std::filesystem::path path{std::string(file_or_spec)};
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) return read_mesh(path);
    if (std::filesystem::is_directory(path, ec))
        throw Error("mesh '" + std::string(file_or_spec) + "' is a directory, not a mesh file");
    if (std::filesystem::exists(path, ec))
        throw Error("mesh '" + std::string(file_or_spec) + "' is not a regular file");
    if (is_procedural_kind(file_or_spec)) return make_procedural(file_or_spec);
    const std::string arg(file_or_spec);
    if (is_mesh_file_extension(path.extension().string()))
        throw FileNotFoundError("mesh file '" + arg + "' does not exist");
    throw Error("'" + arg +
                "' is neither an existing mesh file (.obj, .ply, .stl) nor a generator spec "
                "kind[:key=value,...] with one of these kinds:\n" +
                procedural_spec_help());
}

}  // namespace bvhkit

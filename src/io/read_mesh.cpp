#include "bvhkit/io/read_mesh.hpp"

#include "io_detail.hpp"

namespace bvhkit {

namespace {

enum class MeshFormat { obj, ply, stl, unknown };

// `ext` is lower-case with its dot.
MeshFormat format_of(std::string_view ext) {
    if (ext == ".obj") return MeshFormat::obj;
    if (ext == ".ply") return MeshFormat::ply;
    if (ext == ".stl") return MeshFormat::stl;
    return MeshFormat::unknown;
}

[[noreturn]] void unknown_extension(std::string_view name, const std::string& ext) {
    throw Error("cannot read '" + std::string(name) + "': unknown mesh file extension '" + ext +
                "' (known: .obj, .ply, .stl)");
}

}  // namespace

bool is_mesh_file_extension(std::string_view extension) {
    std::string ext(extension);
    for (char& c : ext)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return format_of(ext) != MeshFormat::unknown;
}

TriangleMesh read_mesh(const std::filesystem::path& path) {
    const std::string ext = io_detail::lower_extension(path.string());
    switch (format_of(ext)) {
        case MeshFormat::obj:
            return read_obj(path);
        case MeshFormat::ply:
            return read_ply(path);
        case MeshFormat::stl:
            return read_stl(path);
        case MeshFormat::unknown:
            break;
    }
    unknown_extension(path.string(), ext);
}

TriangleMesh read_mesh(std::string_view bytes, std::string_view name) {
    const std::string ext = io_detail::lower_extension(name);
    switch (format_of(ext)) {
        case MeshFormat::obj:
            return read_obj(bytes, name);
        case MeshFormat::ply:
            return read_ply(bytes, name);
        case MeshFormat::stl:
            return read_stl(bytes, name);
        case MeshFormat::unknown:
            break;
    }
    unknown_extension(name, ext);
}

}  // namespace bvhkit

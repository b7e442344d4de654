#pragma once
// Shared by the fuzz targets: a reader may accept the input (then the mesh must be usable) or throw
// bvhkit::Error; anything else (another exception, a crash, a sanitizer report) is a finding.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::fuzz {

template <class Reader>
int check_reader(const std::uint8_t* data, std::size_t size, std::string_view name, Reader read) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    try {
        const TriangleMesh mesh = read(bytes, name);
        for (const auto& t : mesh.triangles)
            for (const std::uint32_t i : t)
                if (i >= mesh.vertices.size()) std::abort();  // an index the reader let through
    } catch (const Error&) {
        // Rejected cleanly.
    }
    return 0;
}

}  // namespace bvhkit::fuzz

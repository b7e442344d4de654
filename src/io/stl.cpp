#include "bvhkit/io/stl.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

#include "io_detail.hpp"

namespace bvhkit {

namespace {

using io_detail::fail;
using io_detail::fail_at_line;
using io_detail::fail_at_offset;
using io_detail::quote_token;

constexpr std::size_t binary_header_size = 84;    // 80-byte comment + uint32 triangle count
constexpr std::size_t binary_triangle_size = 50;  // normal, 3 corners (12 float32), uint16

template <class T>
T load_le(const char* p) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, p, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + sizeof(T));
    T v;
    std::memcpy(&v, raw, sizeof(T));
    return v;
}

TriangleMesh read_binary(std::string_view bytes, std::uint64_t count, std::string_view name) {
    // Each triangle brings 3 unshared vertices, and vertex indices are 32-bit.
    if (count > io_detail::max_count_u32 / 3)
        fail_at_offset(
            name, 80,
            "triangle count " + std::to_string(count) + " needs more than 2^32-1 vertices");
    TriangleMesh mesh;
    mesh.vertices.resize(static_cast<std::size_t>(count) * 3);
    mesh.triangles.resize(static_cast<std::size_t>(count));
    const char* p = bytes.data() + binary_header_size;
    for (std::size_t t = 0; t < count; ++t, p += binary_triangle_size) {
        for (std::size_t c = 0; c < 3; ++c) {
            Vec3f& v = mesh.vertices[3 * t + c];
            for (std::size_t axis = 0; axis < 3; ++axis)
                v[axis] = load_le<float>(p + 12 + 12 * c + 4 * axis);
        }
        const auto first = static_cast<std::uint32_t>(3 * t);
        mesh.triangles[t] = {first, first + 1, first + 2};
    }
    io_detail::require_triangles(mesh, name);
    return mesh;
}

class AsciiStl {
  public:
    AsciiStl(std::string_view bytes, std::string_view name) : cursor_(bytes), name_(name) {}

    TriangleMesh parse() {
        expect("solid");
        cursor_.rest_of_line();  // the solid's name
        for (;;) {
            const std::string_view keyword = cursor_.next();
            if (keyword == "endsolid") {
                cursor_.rest_of_line();
                if (cursor_.at_end()) break;
                // Some tools concatenate several solids in one file.
                expect("solid");
                cursor_.rest_of_line();
            } else if (keyword == "facet") {
                read_facet();
            } else if (keyword.empty()) {
                fail_at_line(name_, cursor_.line(), "the file ends before 'endsolid'");
            } else {
                fail_at_line(name_, cursor_.line(),
                             "expected 'facet' or 'endsolid', found " + quote_token(keyword));
            }
        }
        io_detail::require_triangles(mesh_, name_);
        return std::move(mesh_);
    }

  private:
    void expect(std::string_view word) {
        const std::string_view token = cursor_.next();
        if (token != word)
            fail_at_line(
                name_, cursor_.line(),
                "expected '" + std::string(word) + "', found " +
                    (token.empty() ? std::string("the end of the file") : quote_token(token)));
    }
    float number() {
        const std::string_view token = cursor_.next();
        float v = 0;
        if (!io_detail::parse_float(token, v))
            fail_at_line(name_, cursor_.line(),
                         token.empty() ? std::string("the file ends inside a facet")
                                       : "value " + quote_token(token) + " is not a number");
        return v;
    }
    void read_facet() {
        expect("normal");
        for (int i = 0; i < 3; ++i) number();  // normals are recomputed from the corners by users
        expect("outer");
        expect("loop");
        if (mesh_.vertices.size() + 3 > io_detail::max_count_u32)
            fail_at_line(name_, cursor_.line(), "more than 2^32-1 vertices");
        const auto first = static_cast<std::uint32_t>(mesh_.vertices.size());
        for (int c = 0; c < 3; ++c) {
            expect("vertex");
            Vec3f v;
            for (std::size_t axis = 0; axis < 3; ++axis) v[axis] = number();
            mesh_.vertices.push_back(v);
        }
        expect("endloop");
        expect("endfacet");
        mesh_.triangles.push_back({first, first + 1, first + 2});
    }

    io_detail::TextCursor cursor_;
    std::string_view name_;
    TriangleMesh mesh_;
};

bool starts_with_solid(std::string_view bytes) {
    std::size_t i = 0;
    while (i < bytes.size() && io_detail::is_space(bytes[i])) ++i;
    return bytes.substr(i, 5) == "solid" &&
           (i + 5 == bytes.size() || io_detail::is_space(bytes[i + 5]));
}

}  // namespace

TriangleMesh read_stl(std::string_view bytes, std::string_view name) {
    if (bytes.empty()) fail(name, "the file is empty");
    // Binary when the size matches the count exactly; a binary header may start with "solid" too.
    std::uint64_t count = 0;
    std::uint64_t binary_size = 0;
    if (bytes.size() >= binary_header_size) {
        count = load_le<std::uint32_t>(bytes.data() + 80);
        binary_size = binary_header_size + binary_triangle_size * count;
        if (binary_size == bytes.size()) return read_binary(bytes, count, name);
    }
    if (starts_with_solid(bytes)) {
        // Binary headers often begin with "solid" too, and some writers pad the file after the
        // triangles: when the binary layout fits (trailing bytes allowed), a file that is not
        // valid ASCII STL is read as binary. ASCII STL is text, so its bytes 80..83 read as a
        // count of at least 0x09090909 triangles: only a file of over 7 GB could be misread.
        const bool binary_fits = bytes.size() >= binary_header_size && binary_size <= bytes.size();
        if (!binary_fits) return AsciiStl(bytes, name).parse();
        try {
            return AsciiStl(bytes, name).parse();
        } catch (const Error&) {
            return read_binary(bytes, count, name);
        }
    }
    if (bytes.size() < binary_header_size)
        fail(name, "not an ascii STL (no 'solid') and too short (" + std::to_string(bytes.size()) +
                       " bytes) for a binary STL's 84-byte header");
    // Tolerate trailing bytes after the triangles (some writers pad), never fewer than claimed.
    if (binary_size > bytes.size())
        fail_at_offset(name, 80,
                       "binary STL claims " + std::to_string(count) + " triangles (" +
                           std::to_string(binary_size) + " bytes) but the file has " +
                           std::to_string(bytes.size()) + " bytes (truncated file?)");
    return read_binary(bytes, count, name);
}

TriangleMesh read_stl(const std::filesystem::path& path) {
    const std::string bytes = io_detail::read_file_bytes(path);
    return read_stl(bytes, path.string());
}

}  // namespace bvhkit

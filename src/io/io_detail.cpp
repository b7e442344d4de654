#include "io_detail.hpp"

#include "bvhkit/io/file_access.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace bvhkit::io_detail {

std::string read_file_bytes(const std::filesystem::path& path) {
    return file_detail::read_regular_file<std::string>(path, "mesh file");
}

std::string quote_token(std::string_view token) {
    constexpr std::size_t max_shown = 40;
    std::string out = "'";
    for (std::size_t i = 0; i < token.size() && i < max_shown; ++i) {
        const auto c = static_cast<unsigned char>(token[i]);
        if (c >= 0x20 && c < 0x7f) {
            out += static_cast<char>(c);
        } else {
            char hex[8];
            std::snprintf(hex, sizeof hex, "\\x%02x", c);
            out += hex;
        }
    }
    if (token.size() > max_shown) out += "...";
    return out + "'";
}

void fail_at_line(std::string_view name, std::size_t line, const std::string& what) {
    throw Error(std::string(name) + ":" + std::to_string(line) + ": " + what);
}
void fail_at_offset(std::string_view name, std::size_t offset, const std::string& what) {
    throw Error(std::string(name) + ": byte " + std::to_string(offset) + ": " + what);
}
void fail(std::string_view name, const std::string& what) {
    throw Error(std::string(name) + ": " + what);
}

namespace {

// from_chars leaves the value untouched on overflow/underflow; strtod's answer (+-inf or a tiny
// value) is what a reader of the file would expect, so the rare out-of-range token takes that path.
template <class T>
bool parse_real(std::string_view token, T& out) {
    const char* first = token.data();
    const char* last = first + token.size();
    if (first != last && *first == '+') {
        ++first;
        if (first != last && (*first == '-' || *first == '+')) return false;
    }
    if (first == last) return false;
    const auto [ptr, ec] = std::from_chars(first, last, out, std::chars_format::general);
    if (ptr != last) return false;
    if (ec == std::errc()) return true;
    if (ec != std::errc::result_out_of_range) return false;
    const std::string copy(first, last);
    if constexpr (std::is_same_v<T, float>) {
        out = std::strtof(copy.c_str(), nullptr);
    } else {
        out = std::strtod(copy.c_str(), nullptr);
    }
    return true;
}

}  // namespace

bool parse_float(std::string_view token, float& out) {
    return parse_real(token, out);
}
bool parse_double(std::string_view token, double& out) {
    return parse_real(token, out);
}

void require_triangles(const TriangleMesh& mesh, std::string_view name) {
    if (mesh.triangles.empty()) fail(name, "the file contains no triangles");
}

std::string lower_extension(std::string_view name) {
    const std::size_t slash = name.find_last_of("/\\");
    const std::size_t dot = name.rfind('.');
    if (dot == std::string_view::npos || (slash != std::string_view::npos && dot < slash))
        return {};
    std::string ext(name.substr(dot));
    for (char& c : ext)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return ext;
}

}  // namespace bvhkit::io_detail

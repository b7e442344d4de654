#pragma once
// Helpers shared by the mesh readers (private to src/io): reading a whole file, error messages that
// name the file and the line or byte offset, number parsing with std::from_chars, and a whitespace
// token cursor for the text formats.
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>

#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::io_detail {

/// The whole file as bytes; an Error naming the path when it cannot be opened or read.
std::string read_file_bytes(const std::filesystem::path& path);

/// A token for an error message: quote_token, at most 40 characters, non-printable bytes as \xNN.
std::string quote_token(std::string_view token);

[[noreturn]] void fail_at_line(std::string_view name, std::size_t line, const std::string& what);
[[noreturn]] void fail_at_offset(std::string_view name, std::size_t offset,
                                 const std::string& what);
[[noreturn]] void fail(std::string_view name, const std::string& what);

/// Parses the whole token as a float (leading '+' allowed; inf and nan accepted as data; values
/// beyond float's range become +-inf or 0 as strtof would give). False if it is not a number.
bool parse_float(std::string_view token, float& out);
bool parse_double(std::string_view token, double& out);

/// Parses the whole token as a signed 64-bit integer (leading '+' allowed). False otherwise.
inline bool parse_int(std::string_view token, std::int64_t& out) {
    const char* first = token.data();
    const char* last = first + token.size();
    if (first != last && *first == '+') {
        ++first;
        if (first != last && *first == '-') return false;
    }
    if (first == last) return false;
    const auto [ptr, ec] = std::from_chars(first, last, out);
    return ec == std::errc() && ptr == last;
}

inline bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

/// Whitespace-separated tokens of a text file, counting lines (1-based) for messages.
class TextCursor {
  public:
    TextCursor(std::string_view text, std::size_t first_line = 1)
        : text_(text), line_(first_line) {}

    /// The next token, or an empty view at the end of the text.
    std::string_view next() {
        skip_space();
        const std::size_t start = pos_;
        while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
        return text_.substr(start, pos_ - start);
    }
    /// The rest of the current line (without the newline), moving past the newline.
    std::string_view rest_of_line() {
        const std::size_t start = pos_;
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
        std::string_view rest = text_.substr(start, pos_ - start);
        if (pos_ < text_.size()) {
            ++pos_;
            ++line_;
        }
        return rest;
    }
    bool at_end() {
        skip_space();
        return pos_ >= text_.size();
    }
    /// Line of the last token returned (or of the cursor before any token).
    std::size_t line() const { return line_; }
    std::size_t remaining_bytes() const { return text_.size() - pos_; }

  private:
    void skip_space() {
        while (pos_ < text_.size() && is_space(text_[pos_])) {
            if (text_[pos_] == '\n') ++line_;
            ++pos_;
        }
    }
    std::string_view text_;
    std::size_t pos_ = 0;
    std::size_t line_;
};

inline constexpr std::uint64_t max_count_u32 = std::numeric_limits<std::uint32_t>::max();

/// The readers' shared last check: a mesh without triangles is an Error (nothing to build on).
void require_triangles(const TriangleMesh& mesh, std::string_view name);

/// Lower-case extension of a file name with its dot (".obj"), empty when there is none.
std::string lower_extension(std::string_view name);

}  // namespace bvhkit::io_detail

#include "bvhkit/io/obj.hpp"

#include <cstring>
#include <vector>

#include "io_detail.hpp"

namespace bvhkit {

namespace {

using io_detail::fail_at_line;
using io_detail::quote_token;

// Statements of the OBJ specification that carry nothing a triangle mesh needs.
constexpr std::string_view ignored_statements[] = {
    "vt",        "vn",     "vp",       "l",        "p",    "o",      "g",      "s",
    "usemtl",    "mtllib", "cstype",   "deg",      "bmat", "step",   "curv",   "curv2",
    "surf",      "parm",   "trim",     "hole",     "scrv", "sp",     "end",    "con",
    "mg",        "bevel",  "c_interp", "d_interp", "lod",  "maplib", "usemap", "shadow_obj",
    "trace_obj", "ctech",  "stech",    "call",     "csh"};

bool is_ignored_statement(std::string_view keyword) {
    for (const std::string_view s : ignored_statements)
        if (s == keyword) return true;
    return false;
}

// Tokens of one line; a '#' at the start of a token ends the line (trailing comment).
class LineTokens {
  public:
    explicit LineTokens(std::string_view line) : line_(line) {}
    std::string_view next() {
        while (pos_ < line_.size() && io_detail::is_space(line_[pos_])) ++pos_;
        if (pos_ < line_.size() && line_[pos_] == '#') pos_ = line_.size();
        const std::size_t start = pos_;
        while (pos_ < line_.size() && !io_detail::is_space(line_[pos_])) ++pos_;
        return line_.substr(start, pos_ - start);
    }

  private:
    std::string_view line_;
    std::size_t pos_ = 0;
};

class ObjParser {
  public:
    ObjParser(std::string_view bytes, std::string_view name) : bytes_(bytes), name_(name) {}

    TriangleMesh parse() {
        // A typical line is 20-40 bytes; reserving avoids most regrowth on large files.
        mesh_.vertices.reserve(bytes_.size() / 64);
        mesh_.triangles.reserve(bytes_.size() / 64);
        std::size_t pos = 0;
        // Some Windows tools start text files with a UTF-8 byte order mark.
        if (bytes_.starts_with("\xEF\xBB\xBF")) pos = 3;
        while (pos < bytes_.size()) {
            const void* nl = std::memchr(bytes_.data() + pos, '\n', bytes_.size() - pos);
            const std::size_t end =
                nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - bytes_.data())
                   : bytes_.size();
            ++line_;
            parse_line(bytes_.substr(pos, end - pos));
            pos = end + 1;
        }
        if (max_positive_index_ > mesh_.vertices.size())
            fail_at_line(name_, max_index_line_,
                         "face index " + std::to_string(max_positive_index_) +
                             " is out of range (the file has " +
                             std::to_string(mesh_.vertices.size()) + " vertices)");
        io_detail::require_triangles(mesh_, name_);
        return std::move(mesh_);
    }

  private:
    void parse_line(std::string_view line) {
        LineTokens tokens(line);
        const std::string_view keyword = tokens.next();
        if (keyword.empty()) return;
        if (keyword == "v") {
            parse_vertex(tokens);
        } else if (keyword == "f") {
            parse_face(tokens);
        } else if (!is_ignored_statement(keyword)) {
            fail_at_line(name_, line_, "unknown statement " + quote_token(keyword));
        }
    }

    void parse_vertex(LineTokens& tokens) {
        Vec3f p;
        for (int axis = 0; axis < 3; ++axis) {
            const std::string_view token = tokens.next();
            if (token.empty()) fail_at_line(name_, line_, "vertex has fewer than 3 coordinates");
            if (!io_detail::parse_float(token, p[axis]))
                fail_at_line(name_, line_,
                             "vertex coordinate " + quote_token(token) + " is not a number");
        }
        // Further numbers (w, or the r g b some exporters append) are ignored.
        if (mesh_.vertices.size() >= io_detail::max_count_u32)
            fail_at_line(name_, line_, "more than 2^32-1 vertices");
        mesh_.vertices.push_back(p);
    }

    void parse_face(LineTokens& tokens) {
        corners_.clear();
        for (std::string_view token = tokens.next(); !token.empty(); token = tokens.next())
            corners_.push_back(resolve_index(token));
        if (corners_.size() < 3)
            fail_at_line(
                name_, line_,
                "face has " + std::to_string(corners_.size()) + " vertices; at least 3 are needed");
        for (std::size_t k = 1; k + 1 < corners_.size(); ++k) {
            if (mesh_.triangles.size() >= io_detail::max_count_u32)
                fail_at_line(name_, line_, "more than 2^32-1 triangles");
            mesh_.triangles.push_back({corners_[0], corners_[k], corners_[k + 1]});
        }
    }

    // One face corner "v", "v/vt", "v//vn" or "v/vt/vn": the vertex index, 0-based.
    std::uint32_t resolve_index(std::string_view token) {
        const std::size_t slash = token.find('/');
        const std::string_view index_text = token.substr(0, slash);
        std::int64_t index = 0;
        if (!io_detail::parse_int(index_text, index))
            fail_at_line(name_, line_, "face index " + quote_token(token) + " is not an integer");
        if (slash != std::string_view::npos) {
            for (const char c : token.substr(slash))
                if (!(c == '/' || c == '-' || c == '+' || (c >= '0' && c <= '9')))
                    fail_at_line(name_, line_,
                                 "face corner " + quote_token(token) + " is malformed");
        }
        if (index == 0) fail_at_line(name_, line_, "face index 0 (OBJ indices start at 1)");
        if (index < 0) {
            // Relative: -1 is the last vertex read so far.
            // Compared as index < -count: negating the index would overflow at INT64_MIN.
            const auto count = static_cast<std::int64_t>(mesh_.vertices.size());
            if (index < -count)
                fail_at_line(name_, line_,
                             "relative face index " + std::to_string(index) +
                                 " reaches before the first vertex (" + std::to_string(count) +
                                 " vertices so far)");
            return static_cast<std::uint32_t>(count + index);
        }
        if (static_cast<std::uint64_t>(index) > io_detail::max_count_u32)
            fail_at_line(name_, line_, "face index " + quote_token(index_text) + " exceeds 2^32-1");
        // Positive indices may name vertices defined later in the file; checked once at the end.
        if (static_cast<std::uint64_t>(index) > max_positive_index_) {
            max_positive_index_ = static_cast<std::uint64_t>(index);
            max_index_line_ = line_;
        }
        return static_cast<std::uint32_t>(index - 1);
    }

    std::string_view bytes_;
    std::string_view name_;
    TriangleMesh mesh_;
    std::vector<std::uint32_t> corners_;
    std::size_t line_ = 0;
    std::uint64_t max_positive_index_ = 0;
    std::size_t max_index_line_ = 0;
};

}  // namespace

TriangleMesh read_obj(std::string_view bytes, std::string_view name) {
    return ObjParser(bytes, name).parse();
}

TriangleMesh read_obj(const std::filesystem::path& path) {
    const std::string bytes = io_detail::read_file_bytes(path);
    return read_obj(bytes, path.string());
}

}  // namespace bvhkit

#include "bvhkit/io/ply.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <optional>
#include <vector>

#include "io_detail.hpp"

namespace bvhkit {

namespace {

using io_detail::fail;
using io_detail::fail_at_line;
using io_detail::fail_at_offset;
using io_detail::quote_token;

enum class Scalar : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

std::optional<Scalar> scalar_from_name(std::string_view n) {
    if (n == "char" || n == "int8") return Scalar::i8;
    if (n == "uchar" || n == "uint8") return Scalar::u8;
    if (n == "short" || n == "int16") return Scalar::i16;
    if (n == "ushort" || n == "uint16") return Scalar::u16;
    if (n == "int" || n == "int32") return Scalar::i32;
    if (n == "uint" || n == "uint32") return Scalar::u32;
    if (n == "float" || n == "float32") return Scalar::f32;
    if (n == "double" || n == "float64") return Scalar::f64;
    return std::nullopt;
}

std::size_t scalar_size(Scalar s) {
    switch (s) {
        case Scalar::i8:
        case Scalar::u8:
            return 1;
        case Scalar::i16:
        case Scalar::u16:
            return 2;
        case Scalar::i32:
        case Scalar::u32:
        case Scalar::f32:
            return 4;
        case Scalar::f64:
            return 8;
    }
    return 0;
}

bool is_integer(Scalar s) {
    return s != Scalar::f32 && s != Scalar::f64;
}

struct Property {
    std::string name;
    bool is_list = false;
    Scalar type = Scalar::f32;       // item type for lists
    Scalar count_type = Scalar::u8;  // lists only
};

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
    std::size_t header_line = 0;

    // Bytes (binary) or numbers (ascii) an instance takes at least: lists may be empty.
    std::uint64_t min_binary_size() const {
        std::uint64_t n = 0;
        for (const Property& p : properties) n += scalar_size(p.is_list ? p.count_type : p.type);
        return n;
    }
    std::uint64_t min_number_count() const { return properties.size(); }
    const Property* find(std::string_view n) const {
        for (const Property& p : properties)
            if (p.name == n) return &p;
        return nullptr;
    }
};

enum class Format { ascii, binary_le, binary_be };

struct Header {
    Format format = Format::ascii;
    std::vector<Element> elements;
    std::size_t data_offset = 0;  // first byte after end_header's newline
    std::size_t data_line = 0;    // line number of that byte (ascii messages)
};

// The header's statements, one function each; `line` is the statement's line (for messages).

Format parse_format(io_detail::TextCursor& tokens, std::string_view name, std::size_t line) {
    const std::string_view f = tokens.next();
    Format format = Format::ascii;
    if (f == "ascii") {
        format = Format::ascii;
    } else if (f == "binary_little_endian") {
        format = Format::binary_le;
    } else if (f == "binary_big_endian") {
        format = Format::binary_be;
    } else {
        fail_at_line(name, line,
                     "unknown format " + quote_token(f) +
                         " (known: ascii, binary_little_endian, binary_big_endian)");
    }
    if (tokens.next().empty()) fail_at_line(name, line, "the format has no version");
    return format;
}

Element parse_element(io_detail::TextCursor& tokens, const std::vector<Element>& before,
                      std::string_view name, std::size_t line) {
    Element e;
    e.name = std::string(tokens.next());
    const std::string_view count = tokens.next();
    std::int64_t n = 0;
    if (e.name.empty() || !io_detail::parse_int(count, n) || n < 0)
        fail_at_line(name, line,
                     "element " + quote_token(e.name) + " has a bad count " + quote_token(count));
    e.count = static_cast<std::uint64_t>(n);
    e.header_line = line;
    for (const Element& other : before)
        if (other.name == e.name)
            fail_at_line(name, line, "element " + quote_token(e.name) + " appears twice");
    return e;
}

Property parse_property(io_detail::TextCursor& tokens, std::string_view name, std::size_t line) {
    Property p;
    std::string_view type = tokens.next();
    if (type == "list") {
        p.is_list = true;
        const std::string_view count_type = tokens.next();
        const auto c = scalar_from_name(count_type);
        if (!c) fail_at_line(name, line, "unknown list count type " + quote_token(count_type));
        if (!is_integer(*c))
            fail_at_line(name, line,
                         "list count type " + quote_token(count_type) + " is not an integer");
        p.count_type = *c;
        type = tokens.next();
    }
    const auto t = scalar_from_name(type);
    if (!t) fail_at_line(name, line, "unknown property type " + quote_token(type));
    p.type = *t;
    p.name = std::string(tokens.next());
    if (p.name.empty()) fail_at_line(name, line, "property without a name");
    return p;
}

Header parse_header(std::string_view bytes, std::string_view name) {
    Header h;
    bool have_format = false;
    std::size_t pos = 0;
    std::size_t line = 0;
    auto next_line = [&](std::string_view& out) {
        if (pos >= bytes.size()) return false;
        const std::size_t nl = bytes.find('\n', pos);
        if (nl == std::string_view::npos)
            fail_at_line(name, line + 1, "the header does not end with 'end_header'");
        out = bytes.substr(pos, nl - pos);
        pos = nl + 1;
        ++line;
        return true;
    };
    std::string_view text;
    if (!next_line(text) || io_detail::TextCursor(text).next() != "ply")
        fail(name, "not a PLY file (it does not begin with 'ply')");
    for (;;) {
        if (!next_line(text)) fail_at_line(name, line, "the header does not end with 'end_header'");
        io_detail::TextCursor tokens(text);
        const std::string_view keyword = tokens.next();
        if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
        if (keyword == "end_header") break;
        if (keyword == "format") {
            h.format = parse_format(tokens, name, line);
            have_format = true;
        } else if (keyword == "element") {
            if (!have_format) fail_at_line(name, line, "element before the format line");
            h.elements.push_back(parse_element(tokens, h.elements, name, line));
        } else if (keyword == "property") {
            if (h.elements.empty()) fail_at_line(name, line, "property before any element");
            Property p = parse_property(tokens, name, line);
            // A repeated name would make "which x?" depend on the reader (last or first wins).
            for (const Property& other : h.elements.back().properties)
                if (other.name == p.name)
                    fail_at_line(name, line,
                                 "property " + quote_token(p.name) + " of element " +
                                     quote_token(h.elements.back().name) + " appears twice");
            h.elements.back().properties.push_back(std::move(p));
        } else {
            fail_at_line(name, line, "unknown header statement " + quote_token(keyword));
        }
    }
    if (!have_format) fail(name, "the header has no format line");
    h.data_offset = pos;
    h.data_line = line + 1;
    return h;
}

double clamp_to_float_range(double v) {
    // Converting a finite double beyond float's range is undefined behaviour; such values are inf.
    constexpr double fmax = std::numeric_limits<float>::max();
    if (v > fmax) return std::numeric_limits<double>::infinity();
    if (v < -fmax) return -std::numeric_limits<double>::infinity();
    return v;
}

// Binary data: scalars in the file's byte order, every read bounds-checked.
class BinaryReader {
  public:
    BinaryReader(std::string_view bytes, std::size_t offset, bool big_endian, std::string_view name)
        : data_(reinterpret_cast<const unsigned char*>(bytes.data())),
          size_(bytes.size()),
          pos_(offset),
          swap_(big_endian != (std::endian::native == std::endian::big)),
          name_(name) {}

    double real(Scalar s) {
        switch (s) {
            case Scalar::f32:
                return load<float>();
            case Scalar::f64:
                return load<double>();
            default:
                return static_cast<double>(integer(s));
        }
    }
    std::int64_t integer(Scalar s) {
        switch (s) {
            case Scalar::i8:
                return load<std::int8_t>();
            case Scalar::u8:
                return load<std::uint8_t>();
            case Scalar::i16:
                return load<std::int16_t>();
            case Scalar::u16:
                return load<std::uint16_t>();
            case Scalar::i32:
                return load<std::int32_t>();
            case Scalar::u32:
                return load<std::uint32_t>();
            default:
                fail_here("a floating-point value where an integer is needed");
        }
    }
    void skip_scalar(Scalar s) { skip(scalar_size(s)); }
    std::uint64_t items_bound() const { return size_ - pos_; }
    // Checked before a list's items are read one by one, so a huge count fails at once.
    void require_items(std::uint64_t count, Scalar item) {
        if (count > (size_ - pos_) / scalar_size(item))
            fail_here("a list of " + std::to_string(count) +
                      " items runs past the end of the file");
    }
    void skip_list(const Property& p) {
        const std::int64_t n = list_count(p);
        require_items(static_cast<std::uint64_t>(n), p.type);
        pos_ += static_cast<std::size_t>(n) * scalar_size(p.type);
    }
    std::int64_t list_count(const Property& p) {
        const std::size_t at = pos_;
        const std::int64_t n = integer(p.count_type);
        if (n < 0) fail_at_offset(name_, at, "list count " + std::to_string(n) + " is negative");
        return n;
    }
    void skip_element(const Element& e) {
        bool all_scalar = true;
        for (const Property& p : e.properties) all_scalar = all_scalar && !p.is_list;
        if (all_scalar) {
            // The up-front size check guarantees count * size fits in the file.
            skip(static_cast<std::size_t>(e.count * e.min_binary_size()));
            return;
        }
        for (std::uint64_t i = 0; i < e.count; ++i)
            for (const Property& p : e.properties) p.is_list ? skip_list(p) : skip_scalar(p.type);
    }
    [[noreturn]] void fail_here(const std::string& what) const {
        fail_at_offset(name_, pos_, what);
    }
    /// An error about the value just read, naming where it starts.
    [[noreturn]] void fail_at_value(const std::string& what) const {
        fail_at_offset(name_, last_value_offset_, what);
    }

  private:
    template <class T>
    T load() {
        if (size_ - pos_ < sizeof(T)) fail_here("the data ends early (truncated file)");
        last_value_offset_ = pos_;
        unsigned char raw[sizeof(T)];
        std::memcpy(raw, data_ + pos_, sizeof(T));
        if (swap_) std::reverse(raw, raw + sizeof(T));
        T v;
        std::memcpy(&v, raw, sizeof(T));
        pos_ += sizeof(T);
        return v;
    }
    void skip(std::size_t n) {
        if (size_ - pos_ < n) fail_here("the data ends early (truncated file)");
        pos_ += n;
    }

    const unsigned char* data_;
    std::size_t size_;
    std::size_t pos_;
    bool swap_;
    std::string_view name_;
    std::size_t last_value_offset_ = 0;
};

// Ascii data: whitespace-separated numbers, each range-checked against its declared type.
class AsciiReader {
  public:
    AsciiReader(std::string_view bytes, std::size_t offset, std::size_t first_line,
                std::string_view name)
        : cursor_(bytes.substr(offset), first_line), name_(name) {}

    double real(Scalar s) {
        if (is_integer(s)) return static_cast<double>(integer(s));
        const std::string_view token = next();
        double v = 0;
        if (!io_detail::parse_double(token, v))
            fail_here("value " + quote_token(token) + " is not a number");
        return v;
    }
    std::int64_t integer(Scalar s) {
        const std::string_view token = next();
        std::int64_t v = 0;
        if (!is_integer(s)) fail_here("a floating-point value where an integer is needed");
        if (!io_detail::parse_int(token, v))
            fail_here("value " + quote_token(token) + " is not an integer");
        std::int64_t lo = 0, hi = 0;
        switch (s) {
            case Scalar::i8:
                lo = -128, hi = 127;
                break;
            case Scalar::u8:
                lo = 0, hi = 255;
                break;
            case Scalar::i16:
                lo = -32768, hi = 32767;
                break;
            case Scalar::u16:
                lo = 0, hi = 65535;
                break;
            case Scalar::i32:
                lo = -2147483648LL, hi = 2147483647LL;
                break;
            default:
                lo = 0, hi = 4294967295LL;
                break;
        }
        if (v < lo || v > hi)
            fail_here("value " + quote_token(token) + " is out of its type's range");
        return v;
    }
    void skip_scalar(Scalar s) { real(s); }
    void require_items(std::uint64_t, Scalar) {}  // items are read one token at a time
    // At most this many numbers remain (each takes 2 bytes but the last).
    std::uint64_t items_bound() const { return cursor_.remaining_bytes() / 2 + 1; }
    std::int64_t list_count(const Property& p) {
        const std::int64_t n = integer(p.count_type);
        if (n < 0) fail_here("list count " + std::to_string(n) + " is negative");
        return n;
    }
    void skip_list(const Property& p) {
        const std::int64_t n = list_count(p);
        for (std::int64_t i = 0; i < n; ++i) real(p.type);
    }
    void skip_element(const Element& e) {
        if (e.properties.empty()) return;
        for (std::uint64_t i = 0; i < e.count; ++i)
            for (const Property& p : e.properties) p.is_list ? skip_list(p) : skip_scalar(p.type);
    }
    [[noreturn]] void fail_here(const std::string& what) const {
        fail_at_line(name_, cursor_.line(), what);
    }
    [[noreturn]] void fail_at_value(const std::string& what) const { fail_here(what); }

  private:
    std::string_view next() {
        const std::string_view token = cursor_.next();
        if (token.empty()) fail_here("the data ends early (truncated file)");
        return token;
    }
    io_detail::TextCursor cursor_;
    std::string_view name_;
};

// Bounded memory: every claimed element must fit in the bytes that follow the header, so nothing
// is allocated for counts a small file cannot hold.
void check_counts_fit(const Header& h, std::size_t total_size, std::string_view name) {
    std::uint64_t remaining = total_size - h.data_offset;
    const bool ascii = h.format == Format::ascii;
    if (ascii) remaining += 1;  // the last number needs no separator after it
    for (const Element& e : h.elements) {
        // ascii: at least 2 bytes (a digit and a separator) per number.
        const std::uint64_t per = ascii ? 2 * e.min_number_count() : e.min_binary_size();
        if (per == 0 || e.count == 0) continue;
        if (e.count > remaining / per)
            fail_at_line(name, e.header_line,
                         "element " + quote_token(e.name) + " claims " + std::to_string(e.count) +
                             " items, more than the " + std::to_string(total_size - h.data_offset) +
                             " bytes of data can hold");
        remaining -= e.count * per;
    }
}

template <class Reader>
class BodyReader {
  public:
    BodyReader(Reader& reader, const Header& header, TriangleMesh& mesh, std::uint64_t vertex_count,
               std::string_view name)
        : r_(reader), h_(header), mesh_(mesh), vertex_count_(vertex_count), name_(name) {}

    void read() {
        for (const Element& e : h_.elements) {
            if (e.name == "vertex") {
                read_vertices(e);
            } else if (e.name == "face") {
                read_polygons(e, face_property(e));
            } else if (e.name == "tristrips") {
                const Property* p = e.find("vertex_indices");
                if (!p || !p->is_list)
                    fail_at_line(name(), e.header_line,
                                 "element 'tristrips' has no list property 'vertex_indices'");
                read_strips(e, *p);
            } else {
                r_.skip_element(e);
            }
        }
    }

  private:
    std::string_view name() const { return name_; }

    const Property& face_property(const Element& e) {
        const Property* p = e.find("vertex_indices");
        if (!p) p = e.find("vertex_index");
        if (!p || !p->is_list)
            fail_at_line(name(), e.header_line,
                         "element 'face' has no list property 'vertex_indices' or 'vertex_index'");
        if (!is_integer(p->type))
            fail_at_line(name(), e.header_line, "face indices of a floating-point type");
        return *p;
    }

    void read_vertices(const Element& e) {
        std::vector<int> axes(e.properties.size(), -1);
        bool seen[3] = {false, false, false};
        for (std::size_t i = 0; i < e.properties.size(); ++i) {
            const Property& p = e.properties[i];
            const int axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
            if (axis < 0) continue;
            if (p.is_list)
                fail_at_line(name(), e.header_line,
                             "vertex property " + quote_token(p.name) + " is a list, not a scalar");
            axes[i] = axis;
            seen[axis] = true;
        }
        if (!seen[0] || !seen[1] || !seen[2])
            fail_at_line(name(), e.header_line, "element 'vertex' lacks property x, y or z");
        mesh_.vertices.resize(static_cast<std::size_t>(e.count));
        for (std::uint64_t v = 0; v < e.count; ++v) {
            Vec3f& out = mesh_.vertices[static_cast<std::size_t>(v)];
            for (std::size_t i = 0; i < e.properties.size(); ++i) {
                const Property& p = e.properties[i];
                if (p.is_list) {
                    r_.skip_list(p);
                } else if (axes[i] >= 0) {
                    out[static_cast<std::size_t>(axes[i])] =
                        static_cast<float>(clamp_to_float_range(r_.real(p.type)));
                } else {
                    r_.skip_scalar(p.type);
                }
            }
        }
    }

    std::uint32_t checked_index(std::int64_t index) {
        if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_count_)
            r_.fail_at_value("vertex index " + std::to_string(index) + " is out of range (" +
                             std::to_string(vertex_count_) + " vertices)");
        return static_cast<std::uint32_t>(index);
    }

    void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        if (mesh_.triangles.size() >= io_detail::max_count_u32)
            r_.fail_here("more than 2^32-1 triangles");
        mesh_.triangles.push_back({a, b, c});
    }

    void read_polygons(const Element& e, const Property& list) {
        mesh_.triangles.reserve(mesh_.triangles.size() + static_cast<std::size_t>(e.count));
        std::vector<std::uint32_t> corners;
        for (std::uint64_t f = 0; f < e.count; ++f) {
            for (const Property& p : e.properties) {
                if (&p != &list) {
                    p.is_list ? r_.skip_list(p) : r_.skip_scalar(p.type);
                    continue;
                }
                const std::int64_t n = r_.list_count(p);
                if (n < 3)
                    r_.fail_at_value("face " + std::to_string(f) + " has " + std::to_string(n) +
                                     " vertices; at least 3 are needed");
                r_.require_items(static_cast<std::uint64_t>(n), p.type);
                corners.clear();
                for (std::int64_t k = 0; k < n; ++k)
                    corners.push_back(checked_index(r_.integer(p.type)));
                for (std::size_t k = 1; k + 1 < corners.size(); ++k)
                    add_triangle(corners[0], corners[k], corners[k + 1]);
            }
        }
    }

    void read_strips(const Element& e, const Property& list) {
        if (!is_integer(list.type))
            fail_at_line(name(), e.header_line, "strip indices of a floating-point type");
        for (std::uint64_t s = 0; s < e.count; ++s) {
            for (const Property& p : e.properties) {
                if (&p != &list) {
                    p.is_list ? r_.skip_list(p) : r_.skip_scalar(p.type);
                    continue;
                }
                const std::int64_t n = r_.list_count(p);
                r_.require_items(static_cast<std::uint64_t>(n), p.type);
                const std::uint64_t bound = std::min<std::uint64_t>(n, r_.items_bound());
                mesh_.triangles.reserve(mesh_.triangles.size() + static_cast<std::size_t>(bound));
                // a, b: the two corners before the current one in this run; k: the triangle's
                // position in the run (odd ones are wound the other way round).
                std::uint32_t a = 0, b = 0;
                std::int64_t run_length = 0, k = 0;
                for (std::int64_t i = 0; i < n; ++i) {
                    const std::int64_t index = r_.integer(p.type);
                    if (index == -1) {
                        run_length = 0;
                        k = 0;
                        continue;
                    }
                    const std::uint32_t c = checked_index(index);
                    if (run_length >= 2) {
                        const bool degenerate = a == b || b == c || a == c;
                        if (!degenerate)
                            (k % 2 == 0) ? add_triangle(a, b, c) : add_triangle(b, a, c);
                        ++k;
                    }
                    a = b;
                    b = c;
                    ++run_length;
                }
            }
        }
    }

    Reader& r_;
    const Header& h_;
    TriangleMesh& mesh_;
    std::uint64_t vertex_count_;
    std::string_view name_;
};

}  // namespace

TriangleMesh read_ply(std::string_view bytes, std::string_view name) {
    if (bytes.empty()) fail(name, "the file is empty");
    const Header header = parse_header(bytes, name);
    const Element* vertex = nullptr;
    bool has_faces = false;
    for (const Element& e : header.elements) {
        if (e.name == "vertex") vertex = &e;
        if (e.name == "face" || e.name == "tristrips") has_faces = true;
    }
    if (!vertex) fail(name, "the header declares no 'vertex' element");
    if (!has_faces) fail(name, "the header declares no 'face' or 'tristrips' element");
    if (vertex->count > io_detail::max_count_u32)
        fail_at_line(name, vertex->header_line,
                     "vertex count " + std::to_string(vertex->count) + " exceeds 2^32-1");
    check_counts_fit(header, bytes.size(), name);

    TriangleMesh mesh;
    if (header.format == Format::ascii) {
        AsciiReader reader(bytes, header.data_offset, header.data_line, name);
        BodyReader(reader, header, mesh, vertex->count, name).read();
    } else {
        BinaryReader reader(bytes, header.data_offset, header.format == Format::binary_be, name);
        BodyReader(reader, header, mesh, vertex->count, name).read();
    }
    io_detail::require_triangles(mesh, name);
    return mesh;
}

TriangleMesh read_ply(const std::filesystem::path& path) {
    const std::string bytes = io_detail::read_file_bytes(path);
    return read_ply(bytes, path.string());
}

}  // namespace bvhkit

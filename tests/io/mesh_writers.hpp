#pragma once
// Test-side writers: the io tests produce every file variant themselves (OBJ face forms, PLY
// encodings and property orders, strips, STL flavours) from a known mesh, so a read can be compared
// with what was written.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::test {

/// A mesh described as polygons; `fanned()` is what a reader must return for it.
struct PolygonMesh {
    std::vector<Vec3f> vertices;
    std::vector<std::vector<std::uint32_t>> polygons;

    TriangleMesh fanned() const {
        TriangleMesh m;
        m.vertices = vertices;
        for (const auto& p : polygons)
            for (std::size_t k = 1; k + 1 < p.size(); ++k)
                m.triangles.push_back({p[0], p[k], p[k + 1]});
        return m;
    }
};

/// Random vertices (varied magnitudes and signs, exactly representable as float) and polygons of
/// 3 to 6 distinct corners.
inline PolygonMesh random_polygon_mesh(std::uint32_t vertex_count, std::uint32_t polygon_count,
                                       std::uint32_t seed, bool triangles_only = false) {
    std::mt19937 rng(seed);
    PolygonMesh m;
    for (std::uint32_t i = 0; i < vertex_count; ++i) {
        Vec3f p;
        for (int k = 0; k < 3; ++k) {
            // A signed 24-bit integer times a power of two: exact in float, printed exactly.
            const auto mantissa = static_cast<std::int32_t>(rng() % (1u << 24)) - (1 << 23);
            const int exponent = static_cast<int>(rng() % 20) - 24;
            p[k] = std::ldexp(static_cast<float>(mantissa), exponent);
        }
        m.vertices.push_back(p);
    }
    for (std::uint32_t f = 0; f < polygon_count; ++f) {
        const std::uint32_t n = triangles_only ? 3 : 3 + rng() % 4;
        std::vector<std::uint32_t> poly;
        while (poly.size() < n) {
            const std::uint32_t v = rng() % vertex_count;
            if (std::find(poly.begin(), poly.end(), v) == poly.end()) poly.push_back(v);
        }
        m.polygons.push_back(poly);
    }
    return m;
}

inline std::string format_float(float v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
    return buf;
}

// ---- OBJ ------------------------------------------------------------------------------------

enum class ObjFaceForm { plain, with_texture, with_normal, with_both, mixed };

struct ObjOptions {
    ObjFaceForm form = ObjFaceForm::plain;
    bool negative_indices = false;
    bool crlf = false;
    bool comments_and_other_statements = false;
};

inline std::string write_obj(const PolygonMesh& m, const ObjOptions& o) {
    const std::string nl = o.crlf ? "\r\n" : "\n";
    std::string s;
    if (o.comments_and_other_statements)
        s +=
            "# written by the bvhkit io tests" + nl + "mtllib scene.mtl" + nl + nl + "o thing" + nl;
    for (const Vec3f& p : m.vertices) {
        s += "v " + format_float(p[0]) + " " + format_float(p[1]) + "  " + format_float(p[2]);
        if (o.comments_and_other_statements) s += " # a vertex";
        s += nl;
        if (o.comments_and_other_statements) s += "vt 0.5 0.25" + nl + "vn 0 0 1" + nl;
    }
    if (o.comments_and_other_statements)
        s += nl + "g group one" + nl + "usemtl red" + nl + "s off" + nl + "l 1 2" + nl + "p 3" + nl;
    const auto count = static_cast<std::int64_t>(m.vertices.size());
    std::size_t f = 0;
    for (const auto& poly : m.polygons) {
        s += "f";
        for (const std::uint32_t v : poly) {
            const std::int64_t index = o.negative_indices ? static_cast<std::int64_t>(v) - count
                                                          : static_cast<std::int64_t>(v) + 1;
            const std::string i = std::to_string(index);
            ObjFaceForm form = o.form;
            if (form == ObjFaceForm::mixed) form = static_cast<ObjFaceForm>((f + v) % 4);
            switch (form) {
                case ObjFaceForm::plain:
                    s += " " + i;
                    break;
                case ObjFaceForm::with_texture:
                    s += " " + i + "/" + i;
                    break;
                case ObjFaceForm::with_normal:
                    s += " " + i + "//" + i;
                    break;
                default:
                    s += " " + i + "/" + i + "/" + i;
                    break;
            }
        }
        if (o.comments_and_other_statements && f % 3 == 0) s += "\t# trailing comment";
        s += nl;
        ++f;
    }
    return s;
}

// ---- PLY ------------------------------------------------------------------------------------

enum class PlyEncoding { ascii, binary_le, binary_be };

struct PlyOptions {
    PlyEncoding encoding = PlyEncoding::ascii;
    std::string coordinate_type = "float";  // float, double, float32, float64
    std::string count_type = "uchar";
    std::string index_type = "int";
    std::string face_list_name = "vertex_indices";
    bool shuffle_vertex_properties = false;  // extra properties, x y z in another order
    bool extra_elements = false;             // elements before and after vertex/face
    std::uint32_t seed = 1;
};

/// Serialises typed values in the file's encoding.
class PlyValueWriter {
  public:
    explicit PlyValueWriter(PlyEncoding e) : encoding_(e) {}
    void value(const std::string& type, double v) {
        if (encoding_ == PlyEncoding::ascii) {
            char buf[64];
            if (type == "float" || type == "float32") {
                std::snprintf(buf, sizeof buf, "%.9g", v);
            } else if (type == "double" || type == "float64") {
                std::snprintf(buf, sizeof buf, "%.17g", v);
            } else {
                std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(v));
            }
            out_ += pending_space_ ? " " : "";
            out_ += buf;
            pending_space_ = true;
            return;
        }
        if (type == "char" || type == "int8")
            put(static_cast<std::int8_t>(v));
        else if (type == "uchar" || type == "uint8")
            put(static_cast<std::uint8_t>(v));
        else if (type == "short" || type == "int16")
            put(static_cast<std::int16_t>(v));
        else if (type == "ushort" || type == "uint16")
            put(static_cast<std::uint16_t>(v));
        else if (type == "int" || type == "int32")
            put(static_cast<std::int32_t>(v));
        else if (type == "uint" || type == "uint32")
            put(static_cast<std::uint32_t>(v));
        else if (type == "float" || type == "float32")
            put(static_cast<float>(v));
        else
            put(v);
    }
    void end_item() {
        if (encoding_ == PlyEncoding::ascii) {
            out_ += "\n";
            pending_space_ = false;
        }
    }
    std::string take() { return std::move(out_); }

  private:
    template <class T>
    void put(T v) {
        unsigned char raw[sizeof(T)];
        std::memcpy(raw, &v, sizeof(T));
        const bool big = encoding_ == PlyEncoding::binary_be;
        if (big != (std::endian::native == std::endian::big)) std::reverse(raw, raw + sizeof(T));
        out_.append(reinterpret_cast<const char*>(raw), sizeof(T));
    }
    PlyEncoding encoding_;
    std::string out_;
    bool pending_space_ = false;
};

inline const char* ply_format_name(PlyEncoding e) {
    return e == PlyEncoding::ascii       ? "ascii"
           : e == PlyEncoding::binary_le ? "binary_little_endian"
                                         : "binary_big_endian";
}

/// One element's worth of extra data the reader must skip: a scalar and a list per item.
inline void write_extra_element(std::string& header, PlyValueWriter& w, const std::string& name,
                                int count) {
    header += "element " + name + " " + std::to_string(count) + "\n";
    header += "property ushort id\nproperty list uchar double weights\nproperty float alpha\n";
    for (int i = 0; i < count; ++i) {
        w.value("ushort", 1000 + i);
        w.value("uchar", i % 4);
        for (int k = 0; k < i % 4; ++k) w.value("double", 0.5 * k);
        w.value("float", 0.25);
        w.end_item();
    }
}

/// Faces as polygons (element `face`), or, when `strips` is given, a `tristrips` element instead.
inline std::string write_ply(const PolygonMesh& m, const PlyOptions& o,
                             const std::vector<std::vector<std::int32_t>>* strips = nullptr) {
    std::string header = std::string("ply\nformat ") + ply_format_name(o.encoding) + " 1.0\n";
    header += "comment written by the bvhkit io tests\n";
    PlyValueWriter w(o.encoding);
    if (o.extra_elements) write_extra_element(header, w, "material", 3);

    // Vertex properties: x y z plus extras, possibly shuffled.
    struct Prop {
        std::string name, type;
    };
    std::vector<Prop> props = {
        {"x", o.coordinate_type}, {"y", o.coordinate_type}, {"z", o.coordinate_type}};
    if (o.shuffle_vertex_properties) {
        props.push_back({"red", "uchar"});
        props.push_back({"confidence", "double"});
        props.push_back({"nx", "float"});
        props.push_back({"flags", "int16"});
        std::mt19937 rng(o.seed);
        std::shuffle(props.begin(), props.end(), rng);
    }
    header += "element vertex " + std::to_string(m.vertices.size()) + "\n";
    for (const Prop& p : props) header += "property " + p.type + " " + p.name + "\n";
    if (o.shuffle_vertex_properties) header += "property list uchar int16 neighbours\n";
    for (const Vec3f& v : m.vertices) {
        for (const Prop& p : props) {
            const double value = p.name == "x"     ? v[0]
                                 : p.name == "y"   ? v[1]
                                 : p.name == "z"   ? v[2]
                                 : p.name == "red" ? 200
                                                   : -3;
            w.value(p.type, value);
        }
        if (o.shuffle_vertex_properties) {
            w.value("uchar", 2);
            w.value("int16", 7);
            w.value("int16", -7);
        }
        w.end_item();
    }
    if (strips) {
        header += "element tristrips " + std::to_string(strips->size()) + "\n";
        header += "property list " + o.count_type + " " + o.index_type + " vertex_indices\n";
        for (const auto& strip : *strips) {
            w.value(o.count_type, static_cast<double>(strip.size()));
            for (const std::int32_t i : strip) w.value(o.index_type, i);
            w.end_item();
        }
    } else {
        header += "element face " + std::to_string(m.polygons.size()) + "\n";
        if (o.extra_elements) header += "property uchar flags\n";
        header +=
            "property list " + o.count_type + " " + o.index_type + " " + o.face_list_name + "\n";
        if (o.extra_elements) header += "property list uchar float texcoord\n";
        for (const auto& poly : m.polygons) {
            if (o.extra_elements) w.value("uchar", 9);
            w.value(o.count_type, static_cast<double>(poly.size()));
            for (const std::uint32_t i : poly) w.value(o.index_type, i);
            if (o.extra_elements) {
                w.value("uchar", 2);
                w.value("float", 0.5);
                w.value("float", 0.75);
            }
            w.end_item();
        }
    }
    if (o.extra_elements) write_extra_element(header, w, "edge_info", 4);
    header += "end_header\n";
    return header + w.take();
}

// ---- STL ------------------------------------------------------------------------------------

inline std::string write_stl_ascii(const TriangleMesh& m, bool crlf = false) {
    const std::string nl = crlf ? "\r\n" : "\n";
    std::string s = "solid test mesh" + nl;
    for (const auto& t : m.triangles) {
        s += "  facet normal 0 0 1" + nl + "    outer loop" + nl;
        for (const std::uint32_t i : t) {
            const Vec3f& p = m.vertices[i];
            s += "      vertex " + format_float(p[0]) + " " + format_float(p[1]) + " " +
                 format_float(p[2]) + nl;
        }
        s += "    endloop" + nl + "  endfacet" + nl;
    }
    return s + "endsolid test mesh" + nl;
}

inline std::string write_stl_binary(const TriangleMesh& m, const std::string& header_text) {
    std::string s(80, '\0');
    std::memcpy(s.data(), header_text.data(), std::min<std::size_t>(80, header_text.size()));
    auto put_u32 = [&](std::uint32_t v) {
        for (int k = 0; k < 4; ++k) s += static_cast<char>((v >> (8 * k)) & 0xff);
    };
    auto put_f32 = [&](float f) { put_u32(std::bit_cast<std::uint32_t>(f)); };
    put_u32(static_cast<std::uint32_t>(m.triangles.size()));
    for (const auto& t : m.triangles) {
        for (int k = 0; k < 3; ++k) put_f32(0.0f);  // normal
        for (const std::uint32_t i : t)
            for (int k = 0; k < 3; ++k) put_f32(m.vertices[i][k]);
        s += std::string(2, '\0');  // attribute byte count
    }
    return s;
}

}  // namespace bvhkit::test

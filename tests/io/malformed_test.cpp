// Malformed input: every case must throw bvhkit::Error (never crash, never another exception, never
// allocate for counts the file cannot hold), with messages that name the file and where.
#include <gtest/gtest.h>

#include <random>

#include "bvhkit/io/read_mesh.hpp"
#include "mesh_writers.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

std::string error_of(const std::string& bytes, const std::string& name) {
    try {
        read_mesh(bytes, name);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

#define EXPECT_ERROR_MENTIONS(bytes, name, fragment)                             \
    do {                                                                         \
        const std::string message_ = error_of(bytes, name);                      \
        EXPECT_NE(message_.find(fragment), std::string::npos)                    \
            << "message: " << message_ << "\nexpected to contain: " << fragment; \
    } while (0)

// Accepts a mesh only if it is usable: every index names a vertex.
void expect_error_or_valid(const std::string& bytes, const std::string& name,
                           const std::string& what) {
    try {
        const TriangleMesh m = read_mesh(bytes, name);
        for (const auto& t : m.triangles)
            for (const std::uint32_t i : t) ASSERT_LT(i, m.vertices.size()) << what;
    } catch (const Error&) {
    }
}

const std::string small_obj = "# small\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";

std::string small_ply(PlyEncoding enc) {
    PlyOptions o;
    o.encoding = enc;
    o.extra_elements = true;
    return write_ply(random_polygon_mesh(6, 4, 5), o);
}

std::string small_strip_ply(PlyEncoding enc) {
    const PolygonMesh m = random_polygon_mesh(6, 0, 5);
    const std::vector<std::vector<std::int32_t>> strips = {{0, 1, 2, 3, -1, 4, 5, 0}};
    PlyOptions o;
    o.encoding = enc;
    o.count_type = "int";
    return write_ply(m, o, &strips);
}

TriangleMesh two_triangles() {
    return read_obj(small_obj, "small.obj");
}

// ---- Files and emptiness ----------------------------------------------------------------------

TEST(Malformed, MissingFilesNameThePath) {
    const std::filesystem::path missing = "/nonexistent/dir/mesh";
    for (const char* ext : {".obj", ".ply", ".stl"}) {
        const auto p = missing.string() + ext;
        EXPECT_THROW(read_mesh(std::filesystem::path(p)), Error) << p;
        try {
            read_mesh(std::filesystem::path(p));
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(read_obj(std::filesystem::path("/nonexistent.obj")), Error);
    EXPECT_THROW(read_ply(std::filesystem::path("/nonexistent.ply")), Error);
    EXPECT_THROW(read_stl(std::filesystem::path("/nonexistent.stl")), Error);
    EXPECT_THROW(read_obj(std::filesystem::temp_directory_path()), Error);  // a directory
}

TEST(Malformed, EmptyFilesAndFilesWithoutTriangles) {
    for (const char* name : {"e.obj", "e.ply", "e.stl"}) EXPECT_THROW(read_mesh("", name), Error);
    EXPECT_THROW(read_obj("# only a comment\n\n", "c.obj"), Error);
    EXPECT_THROW(read_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "v.obj"), Error);
    EXPECT_THROW(read_stl("solid x\nendsolid x\n", "s.stl"), Error);
    EXPECT_THROW(read_stl(write_stl_binary(TriangleMesh{}, "empty"), "s.stl"), Error);
    EXPECT_ERROR_MENTIONS("", "e.obj", "e.obj");
}

// ---- OBJ --------------------------------------------------------------------------------------

TEST(Malformed, ObjBadStatements) {
    const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for (const std::string& bad : std::vector<std::string>{
             v3 + "f 0 1 2\n",                        // 0 is not an index
             v3 + "f 1 2 4\n",                        // out of range
             v3 + "f 1 2 99999999999\n",              // beyond 2^32-1
             v3 + "f 1 2 99999999999999999999999\n",  // beyond int64
             v3 + "f -4 1 2\n",                       // relative index before the first vertex
             v3 + "f 1 2\n",                          // too few corners
             v3 + "f\n",                              // no corners
             v3 + "f 1 a 2\n",                        // not a number
             v3 + "f 1 2 3x\n",                       // trailing junk
             v3 + "f 1/x 2 3\n",                      // malformed corner
             v3 + "f 1.5 2 3\n",                      // not an integer
             v3 + "f +-1 2 3\n",                      // sign soup
             "v 1 x 3\n" + v3 + "f 1 2 3\n",          // non-numeric coordinate
             "v 1 2\n" + v3 + "f 1 2 3\n",            // too few coordinates
             "v 1 2 3abc\n" + v3 + "f 1 2 3\n",       // trailing junk in a number
             "v 1 2 --3\n" + v3 + "f 1 2 3\n",        // not a number
             v3 + "frobnicate 1 2 3\nf 1 2 3\n",      // unknown statement
             v3 + "\x01\x02\x03\nf 1 2 3\n",          // binary junk
         })
        EXPECT_THROW(read_obj(bad, "bad.obj"), Error) << bad;
}

TEST(Malformed, ObjMessagesNameTheFileAndLine) {
    EXPECT_ERROR_MENTIONS("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "dir/mesh.obj",
                          "dir/mesh.obj:4:");
    EXPECT_ERROR_MENTIONS("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "dir/mesh.obj", "7");
    EXPECT_ERROR_MENTIONS("v 0 0 0\r\n\r\nv 1 zero 0\r\n", "m.obj", "m.obj:3:");
    EXPECT_ERROR_MENTIONS("v 0 0 0\r\n\r\nv 1 zero 0\r\n", "m.obj", "'zero'");
    EXPECT_ERROR_MENTIONS("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 3 -9 1\n", "m.obj", "m.obj:5:");
}

// ---- PLY --------------------------------------------------------------------------------------

std::string ply_header(const std::string& format, const std::string& body_elements) {
    return "ply\nformat " + format + " 1.0\n" + body_elements + "end_header\n";
}

const std::string vertex_face_header =
    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\n";

TEST(Malformed, PlyHeaders) {
    const std::string data = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    for (const std::string& bad : std::vector<std::string>{
             std::string("ply\n"),
             std::string("ply"),
             std::string("PLY\nformat ascii 1.0\nend_header\n"),
             std::string("not a ply at all\n"),
             "ply\nformat ascii 1.0\n" + vertex_face_header + data,  // no end_header
             ply_header("binary_middle_endian", vertex_face_header) + data,
             "ply\nformat ascii\n" + vertex_face_header + "end_header\n" + data,  // no version
             "ply\n" + vertex_face_header + "format ascii 1.0\nend_header\n" + data,
             ply_header("ascii", "property float x\n" + vertex_face_header) + data,
             ply_header("ascii",
                        "element vertex 3\nproperty float128 x\nproperty float y\nproperty float "
                        "z\nelement face 1\nproperty list uchar int vertex_indices\n") +
                 data,
             ply_header("ascii",
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float "
                        "z\nelement face 1\nproperty list float int vertex_indices\n") +
                 data,
             ply_header("ascii",
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float "
                        "z\nelement face 1\nproperty list uchar float vertex_indices\n") +
                 data,
             ply_header("ascii",
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float "
                        "w\nelement face 1\nproperty list uchar int vertex_indices\n") +
                 data,  // no z
             ply_header("ascii",
                        "element vertex 3\nproperty float x\nproperty float y\nproperty list "
                        "uchar float z\nelement face 1\nproperty list uchar int vertex_indices\n") +
                 data,  // z is a list
             ply_header("ascii",
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float "
                        "z\nelement face 1\nproperty list uchar int corners\n") +
                 data,  // no vertex_indices
             ply_header(
                 "ascii",
                 "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n") +
                 data,  // no faces
             ply_header("ascii", "element face 1\nproperty list uchar int vertex_indices\n") +
                 "3 0 1 2\n",                                                        // no vertices
             ply_header("ascii", vertex_face_header + "element vertex 3\n") + data,  // twice
             ply_header("ascii", "element vertex -3\n" + vertex_face_header) + data,
             ply_header("ascii", "element vertex many\n" + vertex_face_header) + data,
             ply_header("ascii", "bogus line\n" + vertex_face_header) + data,
             ply_header("ascii", "element vertex 3\nproperty float\n") + data,
         })
        EXPECT_THROW(read_ply(bad, "bad.ply"), Error) << bad;
}

TEST(Malformed, PlyData) {
    const std::string h = ply_header("ascii", vertex_face_header);
    for (const std::string& bad : std::vector<std::string>{
             h + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",     // index out of range
             h + "0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n",    // negative index
             h + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n",       // face with 2 corners
             h + "0 0 0\n1 0 0\n0 1 0\n-1 0 1 2\n",    // negative count (out of uchar's range)
             h + "0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n",   // count out of uchar's range
             h + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n",  // non-numeric
             h + "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n",   // non-integer index
             h + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n",       // ends early
             h + "0 0 0\n1 0 0\n",                     // wrong (too few) vertices
             ply_header("ascii",
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float "
                        "z\nelement face 1\nproperty list char int vertex_indices\n") +
                 "0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n",  // negative list count
             ply_header("ascii",
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float "
                        "z\nelement tristrips 1\nproperty list int int vertex_indices\n") +
                 "0 0 0\n1 0 0\n0 1 0\n4 0 1 -2 2\n",  // -2 in a strip
             ply_header("ascii",
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float "
                        "z\nelement tristrips 1\nproperty list int int vertex_indices\n") +
                 "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",  // strip index out of range
         })
        EXPECT_THROW(read_ply(bad, "bad.ply"), Error) << bad;

    // Binary: a negative list count and an index past the vertex count.
    PlyValueWriter w(PlyEncoding::binary_le);
    for (int i = 0; i < 9; ++i) w.value("float", i);
    w.value("char", -3);
    w.value("int", 0);
    const std::string header = ply_header(
        "binary_little_endian",
        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
        "property list char int vertex_indices\n");
    const std::string negative_count = header + w.take() + std::string(16, '\0');
    EXPECT_THROW(read_ply(negative_count, "neg.ply"), Error);
    EXPECT_ERROR_MENTIONS(negative_count, "neg.ply",
                          "neg.ply: byte " + std::to_string(header.size() + 36));
}

TEST(Malformed, PlyHugeCountsAreRejectedBeforeAllocating) {
    for (const char* count : {"1000000000", "1000000000000", "4294967296", "18446744073709551615"})
        for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
            const std::string claims_vertices =
                ply_header(format,
                           std::string("element vertex ") + count +
                               "\nproperty float x\nproperty float y\nproperty float z\nelement "
                               "face 1\nproperty list uchar int vertex_indices\n") +
                std::string(60, '1');
            const std::string claims_faces =
                ply_header(format,
                           std::string("element vertex 3\nproperty float x\nproperty float y\n"
                                       "property float z\nelement face ") +
                               count + "\nproperty list uchar int vertex_indices\n") +
                std::string(60, '1');
            const std::string claims_other =
                ply_header(format, "element junk " + std::string(count) + "\nproperty double a\n" +
                                       vertex_face_header) +
                std::string(60, '1');
            for (const std::string& bad :
                 std::vector<std::string>{claims_vertices, claims_faces, claims_other}) {
                ASSERT_LT(bad.size(), 400u);
                EXPECT_THROW(read_ply(bad, "huge.ply"), Error) << bad;
            }
        }
    // Binary list counts are checked against the bytes left before the items are read.
    PlyValueWriter w(PlyEncoding::binary_le);
    for (int i = 0; i < 9; ++i) w.value("float", i);
    w.value("uint", 4000000000.0);
    const std::string huge_list =
        ply_header("binary_little_endian",
                   "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "element tristrips 1\nproperty list uint int vertex_indices\n") +
        w.take() + std::string(40, '\0');
    EXPECT_THROW(read_ply(huge_list, "list.ply"), Error);
    EXPECT_ERROR_MENTIONS(huge_list, "list.ply", "byte");
}

TEST(Malformed, PlyMessagesNameTheFileAndLineOrOffset) {
    const std::string h = ply_header("ascii", vertex_face_header);
    EXPECT_ERROR_MENTIONS(h + "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "m.ply", "m.ply:13:");
    EXPECT_ERROR_MENTIONS(h + "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "m.ply", "9");
    EXPECT_ERROR_MENTIONS(ply_header("binary_middle_endian", vertex_face_header), "m.ply",
                          "m.ply:2:");
    const std::string binary = small_ply(PlyEncoding::binary_le);
    EXPECT_ERROR_MENTIONS(binary.substr(0, binary.size() - 3), "cut.ply", "cut.ply: byte ");
}

// ---- STL --------------------------------------------------------------------------------------

TEST(Malformed, StlAsciiAndBinary) {
    const std::string facet =
        "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
        "endfacet\n";
    for (const std::string& bad : std::vector<std::string>{
             std::string("solid"),
             "solid x\n" + facet,  // no endsolid
             "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 "
             "0\nvertex 1 1 0\nendloop\nendfacet\nendsolid\n",  // four corners
             "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n"
             "endfacet\nendsolid\n",  // two corners
             "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 zero 0\nvertex 1 0 0\nvertex 0 "
             "1 0\nendloop\nendfacet\nendsolid\n",  // non-numeric
             "solid x\nfacet normal 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 "
             "0\nendloop\nendfacet\nendsolid\n",  // short normal
             "solid x\nfacet\n" + facet + "endsolid\n",
             "solid x\n" + facet + "endsolid x\ngarbage\n",  // junk after the solid
             "solid x\nwhatever\nendsolid\n",
             std::string("hello, this is not an stl file at all"),
         })
        EXPECT_THROW(read_stl(bad, "bad.stl"), Error) << bad;

    const TriangleMesh m = two_triangles();
    std::string binary = write_stl_binary(m, "binary");
    // Claims more triangles than present.
    std::string wrong = binary;
    wrong[80] = 3;
    EXPECT_THROW(read_stl(wrong, "wrong.stl"), Error);
    // Claims 2^32-1 triangles in a small file.
    std::string huge = binary;
    for (int k = 80; k < 84; ++k) huge[k] = '\xff';
    EXPECT_THROW(read_stl(huge, "huge.stl"), Error);
    EXPECT_ERROR_MENTIONS(huge, "huge.stl", "huge.stl: byte 80");
    // Too short for a header and not ascii.
    EXPECT_THROW(read_stl(std::string(50, '\0'), "short.stl"), Error);
    // The same with a "solid" header: falls back to ascii, which fails.
    std::string solid_huge = write_stl_binary(m, "solid binary");
    for (int k = 80; k < 84; ++k) solid_huge[k] = '\x7f';
    EXPECT_THROW(read_stl(solid_huge, "huge.stl"), Error);
    EXPECT_ERROR_MENTIONS("solid x\nfacet normal 0 0 1\nouter lop\n", "m.stl", "m.stl:3:");
}

// ---- Truncation and garbage --------------------------------------------------------------------

bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n';
}

// Where the last token of a text file starts: prefixes ending before it cut something that matters.
std::size_t last_token_start(const std::string& text) {
    std::size_t end = text.size();
    while (end > 0 && is_blank(text[end - 1])) --end;
    std::size_t start = end;
    while (start > 0 && !is_blank(text[start - 1])) --start;
    return start;
}

TEST(Malformed, EveryTruncationOfABinaryFileIsAnError) {
    const std::vector<std::pair<std::string, std::string>> files = {
        {small_ply(PlyEncoding::binary_le), "t.ply"},
        {small_ply(PlyEncoding::binary_be), "t.ply"},
        {small_strip_ply(PlyEncoding::binary_le), "t.ply"},
        {write_stl_binary(two_triangles(), "binary"), "t.stl"},
        {write_stl_binary(two_triangles(), "solid binary"), "t.stl"},
    };
    for (const auto& [bytes, name] : files) {
        ASSERT_NO_THROW(read_mesh(bytes, name));
        for (std::size_t n = 0; n < bytes.size(); ++n)
            EXPECT_THROW(read_mesh(bytes.substr(0, n), name), Error) << name << " cut at " << n;
    }
}

TEST(Malformed, EveryTruncationOfACountedTextFileIsAnError) {
    // ascii PLY and STL know where they end; cutting inside the last token may still leave a valid
    // number or name, so only the prefixes before it must fail.
    const std::vector<std::pair<std::string, std::string>> files = {
        {small_ply(PlyEncoding::ascii), "t.ply"},
        {small_strip_ply(PlyEncoding::ascii), "t.ply"},
        {write_stl_ascii(two_triangles()), "t.stl"},
    };
    for (const auto& [bytes, name] : files) {
        ASSERT_NO_THROW(read_mesh(bytes, name));
        std::size_t must_fail_below = last_token_start(bytes);
        if (name == "t.stl") must_fail_below = bytes.rfind("endsolid") + 8;
        for (std::size_t n = 0; n < bytes.size(); ++n) {
            if (n < must_fail_below) {
                EXPECT_THROW(read_mesh(bytes.substr(0, n), name), Error) << name << " cut at " << n;
            } else {
                expect_error_or_valid(bytes.substr(0, n), name, "cut at " + std::to_string(n));
            }
        }
    }
}

TEST(Malformed, EveryTruncationOfAnObjIsAnErrorOrAValidPrefix) {
    // OBJ has no counts: a prefix may be a smaller valid mesh, but never a broken one.
    const std::string obj =
        write_obj(random_polygon_mesh(8, 6, 7), {ObjFaceForm::mixed, true, true, true});
    for (std::size_t n = 0; n < obj.size(); ++n)
        expect_error_or_valid(obj.substr(0, n), "t.obj", "cut at " + std::to_string(n));
    EXPECT_THROW(read_obj(small_obj.substr(0, small_obj.size() - 4), "t.obj"), Error);  // "f 1 3"
}

TEST(Malformed, GarbageBytesAreErrors) {
    std::mt19937 rng(17);
    for (int trial = 0; trial < 50; ++trial) {
        std::string junk(200 + rng() % 300, '\0');
        for (char& c : junk) c = static_cast<char>(rng());
        for (const char* name : {"g.obj", "g.ply", "g.stl"})
            EXPECT_THROW(read_mesh(junk, name), Error) << name << " trial " << trial;
        EXPECT_THROW(read_mesh("ply\nformat ascii 1.0\n" + junk, "g.ply"), Error);
        EXPECT_THROW(read_mesh("solid " + junk, "g.stl"), Error);
        EXPECT_THROW(read_mesh("v 1 2 3\n" + junk, "g.obj"), Error);
    }
}

}  // namespace

// Round trips: the test writes one random mesh in every supported variant and checks that reading
// gives back exactly what was written (for STL: the same corner positions, triangle by triangle).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "bvhkit/io/read_mesh.hpp"
#include "mesh_writers.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

void expect_same_mesh(const TriangleMesh& got, const TriangleMesh& want, const std::string& what) {
    EXPECT_EQ(got.vertices, want.vertices) << what;
    EXPECT_EQ(got.triangles, want.triangles) << what;
}

// STL has no shared vertices: compare corner positions in order.
void expect_same_corners(const TriangleMesh& got, const TriangleMesh& want,
                         const std::string& what) {
    ASSERT_EQ(got.triangle_count(), want.triangle_count()) << what;
    EXPECT_EQ(got.vertices.size(), 3 * want.triangle_count()) << what;
    for (std::size_t t = 0; t < want.triangle_count(); ++t)
        for (int c = 0; c < 3; ++c)
            ASSERT_EQ(got.vertices[got.triangles[t][c]], want.vertices[want.triangles[t][c]])
                << what << ": triangle " << t << " corner " << c;
}

TEST(ObjRoundTrip, EveryFaceFormIndexingAndLineEnding) {
    const PolygonMesh mesh = random_polygon_mesh(40, 60, 1);
    const TriangleMesh want = mesh.fanned();
    for (const ObjFaceForm form :
         {ObjFaceForm::plain, ObjFaceForm::with_texture, ObjFaceForm::with_normal,
          ObjFaceForm::with_both, ObjFaceForm::mixed})
        for (const bool negative : {false, true})
            for (const bool crlf : {false, true})
                for (const bool extras : {false, true}) {
                    const std::string text = write_obj(mesh, {form, negative, crlf, extras});
                    const std::string what = "form " + std::to_string(static_cast<int>(form)) +
                                             (negative ? " negative" : "") + (crlf ? " crlf" : "") +
                                             (extras ? " extras" : "");
                    expect_same_mesh(read_obj(text, "test.obj"), want, what);
                }
}

TEST(ObjRoundTrip, PolygonsAreFannedInFileOrder) {
    const TriangleMesh m = read_obj(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 1 0\nf 1 2 3 4 5\n"
        "f 5 4 3\n",
        "fan.obj");
    const std::vector<std::array<std::uint32_t, 3>> want = {
        {0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {4, 3, 2}};
    EXPECT_EQ(m.triangles, want);
}

TEST(ObjRoundTrip, RelativeIndicesReferToVerticesReadSoFar) {
    // Faces interleaved with vertices: -1 is always the latest vertex.
    const TriangleMesh m = read_obj(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 1 1 0\nf -3 -1 -2\nf 2 4 3\n", "rel.obj");
    const std::vector<std::array<std::uint32_t, 3>> want = {{0, 1, 2}, {1, 3, 2}, {1, 3, 2}};
    EXPECT_EQ(m.triangles, want);
}

TEST(ObjRoundTrip, FacesMayPrecedeTheirVertices) {
    const TriangleMesh m = read_obj("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "late.obj");
    EXPECT_EQ(m.triangle_count(), 1u);
}

TEST(ObjRoundTrip, AByteOrderMarkIsSkipped) {
    EXPECT_EQ(
        read_obj("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "bom.obj").triangle_count(),
        1u);
}

TEST(ObjRoundTrip, NonFiniteCoordinatesAreKeptAsData) {
    const TriangleMesh m =
        read_obj("v nan 0 0\nv inf -inf 1e39\nv +1.5 -0 1e-50\nf 1 2 3\n", "nonfinite.obj");
    ASSERT_EQ(m.vertices.size(), 3u);
    EXPECT_TRUE(std::isnan(m.vertices[0][0]));
    EXPECT_EQ(m.vertices[1][0], std::numeric_limits<float>::infinity());
    EXPECT_EQ(m.vertices[1][1], -std::numeric_limits<float>::infinity());
    EXPECT_EQ(m.vertices[1][2], std::numeric_limits<float>::infinity());
    EXPECT_EQ(m.vertices[2][0], 1.5f);
    EXPECT_EQ(m.vertices[2][2], 0.0f);
}

TEST(PlyRoundTrip, EveryEncodingTypeAndPropertyLayout) {
    const PolygonMesh mesh = random_polygon_mesh(50, 70, 2);
    const TriangleMesh want = mesh.fanned();
    int variant = 0;
    for (const PlyEncoding enc :
         {PlyEncoding::ascii, PlyEncoding::binary_le, PlyEncoding::binary_be})
        for (const char* coord : {"float", "double", "float32", "float64"})
            for (const auto& [count_type, index_type] :
                 std::vector<std::pair<const char*, const char*>>{{"uchar", "int"},
                                                                  {"uint8", "uint32"},
                                                                  {"ushort", "int"},
                                                                  {"int", "uint"},
                                                                  {"char", "int16"},
                                                                  {"uint", "uchar"}})
                for (const bool shuffle : {false, true})
                    for (const bool extra : {false, true}) {
                        PlyOptions o;
                        o.encoding = enc;
                        o.coordinate_type = coord;
                        o.count_type = count_type;
                        o.index_type = index_type;
                        o.shuffle_vertex_properties = shuffle;
                        o.extra_elements = extra;
                        o.face_list_name = variant % 2 ? "vertex_index" : "vertex_indices";
                        o.seed = static_cast<std::uint32_t>(++variant);
                        const std::string what = std::string(ply_format_name(enc)) + " " + coord +
                                                 " " + count_type + "/" + index_type +
                                                 (shuffle ? " shuffled" : "") +
                                                 (extra ? " extra-elements" : "");
                        expect_same_mesh(read_ply(write_ply(mesh, o), "test.ply"), want, what);
                    }
}

TEST(PlyRoundTrip, IntegerCoordinatesAndNonFiniteValues) {
    const std::string text =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty short x\nproperty uchar y\n"
        "property double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
        "-5 200 nan\n7 0 inf\n0 1 1e300\n3 0 1 2\n";
    const TriangleMesh m = read_ply(text, "ints.ply");
    EXPECT_EQ(m.vertices[0][0], -5.0f);
    EXPECT_EQ(m.vertices[0][1], 200.0f);
    EXPECT_TRUE(std::isnan(m.vertices[0][2]));
    EXPECT_EQ(m.vertices[1][2], std::numeric_limits<float>::infinity());
    EXPECT_EQ(m.vertices[2][2], std::numeric_limits<float>::infinity());  // beyond float's range
}

TEST(PlyRoundTrip, ElementsInAnyOrder) {
    // Faces before vertices: indices are checked against the header's vertex count.
    const std::string text =
        "ply\r\nformat ascii 1.0\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\n"
        "element vertex 3\r\nproperty float z\r\nproperty float y\r\nproperty float x\r\n"
        "end_header\r\n3 2 1 0\r\n1 2 3\r\n4 5 6\r\n7 8 9\r\n";
    const TriangleMesh m = read_ply(text, "order.ply");
    ASSERT_EQ(m.triangle_count(), 1u);
    EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{2, 1, 0}));
    EXPECT_EQ(m.vertices[0], Vec3f(3, 2, 1));
    EXPECT_EQ(m.vertices[2], Vec3f(9, 8, 7));
}

// Encodes known triangles as strips: pairs (a,b,c),(c,b,d) sharing an edge become "a b c d"; runs
// are separated by -1 or joined by repeated vertices (degenerate triangles) keeping the parity.
struct StripFixture {
    PolygonMesh mesh;
    std::vector<std::vector<std::int32_t>> strips;
};

StripFixture make_strip_fixture(std::uint32_t seed) {
    std::mt19937 rng(seed);
    StripFixture f;
    f.mesh = random_polygon_mesh(30, 0, seed);
    auto distinct = [&](std::vector<std::uint32_t> avoid) {
        for (;;) {
            const std::uint32_t v = rng() % 30;
            if (std::find(avoid.begin(), avoid.end(), v) == avoid.end()) return v;
        }
    };
    for (int s = 0; s < 12; ++s) {
        std::vector<std::int32_t> strip;
        const int chunks = 1 + static_cast<int>(rng() % 4);
        for (int c = 0; c < chunks; ++c) {
            std::vector<std::int32_t> chunk;
            const std::uint32_t a = distinct({}), b = distinct({a}), cc = distinct({a, b});
            f.mesh.polygons.push_back({a, b, cc});
            chunk = {std::int32_t(a), std::int32_t(b), std::int32_t(cc)};
            if (rng() % 2) {
                const std::uint32_t d = distinct({b, cc});
                f.mesh.polygons.push_back({cc, b, d});
                chunk.push_back(std::int32_t(d));
            }
            if (!strip.empty()) {
                if (rng() % 2) {
                    strip.push_back(-1);  // restart
                } else {
                    // Degenerate joint: repeat the last vertex and the chunk's first, then pad so
                    // the chunk starts at an even position (even triangles keep their winding).
                    std::size_t run_start = 0;
                    for (std::size_t i = 0; i < strip.size(); ++i)
                        if (strip[i] == -1) run_start = i + 1;
                    strip.push_back(strip.back());
                    strip.push_back(chunk[0]);
                    if ((strip.size() - run_start) % 2 == 1) strip.push_back(chunk[0]);
                }
            }
            strip.insert(strip.end(), chunk.begin(), chunk.end());
        }
        if (rng() % 3 == 0) strip.push_back(-1);  // a trailing restart is harmless
        f.strips.push_back(strip);
    }
    return f;
}

TEST(PlyRoundTrip, TriangleStripsWithRestartsAndDegenerateJoints) {
    for (std::uint32_t seed = 1; seed <= 20; ++seed) {
        const StripFixture f = make_strip_fixture(seed);
        const TriangleMesh want = f.mesh.fanned();
        for (const PlyEncoding enc :
             {PlyEncoding::ascii, PlyEncoding::binary_le, PlyEncoding::binary_be})
            for (const char* index_type : {"int", "int32", "short"}) {
                PlyOptions o;
                o.encoding = enc;
                o.count_type = "int";
                o.index_type = index_type;
                o.extra_elements = seed % 2 == 0;
                expect_same_mesh(
                    read_ply(write_ply(f.mesh, o, &f.strips), "strips.ply"), want,
                    std::string(ply_format_name(enc)) + " seed " + std::to_string(seed));
            }
    }
}

TEST(PlyRoundTrip, AStripOverAGridKeepsOneWinding) {
    // 0 1 2 above 3 4 5 (a 2x1 grid of quads); the strip 3 0 4 1 5 2 covers it with 4 triangles
    // that must all turn the same way in the plane.
    const std::string text =
        "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
        "property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n"
        "0 1 0\n1 1 0\n2 1 0\n0 0 0\n1 0 0\n2 0 0\n6 3 0 4 1 5 2\n";
    const TriangleMesh m = read_ply(text, "grid.ply");
    const std::vector<std::array<std::uint32_t, 3>> want = {
        {3, 0, 4}, {4, 0, 1}, {4, 1, 5}, {5, 1, 2}};
    EXPECT_EQ(m.triangles, want);
    for (const auto& t : m.triangles) {
        const Vec3f n =
            cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]);
        EXPECT_LT(n[2], 0.0f);
    }
}

TEST(StlRoundTrip, AsciiAndBinaryIncludingASolidHeader) {
    const TriangleMesh want = random_polygon_mesh(40, 50, 3, /*triangles_only=*/true).fanned();
    expect_same_corners(read_stl(write_stl_ascii(want), "a.stl"), want, "ascii");
    expect_same_corners(read_stl(write_stl_ascii(want, true), "a.stl"), want, "ascii crlf");
    expect_same_corners(read_stl(write_stl_binary(want, "binary from the tests"), "b.stl"), want,
                        "binary");
    expect_same_corners(read_stl(write_stl_binary(want, "solid but really binary"), "b.stl"), want,
                        "binary with a solid header");
    expect_same_corners(read_stl(write_stl_binary(want, "solid\nfacet normal 0 0 1\n"), "b.stl"),
                        want, "binary with an ascii-looking header");
    // Trailing bytes after the declared triangles are tolerated (never fewer bytes than claimed).
    expect_same_corners(read_stl(write_stl_binary(want, "padded") + std::string(7, '\0'), "b.stl"),
                        want, "binary with padding");
    // Several solids in one ascii file.
    const std::string two = write_stl_ascii(want) + write_stl_ascii(want);
    EXPECT_EQ(read_stl(two, "two.stl").triangle_count(), 2 * want.triangle_count());
}

TEST(ReadMesh, FilesOnDiskAndExtensionDispatch) {
    const auto dir = std::filesystem::temp_directory_path() / "bvhkit_io_round_trip";
    std::filesystem::create_directories(dir);
    const PolygonMesh mesh = random_polygon_mesh(20, 15, 4);
    const TriangleMesh want = mesh.fanned();
    const TriangleMesh tris = random_polygon_mesh(20, 15, 4, true).fanned();
    auto save = [&](const std::string& name, const std::string& bytes) {
        std::ofstream(dir / name, std::ios::binary) << bytes;
        return dir / name;
    };
    PlyOptions binary;
    binary.encoding = PlyEncoding::binary_le;
    expect_same_mesh(read_mesh(save("m.OBJ", write_obj(mesh, {}))), want, "obj");
    expect_same_mesh(read_mesh(save("m.Ply", write_ply(mesh, binary))), want, "ply");
    expect_same_corners(read_mesh(save("m.stl", write_stl_binary(tris, "x"))), tris, "stl");
    expect_same_mesh(read_obj(dir / "m.OBJ"), want, "read_obj");
    expect_same_mesh(read_ply(dir / "m.Ply"), want, "read_ply");
    expect_same_corners(read_stl(dir / "m.stl"), tris, "read_stl");
    EXPECT_THROW(read_mesh(save("m.off", "OFF\n")), Error);
    EXPECT_THROW(read_mesh(save("noext", "v 0 0 0\n")), Error);
    std::filesystem::remove_all(dir);
}

}  // namespace

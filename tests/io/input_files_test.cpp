// What the file readers do with files that are not mesh files at all (a device that never ends, a
// FIFO that never delivers, a file that is missing), with indices that name no vertex, and with the
// format corners a careful writer can produce (a binary STL whose header says "solid" followed by
// padding) or a careless one (a PLY property named twice). Also the ray and hit files' writers when
// the bytes cannot be written.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>

#include "bvhkit/io/ray_files.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "special_files.hpp"

using namespace bvhkit;

namespace {

std::string input_error_of(const std::function<void()>& body) {
    try {
        body();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

bool mentions(const std::string& message, const std::string& fragment) {
    return message.find(fragment) != std::string::npos;
}

const std::string kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

}  // namespace

// Before the check, /dev/zero read as an empty file (a misleading "no triangles") and the CLI's and
// Python's readers, which read to the end, grew without bound.
TEST(InputFiles, DevZeroIsRefusedAsNotARegularFile) {
    const std::vector<std::function<void()>> readers = {
        [] { read_obj(std::filesystem::path("/dev/zero")); },
        [] { read_ply(std::filesystem::path("/dev/zero")); },
        [] { read_stl(std::filesystem::path("/dev/zero")); },
        [] { read_rays("/dev/zero"); },
        [] { read_hits("/dev/zero"); },
    };
    for (std::size_t i = 0; i < readers.size(); ++i) {
        const std::string message = input_error_of(readers[i]);
        EXPECT_TRUE(mentions(message, "not a regular file")) << i << ": " << message;
        EXPECT_TRUE(mentions(message, "/dev/zero")) << i << ": " << message;
    }
    EXPECT_TRUE(mentions(input_error_of([] { load_mesh("/dev/zero"); }), "not a regular file"));
}

TEST(InputFiles, FifoIsRefusedWithoutBlocking) {
    const test::ScratchDir dir("input_fifo");
    for (const char* name : {"mesh.obj", "mesh.ply", "mesh.stl", "rays.bin"}) {
        const std::filesystem::path fifo = dir / name;
        ASSERT_TRUE(test::make_fifo(fifo)) << fifo;
        const bool rays = std::string(name) == "rays.bin";
        std::exception_ptr thrown;
        const bool returned = test::returns_without_blocking(
            [&] {
                if (rays)
                    read_rays(fifo);
                else
                    read_mesh(fifo);
            },
            fifo, thrown);
        EXPECT_TRUE(returned) << name << ": the reader blocked on a FIFO";
        ASSERT_TRUE(thrown) << name;
        try {
            std::rethrow_exception(thrown);
        } catch (const Error& e) {
            EXPECT_TRUE(mentions(e.what(), "not a regular file")) << name << ": " << e.what();
        } catch (...) {
            ADD_FAILURE() << name << ": not a bvhkit::Error";
        }
    }
}

// A missing file is FileNotFoundError (an Error) so callers can tell it from a damaged file.
TEST(InputFiles, MissingFileIsFileNotFoundError) {
    const test::ScratchDir dir("input_missing");
    const std::filesystem::path missing = dir / "missing.obj";
    EXPECT_THROW(read_mesh(missing), FileNotFoundError);
    EXPECT_THROW(read_rays(dir / "missing.bin"), FileNotFoundError);
    EXPECT_THROW(load_mesh(missing.string()), FileNotFoundError);
    // A damaged file is an Error but not FileNotFoundError.
    std::ofstream(dir / "bad.obj") << "f 1 2 3\n";
    try {
        read_mesh(dir / "bad.obj");
        ADD_FAILURE() << "bad.obj was accepted";
    } catch (const FileNotFoundError&) {
        ADD_FAILURE() << "a damaged file reported as missing";
    } catch (const Error&) {
    }
}

// -2^63 cannot be negated in int64: the reader once wrapped it to vertex 3 of a 3-vertex mesh.
TEST(InputFiles, ObjIndexOutsideTheVerticesIsAnErrorNamingTheLine) {
    for (const char* corner : {"-9223372036854775808", "-9223372036854775807", "-4", "4",
                               "9223372036854775807", "4294967296", "-4294967297"}) {
        const std::string obj = kTriangleObj + "f 1 2 " + corner + "\n";
        const std::string message = input_error_of([&] { read_obj(obj, "edge.obj"); });
        EXPECT_TRUE(mentions(message, "edge.obj:4")) << corner << ": " << message;
    }
    // The extremes that are in range still resolve to the right vertex.
    const TriangleMesh m = read_obj(kTriangleObj + "f -3 2 3\n", "ok.obj");
    ASSERT_EQ(m.triangles.size(), 1u);
    EXPECT_EQ(m.triangles[0][0], 0u);
}

namespace {

void put_u32(std::string& s, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) s.push_back(char((v >> (8 * i)) & 0xff));
}
void put_f32(std::string& s, float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    put_u32(s, v);
}

// A binary STL of `n` triangles (corner k of triangle t at (t, k, 0.5)) whose 80-byte header starts
// with "solid", as many exporters write it.
std::string solid_headed_binary_stl(std::uint32_t n) {
    std::string s = "solid exported-by-a-cad-tool";
    s.resize(80, ' ');
    put_u32(s, n);
    for (std::uint32_t t = 0; t < n; ++t) {
        for (int i = 0; i < 3; ++i) put_f32(s, 0.0f);  // normal
        for (int k = 0; k < 3; ++k) {
            put_f32(s, float(t));
            put_f32(s, float(k));
            put_f32(s, 0.5f);
        }
        s += std::string(2, '\0');  // attribute bytes
    }
    return s;
}

}  // namespace

TEST(InputFiles, BinaryStlWithSolidHeaderAndTrailingBytesIsReadAsBinary) {
    for (const std::size_t trailing : {std::size_t(0), std::size_t(1), std::size_t(37)}) {
        const std::string stl = solid_headed_binary_stl(2) + std::string(trailing, '\0');
        TriangleMesh m;
        ASSERT_NO_THROW(m = read_stl(stl, "padded.stl")) << trailing;
        ASSERT_EQ(m.triangles.size(), 2u);
        ASSERT_EQ(m.vertices.size(), 6u);
        for (std::uint32_t t = 0; t < 2; ++t)
            for (std::uint32_t k = 0; k < 3; ++k) {
                const Vec3f v = m.vertices[m.triangles[t][k]];
                EXPECT_EQ(v[0], float(t));
                EXPECT_EQ(v[1], float(k));
                EXPECT_EQ(v[2], 0.5f);
            }
    }
    // An ASCII file still reads as ASCII, and a broken one still gets the ASCII message.
    const std::string ascii =
        "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid s\n";
    EXPECT_EQ(read_stl(ascii, "a.stl").triangles.size(), 1u);
    EXPECT_TRUE(
        mentions(input_error_of([&] { read_stl(ascii.substr(0, 60), "a.stl"); }), "a.stl:"));
}

TEST(InputFiles, PlyPropertyNamedTwiceIsAnErrorNamingIt) {
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nproperty float x\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n"
        "0 0 0 5\n1 0 0 5\n0 1 0 5\n3 0 1 2\n";
    const std::string message = input_error_of([&] { read_ply(ply, "twice.ply"); });
    EXPECT_TRUE(mentions(message, "twice.ply:7")) << message;
    EXPECT_TRUE(mentions(message, "'x'")) << message;
}

// The ray and hit writers: a device that is full is an Error naming it (the stream's buffer once
// hid the failure), and an ordinary target is replaced whole.
TEST(InputFiles, RayFileWritersReportFailureAndReplaceWhole) {
    const std::vector<Ray3f> rays(1000, Ray3f({0, 0, 0}, {0, 0, 1}, 0, 1));
    const std::string message = input_error_of([&] { write_rays("/dev/full", rays); });
    EXPECT_TRUE(mentions(message, "/dev/full")) << message;
    EXPECT_TRUE(mentions(input_error_of([&] {
                             write_hits("/dev/full", std::vector<FileHit>(10, FileHit{1, 2}));
                         }),
                         "/dev/full"));
    const test::ScratchDir dir("ray_writer");
    write_rays(dir / "rays.bin", rays);
    write_rays(dir / "rays.bin", std::vector<Ray3f>(3, rays[0]));
    EXPECT_EQ(read_rays(dir / "rays.bin").size(), 3u);
    EXPECT_EQ(dir.names(), std::vector<std::string>{"rays.bin"});
}
